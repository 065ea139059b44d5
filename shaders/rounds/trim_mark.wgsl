// Trimming, step 3: per edge up to edge_capacity, the faces a winner in the trim bin removes
// (else 0): the input of the prefix sum that orders them by edge id.

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> candidates: array<EdgeCandidate>; // per edge
@group(0) @binding(2) var<storage, read> edge_state: array<u32>;          // per edge
@group(0) @binding(3) var<storage, read> edge_offsets: array<u32>;        // per vertex + 1
@group(0) @binding(4) var<storage, read> counters: array<u32, 16>;
@group(0) @binding(5) var<storage, read_write> marks: array<u32>;         // edge_capacity + 1

@compute @workgroup_size(256)
fn trim_mark(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    // A round planned on the device records the trim in every round; it acts only when asked.
    if (params.trim == 0u) {
        return;
    }
    let e = gid.x + gid.y * nwg.x * WG;
    if (e >= params.edge_capacity) {
        return;
    }
    var m = 0u;
    if (e < edge_offsets[params.vertex_count] && edge_state[e] == STATE_WON
        && (candidates[e].cost_bits >> HIST_SHIFT) == counters[C_TRIM_BIN]) {
        m = candidates[e].faces;
    }
    marks[e] = m;
}
