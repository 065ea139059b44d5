//! The uniform grid and the search for its cell size: a continuous size (not meshoptimizer's
//! integer resolution, whose steps near 20 cells an axis move the face count by ~10%, more than
//! the ±5% band) found by counting passes (`cluster_probe`), four sizes a pass.

use crate::cpu::common::{V3, xyz};
use crate::mesh::morton::morton3;
use rayon::prelude::*;

/// A singleton key (a locked vertex, clustered with nobody): above every Morton cell key.
pub const SINGLETON: u32 = 1 << 31;

/// Cells an axis at most: keys are 30-bit Morton codes.
pub const MAX_CELLS: u32 = 1024;

/// A grid of cubes of side `h` from `lo`, `dims` cells an axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    pub lo: V3,
    pub h: f32,
    /// `1 / h`: cells are found by multiplying, which Vulkan rounds correctly where a division
    /// may be off by 2.5 ulp (the GPU must find the same cells), and which is several times
    /// cheaper than dividing (the counting pass took 0.016 s of 0.09 s on the 1M scan).
    pub inv_h: f32,
    pub dims: [u32; 3],
}

impl Grid {
    /// The grid of size `h` over the box `[lo, hi]`; `h` is raised to what 1024 cells an axis
    /// allow.
    pub fn new(lo: V3, hi: V3, h: f32) -> Grid {
        let extent = (0..3).map(|i| hi[i] - lo[i]).fold(0.0f32, f32::max);
        let h = h
            .max(extent / (MAX_CELLS - 1) as f32)
            .max(f32::MIN_POSITIVE);
        let dims = [0, 1, 2].map(|i| (((hi[i] - lo[i]) / h).floor() as u32 + 1).min(MAX_CELLS));
        Grid {
            lo,
            h,
            inv_h: 1.0 / h,
            dims,
        }
    }

    #[inline]
    pub fn coords(&self, p: V3) -> [u32; 3] {
        [0, 1, 2]
            .map(|i| (((p[i] - self.lo[i]) * self.inv_h).max(0.0) as u32).min(self.dims[i] - 1))
    }

    #[inline]
    pub fn key(&self, p: V3) -> u32 {
        let [x, y, z] = self.coords(p);
        morton3(x, y, z)
    }

    /// The box of the cell with key `key`.
    pub fn cell_box(&self, key: u32) -> (V3, V3) {
        let c = unmorton(key);
        let lo = [0, 1, 2].map(|i| self.lo[i] + c[i] as f32 * self.h);
        (lo, [0, 1, 2].map(|i| lo[i] + self.h))
    }
}

fn unmorton(k: u32) -> [u32; 3] {
    let compact = |mut x: u32| {
        x &= 0x09249249;
        x = (x | (x >> 2)) & 0x030c30c3;
        x = (x | (x >> 4)) & 0x0300f00f;
        x = (x | (x >> 8)) & 0x030000ff;
        (x | (x >> 16)) & 0x3ff
    };
    [compact(k), compact(k >> 1), compact(k >> 2)]
}

/// `cluster_probe`: for each grid, the faces whose three corners fall in three different cells
/// (a locked corner is a cell of its own), counted on every `stride`-th face and multiplied
/// back: before connectivity splitting and before duplicates are dropped, so an estimate of
/// what a build at that size keeps, which the builds' own counts then correct.
pub fn probe_sampled(
    grids: &[Grid],
    positions: &[[f32; 4]],
    locked: &[bool],
    faces: &[[u32; 3]],
    stride: usize,
) -> Vec<usize> {
    assert!(grids.len() <= 4, "a probe counts four grids at most");
    // Runs of 64 faces, one run in `stride`: a file's faces are often not in spatial order,
    // and single faces `stride` apart read their corners from all over memory (0.016 s for the
    // 1M scan's sample, against 0.004 s in runs).
    const RUN: usize = 64;
    let sampled: Vec<usize> = (0..faces.len())
        .step_by(RUN * stride)
        .flat_map(|a| a..(a + RUN).min(faces.len()))
        .collect();
    // One pass for all four grids: each sampled face's corners read once.
    let counts = sampled
        .par_iter()
        .with_min_len(4096)
        .fold(
            || [0usize; 4],
            |mut acc, &i| {
                let t = faces[i];
                let p = t.map(|v| xyz(positions[v as usize]));
                for (g, a) in grids.iter().zip(acc.iter_mut()) {
                    let k = [0, 1, 2].map(|c| {
                        if locked[t[c] as usize] {
                            SINGLETON | t[c]
                        } else {
                            g.key(p[c])
                        }
                    });
                    *a += (k[0] != k[1] && k[1] != k[2] && k[0] != k[2]) as usize;
                }
                acc
            },
        )
        .reduce(|| [0usize; 4], |a, b| [0, 1, 2, 3].map(|i| a[i] + b[i]));
    let scale = faces.len() as f64 / sampled.len().max(1) as f64;
    counts[..grids.len()]
        .iter()
        .map(|&c| (c as f64 * scale).round() as usize)
        .collect()
}

/// The size where a power law `faces = a·h^s` through `(h, faces)` points (least squares in
/// log-log) predicts `target`; `None` when the points do not fall with `h`.
pub fn fit(points: &[(f64, f64)], target: f64) -> Option<f64> {
    let pts: Vec<(f64, f64)> = points
        .iter()
        .filter(|p| p.0 > 0.0 && p.1 > 0.0)
        .map(|p| (p.0.ln(), p.1.ln()))
        .collect();
    if pts.len() < 2 {
        return None;
    }
    let n = pts.len() as f64;
    let (mx, my) = (
        pts.iter().map(|p| p.0).sum::<f64>() / n,
        pts.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx) * (p.0 - mx)).sum();
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let slope = sxy / sxx;
    if !(slope < -0.1 && slope.is_finite()) {
        return None;
    }
    let h = (mx + (target.max(1.0).ln() - my) / slope).exp();
    h.is_finite().then_some(h)
}
