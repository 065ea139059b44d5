//! Twin of shaders/rounds/group_errors.wgsl, invocation by invocation: one of the grouped rounds'
//! stages, which [`super::group_flags`] tells whole.

use super::group_flags::group_of;
use super::par_for;
use crate::compute::types::{EdgeCandidate, FaceExtra, Params, state};
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

/// Per edge before the collapses: each winner's squared error into its group's largest.
#[allow(clippy::too_many_arguments)]
pub fn group_errors(
    params: &Params,
    candidates: &[EdgeCandidate],
    edge_state: &[u32],
    edge_offsets: &[u32], // per vertex + 1: the edge count at [vertex_count]
    offsets: &[u32],
    vertex_faces: &[u32],
    face_extra: &[FaceExtra],
    face_group: &[u32],
    group_err: &[AtomicU32], // per group
) {
    let ne = edge_offsets[params.vertex_count as usize];
    par_for(ne, |e| {
        if edge_state[e as usize] == state::WON {
            let c = &candidates[e as usize];
            let g = group_of(offsets, vertex_faces, face_extra, face_group, c.remove);
            group_err[g as usize].fetch_max(c.pos[3].to_bits(), Relaxed);
        }
    });
}
