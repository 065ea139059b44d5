// Each winner moves its survivor to the new position with both quadrics re-centred there and
// summed, carries the border bit, and points the removed vertex at the survivor; when the
// survivor is a seam vertex, the removed vertex's corners take their attribute vertices by the
// seam rule edge_errors checked. With appearance channels, the attribute sums of the removed
// vertex's sides join those of the survivor's they map to, and a survivor that moves takes the
// values that are best for the merged sums at its new place (Hoppe 1999), kept valid: colours in
// 0..1, UVs within the two ends' range. Winners share no face, hence no vertex (and each
// attribute vertex belongs to one vertex), so these writes never meet.

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> candidates: array<EdgeCandidate>; // per edge
@group(0) @binding(2) var<storage, read> edge_state: array<u32>;          // per edge
@group(0) @binding(3) var<storage, read> edge_offsets: array<u32>;        // per vertex + 1
@group(0) @binding(4) var<storage, read> indices: array<u32>;             // per face × 3
@group(0) @binding(5) var<storage, read> offsets: array<u32>;             // per vertex + 1
@group(0) @binding(6) var<storage, read> vertex_faces: array<u32>;       // per corner
@group(0) @binding(7) var<storage, read> vertex_attr: array<u32>;        // per vertex
@group(0) @binding(8) var<storage, read_write> positions: array<vec4<f32>>; // per vertex
@group(0) @binding(9) var<storage, read_write> quadrics: array<Quadric>;   // per vertex
@group(0) @binding(10) var<storage, read_write> flags: array<u32>;          // per vertex
@group(0) @binding(11) var<storage, read_write> remap: array<u32>;          // per vertex
@group(0) @binding(12) var<storage, read_write> face_extra: array<FaceExtra>; // per face
@group(0) @binding(13) var<storage, read_write> attr_values: array<f32>;    // per attribute vertex × m
@group(0) @binding(14) var<storage, read_write> attr_sums: array<f32>;      // per attribute vertex × (4m + 1)

// The attribute vertex a corner of the removed vertex takes under map m (see NO_ATTR in
// src/compute/types.rs).
fn mapped(m: vec4<u32>, a: u32) -> u32 {
    if (m.x == NO_ATTR || a == m.x) { return m.y; }
    if (a == m.z) { return m.w; }
    return a;
}

// The removed vertex r's corners onto seam vertex k: the map from the faces on the edge (locked
// since edge_errors checked it): each side's pair for a seam vertex sliding along its seam, k's
// attribute vertex for all corners of a free one; returned for the attribute sums.
fn onto_seam_corners(k: u32, r: u32) -> vec4<u32> {
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
    return m;
}

// Attribute vertex src's sums (measured from its vertex moved by t) added to dst's.
fn join_sums(dst: u32, src: u32, t: vec3<f32>) {
    let m = attr_m();
    let s = attr_stride();
    for (var j = 0u; j < m; j = j + 1u) {
        let d = attr_d(src, j, t);
        for (var k = 0u; k < 3u; k = k + 1u) {
            attr_sums[dst * s + 3u * j + k] = attr_sums[dst * s + 3u * j + k] + attr_sums[src * s + 3u * j + k];
        }
        attr_sums[dst * s + 3u * m + j] = attr_sums[dst * s + 3u * m + j] + d;
    }
    attr_sums[dst * s + 4u * m] = attr_sums[dst * s + 4u * m] + attr_w(src);
}

// Survivor k moving from pk to p takes r's sums and the best values for both at p, kept valid.
fn merge_moving(k: u32, r: u32, p: vec3<f32>, pk: vec3<f32>, pr: vec3<f32>) {
    let ak = vertex_attr[k];
    let ar = vertex_attr[r];
    let m = attr_m();
    let s = attr_stride();
    // k's own sums re-measured from p first (D += G·(p - pk)), then r's joined.
    let tk = p - pk;
    for (var j = 0u; j < m; j = j + 1u) {
        attr_sums[ak * s + 3u * m + j] = attr_d(ak, j, tk);
    }
    join_sums(ak, ar, p - pr);
    let w = attr_w(ak);
    if (!(w > 0.0)) { return; }
    let colors = attr_colors();
    var uv_end = colors;
    if (attr_has_uv()) { uv_end = colors + 2u; }
    for (var j = 0u; j < m; j = j + 1u) {
        var x = attr_sums[ak * s + 3u * m + j] / w;
        let old_k = attr_values[ak * m + j];
        let old_r = attr_values[ar * m + j];
        if (j < colors) {
            x = clamp(x, 0.0, params.color_weight);
        } else if (j < uv_end) {
            x = clamp(x, min(old_k, old_r), max(old_k, old_r));
        }
        attr_values[ak * m + j] = x;
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
    var map = vec4<u32>(vertex_attr[r], vertex_attr[k], NO_ATTR, NO_ATTR);
    if ((flags[k] & FLAG_SEAM) != 0u) {
        let seam = onto_seam_corners(k, r);
        map.y = seam.y;
        if ((flags[r] & FLAG_SEAM) != 0u) { map = seam; }
    }
    let pk = positions[k].xyz;
    let pr = positions[r].xyz;
    let p = c.pos.xyz;
    if (attr_m() != 0u) {
        if ((flags[k] & (FLAG_PINNED | FLAG_SEAM)) == 0u) {
            merge_moving(k, r, p, pk, pr);
        } else {
            // A survivor that stays put keeps its values; r's sides join the sides they map to.
            join_sums(map.y, map.x, pk - pr);
            if (map.z != NO_ATTR) { join_sums(map.w, map.z, pk - pr); }
        }
    }
    quadrics[k] = quadric_add(quadric_shift(quadrics[k], p - pk), quadric_shift(quadrics[r], p - pr));
    var moved = 0u;
    if (any(p != pk)) { moved = FLAG_MOVED; }
    flags[k] = flags[k] | (flags[r] & FLAG_BORDER) | moved;
    positions[k] = vec4<f32>(p, 1.0);
    remap[r] = k;
}
