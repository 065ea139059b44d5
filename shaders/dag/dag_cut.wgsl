// Per cluster of a DAG: whether it is in the cut for the camera (its own error projects to at
// most the threshold, its group's to more: Karis et al. 2021), whether its bounds meet the view
// frustum, and its indirect draw over its triangles' corners (the viewer pulls its vertices:
// one instance when drawn, none otherwise; the instance numbers the cluster where the device
// reads indirect first instances, for the cluster and level colours). Twin of src/dag/cut.rs::dag_cut; the
// command line's `dag cut --camera` runs the same test (`passes`), so the two agree.

// Twin of crate::compute::types::CutParams.
struct CutParams {
    // The eye (w unused).
    eye: vec4<f32>,
    // The frustum's planes: a point p is inside when dot(n.xyz, p) + n.w >= 0 for all six.
    planes: array<vec4<f32>, 6>,
    // Pixels per unit of error at unit distance, over the threshold in pixels.
    scale: f32,
    clusters: u32,
    // 1: clusters outside the frustum are not drawn.
    cull: u32,
    // 1: each draw's first instance is its cluster, level in the top 8 bits (the device
    // reads indirect first instances); 0 otherwise.
    number: u32,
}

// Twin of crate::compute::types::CornerDraw: a non-indexed indirect draw, the corners of
// `vertex_count / 3` triangles from corner `first_vertex`.
struct CornerDraw {
    vertex_count: u32,
    instance_count: u32,
    first_vertex: u32,
    first_instance: u32,
}

// Twin of crate::compute::types::CutCluster.
struct CutCluster {
    lod_sphere: vec4<f32>,
    bounds: vec4<f32>,
    // The sphere and error of the group that simplifies it (unused for a root).
    group_sphere: vec4<f32>,
    error: f32,
    group_error: f32,
    first_triangle: u32,
    triangle_count: u32,
    // 1 for a root: no group, always coarse enough.
    root: u32,
    depth: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(0) @binding(0) var<uniform> cut: CutParams;
@group(0) @binding(1) var<storage, read> clusters: array<CutCluster>;
@group(0) @binding(2) var<storage, read_write> draws: array<CornerDraw>;           // per cluster
// In the cut, drawn, triangles drawn, (unused).
@group(0) @binding(3) var<storage, read_write> cut_counts: array<atomic<u32>, 4>;

// Whether an error `e` at sphere `s` projects to at most the threshold, with no square root or
// division: e * scale / (|s - eye| - r) <= 1, i.e. (e * scale + r)^2 <= |s - eye|^2 (inside
// the sphere the projection is unbounded and the test fails, unless e is 0).
fn passes(s: vec4<f32>, e: f32) -> bool {
    if (e <= 0.0) {
        return true;
    }
    let d = s.xyz - cut.eye.xyz;
    let reach = e * cut.scale + s.w;
    return reach * reach <= d.x * d.x + d.y * d.y + d.z * d.z;
}

// Whether the sphere `b` meets the frustum.
fn in_view(b: vec4<f32>) -> bool {
    for (var i = 0u; i < 6u; i++) {
        let n = cut.planes[i];
        if (n.x * b.x + n.y * b.y + n.z * b.z + n.w < -b.w) {
            return false;
        }
    }
    return true;
}

@compute @workgroup_size(256)
fn dag_cut(
    @builtin(global_invocation_id) gid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
) {
    let c = gid.x + gid.y * nwg.x * WG;
    if (c >= cut.clusters) {
        return;
    }
    let k = clusters[c];
    let in_cut = passes(k.lod_sphere, k.error)
        && (k.root != 0u || !passes(k.group_sphere, k.group_error));
    let drawn = in_cut && (cut.cull == 0u || in_view(k.bounds));
    var d: CornerDraw;
    d.vertex_count = 3u * k.triangle_count;
    d.instance_count = select(0u, 1u, drawn);
    d.first_vertex = 3u * k.first_triangle;
    d.first_instance = select(0u, (min(k.depth, 255u) << 24u) | c, cut.number != 0u);
    draws[c] = d;
    if (in_cut) {
        atomicAdd(&cut_counts[0], 1u);
    }
    if (drawn) {
        atomicAdd(&cut_counts[1], 1u);
        atomicAdd(&cut_counts[2], k.triangle_count);
    }
}
