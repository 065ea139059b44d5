//! Twin of shaders/core/face_planes.wgsl: each face's unit normal and area (first round only). The
//! normal stays with the face as its reference for the flip test; the area weights its quadric.

use crate::compute::common::{cross, length, scale, sub, xyz};
use crate::compute::types::Params;
use rayon::prelude::*;

pub fn face_planes(
    params: &Params,
    positions: &[[f32; 4]],        // per vertex
    indices: &[u32],               // per face × 3
    face_normals: &mut [[f32; 4]], // per face: unit normal, area
) {
    face_normals[..params.face_count as usize]
        .par_iter_mut()
        .enumerate()
        .for_each(|(f, out)| {
            let p = [0, 1, 2].map(|k| xyz(positions[indices[3 * f + k] as usize]));
            let c = cross(sub(p[1], p[0]), sub(p[2], p[0]));
            let l = length(c);
            *out = if l > 0.0 {
                let n = scale(c, 1.0 / l);
                [n[0], n[1], n[2], 0.5 * l]
            } else {
                [0.0; 4]
            };
        });
}
