// Grouped rounds, per face after compaction: each kept face counts towards its group (integer
// atomics: the same counts whatever the order).

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> face_keep: array<u32>;           // per face + 1
@group(0) @binding(2) var<storage, read> face_extra_out: array<FaceExtra>; // per kept face
@group(0) @binding(3) var<storage, read> face_group: array<u32>;          // per input face
@group(0) @binding(4) var<storage, read_write> group_count: array<atomic<u32>>; // per group

@compute @workgroup_size(256)
fn group_faces(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let f = gid.x + gid.y * nwg.x * WG;
    if (f >= face_keep[params.face_count]) {
        return;
    }
    atomicAdd(&group_count[face_group[face_extra_out[f].origin]], 1u);
}
