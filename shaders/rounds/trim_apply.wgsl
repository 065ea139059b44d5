// Trimming, step 4: winners above the trim bin lose, and in it those whose edge-id-order
// predecessors already remove the budget; the count then lands on the target or one below it
// (the last winner kept may remove two faces where one was left), never above.

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> candidates: array<EdgeCandidate>; // per edge
@group(0) @binding(2) var<storage, read> marks: array<u32>;               // scanned
@group(0) @binding(3) var<storage, read> counters: array<u32, 16>;
@group(0) @binding(4) var<storage, read> edge_offsets: array<u32>;        // per vertex + 1
@group(0) @binding(5) var<storage, read_write> edge_state: array<u32>;    // per edge

@compute @workgroup_size(256)
fn trim_apply(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    // A round planned on the device records the trim in every round; it acts only when asked.
    if (params.trim == 0u) {
        return;
    }
    let e = gid.x + gid.y * nwg.x * WG;
    if (e >= edge_offsets[params.vertex_count] || edge_state[e] != STATE_WON) {
        return;
    }
    let c = candidates[e];
    let bin = c.cost_bits >> HIST_SHIFT;
    let trim_bin = counters[C_TRIM_BIN];
    if (bin > trim_bin || (bin == trim_bin && marks[e] >= counters[C_TRIM_BUDGET])) {
        edge_state[e] = STATE_OUT;
    }
}
