//! Twin of shaders/rounds/trim_ceiling.wgsl, invocation by invocation: one of the trim's stages,
//! which [`super::trim_histogram`] tells whole.

use super::counters::{CounterField, counter};
use crate::compute::types::{HIST_BINS, Params};
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

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
