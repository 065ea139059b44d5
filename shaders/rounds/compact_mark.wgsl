// Per max(vertex, face): 1 for a surviving vertex and for a face whose remapped corners are
// still three distinct vertices — the inputs of the two compaction prefix sums.

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> indices: array<u32>;            // per face × 3
@group(0) @binding(2) var<storage, read> remap: array<u32>;              // per vertex
@group(0) @binding(3) var<storage, read_write> vertex_keep: array<u32>;  // per vertex + 1
@group(0) @binding(4) var<storage, read_write> face_keep: array<u32>;    // per face + 1

@compute @workgroup_size(256)
fn compact_mark(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let id = gid.x + gid.y * nwg.x * WG;
    if (id < params.vertex_count) {
        vertex_keep[id] = select(0u, 1u, remap[id] == id);
    }
    if (id < params.face_count) {
        let a = remap[indices[3u * id]];
        let b = remap[indices[3u * id + 1u]];
        let c = remap[indices[3u * id + 2u]];
        face_keep[id] = select(0u, 1u, a != b && b != c && a != c);
    }
}
