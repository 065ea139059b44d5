//! Twin of shaders/collapse.wgsl: each winner moves its survivor to the new position, gives it
//! the sum of both quadrics (re-centred on the new position) and the removed vertex's border
//! bit, and points the removed vertex at the survivor; when the survivor is a seam vertex, the
//! removed vertex's corners take their attribute vertices from the candidate's map. Winners
//! share no face, hence no vertex, so these writes never meet.

use super::common::{quadric_add, quadric_shift, sub, xyz};
use super::{Scatter, face_of, faces_of, par_for};
use crate::gpu::types::{EdgeCandidate, FaceExtra, NO_ATTR, Params, Quadric, flag, state};

/// The attribute vertex a corner of the removed vertex takes under `m`
/// (`EdgeCandidate::attr_map`).
fn mapped(m: [u32; 4], a: u32) -> u32 {
    if m[0] == NO_ATTR || a == m[0] {
        m[1]
    } else if a == m[2] {
        m[3]
    } else {
        a
    }
}

#[allow(clippy::too_many_arguments)]
pub fn collapse(
    params: &Params,
    candidates: &[EdgeCandidate],   // per edge
    edge_state: &[u32],             // per edge
    edge_offsets: &[u32],           // per vertex + 1: the edge count at [vertex_count]
    positions: Scatter<[f32; 4]>,   // per vertex
    quadrics: Scatter<Quadric>,     // per vertex
    flags: Scatter<u32>,            // per vertex
    remap: Scatter<u32>,            // per vertex
    indices: &[u32],                // per face × 3
    offsets: &[u32],                // per vertex + 1
    vertex_faces: &[u32],           // per corner
    face_extra: Scatter<FaceExtra>, // per face
) {
    let edge_count = edge_offsets[params.vertex_count as usize];
    par_for(edge_count, |e| {
        if edge_state[e as usize] != state::WON {
            return;
        }
        let c = &candidates[e as usize];
        let (k, r) = (c.keep as usize, c.remove as usize);
        // SAFETY: winners share no face and so no vertex (select_win); each winner reads and
        // writes only its own two vertices and the faces around the removed one, which the
        // face locks of `validate` give to this winner alone.
        unsafe {
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
            if c.attr_map[1] != NO_ATTR {
                // The faces that stay (those on the edge go).
                for &f in faces_of(offsets, vertex_faces, c.remove) {
                    let t = face_of(indices, f);
                    if t.contains(&c.keep) {
                        continue;
                    }
                    let mut x = face_extra.read(f as usize);
                    for (i, &u) in t.iter().enumerate() {
                        if u == c.remove {
                            x.attr[i] = mapped(c.attr_map, x.attr[i]);
                        }
                    }
                    face_extra.write(f as usize, x);
                }
            }
        }
    });
}
