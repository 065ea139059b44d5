// Border and pinned vertices (first round): an edge with one face marks a border, an edge with
// more than two faces or a vertex with more than one fan of faces pins it (so does a border under
// lock_border). Relies on sorted face lists; collapses keep these flags true afterwards.

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> indices: array<u32>;       // per face × 3
@group(0) @binding(2) var<storage, read> offsets: array<u32>;       // per vertex + 1
@group(0) @binding(3) var<storage, read> vertex_faces: array<u32>;  // per corner
@group(0) @binding(4) var<storage, read_write> flags: array<u32>;   // per vertex

// The corner of t other than v and not_this (v when there is none).
fn other_corner(t: vec3<u32>, v: u32, not_this: u32) -> u32 {
    for (var k = 0u; k < 3u; k = k + 1u) {
        if (t[k] != v && t[k] != not_this) { return t[k]; }
    }
    return v;
}

// Faces reachable from the first face by crossing edges at v.
fn fan_size(lo: u32, hi: u32, v: u32) -> u32 {
    let first = vertex_faces[lo];
    let t = face_of(first);
    var visited = 1u;
    for (var dir = 0u; dir < 2u; dir = dir + 1u) {
        // The two corners other than v, in index order.
        var start = other_corner(t, v, v);
        if (dir == 1u) { start = other_corner(t, v, start); }
        var cur = first;
        var through = start;
        for (var step = lo; step < hi; step = step + 1u) {
            var next = 0xffffffffu;
            for (var i = lo; i < hi; i = i + 1u) {
                let g = vertex_faces[i];
                if (g != cur && has(face_of(g), through)) { next = g; break; }
            }
            if (next == 0xffffffffu) { break; }
            if (next == first) { return visited; }
            visited = visited + 1u;
            through = other_corner(face_of(next), v, through);
            cur = next;
        }
    }
    return visited;
}

@compute @workgroup_size(256)
fn vertex_flags(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let v = gid.x + gid.y * nwg.x * WG;
    if (v >= params.vertex_count) {
        return;
    }
    let lo = offsets[v];
    let hi = offsets[v + 1u];
    var border = false;
    var pinned = false;
    for (var i = lo; i < hi; i = i + 1u) {
        let t = face_of(vertex_faces[i]);
        for (var k = 0u; k < 3u; k = k + 1u) {
            let u = t[k];
            if (u != v) {
                let c = count_containing(lo, hi, u);
                if (c == 1u) { border = true; }
                if (c > 2u) { pinned = true; }
            }
        }
    }
    if (hi > lo && !pinned && fan_size(lo, hi, v) < hi - lo) {
        pinned = true;
    }
    if (border && params.lock_border != 0u) {
        pinned = true;
    }
    // SEAM and the caller's pins come from the host; the rest is found here.
    var fl = flags[v] & (FLAG_SEAM | FLAG_PINNED);
    if (border) { fl = fl | FLAG_BORDER; }
    if (pinned) { fl = fl | FLAG_PINNED; }
    flags[v] = fl;
}
