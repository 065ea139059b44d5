//! Twin of shaders/rounds/cost_ceiling.wgsl (one invocation): the ceiling below which candidates
//! compete this round, the smallest histogram bin boundary under which at least
//! `ceiling_wanted` candidates lie. Keeps each round's collapses among the cheapest edges, so
//! the order stays close to the greedy one.

use super::counters::{CounterField, counter};
use crate::compute::types::{HIST_BINS, HIST_SHIFT, INVALID_COST, Params};
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

pub fn cost_ceiling(params: &Params, histogram: &[u32], counters: &[AtomicU32]) {
    let mut cum = 0u32;
    let mut ceiling = INVALID_COST;
    for bin in 0..HIST_BINS {
        cum += histogram[bin as usize];
        if cum >= params.ceiling_wanted {
            if bin + 1 < HIST_BINS {
                ceiling = (bin + 1) << HIST_SHIFT;
            }
            break;
        }
    }
    counter(counters, CounterField::Ceiling).store(ceiling, Relaxed);
}
