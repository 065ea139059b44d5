// Each winner moves its survivor to the new position with both quadrics re-centred there and
// summed, carries the border bit, and points the removed vertex at the survivor; when the
// survivor is a seam vertex, the removed vertex's corners take their attribute vertices by the
// seam rule edge_errors checked. Winners share no face, hence no vertex, so these writes never
// meet.

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> candidates: array<EdgeCandidate>; // per edge
@group(0) @binding(2) var<storage, read> edge_state: array<u32>;          // per edge
@group(0) @binding(3) var<storage, read> edge_offsets: array<u32>;        // per vertex + 1
@group(0) @binding(4) var<storage, read> indices: array<u32>;             // per face × 3
@group(0) @binding(5) var<storage, read> offsets: array<u32>;             // per vertex + 1
@group(0) @binding(6) var<storage, read> vertex_faces: array<u32>;       // per corner
@group(0) @binding(7) var<storage, read_write> positions: array<vec4<f32>>; // per vertex
@group(0) @binding(8) var<storage, read_write> quadrics: array<Quadric>;   // per vertex
@group(0) @binding(9) var<storage, read_write> flags: array<u32>;          // per vertex
@group(0) @binding(10) var<storage, read_write> remap: array<u32>;          // per vertex
@group(0) @binding(11) var<storage, read_write> face_extra: array<FaceExtra>; // per face

// The attribute vertex a corner of the removed vertex takes under map m (see NO_ATTR in
// src/gpu/types.rs).
fn mapped(m: vec4<u32>, a: u32) -> u32 {
    if (m.x == NO_ATTR || a == m.x) { return m.y; }
    if (a == m.z) { return m.w; }
    return a;
}

// The removed vertex r's corners onto seam vertex k: the map from the faces on the edge (locked
// since edge_errors checked it): each side's pair for a seam vertex sliding along its seam, k's
// attribute vertex for all corners of a free one.
fn onto_seam_corners(k: u32, r: u32) {
    let slides = (flags[r] & FLAG_SEAM) != 0u;
    var m = vec4<u32>(NO_ATTR);
    var n = 0u;
    for (var i = offsets[r]; i < offsets[r + 1u]; i = i + 1u) {
        let f = vertex_faces[i];
        if (has(face_of(f), k)) {
            if (!slides) {
                m.y = corner_attr(f, k);
            } else if (n == 0u) {
                m.x = corner_attr(f, r);
                m.y = corner_attr(f, k);
            } else {
                m.z = corner_attr(f, r);
                m.w = corner_attr(f, k);
            }
            n = n + 1u;
        }
    }
    // The faces that stay (those on the edge go); no other winner touches them (winners share
    // no face).
    for (var i = offsets[r]; i < offsets[r + 1u]; i = i + 1u) {
        let f = vertex_faces[i];
        let t = face_of(f);
        if (has(t, k)) { continue; }
        var x = face_extra[f];
        if (t.x == r) { x.attr0 = mapped(m, x.attr0); }
        if (t.y == r) { x.attr1 = mapped(m, x.attr1); }
        if (t.z == r) { x.attr2 = mapped(m, x.attr2); }
        face_extra[f] = x;
    }
}

@compute @workgroup_size(256)
fn collapse(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let e = gid.x + gid.y * nwg.x * WG;
    if (e >= edge_offsets[params.vertex_count] || edge_state[e] != STATE_WON) {
        return;
    }
    let c = candidates[e];
    let k = c.keep;
    let r = c.remove;
    if ((flags[k] & FLAG_SEAM) != 0u) {
        onto_seam_corners(k, r);
    }
    let pk = positions[k].xyz;
    let pr = positions[r].xyz;
    let p = c.pos.xyz;
    quadrics[k] = quadric_add(quadric_shift(quadrics[k], p - pk), quadric_shift(quadrics[r], p - pr));
    var moved = 0u;
    if (any(p != pk)) { moved = FLAG_MOVED; }
    flags[k] = flags[k] | (flags[r] & FLAG_BORDER) | moved;
    positions[k] = vec4<f32>(p, 1.0);
    remap[r] = k;
}
