//! Twin of shaders/vertex_quadrics.wgsl (first round): each vertex gathers the area-weighted plane
//! quadrics of its faces and, for each border edge at it, Hoppe's constraint plane through the
//! edge perpendicular to its face, weighted by the squared edge length. A gather in the sorted
//! face order, so the sums do not depend on thread timing. Quadrics are relative to the vertex.

use super::common::{cross, dot, length, quadric_add, quadric_from_plane, scale, sub, xyz};
use super::vertex_flags::count_containing;
use super::{face_of, faces_of, par_for_mut};
use crate::gpu::types::{Params, Quadric};

pub fn vertex_quadrics(
    params: &Params,
    positions: &[[f32; 4]],    // per vertex
    indices: &[u32],           // per face × 3
    offsets: &[u32],           // per vertex + 1
    vertex_faces: &[u32],      // per corner
    face_normals: &[[f32; 4]], // per face: unit normal, area
    quadrics: &mut [Quadric],  // per vertex
) {
    par_for_mut(&mut quadrics[..params.vertex_count as usize], |v, out| {
        let pv = xyz(positions[v as usize]);
        let list = faces_of(offsets, vertex_faces, v);
        let mut q = Quadric::default();
        for &f in list {
            let fnrm = face_normals[f as usize];
            let t = face_of(indices, f);
            if fnrm[3] > 0.0 {
                let n = xyz(fnrm);
                let d = dot(n, sub(pv, xyz(positions[t[0] as usize])));
                q = quadric_add(&q, &quadric_from_plane(n, d, fnrm[3]));
            }
            if params.border_weight > 0.0 {
                for u in t {
                    if u != v && count_containing(indices, list, u) == 1 {
                        let e = sub(xyz(positions[u as usize]), pv);
                        let c = cross(e, xyz(fnrm));
                        let l = length(c);
                        if l > 0.0 {
                            let w = params.border_weight * dot(e, e);
                            q = quadric_add(&q, &quadric_from_plane(scale(c, 1.0 / l), 0.0, w));
                        }
                    }
                }
            }
        }
        *out = q;
    });
}
