//! Twin of shaders/rounds/group_flags.wgsl, the first of the grouped rounds' four stages (then
//! group_errors.rs, group_faces.rs, group_open.rs). Grouped rounds ([`Params::groups`]), where each
//! group of faces has a target of its own — a level of the cluster DAG, every group simplified to
//! half in one run, the vertices groups share pinned. A free vertex then has faces of one group
//! only, so its first face names its group. Each stage does nothing without groups (the schedule
//! runs them only with: `When::Grouped`).

use super::par_for_mut;
use crate::compute::types::{FaceExtra, Params, flag};

/// The group of free vertex `v`: its first face's.
pub(super) fn group_of(
    offsets: &[u32],
    vertex_faces: &[u32],
    face_extra: &[FaceExtra],
    face_group: &[u32],
    v: u32,
) -> u32 {
    let f = vertex_faces[offsets[v as usize] as usize];
    face_group[face_extra[f as usize].origin as usize]
}

/// Per vertex at the start of a round: a free vertex of a closed group is CLOSED, every other
/// vertex not.
pub fn group_flags(
    params: &Params,
    offsets: &[u32],          // per vertex + 1
    vertex_faces: &[u32],     // per corner
    face_extra: &[FaceExtra], // per face
    face_group: &[u32],       // per input face
    group_closed: &[u32],     // per group
    flags: &mut [u32],        // per vertex
) {
    par_for_mut(&mut flags[..params.vertex_count as usize], |v, fl| {
        let mut f = *fl & !flag::CLOSED;
        let vu = v as usize;
        if f & flag::PINNED == 0 && offsets[vu] < offsets[vu + 1] {
            let g = group_of(offsets, vertex_faces, face_extra, face_group, v);
            if group_closed[g as usize] != 0 {
                f |= flag::CLOSED;
            }
        }
        *fl = f;
    });
}
