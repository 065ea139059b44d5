// Per edge: the collapse position and quadric error, and the histogram of errors cost_ceiling
// picks the round's ceiling from. The faces that move (the costly half of an edge's evaluation)
// wait for edge_costs, which checks only the edges under the ceiling; the topological checks
// wait for validate. Seam vertices follow the greedy reference's rules (onto_seam, seam_slide);
// collapse makes the attribute map again from the same faces. With appearance channels, two
// free vertices meet where the quadric reduced by their merged attribute sums is least, and a
// survivor that stays put is charged with its values held (the greedy's placement). Relies on
// the current CSR face lists and on the seam corners' attribute vertices in face_extra.

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> positions: array<vec4<f32>>;        // per vertex
@group(0) @binding(2) var<storage, read> quadrics: array<Quadric>;           // per vertex
@group(0) @binding(3) var<storage, read> flags: array<u32>;                  // per vertex
@group(0) @binding(4) var<storage, read> indices: array<u32>;                // per face × 3
@group(0) @binding(5) var<storage, read> offsets: array<u32>;                // per vertex + 1
@group(0) @binding(6) var<storage, read> vertex_faces: array<u32>;           // per corner
@group(0) @binding(7) var<storage, read> edges: array<vec2<u32>>;            // per edge
@group(0) @binding(8) var<storage, read> edge_offsets: array<u32>;           // per vertex + 1
@group(0) @binding(9) var<storage, read> face_extra: array<FaceExtra>;      // per face
@group(0) @binding(10) var<storage, read> vertex_attr: array<u32>;          // per vertex
@group(0) @binding(11) var<storage, read> attr_values: array<f32>;          // per attribute vertex × m
@group(0) @binding(12) var<storage, read> attr_sums: array<f32>;            // per attribute vertex × (4m + 1)
@group(0) @binding(13) var<storage, read_write> candidates: array<EdgeCandidate>; // per edge
@group(0) @binding(14) var<storage, read_write> edge_state: array<u32>;      // per edge
@group(0) @binding(15) var<storage, read_write> histogram: array<atomic<u32>>; // HIST_BINS
@group(0) @binding(16) var<storage, read_write> counters: array<atomic<u32>, 16>;

const VERDICT_INVALID: u32 = 0u;
const VERDICT_OVER: u32 = 1u;
const VERDICT_OK: u32 = 2u;

struct Verdict {
    kind: u32,
    c: EdgeCandidate,
}

fn invalid() -> Verdict {
    return Verdict(VERDICT_INVALID, invalid_candidate());
}

// Free vertex r moving onto seam vertex k: its corners take the attribute vertex k has in the
// faces on the edge, which must agree (else the edge runs along the seam). .y = NO_ATTR if not.
fn onto_seam(k: u32, r: u32) -> vec4<u32> {
    var to = NO_ATTR;
    for (var i = offsets[r]; i < offsets[r + 1u]; i = i + 1u) {
        let f = vertex_faces[i];
        if (has(face_of(f), k)) {
            let a = corner_attr(f, k);
            if (to != NO_ATTR && to != a) { return vec4<u32>(NO_ATTR); }
            to = a;
        }
    }
    return vec4<u32>(NO_ATTR, to, NO_ATTR, NO_ATTR);
}

// Seam vertex r sliding along edge (r, k) onto seam vertex k (the greedy's seam_slide): r is
// free to go (not pinned, not on a border), has two attribute vertices, and the two faces on
// the edge use different ones at both ends. (from1, to1, from2, to2), or all NO_ATTR.
fn seam_slide(r: u32, k: u32) -> vec4<u32> {
    let none = vec4<u32>(NO_ATTR);
    if ((flags[r] & (FLAG_PINNED | FLAG_BORDER)) != 0u) { return none; }
    var attrs = vec2<u32>(NO_ATTR, NO_ATTR);
    var sides = none;
    var n = 0u;
    for (var i = offsets[r]; i < offsets[r + 1u]; i = i + 1u) {
        let f = vertex_faces[i];
        let a = corner_attr(f, r);
        if (attrs.x == NO_ATTR || attrs.x == a) {
            attrs.x = a;
        } else if (attrs.y == NO_ATTR || attrs.y == a) {
            attrs.y = a;
        } else {
            return none; // a seam junction stays
        }
        if (has(face_of(f), k)) {
            if (n == 2u) { return none; }
            if (n == 0u) {
                sides.x = a;
                sides.y = corner_attr(f, k);
            } else {
                sides.z = a;
                sides.w = corner_attr(f, k);
            }
            n = n + 1u;
        }
    }
    if (n == 2u && sides.x != sides.z && sides.y != sides.w) { return sides; }
    return none;
}

// The quadric q (measured from o) of a survivor k that stays put, with each of its attribute
// vertices held at its values against its own sums and those of the removed vertex r's side
// that joins it (map: r's (from, to) pairs as the seam rules gave them; for a free r, its one
// attribute vertex onto k's on the edge). k's attribute vertices: a seam vertex's corners',
// each once; any other's one.
fn held(q: Quadric, k: u32, r: u32, map: vec4<u32>, o: vec3<f32>) -> Quadric {
    let tk = o - positions[k].xyz;
    let tr = o - positions[r].xyz;
    var m = map;
    if ((flags[r] & FLAG_SEAM) == 0u) {
        m = vec4<u32>(vertex_attr[r], vertex_attr[k], NO_ATTR, NO_ATTR);
        if ((flags[k] & FLAG_SEAM) != 0u) { m.y = map.y; }
    }
    var h = q;
    if ((flags[k] & FLAG_SEAM) == 0u) {
        let kv = vertex_attr[k];
        h = attr_hold(h, kv, tk, kv);
        return attr_hold(h, m.x, tr, kv);
    }
    let lo = offsets[k];
    let hi = offsets[k + 1u];
    for (var i = lo; i < hi; i = i + 1u) {
        let kv = corner_attr(vertex_faces[i], k);
        var seen = false;
        for (var j = lo; j < i; j = j + 1u) {
            if (corner_attr(vertex_faces[j], k) == kv) { seen = true; break; }
        }
        if (seen) { continue; }
        h = attr_hold(h, kv, tk, kv);
        if (m.y == kv) {
            h = attr_hold(h, m.x, tr, kv);
        } else if (m.w == kv) {
            h = attr_hold(h, m.z, tr, kv);
        }
    }
    return h;
}

fn evaluate(a: u32, b: u32) -> Verdict {
    let fla = flags[a];
    let flb = flags[b];
    // A closed group's vertex (grouped rounds) takes part in no collapse.
    if (((fla | flb) & FLAG_CLOSED) != 0u) { return invalid(); }
    // Seam vertices keep their position like pinned ones.
    let fixed_a = (fla & (FLAG_PINNED | FLAG_SEAM)) != 0u;
    let fixed_b = (flb & (FLAG_PINNED | FLAG_SEAM)) != 0u;
    let pa = positions[a].xyz;
    let pb = positions[b].xyz;
    let dab = pb - pa;
    var q = quadric_add(quadrics[a], quadric_shift(quadrics[b], pa - pb));
    let weight = q.q2.z;
    var keep = a;
    var remove = b;
    var y = vec3<f32>(0.0);
    var attr_map = vec4<u32>(NO_ATTR);
    if (fixed_a && fixed_b) {
        // Only a seam vertex sliding along its seam onto a seam neighbour; b first, as the
        // greedy tries.
        if ((fla & flb & FLAG_SEAM) == 0u) { return invalid(); }
        attr_map = seam_slide(b, a);
        if (attr_map.y == NO_ATTR) {
            attr_map = seam_slide(a, b);
            keep = b;
            remove = a;
            y = dab;
        }
        if (attr_map.y == NO_ATTR) { return invalid(); }
    } else if (fixed_a) {
        y = vec3<f32>(0.0);
    } else if (fixed_b) {
        keep = b;
        remove = a;
        y = dab;
    } else {
        // Two free vertices: with appearance channels, each has one attribute vertex, and the
        // position and the values come from one solve of the reduced quadric.
        if (attr_m() != 0u) {
            q = attr_reduce_pair(q, vertex_attr[a], vec3<f32>(0.0), vertex_attr[b], pa - pb);
        }
        var opt = quadric_optimum(q);
        // With appearance channels the reduced quadric may hold a vertex only weakly along the
        // surface: an optimum farther from the edge's midpoint than the edge is long would slide
        // it over its neighbours, so the ends and the midpoint compete instead.
        let off = opt.y - dab * 0.5;
        if (attr_m() != 0u && !(dot(off, off) <= dot(dab, dab))) { opt.ok = false; }
        if (opt.ok) {
            y = opt.y;
        } else {
            var best = vec3<f32>(0.0);
            var best_e = quadric_eval(q, best);
            let e1 = quadric_eval(q, dab);
            if (e1 < best_e) { best = dab; best_e = e1; }
            let mid = dab * 0.5;
            let e2 = quadric_eval(q, mid);
            if (e2 < best_e) { best = mid; best_e = e2; }
            y = best;
        }
        let dy = y - dab;
        if (!(dot(y, y) <= dot(dy, dy))) {
            keep = b;
            remove = a;
        }
    }
    if ((flags[keep] & FLAG_SEAM) != 0u && attr_map.y == NO_ATTR) {
        attr_map = onto_seam(keep, remove);
        if (attr_map.y == NO_ATTR) { return invalid(); }
    }
    if (attr_m() != 0u && (fixed_a || fixed_b)) {
        q = held(q, keep, remove, attr_map, pa);
    }
    let error = quadric_eval(q, y);
    // A survivor that keeps its position keeps it bit for bit (pa + (pb - pa) need not be pb):
    // a seam vertex marked moved would leave its other attribute vertices behind.
    var pos = pa + y;
    if ((flags[keep] & (FLAG_PINNED | FLAG_SEAM)) != 0u) { pos = positions[keep].xyz; }

    var err2 = 0.0;
    if (weight > 0.0) { err2 = error / weight; }
    if (!(is_finite(error) && is_finite(err2) && is_finite(pos.x) && is_finite(pos.y) && is_finite(pos.z))) {
        return invalid();
    }
    if (err2 > params.max_error2) {
        return Verdict(VERDICT_OVER, invalid_candidate());
    }
    return Verdict(VERDICT_OK, EdgeCandidate(vec4<f32>(pos, err2), keep, remove, bitcast<u32>(error), 0u));
}

@compute @workgroup_size(256)
fn edge_errors(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let e = gid.x + gid.y * nwg.x * WG;
    if (e >= edge_offsets[params.vertex_count]) {
        return;
    }
    let ab = edges[e];
    let v = evaluate(ab.x, ab.y);
    edge_state[e] = STATE_OUT;
    if (v.kind == VERDICT_OK) {
        candidates[e] = v.c;
        edge_state[e] = STATE_CANDIDATE;
        atomicAdd(&histogram[v.c.cost_bits >> HIST_SHIFT], 1u);
        atomicAdd(&counters[C_CANDIDATES], 1u);
    } else {
        candidates[e] = invalid_candidate();
        if (v.kind == VERDICT_OVER) {
            atomicAdd(&counters[C_OVER_MAX_ERROR], 1u);
        }
    }
}
