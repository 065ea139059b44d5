//! One direction of the Metro distance: samples on mesh X, distances to the surface of mesh Y.

use rayon::prelude::*;
use serde::Serialize;

use super::bvh::TriangleBvh;
use crate::mesh::{Mesh, SplitMix64};
use glam::DVec3;

/// Samples per parallel task. Fixed, so that every partial sum covers the same samples whatever
/// the number of threads, and the partial sums are added in task order.
const CHUNK: usize = 8192;

/// Largest, mean and root-mean-square distance, and the three relative to A's diagonal: of one
/// direction ([`DirectionStats`]) or of both combined (`Distance::two_sided`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Distances {
    /// Largest distance over every sample (faces, vertices, edges): the one-sided Hausdorff
    /// distance (both directions: the Hausdorff distance).
    pub max: f64,
    /// Mean over the area-uniform face samples: an estimate of the mean distance over the surface.
    pub mean: f64,
    /// Root mean square over the area-uniform face samples.
    pub rms: f64,
    /// `max`, `mean` and `rms` divided by the bounding-box diagonal of A (the reference).
    pub max_rel: f64,
    pub mean_rel: f64,
    pub rms_rel: f64,
}

impl Distances {
    /// The three figures, and each relative to `diagonal` (0 for a diagonal of 0).
    pub fn new(max: f64, mean: f64, rms: f64, diagonal: f64) -> Distances {
        let rel = |v: f64| if diagonal > 0.0 { v / diagonal } else { 0.0 };
        Distances {
            max,
            mean,
            rms,
            max_rel: rel(max),
            mean_rel: rel(mean),
            rms_rel: rel(rms),
        }
    }

    /// Both directions combined: the larger maximum (the Hausdorff distance), the plain
    /// average of the two means, and sqrt((rms(A→B)² + rms(B→A)²) / 2).
    pub fn two_sided(ab: &Distances, ba: &Distances, diagonal: f64) -> Distances {
        Distances::new(
            ab.max.max(ba.max),
            0.5 * (ab.mean + ba.mean),
            (0.5 * (ab.rms * ab.rms + ba.rms * ba.rms)).sqrt(),
            diagonal,
        )
    }
}

/// Distances from the samples of one mesh to the other mesh's surface.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DirectionStats {
    /// The distances; flattened, so that the JSON keys stand beside the sample counts.
    #[serde(flatten)]
    pub distances: Distances,
    /// Points sampled uniformly by area on the faces.
    pub face_samples: usize,
    /// Vertices used by a face, each measured once.
    pub vertex_samples: usize,
    /// Points measured on the unique edges: evenly spaced ones (at least the midpoint of
    /// each edge) and those the refinement near the maximum added.
    pub edge_samples: usize,
    /// Sum of the vertex samples' distances, relative to A's diagonal: how far the sampled
    /// mesh's vertices sit off the other surface, in total.
    pub vertex_distance_sum_rel: f64,
}

/// Partial sums of one task, added in task order.
#[derive(Debug, Clone, Copy, Default)]
struct Acc {
    max: f64,
    sum: f64,
    sum2: f64,
    n: usize,
}

impl Acc {
    fn add(&mut self, d: f64) {
        self.max = self.max.max(d);
        self.sum += d;
        self.sum2 += d * d;
        self.n += 1;
    }
    fn merge(mut self, o: Acc) -> Acc {
        self.max = self.max.max(o.max);
        self.sum += o.sum;
        self.sum2 += o.sum2;
        self.n += o.n;
        self
    }
}

/// Measures every chunk of `0..n` in parallel, each sequentially with the previous answer as
/// the next query's hint, and adds the chunks in order.
fn measure(n: usize, bvh: &TriangleBvh, point: impl Fn(usize) -> [f64; 3] + Sync) -> Acc {
    let parts: Vec<Acc> = (0..n.div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            let mut acc = Acc::default();
            let mut hint = None;
            for i in c * CHUNK..((c + 1) * CHUNK).min(n) {
                let hit = bvh
                    .closest(point(i), hint)
                    .expect("the index has faces (checked by the caller)");
                hint = Some(hit.face);
                acc.add(hit.dist2.sqrt());
            }
            acc
        })
        .collect();
    parts.into_iter().fold(Acc::default(), Acc::merge)
}

/// Edges per parallel task of the edge sampling (fixed, as [`CHUNK`]).
const EDGE_CHUNK: usize = 2048;
/// At most this many evenly spaced segments per edge.
const EDGE_MAX_SEGMENTS: usize = 256;
/// Edges whose evenly spaced samples come within this fraction of the largest distance found
/// are refined.
const EDGE_CANDIDATE: f64 = 0.75;
/// At most this many more points per refined edge.
const EDGE_REFINE_BUDGET: usize = 32;
/// The refinement of an edge stops once its maximum is known within this relative tolerance.
const EDGE_REL_TOL: f64 = 1e-3;

/// A point of an edge: its parameter t in [0, 1] and its distance.
type EdgePoint = (f64, f64);

/// `a + t (b - a)`, not glam's `lerp` (`a (1 - t) + b t`), whose rounding differs.
fn lerp(a: [f64; 3], b: [f64; 3], t: f64) -> [f64; 3] {
    let (a, b) = (DVec3::from_array(a), DVec3::from_array(b));
    (a + (b - a) * t).to_array()
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    DVec3::from_array(a).distance(DVec3::from_array(b))
}

/// Evenly spaced segments of an edge of length `len` for samples `spacing` apart: at least two
/// (the midpoint), at most [`EDGE_MAX_SEGMENTS`].
fn edge_segments(len: f64, spacing: f64) -> usize {
    let k = len / spacing;
    if k.is_finite() {
        (k.ceil() as usize).clamp(2, EDGE_MAX_SEGMENTS)
    } else {
        2
    }
}

/// Samples every unique edge of `x`, measuring each point's distance to `y`, in two passes.
///
/// 1. Metro's edge sampling: each edge of length L is cut into k = ⌈L / `spacing`⌉ equal
///    segments (2 ≤ k ≤ 256, so the midpoint at least) and its k − 1 inner points are measured;
///    `spacing` is the face samples' mean spacing, so a long edge of a coarse mesh gets several
///    points and a short edge of a dense one its midpoint. The endpoints are the vertex samples.
/// 2. Refinement of the edges that may hold the maximum: those whose samples reach
///    [`EDGE_CANDIDATE`] of the largest distance found so far (`lower`, the faces' and
///    vertices', and the edges' of pass 1). The distance to a surface is 1-Lipschitz, so on a
///    segment of length s with distances d0 and d1 at its ends it is at most (d0 + d1 + s) / 2;
///    the segment with the largest such bound is halved, best first, until every bound is within
///    [`EDGE_REL_TOL`] of the largest distance known, or [`EDGE_REFINE_BUDGET`] points were added.
///    A maximum inside an edge, between two evenly spaced points, is so found to 0.1%.
///
/// Deterministic: both passes run over fixed chunks of edges in a fixed order, and the
/// refinement of an edge depends on that edge and on `lower` alone.
fn sample_edges(x: &Mesh, y: &TriangleBvh, spacing: f64, lower: f64) -> Acc {
    let keys = unique_edges(x);
    let ends = |e: usize| {
        (
            p64(x.positions[(keys[e] >> 32) as usize]),
            p64(x.positions[keys[e] as u32 as usize]),
        )
    };
    let closest = |p: [f64; 3], hint: &mut Option<u32>| {
        let hit = y
            .closest(p, *hint)
            .expect("the index has faces (checked by the caller)");
        *hint = Some(hit.face);
        hit.dist2.sqrt()
    };
    // Pass 1: evenly spaced points; keep the edges that come near `lower`.
    let parts: Vec<(Acc, Vec<(usize, f64)>)> = (0..keys.len().div_ceil(EDGE_CHUNK))
        .into_par_iter()
        .map(|c| {
            let mut acc = Acc::default();
            let mut near = Vec::new();
            let mut hint = None;
            for e in c * EDGE_CHUNK..((c + 1) * EDGE_CHUNK).min(keys.len()) {
                let (a, b) = ends(e);
                let k = edge_segments(dist(a, b), spacing);
                let mut emax = 0.0f64;
                for j in 1..k {
                    let d = closest(lerp(a, b, j as f64 / k as f64), &mut hint);
                    acc.add(d);
                    emax = emax.max(d);
                }
                if emax >= EDGE_CANDIDATE * lower {
                    near.push((e, emax));
                }
            }
            (acc, near)
        })
        .collect();
    let mut acc = Acc::default();
    let mut near = Vec::new();
    for (a, n) in parts {
        acc = acc.merge(a);
        near.extend(n);
    }
    let lower = lower.max(acc.max);
    near.retain(|&(_, emax)| emax >= EDGE_CANDIDATE * lower);

    // Pass 2: refine the candidates.
    let refined: Vec<Acc> = near
        .par_chunks(64)
        .map(|chunk| {
            let mut acc = Acc::default();
            let mut hint = None;
            for &(e, _) in chunk {
                let (a, b) = ends(e);
                let len = dist(a, b);
                let k = edge_segments(len, spacing);
                // (t, distance) at the evenly spaced points and the ends, measured again.
                let pts: Vec<EdgePoint> = (0..=k)
                    .map(|j| {
                        let t = j as f64 / k as f64;
                        (t, closest(lerp(a, b, t), &mut hint))
                    })
                    .collect();
                let mut best = pts.iter().fold(0.0f64, |m, p| m.max(p.1));
                let bound =
                    |(t0, d0): (f64, f64), (t1, d1): (f64, f64)| 0.5 * (d0 + d1 + (t1 - t0) * len);
                // Segments as (upper bound, start, end).
                let mut segs: Vec<(f64, EdgePoint, EdgePoint)> = pts
                    .windows(2)
                    .map(|w| (bound(w[0], w[1]), w[0], w[1]))
                    .collect();
                for _ in 0..EDGE_REFINE_BUDGET {
                    let threshold = best.max(lower) * (1.0 + EDGE_REL_TOL);
                    let Some((i, &(ub, p0, p1))) = segs
                        .iter()
                        .enumerate()
                        .max_by(|u, v| u.1.0.total_cmp(&v.1.0))
                    else {
                        break;
                    };
                    if ub <= threshold {
                        break;
                    }
                    segs.swap_remove(i);
                    let t = 0.5 * (p0.0 + p1.0);
                    let d = closest(lerp(a, b, t), &mut hint);
                    acc.add(d);
                    best = best.max(d);
                    segs.push((bound(p0, (t, d)), p0, (t, d)));
                    segs.push((bound((t, d), p1), (t, d), p1));
                }
            }
            acc
        })
        .collect();
    refined.into_iter().fold(acc, Acc::merge)
}

/// A random generator for sample `i` of a stream, independent of every other sample's.
fn sample_rng(seed: u64, i: usize) -> SplitMix64 {
    let mut h = SplitMix64(seed ^ (i as u64).wrapping_mul(0xD1B5_4A32_D192_ED03));
    SplitMix64(h.next_u64())
}

fn p64(p: [f32; 3]) -> [f64; 3] {
    glam::Vec3::from_array(p).as_dvec3().to_array()
}

/// The unique undirected edges of `mesh` (by vertex index), sorted.
fn unique_edges(mesh: &Mesh) -> Vec<u64> {
    let mut keys: Vec<u64> = mesh
        .triangles
        .par_iter()
        .flat_map_iter(|t| {
            (0..3).filter_map(move |i| {
                let (a, b) = (t[i], t[(i + 1) % 3]);
                (a != b).then(|| crate::mesh::topology::edge_key(a, b))
            })
        })
        .collect();
    keys.par_sort_unstable();
    keys.dedup();
    keys
}

/// Systematic area-uniform samples of a mesh's faces: the i-th falls at area (i + u)·total/n of
/// the faces' cumulated areas for one seeded offset u, so each face gets its expected count
/// rounded up or down, and is placed uniformly at random in its face with a generator seeded by
/// (seed, i). The distance and the appearance measures share them.
pub(super) struct AreaSamples {
    /// Cumulated face areas, in f64, summed in face order.
    cum: Vec<f64>,
    pub total: f64,
    n: usize,
    offset: f64,
    seed: u64,
}

impl AreaSamples {
    /// `n` samples of `x` (none on a mesh of zero area).
    pub fn new(x: &Mesh, n: usize, seed: u64) -> AreaSamples {
        let mut cum = Vec::with_capacity(x.triangles.len());
        let mut total = 0.0;
        for f in 0..x.triangles.len() {
            total += x.face_area(f);
            cum.push(total);
        }
        AreaSamples {
            cum,
            total,
            n: if total > 0.0 { n } else { 0 },
            offset: SplitMix64(seed).next_f64(),
            seed,
        }
    }

    pub fn len(&self) -> usize {
        self.n
    }

    /// Sample `i`: its face, its barycentric weights there, and the point.
    pub fn sample(&self, x: &Mesh, i: usize) -> (usize, [f64; 3], [f64; 3]) {
        let s = (i as f64 + self.offset) * self.total / self.n as f64;
        let f = self
            .cum
            .partition_point(|&c| c <= s)
            .min(self.cum.len() - 1);
        let [a, b, c] = x.triangles[f].map(|v| p64(x.positions[v as usize]));
        let mut rng = sample_rng(self.seed, i);
        let (mut u, mut v) = (rng.next_f64(), rng.next_f64());
        if u + v > 1.0 {
            (u, v) = (1.0 - u, 1.0 - v);
        }
        let p = [0, 1, 2].map(|k| a[k] + u * (b[k] - a[k]) + v * (c[k] - a[k]));
        (f, [1.0 - u - v, u, v], p)
    }
}

/// Samples mesh `x` and measures each sample's distance to the surface indexed by `y`.
///
/// Face samples: `face_samples` points by systematic sampling of the cumulated face areas
/// ([`AreaSamples`]). Then, when `vertices_and_edges`, every vertex used by a face
/// and points along every edge ([`sample_edges`]), so that the maximum is not missed between
/// random samples.
pub(crate) fn one_direction(
    x: &Mesh,
    y: &TriangleBvh,
    face_samples: usize,
    vertices_and_edges: bool,
    seed: u64,
    diagonal: f64,
) -> DirectionStats {
    let samples = AreaSamples::new(x, face_samples, seed);
    let (n_faces, total) = (samples.len(), samples.total);
    let faces = measure(n_faces, y, |i| samples.sample(x, i).2);

    let (verts, edges) = if vertices_and_edges {
        let mut used = vec![false; x.positions.len()];
        for t in &x.triangles {
            for &v in t {
                used[v as usize] = true;
            }
        }
        let used: Vec<u32> = (0..x.positions.len() as u32)
            .filter(|&v| used[v as usize])
            .collect();
        let verts = measure(used.len(), y, |i| p64(x.positions[used[i] as usize]));
        // Edge spacing: the mean distance between neighbouring face samples.
        let spacing = if n_faces > 0 {
            (total / n_faces as f64).sqrt()
        } else {
            f64::INFINITY
        };
        let edges = sample_edges(x, y, spacing, faces.max.max(verts.max));
        (verts, edges)
    } else {
        (Acc::default(), Acc::default())
    };

    // The mean and RMS estimate the surface integral, so they use the area-uniform samples
    // only; without any (a mesh of zero area) the vertices and edges stand in.
    let area = if faces.n > 0 {
        faces
    } else {
        verts.merge(edges)
    };
    let max = faces.max.max(verts.max).max(edges.max);
    let (mean, rms) = if area.n > 0 {
        (area.sum / area.n as f64, (area.sum2 / area.n as f64).sqrt())
    } else {
        (0.0, 0.0)
    };
    let rel = |v: f64| if diagonal > 0.0 { v / diagonal } else { 0.0 };
    DirectionStats {
        distances: Distances::new(max, mean, rms, diagonal),
        face_samples: faces.n,
        vertex_samples: verts.n,
        edge_samples: edges.n,
        vertex_distance_sum_rel: rel(verts.sum),
    }
}
