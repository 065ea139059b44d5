//! Normals, colours and UVs for the remeshed vertices, interpolated on the input: each vertex
//! takes the barycentric mix of the corners of the input face its closest point lies on.

use glam::DVec3;
use rayon::prelude::*;

use crate::Mesh;
use crate::metrics::TriangleBvh;

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
            weights_at(source, surface, p, None)
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
                let (f, w) = weights_at(source, surface, p + (centre - p) * 1e-3, Some(p));
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

/// The input face nearest `query` and the barycentric weights in it of `at`, or of the
/// closest point itself without one.
fn weights_at(
    source: &Mesh,
    surface: &TriangleBvh,
    query: DVec3,
    at: Option<DVec3>,
) -> (u32, [f64; 3]) {
    // The remesher refused a surface without faces, so there is always a closest one.
    let (q, hit) = surface
        .closest_point(query, None)
        .expect("the surface has faces");
    let t = source.triangles[hit.face as usize];
    let [a, b, c] = t.map(|v| DVec3::from_array(source.positions[v as usize].map(f64::from)));
    (hit.face, barycentric(at.unwrap_or(q), a, b, c))
}

/// The mix of input face `f`'s corner values by the weights `w`, summed in f64.
fn mix<const N: usize>(source: &Mesh, f: u32, w: [f64; 3], values: &[[f32; N]]) -> [f32; N] {
    let t = source.triangles[f as usize];
    let mut acc = [0.0f64; N];
    for k in 0..3 {
        for (a, &x) in acc.iter_mut().zip(&values[t[k] as usize]) {
            *a += w[k] * x as f64;
        }
    }
    acc.map(|x| x as f32)
}

/// Whether two vertices at one position have different UVs.
fn has_seams(m: &Mesh, uvs: &[[f32; 2]]) -> bool {
    let (class, firsts) = crate::mesh::weld::position_classes(&m.positions);
    class
        .iter()
        .enumerate()
        .any(|(v, &c)| uvs[v] != uvs[firsts[c as usize] as usize])
}

/// The barycentric weights of `p` (on the triangle's plane) in (a, b, c); a corner's own for a
/// degenerate triangle.
fn barycentric(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> [f64; 3] {
    let (v0, v1, v2) = (b - a, c - a, p - a);
    let (d00, d01, d11) = (v0.dot(v0), v0.dot(v1), v1.dot(v1));
    let (d20, d21) = (v2.dot(v0), v2.dot(v1));
    let denom = d00 * d11 - d01 * d01;
    if denom.abs() <= f64::EPSILON * d00 * d11 || !denom.is_finite() {
        return [1.0, 0.0, 0.0];
    }
    let v = ((d11 * d20 - d01 * d21) / denom).clamp(0.0, 1.0);
    let w = ((d00 * d21 - d01 * d20) / denom).clamp(0.0, 1.0 - v);
    [1.0 - v - w, v, w]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn barycentric_weights_rebuild_the_point() {
        let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        let p = DVec3::new(0.25, 0.5, 0.0);
        let w = barycentric(p, a, b, c);
        let q = a * w[0] + b * w[1] + c * w[2];
        assert!(q.distance(p) < 1e-12, "{w:?}");
        assert_eq!(barycentric(p, a, a, a), [1.0, 0.0, 0.0]);
    }
}
