//! Cluster levels of detail: a DAG of meshlets in the manner of Unreal's Nanite (B. Karis,
//! R. Stubbe, G. Wihlidal, "A Deep Dive into Nanite Virtualized Geometry", SIGGRAPH 2021).
//!
//! The input is cut into clusters of at most 128 triangles ([`meshlets`]); neighbouring
//! clusters form groups ([`groups`]); each group is simplified to half its triangles with its
//! border to the other groups pinned, and split into clusters again; the new clusters are
//! grouped afresh, so the borders locked at one level fall inside groups at the next ([`build`]).
//! A renderer picks, per cluster, the coarsest version whose error is under its threshold
//! ([`cut`]): a cluster is drawn when its own error is at most the threshold and its group's is
//! over it. Errors only grow up the DAG and every group's sphere holds its clusters' spheres,
//! so that rule gives a closed surface from any view. The file format is in [`file`].

pub mod build;
pub mod cut;
pub mod file;
pub mod gpu;
pub mod groups;
pub mod meshlets;
pub mod schedule;

pub use build::{DagOptions, DagReport, build, build_with_progress};
pub use cut::CameraCut;

use crate::mesh::Mesh;

/// "No such group": a root cluster's group, a first-level cluster's parent.
pub const NONE: u32 = u32::MAX;

/// One meshlet: a range of [`Dag::mesh`]'s triangles at one depth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cluster {
    /// First triangle in [`Dag::mesh`].
    pub first_triangle: u32,
    pub triangle_count: u32,
    /// 0 for the input's clusters, one more per simplification that made it.
    pub depth: u32,
    /// The group that simplifies this cluster into coarser ones; [`NONE`] for a root.
    pub group: u32,
    /// The group whose simplification made this cluster; [`NONE`] at depth 0.
    pub parent_group: u32,
    /// A sphere around the cluster's own triangles (centre, radius): for frustum tests.
    pub bounds: [f32; 4],
    /// The sphere its error is measured from: its parent group's (its own bounds at depth 0).
    pub lod_sphere: [f32; 4],
    /// Its error in mesh units: its parent group's (0 at depth 0).
    pub error: f32,
}

/// A set of neighbouring clusters simplified together, their outer border kept.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Group {
    /// The depth of the clusters it simplifies.
    pub depth: u32,
    /// Holds its clusters' LOD spheres and the simplified triangles.
    pub sphere: [f32; 4],
    /// The simplified clusters' error: at least each of its clusters' own.
    pub error: f32,
}

/// A cluster DAG: the vertices and every level's triangles in one mesh, the clusters that
/// index it and the groups that join them.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Dag {
    /// The vertices (positions and the input's normals, UVs and colours) and, cluster after
    /// cluster, the triangles of every level.
    pub mesh: Mesh,
    pub clusters: Vec<Cluster>,
    pub groups: Vec<Group>,
    /// The input's bounding-box diagonal: object-space thresholds are fractions of it.
    pub diagonal: f64,
}

impl Dag {
    /// How many depths the clusters span.
    pub fn levels(&self) -> usize {
        self.clusters
            .iter()
            .map(|c| c.depth as usize + 1)
            .max()
            .unwrap_or(0)
    }

    /// Per depth: (clusters, triangles).
    pub fn per_depth(&self) -> Vec<(usize, usize)> {
        let mut v = vec![(0, 0); self.levels()];
        for c in &self.clusters {
            v[c.depth as usize].0 += 1;
            v[c.depth as usize].1 += c.triangle_count as usize;
        }
        v
    }

    /// The error of the group that simplifies `c` (infinite for a root).
    pub fn group_error(&self, c: &Cluster) -> f32 {
        match self.groups.get(c.group as usize) {
            Some(g) => g.error,
            None => f32::INFINITY,
        }
    }

    /// The triangles of cluster `c`.
    pub fn triangles(&self, c: &Cluster) -> &[[u32; 3]] {
        let a = c.first_triangle as usize;
        &self.mesh.triangles[a..a + c.triangle_count as usize]
    }
}

/// The sphere around points: the centre of their box, the farthest point's distance (in f64,
/// rounded up to f32 so the f32 sphere still holds every point).
pub(crate) fn sphere_of_points(points: impl Iterator<Item = [f32; 3]>) -> [f32; 4] {
    sphere_around(&[], &points.collect::<Vec<_>>())
}

/// A sphere holding `spheres` and `points`.
pub(crate) fn sphere_around(spheres: &[[f32; 4]], points: &[[f32; 3]]) -> [f32; 4] {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    let mut take = |p: [f32; 3], r: f32| {
        for i in 0..3 {
            lo[i] = lo[i].min(p[i] as f64 - r as f64);
            hi[i] = hi[i].max(p[i] as f64 + r as f64);
        }
    };
    for s in spheres {
        take([s[0], s[1], s[2]], s[3]);
    }
    for &p in points {
        take(p, 0.0);
    }
    if lo[0] > hi[0] {
        return [0.0; 4];
    }
    let c = [0, 1, 2].map(|i| ((lo[i] + hi[i]) * 0.5) as f32);
    let r = spheres
        .iter()
        .map(|s| dist(c, [s[0], s[1], s[2]]) + s[3] as f64)
        .chain(points.iter().map(|&p| dist(c, p)))
        .fold(0.0f64, f64::max);
    [c[0], c[1], c[2], round_up(r)]
}

fn dist(a: [f32; 3], b: [f32; 3]) -> f64 {
    dist2(a, b).sqrt()
}

/// The squared distance between two points, in f64.
pub(crate) fn dist2(a: [f32; 3], b: [f32; 3]) -> f64 {
    (0..3).map(|i| (a[i] as f64 - b[i] as f64).powi(2)).sum()
}

/// `x` as the smallest f32 at least `x`.
pub(crate) fn round_up(x: f64) -> f32 {
    let y = x as f32;
    if (y as f64) < x { y.next_up() } else { y }
}
