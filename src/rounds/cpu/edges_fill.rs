//! Twin of shaders/rounds/edges_fill.wgsl, invocation by invocation: one of the edge list's stages,
//! which [`super::edges_count`] tells whole.

use super::{Scatter, par_for};
use crate::compute::types::Params;

/// Per vertex: copies its listed neighbours to its scanned edge offset.
pub(crate) fn edges_fill(
    params: &Params,
    offsets: &[u32],          // per vertex + 1
    neighbours: &[u32],       // 2 per corner
    edge_offsets: &[u32],     // per vertex + 1 (scanned counts)
    edges: Scatter<[u32; 2]>, // per edge
) {
    par_for(params.vertex_count, |v| {
        let (lo, hi) = (edge_offsets[v as usize], edge_offsets[v as usize + 1]);
        let base = 2 * offsets[v as usize];
        for i in 0..hi - lo {
            // SAFETY: vertex v owns slots [edge_offsets[v], edge_offsets[v+1]), disjoint from
            // every other vertex's, and writes each once.
            unsafe { edges.write((lo + i) as usize, [v, neighbours[(base + i) as usize]]) };
        }
    });
}
