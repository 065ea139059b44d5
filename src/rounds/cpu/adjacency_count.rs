//! Twin of shaders/core/adjacency_count.wgsl, the first of the vertex-face lists' three stages
//! (then adjacency_fill.rs, adjacency_sort.rs). The vertex→face lists (CSR) of the current faces,
//! built by counting, a prefix sum and a scatter. The scatter's order depends on thread timing, so
//! each list is then sorted: the lists, and everything gathered from them, are the same on every
//! run and on CPU and GPU.

use super::par_for;
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
