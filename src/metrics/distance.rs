//! One direction of the Metro distance: samples on mesh X, distances to the surface of mesh Y.

use rayon::prelude::*;
use serde::Serialize;

use super::bvh::TriangleBvh;
use crate::mesh::{Mesh, SplitMix64};

/// Samples per parallel task. Fixed, so that every partial sum covers the same samples whatever
/// the number of threads, and the partial sums are added in task order.
const CHUNK: usize = 8192;

/// Distances from the samples of one mesh to the other mesh's surface.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DirectionStats {
    /// Largest distance over every sample (faces, vertices, edge midpoints): the one-sided
    /// Hausdorff distance.
    pub max: f64,
    /// Mean over the area-uniform face samples: an estimate of the mean distance over the surface.
    pub mean: f64,
    /// Root mean square over the area-uniform face samples.
    pub rms: f64,
    /// `max`, `mean` and `rms` divided by the bounding-box diagonal of A (the reference).
    pub max_rel: f64,
    pub mean_rel: f64,
    pub rms_rel: f64,
    /// Points sampled uniformly by area on the faces.
    pub face_samples: usize,
    /// Vertices used by a face, each measured once.
    pub vertex_samples: usize,
    /// Midpoints of the unique edges.
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

/// A random generator for sample `i` of a stream, independent of every other sample's.
fn sample_rng(seed: u64, i: usize) -> SplitMix64 {
    let mut h = SplitMix64(seed ^ (i as u64).wrapping_mul(0xD1B5_4A32_D192_ED03));
    SplitMix64(h.next_u64())
}

fn p64(p: [f32; 3]) -> [f64; 3] {
    [p[0] as f64, p[1] as f64, p[2] as f64]
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

/// Samples mesh `x` and measures each sample's distance to the surface indexed by `y`.
///
/// Face samples: `face_samples` points by systematic sampling of the cumulated face areas (the
/// i-th sample falls at area (i + u)·total/n for one seeded offset u, so each face gets its
/// expected count rounded up or down), each placed uniformly at random in its face with a
/// generator seeded by (seed, i). Then, when `vertices_and_edges`, every vertex used by a face
/// and every edge midpoint, so that the maximum is not missed between random samples.
pub(crate) fn one_direction(
    x: &Mesh,
    y: &TriangleBvh,
    face_samples: usize,
    vertices_and_edges: bool,
    seed: u64,
    diagonal: f64,
) -> DirectionStats {
    // Cumulated areas, in f64; the order of the sum is the face order.
    let mut cum = Vec::with_capacity(x.triangles.len());
    let mut total = 0.0;
    for f in 0..x.triangles.len() {
        total += x.face_area(f);
        cum.push(total);
    }
    let n_faces = if total > 0.0 { face_samples } else { 0 };
    let offset = SplitMix64(seed).next_f64();
    let faces = measure(n_faces, y, |i| {
        let s = (i as f64 + offset) * total / n_faces as f64;
        let f = cum.partition_point(|&c| c <= s).min(cum.len() - 1);
        let [a, b, c] = x.triangles[f].map(|v| p64(x.positions[v as usize]));
        let mut rng = sample_rng(seed, i);
        let (mut u, mut v) = (rng.next_f64(), rng.next_f64());
        if u + v > 1.0 {
            (u, v) = (1.0 - u, 1.0 - v);
        }
        [0, 1, 2].map(|k| a[k] + u * (b[k] - a[k]) + v * (c[k] - a[k]))
    });

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
        let keys = unique_edges(x);
        let edges = measure(keys.len(), y, |i| {
            let (a, b) = (
                p64(x.positions[(keys[i] >> 32) as usize]),
                p64(x.positions[keys[i] as u32 as usize]),
            );
            [0, 1, 2].map(|k| 0.5 * (a[k] + b[k]))
        });
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
        max,
        mean,
        rms,
        max_rel: rel(max),
        mean_rel: rel(mean),
        rms_rel: rel(rms),
        face_samples: faces.n,
        vertex_samples: verts.n,
        edge_samples: edges.n,
        vertex_distance_sum_rel: rel(verts.sum),
    }
}
