//! The uniform grid and the search for its cell size: a continuous size (not meshoptimizer's
//! integer resolution, whose steps near 20 cells an axis move the face count by ~10%, more than
//! the ±5% band) found by counting passes (`cluster_probe`), four sizes a pass.

use crate::compute::common::V3;
use crate::mesh::morton::morton3;
use rayon::prelude::*;

/// A singleton key (a locked vertex, clustered with nobody): above every Morton cell key.
pub const SINGLETON: u32 = 1 << 31;

/// Cells an axis at most: keys are 30-bit Morton codes.
pub const MAX_CELLS: u32 = 1024;

/// A grid of cubes of side `h` from `lo`, `dims` cells an axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellGrid {
    pub lo: V3,
    pub h: f32,
    /// `1 / h`: cells are found by multiplying, which Vulkan rounds correctly where a division
    /// may be off by 2.5 ulp (the GPU must find the same cells), and which is several times
    /// cheaper than dividing (the counting pass took 0.016 s of 0.09 s on the 1M scan).
    pub inv_h: f32,
    pub dims: [u32; 3],
}

impl CellGrid {
    /// The grid of size `h` over the box `[lo, hi]`; `h` is raised to what 1024 cells an axis
    /// allow.
    pub fn new(lo: V3, hi: V3, h: f32) -> CellGrid {
        let extent = (0..3).map(|i| hi[i] - lo[i]).fold(0.0f32, f32::max);
        let h = h
            .max(extent / (MAX_CELLS - 1) as f32)
            .max(f32::MIN_POSITIVE);
        let dims = [0, 1, 2].map(|i| (((hi[i] - lo[i]) / h).floor() as u32 + 1).min(MAX_CELLS));
        CellGrid {
            lo,
            h,
            inv_h: 1.0 / h,
            dims,
        }
    }

    /// The cell of `p` an axis, clamped into the grid.
    #[inline]
    pub fn coords(&self, p: V3) -> [u32; 3] {
        let top = self.tops();
        // SAFETY: `top` comes from `tops`.
        [0, 1, 2].map(|i| unsafe { cell_index((p[i] - self.lo[i]) * self.inv_h, top[i]) })
    }

    /// The last cell an axis, as [`cell_index`] takes it: a whole number in [0, 1023] whatever
    /// `dims` holds (its fields are public).
    #[inline]
    fn tops(&self) -> [f32; 3] {
        self.dims.map(|d| (d.clamp(1, MAX_CELLS) - 1) as f32)
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

/// `x` truncated to a cell index and clamped to `[0, top]`, NaN to 0: clamping to the last cell
/// before truncating is clamping after it (`top` is whole), and a truncation known to fit lets
/// the compiler convert four lanes in one instruction, where `as u32` tests each value for
/// range and NaN apart: the probe's pass over the vertices ([`probe_cells`]) took 0.0088-0.0129 s
/// on the 1M scan at 10% with `as`, 0.0019-0.0023 s with this (two cores, means of 15 calls).
///
/// # Safety
///
/// `top` is a whole number in [0, 1023].
#[inline]
unsafe fn cell_index(x: f32, top: f32) -> u32 {
    debug_assert!(top.fract() == 0.0 && (0.0..=1023.0).contains(&top));
    // `max` takes 0 over a NaN and `min` keeps `top` over anything above it, so the value is a
    // number in [0, top], whose truncation fits an i32, as `to_int_unchecked` requires.
    let c = x.max(0.0).min(top);
    // SAFETY: `c` is finite and in [0, 1023] (above; `top` by the caller's promise).
    unsafe { c.to_int_unchecked::<i32>() as u32 }
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
pub fn probe_cells(grids: &[CellGrid], positions: &[[f32; 4]], locked: &[bool]) -> Vec<[u32; 4]> {
    assert!(grids.len() <= 4, "a probe counts four grids at most");
    let lo = grids.first().map_or([0.0; 3], |g| g.lo);
    assert!(
        grids.iter().all(|g| g.lo == lo),
        "a probe's grids share their corner"
    );
    // Per axis, the grids side by side (an unused one: 0 everywhere), so that one four-lane
    // multiply, clamp and truncation finds an axis in all four; `p - lo` is each grid's own.
    let (mut inv, mut top) = ([0.0f32; 4], [[0.0f32; 4]; 3]);
    for (g, grid) in grids.iter().enumerate() {
        inv[g] = grid.inv_h;
        for (i, t) in grid.tops().into_iter().enumerate() {
            top[i][g] = t;
        }
    }
    let used = grids.len();
    positions
        .par_iter()
        .zip(locked)
        .enumerate()
        .with_min_len(4096)
        .map(|(v, (p, &l))| {
            if l {
                return [0, 1, 2, 3].map(|g| if g < used { SINGLETON | v as u32 } else { 0 });
            }
            let axis = |i: usize| {
                let d = p[i] - lo[i];
                // SAFETY: each `top` is `CellGrid::tops`' or 0.
                [0, 1, 2, 3].map(|g| unsafe { cell_index(d * inv[g], top[i][g]) })
            };
            let (x, y, z) = (axis(0), axis(1), axis(2));
            [0, 1, 2, 3].map(|g| x[g] | (y[g] << 10) | (z[g] << 20))
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
                if let Some(ahead) = faces.get(f + crate::prefetch::AHEAD) {
                    for &v in ahead {
                        crate::prefetch::prefetch(cells, v as usize);
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

#[cfg(test)]
mod tests {
    use super::*;

    /// What [`CellGrid::coords`] computed before [`cell_index`]: a saturating cast, then a clamp.
    fn coords_by_casting(g: &CellGrid, p: V3) -> [u32; 3] {
        [0, 1, 2].map(|i| (((p[i] - g.lo[i]) * g.inv_h).max(0.0) as u32).min(g.dims[i] - 1))
    }

    /// Points in and around `[lo, hi]` (a fixed pseudo-random sequence), its corners, and
    /// coordinates no mesh has (NaN, infinities, the largest floats).
    fn points(lo: V3, hi: V3) -> Vec<V3> {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut unit = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let mut pts: Vec<V3> = (0..20_000)
            .map(|_| [0, 1, 2].map(|i| lo[i] + (1.4 * unit() - 0.2) * (hi[i] - lo[i])))
            .collect();
        pts.extend([lo, hi, [lo[0], hi[1], lo[2]]]);
        for x in [
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::MAX,
            -f32::MAX,
            0.0,
        ] {
            pts.push([x, lo[1], hi[2]]);
            pts.push([hi[0], x, x]);
        }
        pts
    }

    #[test]
    fn coords_are_the_saturating_cast_clamped_into_the_grid() {
        let (lo, hi) = ([-0.3, 0.1, -0.05], [0.4, 0.35, 0.6]);
        // One cell an axis, a few, and the 1024 that cap the size.
        for h in [1.0, 0.09, 0.013, 1e-6] {
            let g = CellGrid::new(lo, hi, h);
            for p in points(lo, hi) {
                assert_eq!(g.coords(p), coords_by_casting(&g, p), "{p:?} in {g:?}");
            }
        }
    }

    #[test]
    fn probe_cells_are_each_grids_coords_packed() {
        let (lo, hi) = ([0.0, -0.5, 0.25], [0.5, 0.5, 0.5]);
        let positions: Vec<[f32; 4]> = points(lo, hi)
            .into_iter()
            .filter(|p| p.iter().all(|x| x.is_finite()))
            .map(|[x, y, z]| [x, y, z, 1.0])
            .collect();
        let locked: Vec<bool> = (0..positions.len()).map(|v| v % 7 == 3).collect();
        let all: Vec<CellGrid> = [0.011, 0.02, 0.05, 0.3]
            .iter()
            .map(|&h| CellGrid::new(lo, hi, h))
            .collect();
        // Fewer grids leave the other slots 0.
        for used in 1..=4 {
            let grids = &all[..used];
            let cells = probe_cells(grids, &positions, &locked);
            for (v, p) in positions.iter().enumerate() {
                let want: [u32; 4] = std::array::from_fn(|g| match grids.get(g) {
                    None => 0,
                    Some(_) if locked[v] => SINGLETON | v as u32,
                    Some(grid) => {
                        let [x, y, z] = coords_by_casting(grid, [p[0], p[1], p[2]]);
                        x | (y << 10) | (z << 20)
                    }
                });
                assert_eq!(cells[v], want, "vertex {v} at {p:?}, {used} grids");
            }
        }
    }
}
