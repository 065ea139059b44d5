// Kept faces move to their scanned slot with corners renumbered to the survivors' new ids.
// Relies on face_keep and vertex_keep being exclusive scans of 0/1 keep flags.

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> indices: array<u32>;                  // per face × 3
@group(0) @binding(2) var<storage, read> face_normals: array<vec4<f32>>;       // per face
@group(0) @binding(3) var<storage, read> face_extra: array<FaceExtra>;         // per face
@group(0) @binding(4) var<storage, read> remap: array<u32>;                    // per vertex
@group(0) @binding(5) var<storage, read> vertex_keep: array<u32>;              // per vertex + 1
@group(0) @binding(6) var<storage, read> face_keep: array<u32>;                // per face + 1
@group(0) @binding(7) var<storage, read_write> indices_out: array<u32>;
@group(0) @binding(8) var<storage, read_write> face_normals_out: array<vec4<f32>>;
@group(0) @binding(9) var<storage, read_write> face_extra_out: array<FaceExtra>;

@compute @workgroup_size(256)
fn compact_faces(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let f = gid.x + gid.y * nwg.x * WG;
    if (f >= params.face_count || face_keep[f + 1u] == face_keep[f]) {
        return;
    }
    let n = face_keep[f];
    for (var k = 0u; k < 3u; k = k + 1u) {
        indices_out[3u * n + k] = vertex_keep[remap[indices[3u * f + k]]];
    }
    face_normals_out[n] = face_normals[f];
    face_extra_out[n] = face_extra[f];
}
