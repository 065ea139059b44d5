//! The round's counters ([`Counters`], one buffer every stage shares) seen as atomics by field:
//! what the twins read and bump where the shaders use `atomicAdd` on the same words.

use crate::compute::types::Counters;
use std::sync::atomic::AtomicU32;

/// Fields of [`Counters`] by position, for the atomic view of the buffer.
#[derive(Clone, Copy)]
pub enum CounterField {
    Candidates = 0,
    OverMaxError = 1,
    Ceiling = 2,
    Winners = 3,
    Removed = 4,
    MaxErr2Bits = 5,
    TrimBin = 6,
    TrimBudget = 7,
    VerticesOut = 8,
    FacesOut = 9,
    Tentative = 10,
    Live = 11,
    OpenGroups = 12,
    OpenExcess = 13,
    OpenFaces = 14,
}

/// Field `f` of the atomic view of the counters buffer.
pub fn counter(counters: &[AtomicU32], f: CounterField) -> &AtomicU32 {
    const _: () = assert!(std::mem::size_of::<Counters>() == 16 * 4);
    &counters[f as usize]
}
