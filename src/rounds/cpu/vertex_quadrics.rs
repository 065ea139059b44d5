//! Twin of shaders/rounds/vertex_quadrics.wgsl (first round): each vertex gathers the area-weighted
//! plane quadrics of its faces and, for each border edge at it, Hoppe's constraint plane through
//! the edge perpendicular to its face, weighted by the squared edge length; likewise for each
//! attribute-seam edge (its two faces use different attribute vertices at an end), perpendicular to
//! their mean normal, as the greedy reference does. A gather in the sorted face order, so the sums
//! do not depend on thread timing. Quadrics are relative to the vertex.

use super::{corner_attr, face_of, faces_of, par_for_mut};
use crate::compute::common::{
    cross, dot, length, quadric_add, quadric_from_plane, scale, sub, xyz,
};
use crate::compute::types::{FaceExtra, Params, Quadric};

/// The constraint plane through edge `e` (from the vertex) perpendicular to `surface`, weighted
/// by the border weight and the squared edge length; zero when degenerate.
fn edge_plane(params: &Params, e: [f32; 3], surface: [f32; 3]) -> Quadric {
    let c = cross(e, surface);
    let l = length(c);
    if l > 0.0 {
        quadric_from_plane(scale(c, 1.0 / l), 0.0, params.border_weight * dot(e, e))
    } else {
        Quadric::default()
    }
}

/// The faces of `list` containing `u`: how many, and the first other than `f` (`f` when none),
/// from one scan as in the shader.
fn edge_faces(indices: &[u32], list: &[u32], f: u32, u: u32) -> (u32, u32) {
    let mut n = 0;
    let mut other = f;
    for &g in list {
        if face_of(indices, g).contains(&u) {
            n += 1;
            if other == f && g != f {
                other = g;
            }
        }
    }
    (n, other)
}

#[allow(clippy::too_many_arguments)]
pub fn vertex_quadrics(
    params: &Params,
    positions: &[[f32; 4]],    // per vertex
    indices: &[u32],           // per face × 3
    offsets: &[u32],           // per vertex + 1
    vertex_faces: &[u32],      // per corner
    face_normals: &[[f32; 4]], // per face: unit normal, area
    face_extra: &[FaceExtra],  // per face
    quadrics: &mut [Quadric],  // per vertex
) {
    let corner_attr = |f: u32, v: u32| corner_attr(indices, face_extra, f, v);
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
                    if u == v {
                        continue;
                    }
                    let e = sub(xyz(positions[u as usize]), pv);
                    match edge_faces(indices, list, f, u) {
                        (1, _) => q = quadric_add(&q, &edge_plane(params, e, xyz(fnrm))),
                        // A seam: once per edge, from the first of its two faces in the (sorted)
                        // list. In the first round every corner still has its input attribute
                        // vertex.
                        (2, g)
                            if g > f
                                && (corner_attr(f, v) != corner_attr(g, v)
                                    || corner_attr(f, u) != corner_attr(g, u)) =>
                        {
                            let gn = xyz(face_normals[g as usize]);
                            let avg = [fnrm[0] + gn[0], fnrm[1] + gn[1], fnrm[2] + gn[2]];
                            q = quadric_add(&q, &edge_plane(params, e, avg));
                        }
                        _ => {}
                    }
                }
            }
        }
        *out = q;
    });
}
