//! Twin of shaders/rounds/group_faces.wgsl, invocation by invocation: one of the grouped rounds'
//! stages, which [`super::group_flags`] tells whole.

use super::par_for;
use crate::compute::types::{FaceExtra, Params};
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

/// Per face after compaction: each kept face counts towards its group.
pub fn group_faces(
    params: &Params,
    face_keep: &[u32],            // per face + 1: the kept count at [face_count]
    face_extra_out: &[FaceExtra], // per kept face
    face_group: &[u32],
    group_count: &[AtomicU32], // per group, zero
) {
    let kept = face_keep[params.face_count as usize];
    par_for(kept, |f| {
        let g = face_group[face_extra_out[f as usize].origin as usize];
        group_count[g as usize].fetch_add(1, Relaxed);
    });
}
