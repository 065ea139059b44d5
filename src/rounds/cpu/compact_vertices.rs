//! Twin of shaders/rounds/compact_vertices.wgsl, invocation by invocation: one of the compaction's
//! stages, which [`super::compact_mark`] tells whole.

use super::{Scatter, par_for};
use crate::compute::types::{Params, Quadric};

/// Per vertex: survivors move to their scanned slot.
#[allow(clippy::too_many_arguments)]
pub(crate) fn compact_vertices(
    params: &Params,
    vertex_keep: &[u32], // scanned
    positions: &[[f32; 4]],
    quadrics: &[Quadric],
    flags: &[u32],
    vertex_attr: &[u32],
    positions_out: Scatter<[f32; 4]>,
    quadrics_out: Scatter<Quadric>,
    flags_out: Scatter<u32>,
    vertex_attr_out: Scatter<u32>,
) {
    par_for(params.vertex_count, |v| {
        let v = v as usize;
        if vertex_keep[v + 1] != vertex_keep[v] {
            let n = vertex_keep[v] as usize;
            // SAFETY: the exclusive prefix sum of 0/1 flags gives each survivor its own slot.
            unsafe {
                positions_out.write(n, positions[v]);
                quadrics_out.write(n, quadrics[v]);
                flags_out.write(n, flags[v]);
                vertex_attr_out.write(n, vertex_attr[v]);
            }
        }
    });
}
