//! Twin of shaders/rounds/trim_apply.wgsl, invocation by invocation: one of the trim's stages,
//! which [`super::trim_histogram`] tells whole.

use super::counters::{CounterField, counter};
use super::par_for_mut;
use crate::compute::types::{EdgeCandidate, HIST_SHIFT, Params, state};
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

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
