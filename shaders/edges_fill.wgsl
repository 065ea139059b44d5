// Writes each vertex's edges (v, u), u > v, at its scanned offset, in the order edges_count
// counted them. Relies on edge_offsets being the exclusive scan of edge_counts.

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> indices: array<u32>;             // per face × 3
@group(0) @binding(2) var<storage, read> offsets: array<u32>;             // per vertex + 1
@group(0) @binding(3) var<storage, read> vertex_faces: array<u32>;        // per corner
@group(0) @binding(4) var<storage, read> edge_offsets: array<u32>;        // per vertex + 1
@group(0) @binding(5) var<storage, read_write> edges: array<vec2<u32>>;   // per edge

@compute @workgroup_size(256)
fn edges_fill(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let v = gid.x + gid.y * nwg.x * WG;
    if (v >= params.vertex_count) {
        return;
    }
    let lo = offsets[v];
    let hi = offsets[v + 1u];
    var slot = edge_offsets[v];
    for (var i = lo; i < hi; i = i + 1u) {
        let t = face_of(vertex_faces[i]);
        for (var k = 0u; k < 3u; k = k + 1u) {
            if (t[k] > v && !list_has(lo, i, t[k])) {
                edges[slot] = vec2<u32>(v, t[k]);
                slot = slot + 1u;
            }
        }
    }
}
