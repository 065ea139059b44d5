// Trimming, step 2 (one invocation): the bin where the winners' removals reach the budget and what
// is left of the budget in it; HIST_BINS when every winner fits.
// Invariant: the bins below the one returned remove fewer faces than the budget, so `left` >= 1.

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> histogram: array<u32>;               // HIST_BINS
@group(0) @binding(2) var<storage, read_write> counters: array<atomic<u32>, 16>;

@compute @workgroup_size(1)
fn trim_ceiling() {
    // A round planned on the device records the trim in every round; it acts only when asked.
    if (params.trim == 0u) {
        return;
    }
    let budget = params.needed_faces;
    var bin_out = HIST_BINS;
    var left = 0u;
    if (atomicLoad(&counters[C_REMOVED]) > budget) {
        var cum = 0u;
        for (var bin = 0u; bin < HIST_BINS; bin = bin + 1u) {
            let h = histogram[bin];
            if (cum + h >= budget) {
                bin_out = bin;
                left = budget - cum;
                break;
            }
            cum = cum + h;
        }
    }
    atomicStore(&counters[C_TRIM_BIN], bin_out);
    atomicStore(&counters[C_TRIM_BUDGET], left);
}
