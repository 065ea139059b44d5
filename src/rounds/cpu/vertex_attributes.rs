//! Twin of shaders/rounds/vertex_attributes.wgsl (first round, with appearance channels): over
//! each face of a vertex, every channel is the linear function `g·y + d` through its corners;
//! the face folds `area·(g gᵀ, d g, d²)` into the vertex's quadric and adds `area·g`, `area·d`
//! and its area to the sums of the attribute vertex its corner on the vertex uses (Hoppe 1999).
//! Each attribute vertex belongs to one vertex, whose invocation alone writes its sums.

use super::attributes::Channels;
use super::{Scatter, corner_attr, face_of, faces_of, par_for_mut};
use crate::compute::common::{dot, sub, xyz};
use crate::compute::types::{FaceExtra, Params, Quadric};

#[allow(clippy::too_many_arguments)]
pub(crate) fn vertex_attributes(
    params: &Params,
    positions: &[[f32; 4]],    // per vertex
    indices: &[u32],           // per face × 3
    offsets: &[u32],           // per vertex + 1
    vertex_faces: &[u32],      // per corner
    face_normals: &[[f32; 4]], // per face: unit normal, area
    face_extra: &[FaceExtra],  // per face
    attr_values: &[f32],       // per attribute vertex × m
    quadrics: &mut [Quadric],  // per vertex
    attr_sums: Scatter<f32>,   // per attribute vertex × (4m + 1)
) {
    let ch = Channels::of(params);
    let (m, stride) = (ch.m, ch.stride());
    par_for_mut(&mut quadrics[..params.vertex_count as usize], |v, q| {
        let pv = xyz(positions[v as usize]);
        let list = faces_of(offsets, vertex_faces, v);
        let sums_of = |f: u32| {
            let o = corner_attr(indices, face_extra, f, v) as usize * stride;
            // SAFETY: the attribute vertices of v's corners are v's alone (each belongs to one
            // vertex), and v is this invocation's.
            unsafe { attr_sums.range_mut(o, o + stride) }
        };
        for &f in list {
            sums_of(f).fill(0.0);
        }
        for &f in list {
            let area = face_normals[f as usize][3];
            if area.is_nan() || area <= 0.0 {
                continue;
            }
            let t = face_of(indices, f);
            let x = face_extra[f as usize].attr;
            let p0 = xyz(positions[t[0] as usize]);
            let e1 = sub(xyz(positions[t[1] as usize]), p0);
            let e2 = sub(xyz(positions[t[2] as usize]), p0);
            let (a, b, c) = (dot(e1, e1), dot(e1, e2), dot(e2, e2));
            let det = a * c - b * b;
            if det.is_nan() || det <= 0.0 {
                continue;
            }
            let r0 = sub(p0, pv);
            let sums = sums_of(f);
            for j in 0..m {
                let s0 = attr_values[x[0] as usize * m + j];
                let d1 = attr_values[x[1] as usize * m + j] - s0;
                let d2 = attr_values[x[2] as usize * m + j] - s0;
                let alpha = (c * d1 - b * d2) / det;
                let beta = (a * d2 - b * d1) / det;
                let g = [0, 1, 2].map(|k| alpha * e1[k] + beta * e2[k]);
                let d = s0 - dot(g, r0);
                let [q0, q1, q2] = &mut q.q;
                q0[0] += area * g[0] * g[0];
                q0[1] += area * g[0] * g[1];
                q0[2] += area * g[0] * g[2];
                q0[3] += area * g[1] * g[1];
                q1[0] += area * g[1] * g[2];
                q1[1] += area * g[2] * g[2];
                q1[2] += area * d * g[0];
                q1[3] += area * d * g[1];
                q2[0] += area * d * g[2];
                q2[1] += area * d * d;
                for k in 0..3 {
                    sums[3 * j + k] += area * g[k];
                }
                sums[3 * m + j] += area * d;
            }
            sums[4 * m] += area;
        }
    });
}
