//! The clustering's result written out: the clustered mesh and its vertices' quadrics.

use super::stages::Placement;
use super::{Built, Points, colors};
use crate::compute::types::Quadric;
use crate::mesh::Mesh;
use crate::mesh::prepare::denormalize;
use rayon::prelude::*;

/// What to hand out: the mesh (vertices at the clusters, attributes of the nearest member or,
/// with `fit_colors`, colours fitted over the cell; unused clusters dropped) and each output
/// vertex's quadric.
pub(super) fn output(
    mesh: &Mesh,
    pts: &Points,
    b: &Built,
    fit_colors: bool,
) -> (Mesh, Vec<Quadric>) {
    let (order, id) = crate::mesh::first_use(&b.faces, b.clusters, |(_, t)| *t);
    let src = |k: u32| b.placed[k as usize].attr as usize;
    let mut out = mesh.clone_without_geometry();
    out.positions = order
        .par_iter()
        .map(|&k| {
            let p = &b.placed[k as usize];
            if p.how == Placement::Single {
                mesh.positions[src(k)]
            } else {
                let q = p.pos.map(|x| x as f64);
                denormalize(q, pts.center, pts.scale)
            }
        })
        .collect();
    out.normals = mesh
        .normals
        .as_ref()
        .map(|n| order.iter().map(|&k| n[src(k)]).collect());
    out.uvs = mesh
        .uvs
        .as_ref()
        .map(|n| order.iter().map(|&k| n[src(k)]).collect());
    out.colors = fit_colors
        .then(|| colors::cluster_colors(mesh, pts, b, &order))
        .flatten()
        .or_else(|| {
            mesh.colors
                .as_ref()
                .map(|n| order.iter().map(|&k| n[src(k)]).collect())
        });
    out.triangles = b
        .faces
        .par_iter()
        .map(|(_, t)| t.map(|k| id[k as usize]))
        .collect();
    out.face_materials = mesh
        .face_materials
        .as_ref()
        .map(|m| b.faces.iter().map(|(f, _)| m[*f as usize]).collect());
    out.face_groups = mesh
        .face_groups
        .as_ref()
        .map(|g| b.faces.iter().map(|(f, _)| g[*f as usize]).collect());
    let quadrics = order
        .par_iter()
        .map(|&k| b.placed[k as usize].quadric)
        .collect();
    (out, quadrics)
}
