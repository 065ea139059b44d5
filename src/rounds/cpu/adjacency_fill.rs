//! Twin of shaders/core/adjacency_fill.wgsl, invocation by invocation: one of the vertex-face
//! lists' stages, which [`super::adjacency_count`] tells whole.

use super::{Scatter, par_for};
use crate::compute::types::Params;
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

/// Per face: its id into each corner's list at `offsets[v] + cursor[v]++` (`cursor` cleared).
pub(crate) fn adjacency_fill(
    params: &Params,
    indices: &[u32],            // per face × 3
    offsets: &[u32],            // per vertex + 1 (scanned counts)
    cursor: &[AtomicU32],       // per vertex
    vertex_faces: Scatter<u32>, // per corner
) {
    par_for(params.face_count, |f| {
        for k in 0..3 {
            let v = indices[3 * f as usize + k] as usize;
            let slot = offsets[v] + cursor[v].fetch_add(1, Relaxed);
            // SAFETY: `cursor[v]` hands out each slot of v's range once, and ranges of
            // different vertices do not overlap (exclusive prefix sum of the counts).
            unsafe { vertex_faces.write(slot as usize, f) };
        }
    });
}
