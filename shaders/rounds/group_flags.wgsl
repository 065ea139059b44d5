// Grouped rounds, per vertex at the start of a round: a free vertex of a group that has
// reached its target is closed (FLAG_CLOSED), so no edge at it competes. A free vertex has
// faces of one group only (the vertices groups share are pinned), so its first face names it.

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> offsets: array<u32>;        // per vertex + 1
@group(0) @binding(2) var<storage, read> vertex_faces: array<u32>;   // per corner
@group(0) @binding(3) var<storage, read> face_extra: array<FaceExtra>; // per face
@group(0) @binding(4) var<storage, read> face_group: array<u32>;     // per input face
@group(0) @binding(5) var<storage, read> group_closed: array<u32>;   // per group
@group(0) @binding(6) var<storage, read_write> flags: array<u32>;    // per vertex

@compute @workgroup_size(256)
fn group_flags(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let v = gid.x + gid.y * nwg.x * WG;
    if (v >= params.vertex_count) {
        return;
    }
    var fl = flags[v] & ~FLAG_CLOSED;
    if ((fl & FLAG_PINNED) == 0u && offsets[v] < offsets[v + 1u]) {
        let g = face_group[face_extra[vertex_faces[offsets[v]]].origin];
        if (group_closed[g] != 0u) {
            fl = fl | FLAG_CLOSED;
        }
    }
    flags[v] = fl;
}
