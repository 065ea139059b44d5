//! Twin of shaders/rounds/live_list.wgsl: the candidates whose error is under the round's cost
//! ceiling go on the live list, the others drop out; `edge_costs` and the selection passes then run
//! over the list instead of every edge. The GPU lists in an order that depends on timing, the CPU
//! in edge order; no stage's result depends on it (each writes its own edge's slots).

use super::counters::{CounterField, counter};
use crate::compute::types::{EdgeCandidate, Params, state};
use rayon::prelude::*;
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

/// Per edge; `live` is cleared and refilled.
pub fn live_list(
    params: &Params,
    edge_offsets: &[u32],         // per vertex + 1
    candidates: &[EdgeCandidate], // per edge
    edge_state: &mut [u32],       // per edge
    counters: &[AtomicU32],
    live: &mut Vec<u32>, // per listed candidate
) {
    let ne = edge_offsets[params.vertex_count as usize] as usize;
    let ceiling = counter(counters, CounterField::Ceiling).load(Relaxed);
    live.clear();
    live.par_extend(
        edge_state[..ne]
            .par_iter_mut()
            .zip(&candidates[..ne])
            .enumerate()
            .with_min_len(1024)
            .filter_map(|(e, (st, c))| {
                if *st != state::CANDIDATE {
                    return None;
                }
                if c.cost_bits >= ceiling {
                    *st = state::OUT;
                    return None;
                }
                Some(e as u32)
            }),
    );
    counter(counters, CounterField::Live).store(live.len() as u32, Relaxed);
}
