// Trimming, step 1: winners add the faces they remove to their cost bin, so trim_ceiling can
// find where the round's budget (params.needed_faces) runs out. Relies on a cleared histogram.

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> candidates: array<EdgeCandidate>; // per edge
@group(0) @binding(2) var<storage, read> edge_state: array<u32>;          // per edge
@group(0) @binding(3) var<storage, read> edge_offsets: array<u32>;        // per vertex + 1
@group(0) @binding(4) var<storage, read_write> histogram: array<atomic<u32>>; // HIST_BINS

@compute @workgroup_size(256)
fn trim_histogram(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    // A round planned on the device records the trim in every round; it acts only when asked.
    if (params.trim == 0u) {
        return;
    }
    let e = gid.x + gid.y * nwg.x * WG;
    if (e >= edge_offsets[params.vertex_count] || edge_state[e] != STATE_WON) {
        return;
    }
    let c = candidates[e];
    atomicAdd(&histogram[c.cost_bits >> HIST_SHIFT], c.faces);
}
