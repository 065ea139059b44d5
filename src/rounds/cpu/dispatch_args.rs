//! Twin of shaders/rounds/dispatch_args.wgsl: the indirect dispatch sizes of the per-edge stages,
//! of `validate`, of the per-candidate stages and of the trim's per-edge stages (zero unless the
//! round trims). The CPU runs loops of the exact length; this twin exists so tests can diff the GPU
//! stage.

use super::counters::{CounterField, counter};
use crate::compute::types::{Params, WG};
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

fn grid(n: u32) -> [u32; 4] {
    let groups = n.div_ceil(WG).max(1);
    let x = groups.min(65535);
    [x, groups.div_ceil(x), 1, 0]
}

pub fn dispatch_args(
    params: &Params,
    edge_offsets: &[u32],
    counters: &[AtomicU32],
    args: &mut [u32; 16],
) {
    let edges = grid(edge_offsets[params.vertex_count as usize]);
    let tentative = grid(counter(counters, CounterField::Tentative).load(Relaxed));
    let live = grid(counter(counters, CounterField::Live).load(Relaxed));
    args[..4].copy_from_slice(&edges);
    args[4..8].copy_from_slice(&tentative);
    args[8..12].copy_from_slice(&live);
    let trim = if params.trim != 0 { edges } else { [0; 4] };
    args[12..].copy_from_slice(&trim);
}
