//! Meshlets: triangles cut into clusters of at most `max_triangles` triangles and
//! `max_vertices` vertices, grown face by face over shared edges so each is compact and
//! connected where the surface is.
//!
//! Growth after meshoptimizer's `meshopt_buildMeshlets` (A. Kapoulkine): the next triangle is
//! the frontier's that adds the fewest new vertices, then the one nearest the cluster's centre;
//! a cluster whose frontier runs dry goes on from the next unassigned triangle in Morton order.

use crate::mesh::morton::grid_codes;
use rayon::prelude::*;
use rustc_hash::FxHashMap;

/// Limits of one cluster.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Limits {
    pub max_triangles: usize,
    pub max_vertices: usize,
}

/// The triangles `tris` (vertex ids into `positions`; `class[v]` joins vertices at one
/// position, so clusters grow across attribute seams) as clusters: each a list of indices
/// into `tris`, in the order they were added. Deterministic: ties break by index.
pub fn split(
    tris: &[[u32; 3]],
    positions: &[[f32; 3]],
    class: &[u32],
    limits: Limits,
) -> Vec<Vec<u32>> {
    assert!(limits.max_triangles >= 1 && limits.max_vertices >= 3);
    if tris.len() <= CHUNK {
        return split_one(tris, positions, class, limits);
    }
    // A large input is cut along the Morton curve into runs of CHUNK triangles, split apart
    // on the cores: the chunks depend on the input alone, so the clusters do too.
    let order = morton_order(&centroids(tris, positions));
    let chunks: Vec<Vec<Vec<u32>>> = order
        .par_chunks(CHUNK)
        .map(|chunk| {
            let sub: Vec<[u32; 3]> = chunk.iter().map(|&f| tris[f as usize]).collect();
            split_one(&sub, positions, class, limits)
                .into_iter()
                .map(|c| c.into_iter().map(|i| chunk[i as usize]).collect())
                .collect()
        })
        .collect();
    chunks.into_iter().flatten().collect()
}

/// Triangles per chunk of a large input's split (a few hundred clusters each).
const CHUNK: usize = 1 << 15;

fn centroids(tris: &[[u32; 3]], positions: &[[f32; 3]]) -> Vec<[f32; 3]> {
    tris.iter()
        .map(|t| {
            let p = t.map(|v| positions[v as usize]);
            [0, 1, 2].map(|i| (p[0][i] + p[1][i] + p[2][i]) / 3.0)
        })
        .collect()
}

/// [`split`] on one thread.
fn split_one(
    tris: &[[u32; 3]],
    positions: &[[f32; 3]],
    class: &[u32],
    limits: Limits,
) -> Vec<Vec<u32>> {
    let nf = tris.len();
    if nf == 0 {
        return Vec::new();
    }
    let (local, nv) = local_ids(tris);
    let adj = Adjacency::new(tris, class);
    let centroids = centroids(tris, positions);
    let order = morton_order(&centroids);

    let mut cluster_of = vec![u32::MAX; nf];
    let mut in_frontier = vec![u32::MAX; nf];
    let mut vertex_in = vec![u32::MAX; nv];
    let mut clusters: Vec<Vec<u32>> = Vec::new();
    let mut next_seed = 0usize;
    loop {
        while next_seed < nf && cluster_of[order[next_seed] as usize] != u32::MAX {
            next_seed += 1;
        }
        if next_seed == nf {
            break;
        }
        let id = clusters.len() as u32;
        let mut g = Grow {
            id,
            faces: Vec::new(),
            verts: 0,
            sum: [0.0; 3],
            frontier: Vec::new(),
        };
        let mut seed_at = next_seed;
        while g.faces.len() < limits.max_triangles {
            let f = match g.best(&local, &vertex_in, &centroids) {
                Some(f) => f,
                // Frontier empty (a piece closed off by other clusters, or the first face): the
                // next unassigned face in Morton order. Ending the cluster there instead left
                // the 1M scan with 1.6 times the clusters, most of them small, and its groups
                // stuck; the nearest of the next 64 to the cluster's centre, 1.2 times.
                None => {
                    while seed_at < nf && cluster_of[order[seed_at] as usize] != u32::MAX {
                        seed_at += 1;
                    }
                    match order.get(seed_at) {
                        Some(&f) => f,
                        None => break,
                    }
                }
            };
            let new = local[f as usize]
                .iter()
                .filter(|&&v| vertex_in[v as usize] != id)
                .count();
            if g.verts + new > limits.max_vertices {
                break;
            }
            g.take(f, &local, &mut vertex_in, &mut cluster_of, &centroids);
            g.frontier.retain(|&x| x != f);
            for &n in adj.of(f) {
                if cluster_of[n as usize] == u32::MAX && in_frontier[n as usize] != id {
                    in_frontier[n as usize] = id;
                    g.frontier.push(n);
                }
            }
        }
        clusters.push(g.faces);
    }
    clusters
}

/// A cluster while it grows.
struct Grow {
    id: u32,
    faces: Vec<u32>,
    verts: usize,
    sum: [f64; 3],
    frontier: Vec<u32>,
}

impl Grow {
    /// The frontier face adding fewest new vertices, then nearest the centre, then lowest.
    fn best(&self, local: &[[u32; 3]], vertex_in: &[u32], centroids: &[[f32; 3]]) -> Option<u32> {
        let n = self.faces.len().max(1) as f64;
        let c = self.sum.map(|s| s / n);
        let key = |f: u32| {
            let new = local[f as usize]
                .iter()
                .filter(|&&v| vertex_in[v as usize] != self.id)
                .count();
            let p = centroids[f as usize];
            let d: f64 = (0..3).map(|i| (p[i] as f64 - c[i]).powi(2)).sum();
            (new, d, f)
        };
        self.frontier
            .iter()
            .map(|&f| key(f))
            .min_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)).then(a.2.cmp(&b.2)))
            .map(|k| k.2)
    }

    fn take(
        &mut self,
        f: u32,
        local: &[[u32; 3]],
        vertex_in: &mut [u32],
        cluster_of: &mut [u32],
        centroids: &[[f32; 3]],
    ) {
        for &v in &local[f as usize] {
            if vertex_in[v as usize] != self.id {
                vertex_in[v as usize] = self.id;
                self.verts += 1;
            }
        }
        cluster_of[f as usize] = self.id;
        self.faces.push(f);
        for (s, &c) in self.sum.iter_mut().zip(&centroids[f as usize]) {
            *s += c as f64;
        }
    }
}

/// The triangles with their vertex ids renumbered 0.. in order of first use, and how many.
fn local_ids(tris: &[[u32; 3]]) -> (Vec<[u32; 3]>, usize) {
    let mut map: FxHashMap<u32, u32> = FxHashMap::default();
    let local = tris
        .iter()
        .map(|t| {
            t.map(|v| {
                let n = map.len() as u32;
                *map.entry(v).or_insert(n)
            })
        })
        .collect();
    (local, map.len())
}

/// Faces sharing an edge (by position class), as compressed rows.
pub(crate) struct Adjacency {
    start: Vec<u32>,
    faces: Vec<u32>,
}

impl Adjacency {
    pub(crate) fn new(tris: &[[u32; 3]], class: &[u32]) -> Adjacency {
        let mut edges: Vec<(u64, u32)> = Vec::with_capacity(tris.len() * 3);
        for (f, t) in tris.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (class[t[k] as usize], class[t[(k + 1) % 3] as usize]);
                if a != b {
                    edges.push((edge_key(a, b), f as u32));
                }
            }
        }
        sort(&mut edges);
        // Each face's neighbours: the other faces on each of its edges (a face meeting another
        // along two edges lists it twice, which growth tolerates).
        let runs = || edges.chunk_by(|a, b| a.0 == b.0).filter(|r| r.len() > 1);
        let mut start = vec![0u32; tris.len() + 1];
        for run in runs() {
            for e in run {
                start[e.1 as usize + 1] += run.len() as u32 - 1;
            }
        }
        for i in 0..tris.len() {
            start[i + 1] += start[i];
        }
        let mut fill = start.clone();
        let mut faces = vec![0u32; start[tris.len()] as usize];
        for run in runs() {
            for a in run {
                for b in run.iter().filter(|b| b.1 != a.1) {
                    faces[fill[a.1 as usize] as usize] = b.1;
                    fill[a.1 as usize] += 1;
                }
            }
        }
        Adjacency { start, faces }
    }

    pub(crate) fn of(&self, f: u32) -> &[u32] {
        &self.faces[self.start[f as usize] as usize..self.start[f as usize + 1] as usize]
    }
}

/// An undirected edge between two classes as one key.
pub(crate) fn edge_key(a: u32, b: u32) -> u64 {
    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
    (lo as u64) << 32 | hi as u64
}

/// Indices of `points` along a Morton curve over their box, ties by index.
pub(crate) fn morton_order(points: &[[f32; 3]]) -> Vec<u32> {
    let codes = grid_codes(points.len(), |i| points[i]);
    let mut keyed: Vec<(u32, u32)> = codes.into_iter().zip(0..).collect();
    keyed.sort_unstable();
    keyed.into_iter().map(|k| k.1).collect()
}

/// Sorts on the cores when there is enough to share (rayon's sort costs more than it gives
/// below that, inside the groups' parallel simplification).
pub(crate) fn sort<T: Ord + Send>(v: &mut [T]) {
    if v.len() >= 1 << 16 {
        v.par_sort_unstable();
    } else {
        v.sort_unstable();
    }
}
