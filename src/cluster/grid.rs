//! The uniform grid and the search for its cell size: a continuous size (not meshoptimizer's
//! integer resolution, whose steps near 20 cells an axis move the face count by ~10%, more than
//! the ±5% band) found by counting passes (`cluster_probe`), four sizes a pass.

use crate::compute::common::{V3, xyz};
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

/// `cluster_probe`: for each grid (four at most, counted in one pass over the vertices and one
/// over the faces), the faces whose three corners fall in three different cells (a locked
/// corner is a cell of its own), before connectivity splitting and before duplicates are
/// dropped: nearly what a build at that size keeps, which the builds' own counts then correct.
/// Each vertex's cells are found once ([`probe_cells`], packed `x | y << 10 | z << 20`, not
/// Morton-interleaved: comparing them is the same test), then the faces counted
/// ([`probe_count`], block by block when they stream): per corner of a 1/8 sample of the faces
/// took as long on the 1M scan (0.012 s) and six times as long on horse.
///
/// Each vertex's cell in each of (at most four) `grids`, for [`probe_count`].
pub fn probe_cells(grids: &[Grid], positions: &[[f32; 4]], locked: &[bool]) -> Vec<[u32; 4]> {
    assert!(grids.len() <= 4, "a probe counts four grids at most");
    positions
        .par_iter()
        .zip(locked)
        .enumerate()
        .with_min_len(4096)
        .map(|(v, (p, &l))| {
            let mut k = [0u32; 4];
            for (g, k) in grids.iter().zip(k.iter_mut()) {
                *k = if l {
                    SINGLETON | v as u32
                } else {
                    let [x, y, z] = g.coords(xyz(*p));
                    x | (y << 10) | (z << 20)
                };
            }
            k
        })
        .collect()
}

/// Per grid of [`probe_cells`], the `faces` with three corners in three cells (the unused
/// grids' slots count every face whose corners are not one vertex repeated: ignore them).
pub fn probe_count(cells: &[[u32; 4]], faces: &[[u32; 3]]) -> [usize; 4] {
    faces
        .par_iter()
        .enumerate()
        .with_min_len(4096)
        .fold(
            || [0usize; 4],
            |mut acc, (f, t)| {
                // The faces' corners are scattered over the vertices: asked for ahead.
                if let Some(ahead) = faces.get(f + crate::cache::AHEAD) {
                    for &v in ahead {
                        crate::cache::prefetch(cells, v as usize);
                    }
                }
                let [a, b, c] = t.map(|v| cells[v as usize]);
                for i in 0..4 {
                    acc[i] += (a[i] != b[i] && b[i] != c[i] && a[i] != c[i]) as usize;
                }
                acc
            },
        )
        .reduce(|| [0usize; 4], |a, b| [0, 1, 2, 3].map(|i| a[i] + b[i]))
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
