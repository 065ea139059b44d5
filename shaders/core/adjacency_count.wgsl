// Counts the faces around each vertex (one atomic add per corner) for the vertex→face CSR.
// Relies on counts being cleared and vertex_count + 1 long (the scan writes its total there).

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> indices: array<u32>;              // per face × 3
@group(0) @binding(2) var<storage, read_write> counts: array<atomic<u32>>; // per vertex + 1

@compute @workgroup_size(256)
fn adjacency_count(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let f = gid.x + gid.y * nwg.x * WG;
    if (f >= params.face_count) {
        return;
    }
    for (var k = 0u; k < 3u; k = k + 1u) {
        atomicAdd(&counts[indices[3u * f + k]], 1u);
    }
}
