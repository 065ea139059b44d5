// Grouped rounds, per edge before the collapses: each winner's squared error into its group's
// largest (an atomic max on the bits of a non-negative f32, which order as integers: the
// same whatever the order). The removed vertex is free, so its first face names the group.

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> candidates: array<EdgeCandidate>; // per edge
@group(0) @binding(2) var<storage, read> edge_state: array<u32>;          // per edge
@group(0) @binding(3) var<storage, read> edge_offsets: array<u32>;        // per vertex + 1
@group(0) @binding(4) var<storage, read> offsets: array<u32>;             // per vertex + 1
@group(0) @binding(5) var<storage, read> vertex_faces: array<u32>;        // per corner
@group(0) @binding(6) var<storage, read> face_extra: array<FaceExtra>;    // per face
@group(0) @binding(7) var<storage, read> face_group: array<u32>;          // per input face
@group(0) @binding(8) var<storage, read_write> group_err: array<atomic<u32>>; // per group

@compute @workgroup_size(256)
fn group_errors(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let e = gid.x + gid.y * nwg.x * WG;
    if (e >= edge_offsets[params.vertex_count] || edge_state[e] != STATE_WON) {
        return;
    }
    let c = candidates[e];
    let g = face_group[face_extra[vertex_faces[offsets[c.remove]]].origin];
    atomicMax(&group_err[g], bitcast<u32>(c.pos.w));
}
