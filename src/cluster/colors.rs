//! A cluster's colour from its attribute quadric (Hoppe 1999, as `qem` weighs colours; see
//! `crate::quadric::attributes`): the faces around the cluster's members each carry the linear
//! colour function through their corners; their area-weighted least-squares fit, evaluated at
//! the cluster's position, is the vertex's colour. The nearest member's colour, which clustering
//! took before, is one sample of that field; the fit is the whole cell's.

use super::{Built, Points};
use crate::mesh::Mesh;
use crate::quadric::attributes::{FaceTerms, Layout, MAX_CHANNELS, optimum_values};
use rayon::prelude::*;

/// The colour of each cluster in `order`, or `None` without colours or without faces in memory
/// (`--stream` reads them a block at a time). A cluster whose faces have no area keeps its
/// nearest member's colour; solved colours are clamped to 0..1.
pub(super) fn cluster_colors(
    mesh: &Mesh,
    pts: &Points,
    b: &Built,
    order: &[u32],
) -> Option<Vec<[f32; 4]>> {
    let colors = mesh.colors.as_ref()?;
    if pts.faces.is_empty() {
        return None;
    }
    let alpha = colors.iter().any(|c| c[3] != 1.0);
    let layout = Layout::colors(if alpha { 4 } else { 3 });
    let stride = layout.stride();
    let at = |i: u32| {
        let q = pts.positions[i as usize];
        [q[0], q[1], q[2]].map(f64::from)
    };
    let value = |i: u32| colors[i as usize].map(f64::from);
    // In a fixed number of chunks (from the counts alone, so the sums do not depend on the
    // thread count), each summing into its own array, added in order: one sequential pass
    // took 0.08 s on the painted 1M scan, as long as the whole clustering.
    let faces: &[[u32; 3]] = &pts.faces;
    let chunks = (faces.len() / (2 * b.clusters).max(1)).clamp(1, 8);
    let per = faces.len().div_ceil(chunks).max(1);
    let parts: Vec<Vec<f64>> = faces
        .par_chunks(per)
        .map(|part| {
            let mut sums = vec![0.0f64; b.clusters * stride];
            let mut ft = FaceTerms::default();
            for t in part {
                let p = t.map(at);
                let v = t.map(value);
                if !ft.set(&layout, p, [&v[0], &v[1], &v[2]]) {
                    continue;
                }
                let [p0, p1, p2] = p.map(glam::DVec3::from_array);
                let area = 0.5 * (p1 - p0).cross(p2 - p0).length();
                for &i in t {
                    let k = b.vertex_cluster[i as usize] as usize;
                    ft.add_to(&mut sums[k * stride..(k + 1) * stride], area);
                }
            }
            sums
        })
        .collect();
    let mut parts = parts.into_iter();
    let mut sums = parts
        .next()
        .unwrap_or_else(|| vec![0.0; b.clusters * stride]);
    for part in parts {
        for (s, x) in sums.iter_mut().zip(part) {
            *s += x;
        }
    }
    Some(
        order
            .iter()
            .map(|&k| {
                let placed = &b.placed[k as usize];
                let nearest = colors[placed.attr as usize];
                let pos = placed.pos.map(f64::from);
                let mut best = [0.0; MAX_CHANNELS];
                let k = k as usize;
                if !optimum_values(&layout, &sums[k * stride..(k + 1) * stride], pos, &mut best) {
                    return nearest;
                }
                let mut c = nearest;
                for (out, x) in c.iter_mut().zip(best).take(layout.m) {
                    *out = (x as f32).clamp(0.0, 1.0);
                }
                c
            })
            .collect(),
    )
}

/// `hybrid` on a coloured mesh: inside a cell, an edge whose colour step costs more than the
/// cell is wide does not join its ends into one cluster, so a cluster never straddles a sharp
/// colour edge that the rounds after it could not bring back. At the colour weight `w` a step
/// of `Δ` (RGBA distance) costs like a displacement of `w·Δ` diagonals (as in the collapse
/// cost), and a cluster moves its members by up to a cell `h`: the step splits when `w·Δ > h`.
/// Smooth gradients, whose steps between neighbours are small, stay joined.
pub(super) struct ColourSplit<'m> {
    pub colors: &'m [[f32; 4]],
    pub weight: f32,
}

impl<'m> ColourSplit<'m> {
    /// For `mesh`, when its colours are weighed.
    pub(super) fn of(mesh: &'m Mesh, weight: f64) -> Option<ColourSplit<'m>> {
        let colors = mesh.colors.as_deref().filter(|_| weight > 0.0)?;
        Some(ColourSplit {
            colors,
            weight: weight as f32,
        })
    }

    /// Whether points (input vertices) `a` and `b` may join at cell size `h` (unit-diagonal
    /// frame).
    pub(super) fn joins(&self, h: f32) -> impl Fn(u32, u32) -> bool + '_ {
        let limit = (h / self.weight).powi(2);
        move |a, b| {
            let (p, q) = (self.colors[a as usize], self.colors[b as usize]);
            let d2: f32 = (0..4).map(|k| (p[k] - q[k]) * (p[k] - q[k])).sum();
            d2 <= limit
        }
    }
}
