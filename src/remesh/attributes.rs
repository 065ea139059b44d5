//! Normals, colours and UVs for the remeshed vertices, interpolated on the input: each vertex
//! takes the barycentric mix of the corners of the input face its closest point lies on.

use glam::DVec3;
use rayon::prelude::*;

use crate::Mesh;
use crate::metrics::{TriangleBvh, mix, weights_at};

/// Fills `out`'s normals, colours and UVs from `source` (whose faces `surface` indexes) where
/// `source` has them; with UV seams, `out`'s vertices on them are split per side. Returns
/// what could not be carried and why.
pub(super) fn carry(source: &Mesh, surface: &TriangleBvh, out: &mut Mesh) -> Vec<String> {
    let mut not_carried = Vec::new();
    if source.normals.is_none() && source.colors.is_none() && source.uvs.is_none() {
        return not_carried;
    }
    // A seam stores two UVs at one point: the remesher kept the seams as lines, and each
    // face's corners take their UVs from the input's side of the seam that face is on.
    let seamed = source.uvs.as_ref().filter(|uvs| has_seams(source, uvs));
    let uvs = source.uvs.as_ref().filter(|_| seamed.is_none());
    let weights: Vec<(u32, [f64; 3])> = out
        .positions
        .par_iter()
        .map(|p| {
            let p = DVec3::from_array(p.map(f64::from));
            weights_at(source, surface, p, None, None)
        })
        .collect();
    if let Some(n) = &source.normals {
        out.normals = Some(
            weights
                .iter()
                .map(|&(f, w)| {
                    let v = DVec3::from_array(mix(source, f, w, n).map(f64::from));
                    v.try_normalize().unwrap_or(DVec3::Z).as_vec3().to_array()
                })
                .collect(),
        );
    }
    if let Some(c) = &source.colors {
        out.colors = Some(weights.iter().map(|&(f, w)| mix(source, f, w, c)).collect());
    }
    if let Some(uv) = uvs {
        out.uvs = Some(
            weights
                .iter()
                .map(|&(f, w)| mix(source, f, w, uv))
                .collect(),
        );
        out.uv_origin = source.uv_origin;
    }
    if let Some(uv) = seamed {
        corner_uvs(source, surface, uv, out);
        out.uv_origin = source.uv_origin;
    }
    if !source.materials.is_empty() || source.face_groups.is_some() {
        not_carried.push("materials and groups (every face of the result is one surface)".into());
    }
    not_carried
}

/// UVs per face corner, with a vertex split wherever its faces give it different UVs (on the
/// seams). A corner's UV comes from the input face nearest to a point a hair inside its own
/// face: the output's faces do not cross the seams, so that input face is on the same side.
fn corner_uvs(source: &Mesh, surface: &TriangleBvh, uv: &[[f32; 2]], out: &mut Mesh) {
    let pos = |v: u32| DVec3::from_array(out.positions[v as usize].map(f64::from));
    let corner: Vec<[f32; 2]> = out
        .triangles
        .par_iter()
        .flat_map_iter(|t| {
            let centre = (pos(t[0]) + pos(t[1]) + pos(t[2])) / 3.0;
            t.map(|v| {
                let p = pos(v);
                let (f, w) = weights_at(source, surface, p + (centre - p) * 1e-3, Some(p), None);
                mix(source, f, w, uv)
            })
        })
        .collect();
    // Corners of one vertex whose UVs agree (within rounding: they come from different input
    // faces) share it; a corner whose UV differs, across a seam, gets its own copy. In corner
    // order: deterministic.
    const SAME_UV: f32 = 1e-4;
    let mut copies: Vec<Vec<u32>> = vec![Vec::new(); out.positions.len()];
    let mut from = Vec::new();
    let mut uvs: Vec<[f32; 2]> = Vec::new();
    for (k, t) in out.triangles.iter_mut().enumerate() {
        for (j, v) in t.iter_mut().enumerate() {
            let u = corner[3 * k + j];
            let near = |c: &&u32| {
                let w = uvs[**c as usize];
                (w[0] - u[0]).abs() <= SAME_UV && (w[1] - u[1]).abs() <= SAME_UV
            };
            let id = match copies[*v as usize].iter().find(near) {
                Some(&c) => c,
                None => {
                    from.push(*v);
                    uvs.push(u);
                    let c = (from.len() - 1) as u32;
                    copies[*v as usize].push(c);
                    c
                }
            };
            *v = id;
        }
    }
    out.positions = from.iter().map(|&v| out.positions[v as usize]).collect();
    if let Some(n) = &out.normals {
        out.normals = Some(from.iter().map(|&v| n[v as usize]).collect());
    }
    if let Some(c) = &out.colors {
        out.colors = Some(from.iter().map(|&v| c[v as usize]).collect());
    }
    out.uvs = Some(uvs);
}

/// Whether two vertices at one position have different UVs.
fn has_seams(m: &Mesh, uvs: &[[f32; 2]]) -> bool {
    let (class, firsts) = crate::mesh::weld::position_classes(&m.positions);
    class
        .iter()
        .enumerate()
        .any(|(v, &c)| uvs[v] != uvs[firsts[c as usize] as usize])
}
