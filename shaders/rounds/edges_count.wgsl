// Lists each vertex's higher-id neighbours (first occurrence in its sorted face list) into two
// slots per corner of its list, counts them, and resets its collapse remap to itself. Relies on
// sorted face lists for stable edge ids; a face adds at most two neighbours.
// A neighbour is new when the vertex's own list so far lacks it: one load per listed neighbour,
// where scanning the earlier faces for it took four per face (1.81 s of lavapipe time on the 1M
// scan at 1%, the second slowest stage).

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> indices: array<u32>;          // per face × 3
@group(0) @binding(2) var<storage, read> offsets: array<u32>;          // per vertex + 1
@group(0) @binding(3) var<storage, read> vertex_faces: array<u32>;     // per corner
@group(0) @binding(4) var<storage, read_write> edge_counts: array<u32>; // per vertex + 1
@group(0) @binding(5) var<storage, read_write> remap: array<u32>;       // per vertex
@group(0) @binding(6) var<storage, read_write> neighbours: array<u32>;  // 2 per corner

// Some of the n neighbours listed from slot base on is u.
fn listed(base: u32, n: u32, u: u32) -> bool {
    for (var j = 0u; j < n; j = j + 1u) {
        if (neighbours[base + j] == u) { return true; }
    }
    return false;
}

@compute @workgroup_size(256)
fn edges_count(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let v = gid.x + gid.y * nwg.x * WG;
    if (v >= params.vertex_count) {
        return;
    }
    let lo = offsets[v];
    let hi = offsets[v + 1u];
    var n = 0u;
    for (var i = lo; i < hi; i = i + 1u) {
        let t = face_of(vertex_faces[i]);
        for (var k = 0u; k < 3u; k = k + 1u) {
            if (t[k] > v && !listed(2u * lo, n, t[k])) {
                neighbours[2u * lo + n] = t[k];
                n = n + 1u;
            }
        }
    }
    edge_counts[v] = n;
    remap[v] = v;
}
