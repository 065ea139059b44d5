//! Twin of shaders/rounds/collapse.wgsl: each winner moves its survivor to the new position, gives it
//! the sum of both quadrics (re-centred on the new position) and the removed vertex's border
//! bit, and points the removed vertex at the survivor; when the survivor is a seam vertex, the
//! removed vertex's corners take their attribute vertices by the seam rule `edge_errors`
//! checked. Winners share no face, hence no vertex, so these writes never meet.

use super::common::{quadric_add, quadric_shift, sub, xyz};
use super::{Scatter, corner_on, face_of, faces_of, par_for};
use crate::gpu::types::{EdgeCandidate, FaceExtra, NO_ATTR, Params, Quadric, flag, state};

/// The attribute vertex a corner of the removed vertex takes under map `m` (see [`NO_ATTR`]).
fn mapped(m: [u32; 4], a: u32) -> u32 {
    if m[0] == NO_ATTR || a == m[0] {
        m[1]
    } else if a == m[2] {
        m[3]
    } else {
        a
    }
}

/// The faces and their attribute vertices, for rewriting the removed vertex's corners.
struct Corners<'a> {
    indices: &'a [u32],
    offsets: &'a [u32],
    vertex_faces: &'a [u32],
    face_extra: Scatter<'a, FaceExtra>,
}

impl Corners<'_> {
    /// The attribute vertex face `f` uses at its corner on vertex `v`.
    ///
    /// # Safety
    /// No other thread writes face `f` meanwhile.
    unsafe fn corner_attr(&self, f: u32, v: u32) -> u32 {
        let i = corner_on(self.indices, f, v);
        // SAFETY: the caller's.
        unsafe { self.face_extra.read(f as usize).attr[i] }
    }

    /// The removed vertex `r`'s corners onto seam vertex `k`: the map from the faces on the
    /// edge (locked since `edge_errors` checked it): each side's pair for a seam vertex sliding
    /// along its seam, `k`'s attribute vertex for all corners of a free one.
    ///
    /// # Safety
    /// The faces around `r` are this thread's alone (winners share no face: the selection).
    unsafe fn onto_seam(&self, flags: &Scatter<u32>, k: u32, r: u32) {
        let faces = faces_of(self.offsets, self.vertex_faces, r);
        // SAFETY: the caller's: r's faces and flags are this winner's alone.
        unsafe {
            let slides = flags.read(r as usize) & flag::SEAM != 0;
            let mut m = [NO_ATTR; 4];
            let mut n = 0;
            for &f in faces {
                if face_of(self.indices, f).contains(&k) {
                    if !slides {
                        m[1] = self.corner_attr(f, k);
                    } else if n < 2 {
                        m[2 * n] = self.corner_attr(f, r);
                        m[2 * n + 1] = self.corner_attr(f, k);
                    }
                    n += 1;
                }
            }
            // The faces that stay (those on the edge go).
            for &f in faces {
                let t = face_of(self.indices, f);
                if t.contains(&k) {
                    continue;
                }
                let mut x = self.face_extra.read(f as usize);
                for (i, &u) in t.iter().enumerate() {
                    if u == r {
                        x.attr[i] = mapped(m, x.attr[i]);
                    }
                }
                self.face_extra.write(f as usize, x);
            }
        }
    }
}

#[allow(clippy::too_many_arguments)]
pub(crate) fn collapse(
    params: &Params,
    candidates: &[EdgeCandidate],   // per edge
    edge_state: &[u32],             // per edge
    edge_offsets: &[u32],           // per vertex + 1: the edge count at [vertex_count]
    indices: &[u32],                // per face × 3
    offsets: &[u32],                // per vertex + 1
    vertex_faces: &[u32],           // per corner
    positions: Scatter<[f32; 4]>,   // per vertex
    quadrics: Scatter<Quadric>,     // per vertex
    flags: Scatter<u32>,            // per vertex
    remap: Scatter<u32>,            // per vertex
    face_extra: Scatter<FaceExtra>, // per face
) {
    let edge_count = edge_offsets[params.vertex_count as usize];
    let corners = Corners {
        indices,
        offsets,
        vertex_faces,
        face_extra,
    };
    par_for(edge_count, |e| {
        if edge_state[e as usize] != state::WON {
            return;
        }
        let c = &candidates[e as usize];
        let (k, r) = (c.keep as usize, c.remove as usize);
        // SAFETY: winners share no face and so no vertex (the selection; checked every round,
        // release builds included, by `select::shared_face`, after which `CpuRounds::select`
        // stops with an error instead of reaching this stage); each winner reads and writes only its own
        // two vertices and the faces around the removed one, which no other winner touches.
        unsafe {
            if flags.read(k) & flag::SEAM != 0 {
                corners.onto_seam(&flags, c.keep, c.remove);
            }
            let pk = positions.read(k);
            let pr = positions.read(r);
            let p = xyz(c.pos);
            let q = quadric_add(
                &quadric_shift(&quadrics.read(k), sub(p, xyz(pk))),
                &quadric_shift(&quadrics.read(r), sub(p, xyz(pr))),
            );
            quadrics.write(k, q);
            let moved = if p != xyz(pk) { flag::MOVED } else { 0 };
            flags.write(k, flags.read(k) | (flags.read(r) & flag::BORDER) | moved);
            positions.write(k, [p[0], p[1], p[2], 1.0]);
            remap.write(r, k as u32);
        }
    });
}
