// Copies each vertex's listed higher neighbours to its scanned edge offset as edges (v, u).
// Relies on edge_offsets being the exclusive scan of edges_count's counts.

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> offsets: array<u32>;             // per vertex + 1
@group(0) @binding(2) var<storage, read> neighbours: array<u32>;          // 2 per corner
@group(0) @binding(3) var<storage, read> edge_offsets: array<u32>;        // per vertex + 1
@group(0) @binding(4) var<storage, read_write> edges: array<vec2<u32>>;   // per edge

@compute @workgroup_size(256)
fn edges_fill(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let v = gid.x + gid.y * nwg.x * WG;
    if (v >= params.vertex_count) {
        return;
    }
    let lo = edge_offsets[v];
    let n = edge_offsets[v + 1u] - lo;
    let base = 2u * offsets[v];
    for (var i = 0u; i < n; i = i + 1u) {
        edges[lo + i] = vec2<u32>(v, neighbours[base + i]);
    }
}
