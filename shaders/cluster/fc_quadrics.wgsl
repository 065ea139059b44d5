// Per floating cell: gathers the area-weighted planes of its members' faces (members in vertex
// order) relative to its centre, then places its vertex as stages::place does, inside the box of
// half-side r about the centre (a locked centre: itself); both in place.wgsl. Relies on
// adjacency_sort having ordered each vertex's faces and the sort by cluster being stable.

@group(0) @binding(0) var<uniform> cluster: ClusterParams;
@group(0) @binding(1) var<uniform> floating: FloatParams;
@group(0) @binding(2) var<storage, read> positions: array<vec4<f32>>;        // per vertex
@group(0) @binding(3) var<storage, read> indices: array<u32>;                // per face × 3
@group(0) @binding(4) var<storage, read> offsets: array<u32>;                // per vertex + 1
@group(0) @binding(5) var<storage, read> vertex_faces: array<u32>;           // per corner
@group(0) @binding(6) var<storage, read> face_normals: array<vec4<f32>>;     // per face
@group(0) @binding(7) var<storage, read> locked: array<u32>;                 // per vertex
@group(0) @binding(8) var<storage, read> fc_centre: array<u32>;              // per vertex
@group(0) @binding(9) var<storage, read> sort_vals: array<u32>;              // per vertex, by cluster
@group(0) @binding(10) var<storage, read> cell_head: array<u32>;             // per vertex + 1
@group(0) @binding(11) var<storage, read> cell_start: array<u32>;            // per cluster + 1
@group(0) @binding(12) var<storage, read_write> cluster_placed: array<ClusterPlaced>; // per cluster
@group(0) @binding(13) var<storage, read_write> cluster_quadric: array<Quadric>;     // per cluster

@compute @workgroup_size(256)
fn fc_quadrics(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = gid.x + gid.y * nwg.x * WG;
    if (k >= cell_head[cluster.vertex_count]) {
        return;
    }
    let first = cell_start[k];
    let last = cell_start[k + 1u];
    // Every member's centre is the cluster's.
    let centre = fc_centre[sort_vals[first]];
    let o = pos_of(centre);
    var half = floating.r;
    if (locked[centre] != 0u) {
        half = 0.0;
    }
    let lo = vec3<f32>(o.x - half, o.y - half, o.z - half);
    let hi = vec3<f32>(o.x + half, o.y + half, o.z + half);
    let q = gather_members(first, last, o);
    let placed = place_members(q, first, last, o, lo, hi);
    cluster_placed[k] = placed.placed;
    cluster_quadric[k] = placed.quadric;
}
