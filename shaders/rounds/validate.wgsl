// The edges a selection pass picked (listed by select_win, so that SIMD lanes are not spent on
// the other edges) get the topological checks of the greedy reference: link
// condition, no border pinch, no lone triangle, no tetrahedral fold. Those that pass win and lock
// every vertex of the faces around them (select_cost then keeps out the edges at such a vertex:
// those that touch a winner's face); the rest drop out. Relies on tentative winners sharing no
// face; two of them may share a locked vertex, hence the atomic stores.

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> flags: array<u32>;                  // per vertex
@group(0) @binding(2) var<storage, read> indices: array<u32>;                // per face × 3
@group(0) @binding(3) var<storage, read> offsets: array<u32>;                // per vertex + 1
@group(0) @binding(4) var<storage, read> vertex_faces: array<u32>;           // per corner
@group(0) @binding(5) var<storage, read> edges: array<vec2<u32>>;            // per edge
@group(0) @binding(6) var<storage, read> tentative: array<u32>;              // per winner of the pass
@group(0) @binding(7) var<storage, read_write> candidates: array<EdgeCandidate>; // per edge
@group(0) @binding(8) var<storage, read_write> edge_state: array<u32>;       // per edge
@group(0) @binding(9) var<storage, read_write> vertex_lock: array<atomic<u32>>; // per vertex
@group(0) @binding(10) var<storage, read_write> counters: array<atomic<u32>, 16>;

// Faces on the edge (1 or 2), or 0 when the collapse would break the topology.
fn check(keep: u32, remove: u32) -> u32 {
    let klo = offsets[keep];
    let khi = offsets[keep + 1u];
    let rlo = offsets[remove];
    let rhi = offsets[remove + 1u];
    var edge_faces = 0u;
    var opp = vec2<u32>(0xffffffffu, 0xffffffffu);
    for (var i = klo; i < khi; i = i + 1u) {
        let t = face_of(vertex_faces[i]);
        if (has(t, remove)) {
            if (edge_faces == 2u) { return 0u; }
            var o = keep;
            for (var k = 0u; k < 3u; k = k + 1u) {
                if (t[k] != keep && t[k] != remove) { o = t[k]; break; }
            }
            opp[edge_faces] = o;
            edge_faces = edge_faces + 1u;
        }
    }
    if (edge_faces == 0u) { return 0u; }
    // Link condition: the opposite vertices are always common neighbours, so it fails when both
    // faces have the same one, or when any other neighbour of remove is a neighbour of keep.
    if (edge_faces == 2u && opp[0] == opp[1]) { return 0u; }
    for (var i = rlo; i < rhi; i = i + 1u) {
        let t = face_of(vertex_faces[i]);
        for (var k = 0u; k < 3u; k = k + 1u) {
            let u = t[k];
            let is_opp = u == opp[0] || (edge_faces == 2u && u == opp[1]);
            if (u != keep && u != remove && !is_opp && list_has(klo, khi, u)) { return 0u; }
        }
    }
    let bk = (flags[keep] & FLAG_BORDER) != 0u;
    let br = (flags[remove] & FLAG_BORDER) != 0u;
    if (edge_faces == 2u && bk && br) { return 0u; }
    if (edge_faces == 1u) {
        let o = opp[0];
        if (count_containing(klo, khi, o) == 1u && count_containing(rlo, rhi, o) == 1u) {
            return 0u;
        }
    }
    if (edge_faces == 2u) {
        var on_cd = vec2<bool>(false, false);
        for (var side = 0u; side < 2u; side = side + 1u) {
            var other = remove;
            var lo = klo;
            var hi = khi;
            if (side == 1u) { other = keep; lo = rlo; hi = rhi; }
            for (var i = lo; i < hi; i = i + 1u) {
                let t = face_of(vertex_faces[i]);
                if (!has(t, other) && has(t, opp[0]) && has(t, opp[1])) { on_cd[side] = true; break; }
            }
        }
        if (on_cd[0] && on_cd[1]) { return 0u; }
    }
    return edge_faces;
}

@compute @workgroup_size(256)
fn validate(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let id = gid.x + gid.y * nwg.x * WG;
    if (id >= min(atomicLoad(&counters[C_TENTATIVE]), params.edge_capacity)) {
        return;
    }
    let e = tentative[id];
    var c = candidates[e];
    let faces = check(c.keep, c.remove);
    if (faces == 0u) {
        edge_state[e] = STATE_OUT;
        return;
    }
    c.faces = faces;
    candidates[e] = c;
    edge_state[e] = STATE_WON;
    let ab = edges[e];
    for (var s = 0u; s < 2u; s = s + 1u) {
        let v = ab[s];
        for (var i = offsets[v]; i < offsets[v + 1u]; i = i + 1u) {
            let t = face_of(vertex_faces[i]);
            for (var k = 0u; k < 3u; k = k + 1u) { atomicStore(&vertex_lock[t[k]], 1u); }
        }
    }
    atomicAdd(&counters[C_WINNERS], 1u);
    atomicAdd(&counters[C_REMOVED], c.faces);
    atomicMax(&counters[C_MAX_ERR2_BITS], bitcast<u32>(c.pos.w));
}
