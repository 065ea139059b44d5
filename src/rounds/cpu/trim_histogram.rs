//! Twin of shaders/rounds/trim_histogram.wgsl, the first of the trim's four stages (then
//! trim_ceiling.rs, trim_mark.rs, trim_apply.rs). In a round that would overshoot the target, the
//! winners are cut back cheapest first so the face count lands on the target or one below it (a
//! collapse removes one or two faces: the last winner kept may take two where one was left), never
//! above, as the greedy reference does. Bins of the winners' costs find the bin where the budget
//! runs out; within that bin, winners are taken in edge-id order (a prefix sum of the faces they
//! remove) while the budget is not met. Each stage does nothing in a round that does not trim
//! (`Params::trim` 0): a round planned on the device records them in every round.

use super::par_for;
use crate::compute::types::{EdgeCandidate, HIST_SHIFT, Params, state};
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
