//! Twins of shaders/core/adjacency_count.wgsl, adjacency_fill.wgsl and adjacency_sort.wgsl: the
//! vertex→face lists (CSR) of the current faces, built by counting, a prefix sum and a scatter.
//! The scatter's order depends on thread timing, so each list is then sorted: the lists, and
//! everything gathered from them, are the same on every run and on CPU and GPU.

use super::{Scatter, par_for};
use crate::compute::types::Params;
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

/// Per face: one count per corner (`counts` cleared, `vertex_count + 1` long).
pub fn adjacency_count(params: &Params, indices: &[u32], counts: &[AtomicU32]) {
    par_for(params.face_count, |f| {
        for k in 0..3 {
            counts[indices[3 * f as usize + k] as usize].fetch_add(1, Relaxed);
        }
    });
}

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

/// Per vertex: insertion sort of its face list (valences are small).
pub(crate) fn adjacency_sort(params: &Params, offsets: &[u32], vertex_faces: Scatter<u32>) {
    par_for(params.vertex_count, |v| {
        let (lo, hi) = (
            offsets[v as usize] as usize,
            offsets[v as usize + 1] as usize,
        );
        // SAFETY: the ranges [offsets[v], offsets[v+1]) of different vertices are disjoint.
        let list = unsafe { vertex_faces.range_mut(lo, hi) };
        list.sort_unstable();
    });
}
