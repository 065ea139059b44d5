//! How far a simplified mesh's appearance is from its original's: at area-uniform samples of
//! one mesh, its interpolated vertex colour (or normal) against the other's at the closest point
//! of its surface, in both directions — Metro's sampling, with the attribute difference in
//! place of the distance. Colour as the RGB distance in 0..1 channel units (0 to √3), normals
//! as the angle between them in degrees. The measure the appearance-preserving simplification
//! (Hoppe 1999) is judged by; meshoptimizer's and MeshLab's comparisons use the same idea.
//!
//! Deterministic as the distance is: the samples depend on the seed alone and the sums are
//! formed in fixed chunks added in order.

use glam::DVec3;
use rayon::prelude::*;
use serde::Serialize;

use super::bvh::TriangleBvh;
use super::distance::AreaSamples;
use crate::mesh::{Mesh, UvOrigin};

/// Samples per parallel task (fixed, so that the sums do not depend on the thread count).
const CHUNK: usize = 8192;

/// One attribute's difference, both directions combined as the distance's are.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AttributeStats {
    /// Mean over A's samples (against B) and over B's (against A), averaged.
    pub mean: f64,
    /// sqrt of the two directions' mean squares, averaged.
    pub rms: f64,
    /// The largest difference at any sample.
    pub max: f64,
    /// The mean over A's samples alone, and over B's alone.
    pub a_to_b_mean: f64,
    pub b_to_a_mean: f64,
}

/// What of the appearance changed, for the attributes both meshes have.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Appearance {
    /// RGB distance of the vertex colours (alpha left out), 0..1 channel units.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub color: Option<AttributeStats>,
    /// Angle between the vertex normals, degrees.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub normal_deg: Option<AttributeStats>,
    /// RGB distance of the texture's colour at the interpolated UVs (0..1 channel units), when
    /// a texture was given and both meshes have UVs.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub texture: Option<AttributeStats>,
}

/// A texture image to look the UVs up in: RGB in 0..1 (the file's own encoding), sampled
/// bilinearly, repeating outside 0..1 as GPUs do by default.
#[derive(Debug, Clone, PartialEq)]
pub struct Texture {
    pub width: usize,
    pub height: usize,
    /// Row-major from the image's top row.
    pub rgb: Vec<[f32; 3]>,
}

impl Texture {
    /// The colour at `uv` of a mesh whose UVs count from `origin`.
    pub fn sample(&self, uv: [f64; 2], origin: UvOrigin) -> [f64; 3] {
        let (w, h) = (self.width, self.height);
        if w == 0 || h == 0 {
            return [0.0; 3];
        }
        let v = match origin {
            UvOrigin::BottomLeft => 1.0 - uv[1],
            UvOrigin::TopLeft => uv[1],
        };
        // Texel centres at (i + 0.5) / w.
        let x = uv[0] * w as f64 - 0.5;
        let y = v * h as f64 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let wrap = |i: f64, n: usize| (i as i64).rem_euclid(n as i64) as usize;
        let at = |i: f64, j: f64| self.rgb[wrap(j, h) * w + wrap(i, w)].map(f64::from);
        let (c00, c10, c01, c11) = (
            at(x0, y0),
            at(x0 + 1.0, y0),
            at(x0, y0 + 1.0),
            at(x0 + 1.0, y0 + 1.0),
        );
        [0, 1, 2].map(|k| {
            (c00[k] * (1.0 - fx) + c10[k] * fx) * (1.0 - fy)
                + (c01[k] * (1.0 - fx) + c11[k] * fx) * fy
        })
    }
}

/// The appearance difference of B from A at `na` samples of A and `nb` of B (seeded as the
/// distance's), or `None` when the two meshes share no colour or normal attribute.
pub(super) fn appearance(
    a: &Mesh,
    b: &Mesh,
    (bvh_a, bvh_b): (&TriangleBvh, &TriangleBvh),
    (na, nb): (usize, usize),
    (seed_ab, seed_ba): (u64, u64),
    texture: Option<&Texture>,
) -> Option<Appearance> {
    // Both differences are symmetric, so one function serves both directions.
    let both = |f: &Diff<'_>| {
        combine(
            one_direction(a, b, bvh_b, na, seed_ab, f),
            one_direction(b, a, bvh_a, nb, seed_ba, f),
        )
    };
    let color = (a.colors.is_some() && b.colors.is_some()).then(|| {
        both(&|x, fx, wx, y, fy, wy| {
            let (cx, cy) = (
                mix(x, fx, wx, x.colors.as_deref().unwrap_or_default()),
                mix(y, fy, wy, y.colors.as_deref().unwrap_or_default()),
            );
            let d = |k: usize| f64::from(cx[k]) - f64::from(cy[k]);
            DVec3::new(d(0), d(1), d(2)).length()
        })
    });
    let normal_deg = (a.normals.is_some() && b.normals.is_some()).then(|| {
        both(&|x, fx, wx, y, fy, wy| {
            let (nx, ny) = (
                DVec3::from_array(
                    mix(x, fx, wx, x.normals.as_deref().unwrap_or_default()).map(f64::from),
                ),
                DVec3::from_array(
                    mix(y, fy, wy, y.normals.as_deref().unwrap_or_default()).map(f64::from),
                ),
            );
            match (nx.try_normalize(), ny.try_normalize()) {
                (Some(p), Some(q)) => p.dot(q).clamp(-1.0, 1.0).acos().to_degrees(),
                // A normal that cancels out inside a face points nowhere: as far off as it gets.
                _ => 180.0,
            }
        })
    });
    let texture = texture
        .filter(|_| a.uvs.is_some() && b.uvs.is_some())
        .map(|tex| {
            both(&|x, fx, wx, y, fy, wy| {
                let uv = |m: &Mesh, f, w| {
                    let t = mix(m, f, w, m.uvs.as_deref().unwrap_or_default());
                    tex.sample(t.map(f64::from), m.uv_origin)
                };
                let (cx, cy) = (uv(x, fx, wx), uv(y, fy, wy));
                DVec3::from_array(cx).distance(DVec3::from_array(cy))
            })
        });
    (color.is_some() || normal_deg.is_some() || texture.is_some()).then_some(Appearance {
        color,
        normal_deg,
        texture,
    })
}

/// Sums of one direction: (sum, sum of squares, max, count).
type Sums = (f64, f64, f64, usize);

/// The difference of an attribute between a point of one mesh (its face and weights) and a
/// point of the other.
type Diff<'a> = dyn Fn(&Mesh, u32, [f64; 3], &Mesh, u32, [f64; 3]) -> f64 + Sync + 'a;

/// `n` samples of `x`, each compared by `diff` with `y` at the closest point of its surface
/// (`y_bvh`).
fn one_direction(
    x: &Mesh,
    y: &Mesh,
    y_bvh: &TriangleBvh,
    n: usize,
    seed: u64,
    diff: &Diff<'_>,
) -> Sums {
    let samples = AreaSamples::new(x, n, seed);
    let parts: Vec<Sums> = (0..samples.len().div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            let mut acc: Sums = (0.0, 0.0, 0.0, 0);
            let mut hint = None;
            for i in c * CHUNK..((c + 1) * CHUNK).min(samples.len()) {
                let (f, w, p) = samples.sample(x, i);
                let (fy, wy) = weights_at(y, y_bvh, DVec3::from_array(p), None, hint);
                hint = Some(fy);
                let d = diff(x, f as u32, w, y, fy, wy);
                acc = (acc.0 + d, acc.1 + d * d, acc.2.max(d), acc.3 + 1);
            }
            acc
        })
        .collect();
    parts.into_iter().fold((0.0, 0.0, 0.0, 0), |s, p| {
        (s.0 + p.0, s.1 + p.1, s.2.max(p.2), s.3 + p.3)
    })
}

fn combine(ab: Sums, ba: Sums) -> AttributeStats {
    let mean = |s: Sums| if s.3 > 0 { s.0 / s.3 as f64 } else { 0.0 };
    let ms = |s: Sums| if s.3 > 0 { s.1 / s.3 as f64 } else { 0.0 };
    AttributeStats {
        mean: 0.5 * (mean(ab) + mean(ba)),
        rms: (0.5 * (ms(ab) + ms(ba))).sqrt(),
        max: ab.2.max(ba.2),
        a_to_b_mean: mean(ab),
        b_to_a_mean: mean(ba),
    }
}

/// The face of `mesh` (indexed by `bvh`) closest to `query` and the barycentric weights in it
/// of `at`, or of the closest point itself without one; `hint` as [`TriangleBvh::closest`]'s.
pub(crate) fn weights_at(
    mesh: &Mesh,
    bvh: &TriangleBvh,
    query: DVec3,
    at: Option<DVec3>,
    hint: Option<u32>,
) -> (u32, [f64; 3]) {
    // Callers index meshes with faces, so there is always a closest one.
    let (q, hit) = bvh
        .closest_point(query, hint)
        .expect("the surface has faces");
    let t = mesh.triangles[hit.face as usize];
    let [a, b, c] = t.map(|v| DVec3::from_array(mesh.positions[v as usize].map(f64::from)));
    (hit.face, barycentric(at.unwrap_or(q), a, b, c))
}

/// The mix of face `f`'s corner values by the weights `w`, summed in f64.
pub(crate) fn mix<const N: usize>(
    mesh: &Mesh,
    f: u32,
    w: [f64; 3],
    values: &[[f32; N]],
) -> [f32; N] {
    let t = mesh.triangles[f as usize];
    let mut acc = [0.0f64; N];
    for k in 0..3 {
        for (a, &x) in acc.iter_mut().zip(&values[t[k] as usize]) {
            *a += w[k] * x as f64;
        }
    }
    acc.map(|x| x as f32)
}

/// The barycentric weights of `p` (on the triangle's plane) in (a, b, c); a corner's own for a
/// degenerate triangle.
pub(crate) fn barycentric(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> [f64; 3] {
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
