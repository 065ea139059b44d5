// Selection pass, step 3: a candidate that posted its tie rank (select_id: its cost is the best
// at every face around both endpoints) and whose rank is the best at every one of them too wins
// the pass, tentatively until validate checks its topology; the other posters compete again in
// the next pass. Two winners therefore share no face, so the checks each passed stay true when
// both collapse. Only posters are looked at: every other candidate already failed the cost test
// (rechecking it here cost 0.46 s of lavapipe time on the 1M scan at 1%).

@group(0) @binding(0) var<storage, read> offsets: array<u32>;             // per vertex + 1
@group(0) @binding(1) var<storage, read> vertex_faces: array<u32>;        // per corner
@group(0) @binding(2) var<storage, read> edges: array<vec2<u32>>;         // per edge
@group(0) @binding(3) var<storage, read> live: array<u32>;                // per listed candidate
@group(0) @binding(4) var<storage, read> face_id: array<u32>;             // per face
@group(0) @binding(5) var<storage, read_write> edge_state: array<u32>;    // per edge
@group(0) @binding(6) var<storage, read_write> tentative: array<u32>;     // per winner of the pass
@group(0) @binding(7) var<storage, read_write> counters: array<atomic<u32>, 16>;

@compute @workgroup_size(256)
fn select_win(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * WG;
    if (i >= atomicLoad(&counters[C_LIVE])) {
        return;
    }
    let e = live[i];
    if (edge_state[e] != STATE_POSTED) {
        return;
    }
    let rank = ~tie_rank(e);
    let ab = edges[e];
    for (var s = 0u; s < 2u; s = s + 1u) {
        let v = ab[s];
        for (var i = offsets[v]; i < offsets[v + 1u]; i = i + 1u) {
            if (face_id[vertex_faces[i]] != rank) {
                edge_state[e] = STATE_CANDIDATE;
                return;
            }
        }
    }
    edge_state[e] = STATE_TENTATIVE;
    // The list's order depends on timing; validate's results do not (one slot per edge).
    tentative[atomicAdd(&counters[C_TENTATIVE], 1u)] = e;
}
