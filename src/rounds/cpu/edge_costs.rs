//! Twin of shaders/rounds/edge_costs.wgsl: for the candidates whose error (`edge_errors`) is under
//! the round's cost ceiling, the faces that move: no normal may turn past the angle limit (against
//! the current and the input normal), no needle may appear, and the worst new quality scales the
//! error up to the priority the selection ranks by (MeshLab-style). The ceiling picks the edges
//! that compete by their error; the priority orders them. Edges over the ceiling dropped out
//! unchecked (`live_list`): on the 1M scan at 1%, checking the moved faces of every edge was half
//! the run. The topological checks (link condition, border pinch, lone triangle, tetrahedral fold)
//! scan both endpoints' neighbourhoods and rarely fail on a manifold, so they run in `validate`,
//! only for the edges that win a selection pass.

use super::counters::{CounterField, counter};
use super::{Scatter, face_of, faces_of, par_for};
use crate::compute::common::*;
use crate::compute::types::{EdgeCandidate, Params, state};
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

/// The priority of collapsing `c` (its error, as `edge_errors` wrote it, scaled by the worst
/// quality of the faces that move), or None when a moving face would flip or become a needle.
#[allow(clippy::too_many_arguments)]
pub fn moved_faces(
    params: &Params,
    positions: &[[f32; 4]],
    indices: &[u32],
    offsets: &[u32],
    vertex_faces: &[u32],
    face_normals: &[[f32; 4]],
    c: &EdgeCandidate,
) -> Option<f32> {
    let (keep, remove) = (c.keep, c.remove);
    let pos = xyz(c.pos);
    let error = f32::from_bits(c.cost_bits);
    // Faces that move: normals may not turn past the limit (against the current and the input
    // normal), no needle may appear; the worst new quality scales the priority.
    let mut min_q = f32::INFINITY;
    for (moved, other) in [(keep, remove), (remove, keep)] {
        for &f in faces_of(offsets, vertex_faces, moved) {
            let t = face_of(indices, f);
            if t.contains(&other) {
                continue;
            }
            let old = t.map(|u| xyz(positions[u as usize]));
            let new = t.map(|u| {
                if u == moved {
                    pos
                } else {
                    xyz(positions[u as usize])
                }
            });
            let n_old = cross(sub(old[1], old[0]), sub(old[2], old[0]));
            let n_new = cross(sub(new[1], new[0]), sub(new[2], new[0]));
            let (l_old, l_new) = (length(n_old), length(n_new));
            if l_new.is_nan() || l_new <= 0.0 {
                return None;
            }
            if l_old > 0.0 && dot(n_old, n_new) < params.cos_max_angle * l_old * l_new {
                return None;
            }
            let fr = face_normals[f as usize];
            if fr[3] > 0.0 && dot(xyz(fr), n_new) < params.cos_max_angle * l_new {
                return None;
            }
            let q_new = quality_from_area2(l_new, new[0], new[1], new[2]);
            if q_new < params.min_quality && q_new < triangle_quality(old[0], old[1], old[2]) {
                return None;
            }
            min_q = min_q.min(q_new);
        }
    }
    let qt = params.quality_threshold;
    let priority = if qt > 0.0 && min_q < qt {
        error * (qt / min_q.max(1e-12))
    } else {
        error
    };
    priority.is_finite().then_some(priority)
}

/// Per listed candidate (`live_list`): its priority, or it drops out as invalid.
#[allow(clippy::too_many_arguments)]
pub(crate) fn edge_costs(
    params: &Params,
    positions: &[[f32; 4]],             // per vertex
    indices: &[u32],                    // per face × 3
    offsets: &[u32],                    // per vertex + 1
    vertex_faces: &[u32],               // per corner
    face_normals: &[[f32; 4]],          // per face
    live: &[u32],                       // per listed candidate
    candidates: Scatter<EdgeCandidate>, // per edge
    edge_state: Scatter<u32>,           // per edge
    counters: &[AtomicU32],
) {
    let n = counter(counters, CounterField::Live).load(Relaxed);
    par_for(n, |i| {
        let e = live[i as usize] as usize;
        // SAFETY: the live list holds each edge once, so this invocation alone touches slot e.
        let c = unsafe { candidates.read(e) };
        match moved_faces(
            params,
            positions,
            indices,
            offsets,
            vertex_faces,
            face_normals,
            &c,
        ) {
            // SAFETY: as above.
            Some(priority) => unsafe {
                candidates.write(
                    e,
                    EdgeCandidate {
                        cost_bits: priority.to_bits(),
                        ..c
                    },
                )
            },
            None => {
                // SAFETY: as above.
                unsafe {
                    candidates.write(e, EdgeCandidate::INVALID);
                    edge_state.write(e, state::OUT);
                }
                // No longer a valid collapse: when every edge competes (the ceiling is
                // INVALID_COST, as in the round the driver stops on) the count is then exactly
                // the valid edges under the maximum error, which tells MaxError apart.
                counter(counters, CounterField::Candidates).fetch_sub(1, Relaxed);
            }
        }
    });
}
