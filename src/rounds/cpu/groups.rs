//! Twins of shaders/rounds/group_flags.wgsl, group_errors.wgsl, group_faces.wgsl and
//! group_open.wgsl: grouped rounds ([`Params::groups`]), where each group of faces has a target
//! of its own — a level of the cluster DAG, every group simplified to half in one run, the
//! vertices groups share pinned. A free vertex then has faces of one group only, so its first
//! face names its group. Each stage does nothing without groups (the schedule runs them only
//! with: `When::Grouped`).

use super::edge_costs::{CounterField, counter};
use super::{par_for, par_for_mut};
use crate::compute::types::{EdgeCandidate, FaceExtra, Params, flag, state};
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

/// The group of free vertex `v`: its first face's.
fn group_of(
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

/// One invocation: which groups reached their target, the open ones, their excess and their
/// faces into the counters, and the counts zeroed again.
pub fn group_open(
    params: &Params,
    group_target: &[u32],
    group_count: &mut [u32],
    group_closed: &mut [u32],
    counters: &[AtomicU32],
) {
    let (mut open, mut excess, mut faces) = (0u32, 0u32, 0u32);
    for g in 0..params.groups as usize {
        let (n, t) = (group_count[g], group_target[g]);
        group_closed[g] = (n <= t) as u32;
        if n > t {
            open += 1;
            excess += n - t;
            faces += n;
        }
        group_count[g] = 0;
    }
    counter(counters, CounterField::OpenGroups).store(open, Relaxed);
    counter(counters, CounterField::OpenExcess).store(excess, Relaxed);
    counter(counters, CounterField::OpenFaces).store(faces, Relaxed);
}
