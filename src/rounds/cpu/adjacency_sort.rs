//! Twin of shaders/core/adjacency_sort.wgsl, invocation by invocation: one of the vertex-face
//! lists' stages, which [`super::adjacency_count`] tells whole.

use super::{Scatter, par_for};
use crate::compute::types::Params;

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
