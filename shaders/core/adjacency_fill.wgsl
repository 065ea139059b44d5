// Scatters each face id into its corners' lists at offsets[v] + cursor[v]++. The order within a
// list depends on thread timing; adjacency_sort fixes it. Relies on cursor being cleared.

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> indices: array<u32>;               // per face × 3
@group(0) @binding(2) var<storage, read> offsets: array<u32>;               // per vertex + 1
@group(0) @binding(3) var<storage, read_write> cursor: array<atomic<u32>>;  // per vertex
@group(0) @binding(4) var<storage, read_write> vertex_faces: array<u32>;    // per corner

@compute @workgroup_size(256)
fn adjacency_fill(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let f = gid.x + gid.y * nwg.x * WG;
    if (f >= params.face_count) {
        return;
    }
    for (var k = 0u; k < 3u; k = k + 1u) {
        let v = indices[3u * f + k];
        let slot = offsets[v] + atomicAdd(&cursor[v], 1u);
        vertex_faces[slot] = f;
    }
}
