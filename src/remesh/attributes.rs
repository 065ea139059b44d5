//! Normals, colours and UVs for the remeshed vertices, interpolated on the input: each vertex
//! takes the barycentric mix of the corners of the input face its closest point lies on.

use glam::DVec3;
use rayon::prelude::*;

use crate::Mesh;
use crate::metrics::TriangleBvh;

/// Fills `out`'s normals, colours and UVs from `source` (whose faces `surface` indexes) where
/// `source` has them. Returns what could not be carried and why.
pub(super) fn carry(source: &Mesh, surface: &TriangleBvh, out: &mut Mesh) -> Vec<String> {
    let mut not_carried = Vec::new();
    if source.normals.is_none() && source.colors.is_none() && source.uvs.is_none() {
        return not_carried;
    }
    // A seam stores two UVs at one point; one vertex per point cannot hold both, and
    // interpolating across it would smear the texture over the whole atlas between.
    let uvs = source.uvs.as_ref().filter(|uvs| {
        let seams = has_seams(source, uvs);
        if seams {
            not_carried
                .push("UVs (the input has UV seams, which remeshing does not keep yet)".into());
        }
        !seams
    });
    let weights: Vec<(u32, [f64; 3])> = out
        .positions
        .par_iter()
        .map(|p| {
            let p = DVec3::from_array(p.map(f64::from));
            // The remesher refused a surface without faces, so there is always a closest one.
            let (q, hit) = surface
                .closest_point(p, None)
                .expect("the surface has faces");
            let t = source.triangles[hit.face as usize];
            let [a, b, c] =
                t.map(|v| DVec3::from_array(source.positions[v as usize].map(f64::from)));
            (hit.face, barycentric(q, a, b, c))
        })
        .collect();
    let mix = |f: u32, w: [f64; 3], get: &dyn Fn(u32) -> Vec<f32>| -> Vec<f32> {
        let t = source.triangles[f as usize];
        let mut acc = vec![0.0f64; get(t[0]).len()];
        for k in 0..3 {
            for (a, x) in acc.iter_mut().zip(get(t[k])) {
                *a += w[k] * x as f64;
            }
        }
        acc.into_iter().map(|x| x as f32).collect()
    };
    if let Some(n) = &source.normals {
        out.normals = Some(
            weights
                .iter()
                .map(|&(f, w)| {
                    let v = mix(f, w, &|i| n[i as usize].to_vec());
                    let v = DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64);
                    v.try_normalize().unwrap_or(DVec3::Z).as_vec3().to_array()
                })
                .collect(),
        );
    }
    if let Some(c) = &source.colors {
        out.colors = Some(
            weights
                .iter()
                .map(|&(f, w)| {
                    let v = mix(f, w, &|i| c[i as usize].to_vec());
                    [v[0], v[1], v[2], v[3]]
                })
                .collect(),
        );
    }
    if let Some(uv) = uvs {
        out.uvs = Some(
            weights
                .iter()
                .map(|&(f, w)| {
                    let v = mix(f, w, &|i| uv[i as usize].to_vec());
                    [v[0], v[1]]
                })
                .collect(),
        );
        out.uv_origin = source.uv_origin;
    }
    if !source.materials.is_empty() || source.face_groups.is_some() {
        not_carried.push("materials and groups (every face of the result is one surface)".into());
    }
    not_carried
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
