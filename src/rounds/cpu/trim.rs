//! Twins of shaders/rounds/trim_histogram.wgsl, trim_ceiling.wgsl, trim_mark.wgsl and trim_apply.wgsl:
//! in a round that would overshoot the target, the winners are cut back cheapest first so the
//! face count lands on the target or one below it (a collapse removes one or two faces: the last
//! winner kept may take two where one was left), never above, as the greedy reference does. Bins
//! of the winners' costs find the bin where the budget runs out; within that bin, winners are
//! taken in edge-id order (a prefix sum of the faces they remove) while the budget is not met.
//! Each stage does nothing in a round that does not trim (`Params::trim` 0): a round planned on
//! the device records them in every round.

use super::edge_costs::{CounterField, counter};
use super::{par_for, par_for_mut};
use crate::compute::types::{EdgeCandidate, HIST_BINS, HIST_SHIFT, Params, state};
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

/// Per edge: winners add the faces they remove to their cost bin (`histogram` cleared).
pub fn trim_histogram(
    params: &Params,
    candidates: &[EdgeCandidate],
    edge_state: &[u32],
    edge_offsets: &[u32], // per vertex + 1: the edge count at [vertex_count]
    histogram: &[AtomicU32],
) {
    if params.trim == 0 {
        return;
    }
    let edge_count = edge_offsets[params.vertex_count as usize];
    par_for(edge_count, |e| {
        if edge_state[e as usize] == state::WON {
            let c = &candidates[e as usize];
            histogram[(c.cost_bits >> HIST_SHIFT) as usize].fetch_add(c.faces, Relaxed);
        }
    });
}

/// One invocation: the bin where the winners' removals reach `needed_faces`, and what is left of
/// the budget in it (at least 1); `HIST_BINS` (nothing trimmed) when all winners fit.
pub fn trim_ceiling(params: &Params, histogram: &[u32], counters: &[AtomicU32]) {
    if params.trim == 0 {
        return;
    }
    let budget = params.needed_faces;
    let (mut bin_out, mut left) = (HIST_BINS, 0);
    if counter(counters, CounterField::Removed).load(Relaxed) > budget {
        let mut cum = 0u32;
        for bin in 0..HIST_BINS {
            let h = histogram[bin as usize];
            if cum + h >= budget {
                bin_out = bin;
                left = budget - cum;
                break;
            }
            cum += h;
        }
    }
    counter(counters, CounterField::TrimBin).store(bin_out, Relaxed);
    counter(counters, CounterField::TrimBudget).store(left, Relaxed);
}

/// Per edge up to `edge_capacity`: the faces a winner in the trim bin removes, else 0 (the
/// input of the prefix sum that orders them).
pub fn trim_mark(
    params: &Params,
    candidates: &[EdgeCandidate],
    edge_state: &[u32],
    edge_offsets: &[u32], // per vertex + 1: the edge count at [vertex_count]
    counters: &[AtomicU32],
    marks: &mut [u32],
) {
    if params.trim == 0 {
        return;
    }
    let edge_count = edge_offsets[params.vertex_count as usize];
    let trim_bin = counter(counters, CounterField::TrimBin).load(Relaxed);
    par_for_mut(&mut marks[..params.edge_capacity as usize], |e, m| {
        let eu = e as usize;
        *m = if e < edge_count
            && edge_state[eu] == state::WON
            && candidates[eu].cost_bits >> HIST_SHIFT == trim_bin
        {
            candidates[eu].faces
        } else {
            0
        };
    });
}

/// Per edge: winners above the trim bin lose, and in it those whose predecessors in edge-id
/// order already remove the budget.
pub fn trim_apply(
    params: &Params,
    candidates: &[EdgeCandidate],
    marks: &[u32],
    counters: &[AtomicU32],
    edge_offsets: &[u32], // per vertex + 1: the edge count at [vertex_count]
    edge_state: &mut [u32],
) {
    if params.trim == 0 {
        return;
    }
    let edge_count = edge_offsets[params.vertex_count as usize];
    let trim_bin = counter(counters, CounterField::TrimBin).load(Relaxed);
    let budget = counter(counters, CounterField::TrimBudget).load(Relaxed);
    par_for_mut(&mut edge_state[..edge_count as usize], |e, st| {
        let c = &candidates[e as usize];
        let bin = c.cost_bits >> HIST_SHIFT;
        if *st == state::WON && (bin > trim_bin || (bin == trim_bin && marks[e as usize] >= budget))
        {
            *st = state::OUT;
        }
    });
}
