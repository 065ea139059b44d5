//! Twin of shaders/rounds/trim_mark.wgsl, invocation by invocation: one of the trim's stages, which
//! [`super::trim_histogram`] tells whole.

use super::counters::{CounterField, counter};
use super::par_for_mut;
use crate::compute::types::{EdgeCandidate, HIST_SHIFT, Params, state};
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

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
