//! Twin of shaders/edge_costs.wgsl: per edge, where the collapse would put the survivor, its
//! quadric error, the faces that move (no flip past the angle limit, no needle) and the priority
//! (error scaled up for poor triangle quality, MeshLab-style), and the cost histogram the ceiling
//! is picked from. The topological checks (link condition, border pinch, lone triangle,
//! tetrahedral fold) scan both endpoints' neighbourhoods and rarely fail on a manifold, so they
//! run in `validate`, only for the edges that win a selection pass. Seam vertices follow the
//! greedy reference's rules: a free vertex may move onto one, and one may slide along its seam
//! onto a seam neighbour (`collapse` makes the attribute map again from the same faces).

use super::common::*;
use super::{corner_attr, face_of, faces_of};
use crate::gpu::types::{
    Counters, EdgeCandidate, FaceExtra, HIST_SHIFT, NO_ATTR, Params, Quadric, flag, state,
};
use rayon::prelude::*;
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

/// What `edge_costs` decided for one edge, before it is written out.
pub enum Verdict {
    Invalid,
    /// Valid so far, but its error exceeds the maximum.
    OverMaxError,
    Candidate(EdgeCandidate),
}

/// The faces and their attribute vertices, as the seam rules read them.
struct Corners<'a> {
    indices: &'a [u32],
    offsets: &'a [u32],
    vertex_faces: &'a [u32],
    face_extra: &'a [FaceExtra],
}

impl Corners<'_> {
    /// Free vertex `r` moving onto seam vertex `k`: its corners take the attribute vertex `k`
    /// has in the faces on the edge, which must agree (else the edge runs along the seam).
    fn onto_seam(&self, k: u32, r: u32) -> Option<[u32; 4]> {
        let mut to = NO_ATTR;
        for &f in faces_of(self.offsets, self.vertex_faces, r) {
            if face_of(self.indices, f).contains(&k) {
                let a = corner_attr(self.indices, self.face_extra, f, k);
                if to != NO_ATTR && to != a {
                    return None;
                }
                to = a;
            }
        }
        (to != NO_ATTR).then_some([NO_ATTR, to, NO_ATTR, NO_ATTR])
    }

    /// Seam vertex `r` sliding along edge (r, k) onto seam vertex `k` (the greedy's
    /// `seam_slide`): `r` is free to go (not pinned, not on a border), has two attribute
    /// vertices, and the two faces on the edge use different ones at both ends. Returns
    /// (from₁, to₁, from₂, to₂).
    fn seam_slide(&self, flags: &[u32], r: u32, k: u32) -> Option<[u32; 4]> {
        if flags[r as usize] & (flag::PINNED | flag::BORDER) != 0 {
            return None;
        }
        let mut attrs = [NO_ATTR; 2];
        let mut sides = [NO_ATTR; 4];
        let mut n = 0;
        for &f in faces_of(self.offsets, self.vertex_faces, r) {
            let a = corner_attr(self.indices, self.face_extra, f, r);
            if attrs[0] == NO_ATTR || attrs[0] == a {
                attrs[0] = a;
            } else if attrs[1] == NO_ATTR || attrs[1] == a {
                attrs[1] = a;
            } else {
                return None; // a seam junction stays
            }
            if face_of(self.indices, f).contains(&k) {
                if n == 2 {
                    return None;
                }
                sides[2 * n] = a;
                sides[2 * n + 1] = corner_attr(self.indices, self.face_extra, f, k);
                n += 1;
            }
        }
        (n == 2 && sides[0] != sides[2] && sides[1] != sides[3]).then_some(sides)
    }
}

/// The survivor, its new position and the quadric error (`cost_bits`; `pos.w` = error relative
/// to the diagonal, squared). Two pinned ends, and seam vertices other than by the seam rules
/// (`flag::SEAM`), are refused here.
#[allow(clippy::too_many_arguments)]
pub fn placement(
    params: &Params,
    positions: &[[f32; 4]],
    quadrics: &[Quadric],
    flags: &[u32],
    indices: &[u32],
    offsets: &[u32],
    vertex_faces: &[u32],
    face_normals: &[[f32; 4]],
    face_extra: &[FaceExtra],
    a: u32,
    b: u32,
) -> Verdict {
    let (fla, flb) = (flags[a as usize], flags[b as usize]);
    let corners = Corners {
        indices,
        offsets,
        vertex_faces,
        face_extra,
    };
    // Seam vertices keep their position like pinned ones.
    let fixed = |fl: u32| fl & (flag::PINNED | flag::SEAM) != 0;
    let pa = xyz(positions[a as usize]);
    let pb = xyz(positions[b as usize]);
    let dab = sub(pb, pa);
    // b's quadric moved to a's origin: x - pb = (x - pa) + (pa - pb).
    let q = quadric_add(
        &quadrics[a as usize],
        &quadric_shift(&quadrics[b as usize], sub(pa, pb)),
    );
    let mut slides = false;
    let (keep, remove, y) = if fixed(fla) && fixed(flb) {
        // Only a seam vertex sliding along its seam onto a seam neighbour; b first, as the
        // greedy tries.
        if fla & flb & flag::SEAM == 0 {
            return Verdict::Invalid;
        }
        slides = true;
        if corners.seam_slide(flags, b, a).is_some() {
            (a, b, [0.0; 3])
        } else if corners.seam_slide(flags, a, b).is_some() {
            (b, a, dab)
        } else {
            return Verdict::Invalid;
        }
    } else if fixed(fla) {
        (a, b, [0.0; 3])
    } else if fixed(flb) {
        (b, a, dab)
    } else {
        let y = match quadric_optimum(&q) {
            Some(y) => y,
            None => {
                let mut best = [0.0f32; 3];
                let mut best_e = quadric_eval(&q, best);
                for c in [dab, scale(dab, 0.5)] {
                    let e = quadric_eval(&q, c);
                    if e < best_e {
                        best = c;
                        best_e = e;
                    }
                }
                best
            }
        };
        // The survivor is the endpoint nearer the new position.
        if dot(y, y) <= dot(sub(y, dab), sub(y, dab)) {
            (a, b, y)
        } else {
            (b, a, y)
        }
    };
    if flags[keep as usize] & flag::SEAM != 0
        && !slides
        && corners.onto_seam(keep, remove).is_none()
    {
        return Verdict::Invalid;
    }
    let error = quadric_eval(&q, y);
    // A survivor that keeps its position keeps it bit for bit (pa + (pb - pa) need not be pb):
    // a seam vertex marked moved would leave its other attribute vertices behind.
    let pos = if flags[keep as usize] & (flag::PINNED | flag::SEAM) != 0 {
        xyz(positions[keep as usize])
    } else {
        add(pa, y)
    };

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
                return Verdict::Invalid;
            }
            if l_old > 0.0 && dot(n_old, n_new) < params.cos_max_angle * l_old * l_new {
                return Verdict::Invalid;
            }
            let fr = face_normals[f as usize];
            if fr[3] > 0.0 && dot(xyz(fr), n_new) < params.cos_max_angle * l_new {
                return Verdict::Invalid;
            }
            let q_new = quality_from_area2(l_new, new[0], new[1], new[2]);
            if q_new < params.min_quality && q_new < triangle_quality(old[0], old[1], old[2]) {
                return Verdict::Invalid;
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
    let weight = q.q[2][2];
    let err2 = if weight > 0.0 { error / weight } else { 0.0 };
    if !(priority.is_finite() && err2.is_finite() && pos.iter().all(|x| x.is_finite())) {
        return Verdict::Invalid;
    }
    if err2 > params.max_error2 {
        return Verdict::OverMaxError;
    }
    Verdict::Candidate(EdgeCandidate {
        pos: [pos[0], pos[1], pos[2], err2],
        keep,
        remove,
        cost_bits: priority.to_bits(),
        faces: 0,
    })
}

/// Per edge (`edge_capacity` invocations; those past the edge count stop at once).
#[allow(clippy::too_many_arguments)]
pub fn edge_costs(
    params: &Params,
    positions: &[[f32; 4]],           // per vertex
    quadrics: &[Quadric],             // per vertex
    flags: &[u32],                    // per vertex
    indices: &[u32],                  // per face × 3
    offsets: &[u32],                  // per vertex + 1
    vertex_faces: &[u32],             // per corner
    face_normals: &[[f32; 4]],        // per face
    face_extra: &[FaceExtra],         // per face
    edges: &[[u32; 2]],               // per edge
    edge_offsets: &[u32],             // per vertex + 1: the edge count at [vertex_count]
    candidates: &mut [EdgeCandidate], // per edge
    edge_state: &mut [u32],           // per edge
    histogram: &[AtomicU32],          // HIST_BINS, cleared
    counters: &[AtomicU32],           // Counters, cleared
) {
    let ne = edge_offsets[params.vertex_count as usize] as usize;
    candidates[..ne]
        .par_iter_mut()
        .zip(&mut edge_state[..ne])
        .enumerate()
        .with_min_len(256)
        .for_each(|(e, (out, st))| {
            let [a, b] = edges[e];
            let verdict = placement(
                params,
                positions,
                quadrics,
                flags,
                indices,
                offsets,
                vertex_faces,
                face_normals,
                face_extra,
                a,
                b,
            );
            *st = state::OUT;
            *out = EdgeCandidate::INVALID;
            match verdict {
                Verdict::Invalid => {}
                Verdict::OverMaxError => {
                    counter(counters, CounterField::OverMaxError).fetch_add(1, Relaxed);
                }
                Verdict::Candidate(c) => {
                    histogram[(c.cost_bits >> HIST_SHIFT) as usize].fetch_add(1, Relaxed);
                    counter(counters, CounterField::Candidates).fetch_add(1, Relaxed);
                    *out = c;
                    *st = state::CANDIDATE;
                }
            }
        });
}

/// Fields of [`Counters`] by position, for the atomic view of the buffer.
#[derive(Clone, Copy)]
pub enum CounterField {
    Candidates = 0,
    OverMaxError = 1,
    Ceiling = 2,
    Winners = 3,
    Removed = 4,
    MaxErr2Bits = 5,
    TrimBin = 6,
    TrimBudget = 7,
    VerticesOut = 8,
    FacesOut = 9,
    Tentative = 10,
}

pub fn counter(counters: &[AtomicU32], f: CounterField) -> &AtomicU32 {
    const _: () = assert!(std::mem::size_of::<Counters>() == 16 * 4);
    &counters[f as usize]
}
