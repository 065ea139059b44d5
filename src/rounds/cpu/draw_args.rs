//! Twin of shaders/rounds/draw_args.wgsl, invocation by invocation: one of the compaction's stages,
//! which [`super::compact_mark`] tells whole.

use super::counters::{CounterField, counter};
use crate::compute::types::{DrawArgs, Params};
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

/// One invocation: counts after compaction, and the indirect draw arguments.
pub fn draw_args(
    params: &Params,
    vertex_keep: &[u32],
    face_keep: &[u32],
    counters: &[AtomicU32],
    args: &mut DrawArgs,
) {
    let nv = vertex_keep[params.vertex_count as usize];
    let nf = face_keep[params.face_count as usize];
    counter(counters, CounterField::VerticesOut).store(nv, Relaxed);
    counter(counters, CounterField::FacesOut).store(nf, Relaxed);
    *args = DrawArgs {
        index_count: 3 * nf,
        instance_count: 1,
        ..Default::default()
    };
}
