// For the candidates whose error (edge_errors) is under the round's cost ceiling, the faces that
// move: no normal may turn past the angle limit (against the current and the input normal), no
// needle may appear, and the worst new quality scales the error up to the priority the selection
// ranks by. The ceiling picks the edges that compete by their error; the priority orders them.
// Edges over the ceiling dropped out unchecked (live_list). The topological checks wait for
// validate. One invocation per listed candidate; relies on edge_errors' candidates.

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> positions: array<vec4<f32>>;        // per vertex
@group(0) @binding(2) var<storage, read> indices: array<u32>;                // per face × 3
@group(0) @binding(3) var<storage, read> offsets: array<u32>;                // per vertex + 1
@group(0) @binding(4) var<storage, read> vertex_faces: array<u32>;           // per corner
@group(0) @binding(5) var<storage, read> face_normals: array<vec4<f32>>;     // per face
@group(0) @binding(6) var<storage, read> live: array<u32>;                   // per listed candidate
@group(0) @binding(7) var<storage, read_write> candidates: array<EdgeCandidate>; // per edge
@group(0) @binding(8) var<storage, read_write> edge_state: array<u32>;      // per edge
@group(0) @binding(9) var<storage, read_write> counters: array<atomic<u32>, 16>;

// The priority of collapsing c (its error scaled by the worst quality of the faces that move),
// or -1 when a moving face would flip or become a needle.
fn moved_faces(c: EdgeCandidate) -> f32 {
    let keep = c.keep;
    let remove = c.remove;
    let pos = c.pos.xyz;
    let error = bitcast<f32>(c.cost_bits);
    var min_q = 3.0e38;
    for (var side = 0u; side < 2u; side = side + 1u) {
        var moved = keep;
        var other = remove;
        if (side == 1u) { moved = remove; other = keep; }
        for (var i = offsets[moved]; i < offsets[moved + 1u]; i = i + 1u) {
            let f = vertex_faces[i];
            let t = face_of(f);
            if (has(t, other)) { continue; }
            let o0 = positions[t.x].xyz;
            let o1 = positions[t.y].xyz;
            let o2 = positions[t.z].xyz;
            var n0 = o0; var n1 = o1; var n2 = o2;
            if (t.x == moved) { n0 = pos; }
            if (t.y == moved) { n1 = pos; }
            if (t.z == moved) { n2 = pos; }
            let n_old = cross(o1 - o0, o2 - o0);
            let n_new = cross(n1 - n0, n2 - n0);
            let l_old = length(n_old);
            let l_new = length(n_new);
            if (!(l_new > 0.0)) { return -1.0; }
            if (l_old > 0.0 && dot(n_old, n_new) < params.cos_max_angle * l_old * l_new) { return -1.0; }
            let fr = face_normals[f];
            if (fr.w > 0.0 && dot(fr.xyz, n_new) < params.cos_max_angle * l_new) { return -1.0; }
            let q_new = quality_from_area2(l_new, n0, n1, n2);
            if (q_new < params.min_quality && q_new < triangle_quality(o0, o1, o2)) { return -1.0; }
            min_q = min(min_q, q_new);
        }
    }
    let qt = params.quality_threshold;
    var priority = error;
    if (qt > 0.0 && min_q < qt) {
        priority = error * (qt / max(min_q, 1e-12));
    }
    if (!is_finite(priority)) { return -1.0; }
    return priority;
}

@compute @workgroup_size(256)
fn edge_costs(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * WG;
    if (i >= atomicLoad(&counters[C_LIVE])) {
        return;
    }
    let e = live[i];
    let c = candidates[e];
    let priority = moved_faces(c);
    if (priority < 0.0) {
        candidates[e] = invalid_candidate();
        edge_state[e] = STATE_OUT;
        // No longer a valid collapse: with every edge competing (the round the driver stops
        // on) the count is exactly the valid edges under the maximum error.
        atomicSub(&counters[C_CANDIDATES], 1u);
    } else {
        candidates[e].cost_bits = bitcast<u32>(priority);
    }
}
