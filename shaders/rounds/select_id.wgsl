// Selection pass, step 2: among the candidates whose cost is the best at every face around them,
// the lowest tie rank (a hash of the edge id) wins each face (atomicMax of the inverted rank).
// Those that post are marked POSTED, so that select_win looks at them alone. Relies on face_id
// being cleared.

@group(0) @binding(0) var<storage, read> offsets: array<u32>;             // per vertex + 1
@group(0) @binding(1) var<storage, read> vertex_faces: array<u32>;        // per corner
@group(0) @binding(2) var<storage, read> edges: array<vec2<u32>>;         // per edge
@group(0) @binding(3) var<storage, read> live: array<u32>;                // per listed candidate
@group(0) @binding(4) var<storage, read> candidates: array<EdgeCandidate>; // per edge
@group(0) @binding(5) var<storage, read> face_best: array<u32>;           // per face
@group(0) @binding(6) var<storage, read> counters: array<u32, 16>;
@group(0) @binding(7) var<storage, read_write> edge_state: array<u32>;    // per edge
@group(0) @binding(8) var<storage, read_write> face_id: array<atomic<u32>>; // per face

@compute @workgroup_size(256)
fn select_id(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * WG;
    if (i >= counters[C_LIVE]) {
        return;
    }
    let e = live[i];
    if (edge_state[e] != STATE_CANDIDATE) {
        return;
    }
    let inv = ~candidates[e].cost_bits;
    let ab = edges[e];
    // Only an edge with the best cost at every face around it can win; the others need not
    // post their rank (a winner is still the only one best at each of its faces).
    for (var s = 0u; s < 2u; s = s + 1u) {
        let v = ab[s];
        for (var i = offsets[v]; i < offsets[v + 1u]; i = i + 1u) {
            if (face_best[vertex_faces[i]] != inv) { return; }
        }
    }
    for (var s = 0u; s < 2u; s = s + 1u) {
        let v = ab[s];
        for (var i = offsets[v]; i < offsets[v + 1u]; i = i + 1u) {
            atomicMax(&face_id[vertex_faces[i]], ~tie_rank(e));
        }
    }
    edge_state[e] = STATE_POSTED;
}
