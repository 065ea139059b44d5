// One invocation: the cost ceiling of this round, the smallest histogram bin boundary below
// which at least ceiling_wanted candidates lie. Relies on the histogram of edge_errors.

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> histogram: array<u32>;               // HIST_BINS
@group(0) @binding(2) var<storage, read_write> counters: array<atomic<u32>, 16>;

@compute @workgroup_size(1)
fn cost_ceiling() {
    var cum = 0u;
    var ceiling = INVALID_COST;
    for (var bin = 0u; bin < HIST_BINS; bin = bin + 1u) {
        cum = cum + histogram[bin];
        if (cum >= params.ceiling_wanted) {
            if (bin + 1u < HIST_BINS) {
                ceiling = (bin + 1u) << HIST_SHIFT;
            }
            break;
        }
    }
    atomicStore(&counters[C_CEILING], ceiling);
}
