// Per cluster (a whole cell): gathers the area-weighted planes of its members' faces (members in
// sorted (key, id) order) relative to the cell centre, then places its vertex as stages::place
// does, inside the cell (both in place.wgsl). Relies on adjacency_sort having ordered each
// vertex's faces: the sums are in a fixed order.

@group(0) @binding(0) var<uniform> cluster: ClusterParams;
@group(0) @binding(1) var<storage, read> positions: array<vec4<f32>>;        // per vertex
@group(0) @binding(2) var<storage, read> indices: array<u32>;                // per face × 3
@group(0) @binding(3) var<storage, read> offsets: array<u32>;                // per vertex + 1
@group(0) @binding(4) var<storage, read> vertex_faces: array<u32>;           // per corner
@group(0) @binding(5) var<storage, read> face_normals: array<vec4<f32>>;     // per face
@group(0) @binding(6) var<storage, read> sort_vals: array<u32>;              // per vertex, sorted
@group(0) @binding(7) var<storage, read> cell_head: array<u32>;              // per vertex + 1
@group(0) @binding(8) var<storage, read> cell_start: array<u32>;             // per cell + 1
@group(0) @binding(9) var<storage, read> cell_key: array<u32>;               // per cell
@group(0) @binding(10) var<storage, read_write> cluster_placed: array<ClusterPlaced>; // per cell
@group(0) @binding(11) var<storage, read_write> cluster_quadric: array<Quadric>;     // per cell

fn compact3(k0: u32) -> u32 {
    var x = k0 & 0x09249249u;
    x = (x | (x >> 2u)) & 0x030c30c3u;
    x = (x | (x >> 4u)) & 0x0300f00fu;
    x = (x | (x >> 8u)) & 0x030000ffu;
    return (x | (x >> 16u)) & 0x3ffu;
}

@compute @workgroup_size(256)
fn cluster_quadrics(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = gid.x + gid.y * nwg.x * WG;
    if (k >= cell_head[cluster.vertex_count]) {
        return;
    }
    let first = cell_start[k];
    let last = cell_start[k + 1u];
    var o = pos_of(sort_vals[first]);
    var lo = o;
    var hi = o;
    // A lone member is its own origin and box (cluster_quadric's rule); a shared cell's origin
    // is its centre (Grid::cell_box).
    if (last - first > 1u) {
        let key = cell_key[k];
        let c = vec3<f32>(vec3<u32>(compact3(key), compact3(key >> 1u), compact3(key >> 2u)));
        let h = cluster.lo_h.w;
        lo = vec3<f32>(cluster.lo_h.x + c.x * h, cluster.lo_h.y + c.y * h, cluster.lo_h.z + c.z * h);
        hi = vec3<f32>(lo.x + h, lo.y + h, lo.z + h);
        o = 0.5 * (lo + hi);
    }
    let q = gather_members(first, last, o);
    let placed = place_members(q, first, last, o, lo, hi);
    cluster_placed[k] = placed.placed;
    cluster_quadric[k] = placed.quadric;
}
