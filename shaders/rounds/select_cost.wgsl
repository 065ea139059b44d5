// Selection pass, step 1: candidates under the ceiling that touch no face of an earlier pass's
// winner post their inverted cost bits to every face around either endpoint (atomicMax keeps
// the cheapest). Relies on face_best being cleared and vertex_lock marking every vertex of the
// faces around the earlier passes' winners (validate): a face around endpoint a is one of
// theirs exactly when a is such a vertex, so two loads answer what a scan of both endpoints'
// faces did (the scan was most of this stage's 1.7 s of lavapipe time on the 1M scan at 1%).

@group(0) @binding(0) var<storage, read> offsets: array<u32>;             // per vertex + 1
@group(0) @binding(1) var<storage, read> vertex_faces: array<u32>;        // per corner
@group(0) @binding(2) var<storage, read> edges: array<vec2<u32>>;         // per edge
@group(0) @binding(3) var<storage, read> live: array<u32>;                // per listed candidate
@group(0) @binding(4) var<storage, read> candidates: array<EdgeCandidate>; // per edge
@group(0) @binding(5) var<storage, read> vertex_lock: array<u32>;         // per vertex
@group(0) @binding(6) var<storage, read> counters: array<u32, 16>;
@group(0) @binding(7) var<storage, read_write> edge_state: array<u32>;    // per edge
@group(0) @binding(8) var<storage, read_write> face_best: array<atomic<u32>>; // per face

@compute @workgroup_size(256)
fn select_cost(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * WG;
    if (i >= counters[C_LIVE]) {
        return;
    }
    let e = live[i];
    if (edge_state[e] != STATE_CANDIDATE) {
        return;
    }
    let c = candidates[e];
    let ab = edges[e];
    if (vertex_lock[ab.x] != 0u || vertex_lock[ab.y] != 0u) {
        edge_state[e] = STATE_OUT;
        return;
    }
    let inv = ~c.cost_bits;
    for (var s = 0u; s < 2u; s = s + 1u) {
        let v = ab[s];
        for (var i = offsets[v]; i < offsets[v + 1u]; i = i + 1u) {
            atomicMax(&face_best[vertex_faces[i]], inv);
        }
    }
}
