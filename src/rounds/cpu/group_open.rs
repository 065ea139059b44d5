//! Twin of shaders/rounds/group_open.wgsl, invocation by invocation: one of the grouped rounds'
//! stages, which [`super::group_flags`] tells whole.

use super::counters::{CounterField, counter};
use crate::compute::types::Params;
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

/// One invocation: which groups reached their target, the open ones, their excess and their
/// faces into the counters, and the counts zeroed again.
pub fn group_open(
    params: &Params,
    group_target: &[u32],
    group_count: &mut [u32],
    group_closed: &mut [u32],
    counters: &[AtomicU32],
) {
    let (mut open, mut excess, mut faces) = (0u32, 0u32, 0u32);
    for g in 0..params.groups as usize {
        let (n, t) = (group_count[g], group_target[g]);
        group_closed[g] = (n <= t) as u32;
        if n > t {
            open += 1;
            excess += n - t;
            faces += n;
        }
        group_count[g] = 0;
    }
    counter(counters, CounterField::OpenGroups).store(open, Relaxed);
    counter(counters, CounterField::OpenExcess).store(excess, Relaxed);
    counter(counters, CounterField::OpenFaces).store(faces, Relaxed);
}
