//! `--method hybrid`: clustering (cells split by connectivity, clusters that pinch a
//! non-manifold edge taken apart) to an intermediate count, then QEM to the exact target
//! (Garland & Shaffer's multiphase simplification, 2002). On `cpu` (the default) the second
//! phase is the greedy queue on the clustered surface, faster and lower in error than the
//! rounds (docs/PERFORMANCE.md, "Stop 37"); on `cpu-parallel` and `gpu` it is the rounds from
//! the clusters' quadrics, the same upload on both (twins). The clustering stays on the CPU on
//! every backend: its split of cells by connectivity is a union-find, and its repairs are
//! worked out from the build before (docs/PERFORMANCE.md, "Speed against meshoptimizer").

use super::grid::Grid;
use super::{
    Built, ClusterReport, Points, Work, check_backend, cluster_to, max_error, output, prepare,
    tally,
};
use crate::compute::types::Quadric;
use crate::error::Result;
use crate::mesh::Mesh;
use crate::options::{Backend, Method, SimplifyOptions, SimplifyReport};
use rayon::prelude::*;
use std::time::Instant;

/// `hybrid` clusters to this many times the target...
pub const HYBRID_FACTOR: f64 = 2.0;
/// ...plus this many faces: how much clustering costs in error depends on how coarse its cells
/// are against the surface's features, that is on the faces it keeps, not on the ratio. At 2×
/// the target alone the mean error at 10% was 1.07× the greedy's on the oversampled 1M scan but
/// 1.33× on horse and 1.25× on igea; at 3× the 1M scan's hybrid fell below meshoptimizer's
/// speed; 2× + 20,000 gave 1.06×, 1.09× and 1.13× with the 1M scan 1.18× meshoptimizer's
/// speed (docs/PERFORMANCE.md, "Clustering").
pub const HYBRID_EXTRA: f64 = 20_000.0;
/// ...but to no fewer than this share of the input's faces: cells coarse enough for 2% of the
/// 1M scan left errors the rounds could not undo (mean 1.38× the greedy's at 1%, against
/// 1.10× from 5%; docs/PERFORMANCE.md, "hybrid").
pub const HYBRID_MIN_SHARE: f64 = 0.05;
/// ...unless that is more than this share of the input: merging only pairs of vertices costs a
/// clustering without saving rounds, so the rounds start from the input.
pub const HYBRID_SKIP: f64 = 0.5;

/// `hybrid` takes clusters on non-manifold edges apart at most this many times.
const MAX_REPAIRS: usize = 4;

/// The clusters at either end of an edge that more than two faces share, or that two faces
/// run the same way (a fold), sorted. The half-edges are bucketed by their lower cluster (a
/// counting sort) and each small bucket sorted alone: sorting all of them by (edge, direction)
/// took 0.02-0.04 s a check on the 1M scan at 10% (three checks), this 0.013-0.016 s, the
/// same clusters on every scan and shared model at 10% and 1%.
fn pinched_clusters(b: &Built) -> Vec<u32> {
    let half = |i: usize| {
        let t = b.faces[i / 3].1;
        let (a, c) = (t[i % 3], t[(i + 1) % 3]);
        (a.min(c), a.max(c), a < c)
    };
    let (order, start) =
        crate::mesh::prepare::counting_sort(b.clusters, b.faces.len() * 3, |i| half(i).0);
    let mut bad: Vec<u32> = (0..b.clusters)
        .into_par_iter()
        .with_min_len(1024)
        .fold(
            || (Vec::new(), Vec::new()),
            |(mut ends, mut out): (Vec<(u32, bool)>, Vec<u32>), k| {
                let bucket = &order[start[k] as usize..start[k + 1] as usize];
                if bucket.len() < 2 {
                    return (ends, out);
                }
                ends.clear();
                ends.extend(bucket.iter().map(|&i| {
                    let (_, c, forward) = half(i as usize);
                    (c, forward)
                }));
                ends.sort_unstable();
                let mut i = 0;
                while i < ends.len() {
                    let mut j = i + 1;
                    while j < ends.len() && ends[j].0 == ends[i].0 {
                        j += 1;
                    }
                    if j - i > 2 || (j - i == 2 && ends[i].1 == ends[i + 1].1) {
                        out.extend([k as u32, ends[i].0]);
                    }
                    i = j;
                }
                (ends, out)
            },
        )
        .map(|(_, out)| out)
        .reduce(Vec::new, |mut a, b| {
            a.extend(b);
            a
        });
    bad.par_sort_unstable();
    bad.dedup();
    bad
}

/// A cluster face turned more than 60° from the input face it came from counts as folded.
const FOLD_COS: f32 = 0.5;

/// Per face of `b`: the unit normal of the input face it came from (its origin). The rounds
/// after the clustering measure turning from these, not from the clusters' faces. A streamed
/// input's faces are read in blocks for them; faces in memory are looked up: walking all the
/// input's faces for the few that survive took 0.006-0.007 s a build on the 1M scan at 1%
/// (five builds with the repairs), the lookup 0.003-0.005 s.
fn origin_normals(work: &Work, b: &Built) -> Result<Vec<[f32; 3]>> {
    use crate::compute::common::{cross, length, scale, sub, xyz};
    let pos = &work.pts.positions;
    let normal = |t: &[u32; 3]| {
        let p = t.map(|v| xyz(pos[v as usize]));
        let c = cross(sub(p[1], p[0]), sub(p[2], p[0]));
        let l = length(c);
        if l > 0.0 { scale(c, 1.0 / l) } else { [0.0; 3] }
    };
    if work.pts.stream.is_none() {
        let faces = &work.pts.faces;
        return Ok(b
            .faces
            .par_iter()
            .with_min_len(4096)
            .map(|&(origin, _)| normal(&faces[origin as usize]))
            .collect());
    }
    let mut at: Vec<u32> = Vec::new();
    for (k, &(origin, _)) in b.faces.iter().enumerate() {
        let o = origin as usize;
        if o >= at.len() {
            at.resize(o + 1, u32::MAX);
        }
        at[o] = k as u32;
    }
    let mut normals = vec![[0.0f32; 3]; b.faces.len()];
    work.pts.blocks(&mut |first, faces| {
        for (i, t) in faces.iter().enumerate() {
            if let Some(&k) = at.get(first + i).filter(|&&k| k != u32::MAX) {
                normals[k as usize] = normal(t);
            }
        }
        Ok(())
    })?;
    Ok(normals)
}

/// The clusters of each face turned more than 60° from the input face it came from (`normals`,
/// [`origin_normals`]), sorted: a cell can fold a sheet over, and two clusters a colour step
/// split in one cell can stand a face on edge; the rounds after may turn a face up to
/// `max_normal_angle_deg` further, so a face left nearly on edge here could end up flipped.
fn folded_clusters(b: &Built, normals: &[[f32; 3]]) -> Vec<u32> {
    use crate::compute::common::{cross, dot, length, sub};
    let mut bad: Vec<u32> = b
        .faces
        .par_iter()
        .zip(normals)
        .filter_map(|(&(_, t), &o)| {
            let p = t.map(|k| b.placed[k as usize].pos);
            let n = cross(sub(p[1], p[0]), sub(p[2], p[0]));
            (dot(n, o) < FOLD_COS * length(n)).then_some(t)
        })
        .flatten_iter()
        .collect();
    bad.par_sort_unstable();
    bad.dedup();
    bad
}

/// The hybrid's clustering: to at least `intermediate` faces (the rounds then go to `target`),
/// clusters that pinch a non-manifold edge or fold a face over taken apart until none is left.
/// Returns the grid, the build and its faces' input normals ([`origin_normals`]: the rounds'
/// reference, read once per build since a streamed input reads its file for them).
pub(super) fn cluster_repaired(
    work: &mut Work,
    intermediate: usize,
    target: usize,
    report: &mut ClusterReport,
) -> Result<(Grid, Built, Vec<[f32; 3]>)> {
    let (grid, mut built, _) = cluster_to(work, intermediate, None, Some(target), report)?;
    let mut normals = origin_normals(work, &built)?;
    // Splitting cells by connectivity keeps separate sheets apart, but a sheet folded inside
    // one cell can still pinch into a non-manifold edge: take the clusters on one apart (their
    // members each their own cluster) and build again, until none is left.
    for _ in 0..MAX_REPAIRS {
        let mut bad = pinched_clusters(&built);
        bad.extend(folded_clusters(&built, &normals));
        bad.sort_unstable();
        bad.dedup();
        if bad.is_empty() {
            break;
        }
        built = match work.gather {
            Some(_) => take_apart(work, &grid, &built, &bad),
            // Streamed: no vertex→face lists to place the new singletons by, so a whole build.
            None => {
                for (v, &k) in built.vertex_cluster.iter().enumerate() {
                    if bad.binary_search(&k).is_ok() {
                        work.locked[v] = true;
                    }
                }
                work.build(&grid)?
            }
        };
        normals = origin_normals(work, &built)?;
        report.builds += 1;
        report.repaired_clusters += bad.len();
    }
    Ok((grid, built, normals))
}

/// What [`Work::build`] at `grid` gives once the members of the `bad` clusters (sorted ids of
/// `b`, the build at `grid` before) are locked, which this does too: worked out from `b`
/// instead of built again. A cluster is one connected component of its cell, so locking its
/// members takes it out of the cell whole; every other cluster keeps its members, its box,
/// its placement and its place in the order the clusters are numbered in (cells in key order,
/// a cell's clusters by root, the locked vertices last in id order). Only the new singletons
/// are placed, and the faces at them taken again ([`faces_taken_apart`]). Measured on the 1M
/// scan at 10%: a whole build took 0.09 s of each of the two repairs' 0.12 s.
fn take_apart(work: &mut Work, grid: &Grid, b: &Built, bad: &[u32]) -> Built {
    use super::stages::cluster_quadric;
    use crate::compute::common::xyz;
    let mut is_bad = vec![false; b.clusters];
    for &k in bad {
        is_bad[k as usize] = true;
    }
    // The locked vertices, in id order: the singleton clusters at the end of the numbering, with
    // their placement where they were singletons before.
    let mut singles: Vec<(u32, Option<super::stages::Placed>)> = Vec::new();
    for (v, &k) in b.vertex_cluster.iter().enumerate() {
        if work.locked[v] {
            singles.push((v as u32, Some(b.placed[k as usize])));
        } else if is_bad[k as usize] {
            work.locked[v] = true;
            singles.push((v as u32, None));
        }
    }
    // The clusters that stay, in their order; a cell's clusters are consecutive, so counting
    // key changes counts the cells.
    let positions = &work.pts.positions;
    let mut new_id = vec![u32::MAX; b.clusters];
    let mut placed = Vec::with_capacity(b.clusters);
    let mut cells = 0;
    let mut last_key = None;
    for (k, p) in b.placed.iter().enumerate() {
        // Every member of a cluster is locked or none is: `attr` is one of them.
        if work.locked[p.attr as usize] {
            continue;
        }
        new_id[k] = placed.len() as u32;
        placed.push(*p);
        let key = grid.key(xyz(positions[p.attr as usize]));
        if last_key != Some(key) {
            cells += 1;
            last_key = Some(key);
        }
    }
    let kept = placed.len();
    let surface = work
        .surface()
        .expect("taking clusters apart places singletons by the vertex→face lists");
    // A singleton's box is its vertex, as `build` gives it.
    placed.par_extend(singles.par_iter().map(|&(v, old)| {
        old.unwrap_or_else(|| {
            let p = xyz(positions[v as usize]);
            cluster_quadric(&surface, &[v], p, p, p)
        })
    }));
    let mut vertex_cluster: Vec<u32> = b
        .vertex_cluster
        .par_iter()
        .map(|&k| new_id[k as usize])
        .collect();
    for (i, &(v, old)) in singles.iter().enumerate() {
        vertex_cluster[v as usize] = (kept + i) as u32;
        if old.is_some() {
            new_id[b.vertex_cluster[v as usize] as usize] = (kept + i) as u32;
        }
    }
    let clusters = placed.len();
    Built {
        faces: faces_taken_apart(&surface, b, &new_id, &singles, &vertex_cluster, clusters),
        placed,
        vertex_cluster,
        clusters,
        cells: cells + singles.len(),
    }
}

/// The faces of [`take_apart`]'s build. The new numbering keeps the order of the clusters
/// that stay (`new_id`, `u32::MAX` for those taken apart), so a face of `b` on them keeps its
/// place and its rotation; every other face has a new singleton (a vertex of `singles`
/// without a placement before) at a corner, and faces that repeat one another have the same
/// clusters, so the faces at the new singletons are deduplicated among themselves and merged
/// in, in face order. Taking every face again was 0.013 s of a repair on the 1M scan; with
/// this and [`origin_normals`]' lookup the hybrid at 1% took 0.334 s against 0.384 s (best of
/// five interleaved in-process runs).
fn faces_taken_apart(
    s: &super::stages::Surface,
    b: &Built,
    new_id: &[u32],
    singles: &[(u32, Option<super::stages::Placed>)],
    vertex_cluster: &[u32],
    clusters: usize,
) -> Vec<(u32, [u32; 3])> {
    use super::stages::{dedupe_faces, rotated};
    let faces = s.faces;
    let mut around: Vec<u32> = singles
        .iter()
        .filter(|single| single.1.is_none())
        .flat_map(|&(v, _)| s.csr.faces_of(v).iter().copied())
        .collect();
    around.sort_unstable();
    around.dedup();
    let fresh = dedupe_faces(
        around
            .iter()
            .filter_map(|&f| {
                let t = faces[f as usize].map(|v| vertex_cluster[v as usize]);
                Some((f, rotated(t)?))
            })
            .collect(),
        clusters,
        true,
    );
    let mut out = Vec::with_capacity(b.faces.len() + fresh.len());
    let mut fresh = fresh.into_iter().peekable();
    for &(f, t) in &b.faces {
        let t = t.map(|k| new_id[k as usize]);
        if t.contains(&u32::MAX) {
            continue;
        }
        while let Some(n) = fresh.next_if(|n| n.0 < f) {
            out.push(n);
        }
        out.push((f, t));
    }
    out.extend(fresh);
    out
}

/// The rounds from `up` on `opts.backend` (cpu-parallel or gpu).
pub(super) fn rounds(
    up: &crate::rounds::Upload,
    mesh: &Mesh,
    opts: &SimplifyOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<(Mesh, SimplifyReport)> {
    match opts.backend {
        crate::options::Backend::Gpu => {
            let (ctx, sim) = crate::rounds::gpu::shared()?;
            crate::rounds::gpu::simplify_upload(ctx, sim, up, mesh, opts, progress)
        }
        _ => crate::rounds::cpu::simplify_upload(up, mesh, opts, progress),
    }
}

/// The intermediate face count the hybrid clusters to for `target` of `input` faces.
pub(super) fn intermediate(target: usize, input: usize) -> usize {
    ((target as f64 * HYBRID_FACTOR + HYBRID_EXTRA).max(HYBRID_MIN_SHARE * input as f64)).round()
        as usize
}

/// The backend the hybrid's second phase runs on from the clusters `c`: the greedy queue
/// (`cpu`) where `opts` asks for `cpu` or `auto` and no appearance channel is in the cost; the
/// rounds (`cpu-parallel`, or `gpu` when asked for) otherwise: on painted scans at 1% the
/// greedy's colour error was up to 1.05× the rounds' (docs/PERFORMANCE.md, "Stop 37"). Without
/// clusters (a target too close to the input for them to pay) every backend runs the rounds
/// ([`rounds_upload`]): the greedy queue there would be `qem`'s own, whose mean error on the
/// small shared models (teapot, suzanne, spot) is up to 1.14× the rounds'.
pub(crate) fn second_phase(c: &Clustered, opts: &SimplifyOptions) -> Backend {
    match opts.backend {
        Backend::Cpu | Backend::Auto
            if crate::quadric::attributes::Layout::new(&c.mesh, &opts.attributes).is_none() =>
        {
            Backend::Cpu
        }
        Backend::Gpu => Backend::Gpu,
        _ => Backend::CpuParallel,
    }
}

/// The hybrid's first phase as the clusters give it: the clustered mesh, each of its
/// vertices' quadrics (relative to the vertex) and its faces' input normals, in the
/// original's frame, and the clustering's largest error.
pub(crate) struct Clustered {
    pub mesh: Mesh,
    pub quadrics: Vec<Quadric>,
    pub normals: Vec<[f32; 3]>,
    pub frame: ([f64; 3], f64),
    pub error: f64,
}

impl Clustered {
    /// The rounds' upload of the clustered mesh with its quadrics and reference normals.
    pub fn upload(&self, opts: &SimplifyOptions) -> crate::rounds::Upload {
        crate::rounds::Upload::with_quadrics(&self.mesh, self.frame, &self.quadrics)
            .reference_normals(&self.normals)
            .attributes(&opts.attributes)
    }

    /// What the greedy queue takes from it: the frame and the reference normals, not the
    /// quadrics (see [`crate::greedy::Carried`]).
    pub fn carried(&self) -> crate::greedy::Carried<'_> {
        crate::greedy::Carried {
            frame: self.frame,
            normals: &self.normals,
        }
    }
}

/// The hybrid's first phase: the clusters for `opts.target_faces`, or `None` where the target
/// is so close to the input that the second phase starts from the input itself; `report`
/// gets the clustering's figures, its seconds included.
pub(crate) fn clustered(
    mesh: &Mesh,
    opts: &SimplifyOptions,
    report: &mut ClusterReport,
) -> Result<Option<Clustered>> {
    let t = Instant::now();
    let intermediate = intermediate(opts.target_faces, mesh.triangles.len());
    report.method = Method::Hybrid;
    let out = if intermediate as f64 >= HYBRID_SKIP * mesh.triangles.len() as f64
        || opts.target_faces == 0
    {
        None
    } else {
        let mut pts = Points::new(mesh);
        let mut work = prepare(&mut pts, opts, true)?;
        work.colors = super::colors::ColourSplit::of(mesh, opts.attributes.color);
        let (grid, built, normals) =
            cluster_repaired(&mut work, intermediate, opts.target_faces, report)?;
        tally(report, &built);
        report.cell_size = grid.h as f64;
        report.intermediate_faces = Some(built.faces.len());
        let (clustered, quadrics) = output(mesh, work.pts, &built, opts.attributes.color > 0.0);
        Some(Clustered {
            mesh: clustered,
            quadrics,
            normals,
            frame: (work.pts.center, work.pts.scale),
            error: max_error(&built),
        })
    };
    report.seconds = t.elapsed().as_secs_f64();
    Ok(out)
}

/// `--method hybrid`.
pub fn simplify_hybrid(
    mesh: &Mesh,
    opts: &SimplifyOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<(Mesh, SimplifyReport)> {
    let mut report = ClusterReport::default();
    let phase = clustered(mesh, opts, &mut report)?;
    opts.cancel.check()?;
    let (out, mut r) = match &phase {
        Some(c) => finish(c, mesh, opts, progress)?,
        None => {
            let (up, _, opts) = rounds_upload(None, mesh, opts)?;
            rounds(&up, mesh, &opts, progress)?
        }
    };
    r.input_faces = mesh.triangles.len();
    r.input_vertices = mesh.positions.len();
    r.collapses = mesh.positions.len().saturating_sub(out.positions.len());
    r.clustering = Some(report);
    Ok((out, r))
}

/// The hybrid's second phase from its clusters `c` to `opts.target_faces` on the backend
/// [`second_phase`] picks (the rounds write `mesh`'s channels); the report's largest error
/// includes the clustering's.
pub(super) fn finish(
    c: &Clustered,
    mesh: &Mesh,
    opts: &SimplifyOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<(Mesh, SimplifyReport)> {
    let opts = SimplifyOptions {
        backend: second_phase(c, opts),
        ..opts.clone()
    };
    let (out, mut r) = match opts.backend {
        Backend::Cpu => crate::greedy::simplify_carried(&c.mesh, &opts, &c.carried(), progress)?,
        _ => rounds(&c.upload(&opts), mesh, &opts, progress)?,
    };
    r.max_collapse_error = r.max_collapse_error.max(c.error);
    Ok((out, r))
}

/// The rounds' upload from the hybrid's first phase (`None`: from `mesh` itself, which the
/// second phase then starts from on every backend), with the clustering's largest error and
/// the options with the rounds' backend (`cpu-parallel` or `gpu`).
pub(crate) fn rounds_upload(
    phase: Option<&Clustered>,
    mesh: &Mesh,
    opts: &SimplifyOptions,
) -> Result<(crate::rounds::Upload, f64, SimplifyOptions)> {
    let opts = SimplifyOptions {
        backend: check_backend(opts)?,
        ..opts.clone()
    };
    Ok(match phase {
        Some(c) => (c.upload(&opts), c.error, opts),
        None => (
            crate::rounds::Upload::new(mesh).attributes(&opts.attributes),
            0.0,
            opts,
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Placements, faces, vertex clusters and the cluster and cell counts.
    type Bits<'a> = (
        Vec<Vec<u32>>,
        &'a [(u32, [u32; 3])],
        &'a [u32],
        usize,
        usize,
    );

    /// A build's every output as bits, to compare two builds exactly.
    fn bits(b: &Built) -> Bits<'_> {
        let placed = b
            .placed
            .iter()
            .map(|p| {
                let mut v: Vec<u32> = p.pos.iter().map(|x| x.to_bits()).collect();
                v.extend(bytemuck::cast_slice::<_, u32>(std::slice::from_ref(
                    &p.quadric,
                )));
                v.push(p.attr);
                v.push(p.how as u32);
                v
            })
            .collect();
        (placed, &b.faces, &b.vertex_cluster, b.clusters, b.cells)
    }

    /// An edge with three faces pinches both its clusters, as does one that two faces run the
    /// same way; an edge two faces run opposite ways does not.
    #[test]
    fn pinched_clusters_are_three_face_edges_and_folds() {
        let faces = [
            [0, 1, 2],
            [1, 0, 3],
            [0, 1, 4],
            [2, 3, 4],
            [2, 3, 5],
            [3, 6, 5],
        ];
        let b = Built {
            placed: Vec::new(),
            faces: faces
                .iter()
                .enumerate()
                .map(|(f, &t)| (f as u32, t))
                .collect(),
            vertex_cluster: Vec::new(),
            clusters: 7,
            cells: 7,
        };
        assert_eq!(pinched_clusters(&b), [0, 1, 2, 3]);
        // Without the third face on (0, 1) and the second face running 2 -> 3: none.
        let b = Built {
            faces: [faces[0], faces[1], faces[3], [3, 2, 5]]
                .iter()
                .enumerate()
                .map(|(f, &t)| (f as u32, t))
                .collect(),
            ..b
        };
        assert!(pinched_clusters(&b).is_empty());
    }

    /// The border vertices are the grid's outline and none of its inside; a closed sphere has
    /// none, and a face that repeats a vertex adds none (its edges lie on the sphere's own).
    #[test]
    fn border_vertices_are_the_ends_of_one_face_edges() {
        let border = |m: &Mesh| {
            let csr = super::super::Csr::new(m.positions.len(), &m.triangles);
            super::super::border_vertices(&csr, &m.triangles)
        };
        let g = crate::mesh::grid(12);
        let b = g.bounds().unwrap();
        let outline: Vec<bool> = g
            .positions
            .iter()
            .map(|p| (0..2).any(|k| p[k] == b.min[k] || p[k] == b.max[k]))
            .collect();
        assert!(outline.iter().any(|&o| o) && outline.iter().any(|&o| !o));
        assert_eq!(border(&g), outline);
        let mut s = crate::mesh::icosphere(2);
        assert!(!border(&s).contains(&true));
        let [a, c, _] = s.triangles[0];
        s.triangles.push([a, a, c]);
        assert!(!border(&s).contains(&true));
    }

    /// The cells' labels are each vertex's lowest in-cell component id, the same on one thread
    /// and on eight, where big cells (tens of vertices each) make the threads link the same
    /// trees at once.
    #[test]
    fn cell_labels_are_the_same_on_any_thread_count() {
        use super::super::stages::{cell_keys, cell_labels, cell_ranges, radix_sort};
        let mut m = crate::mesh::noisy_sphere(6, 0.02, 11);
        // Two sides of a seam: coincident vertices, joined by position.
        m.positions.push(m.positions[0]);
        let (positions, lo, hi) = super::super::unit_frame_points(&m);
        let grid = Grid::new(lo, hi, 0.04);
        let keys = cell_keys(&grid, &positions, &vec![false; positions.len()]);
        let (sorted, members) = radix_sort(&keys);
        let cells = cell_ranges(&sorted, members);
        let labels = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| cell_labels(&cells, &m.triangles, &positions))
        };
        let one = labels(1);
        let v = positions.len() - 1;
        assert_eq!(one[v], one[0], "coincident vertices are one component");
        for (v, &l) in one.iter().enumerate() {
            assert!(
                l as usize <= v && one[l as usize] == l,
                "vertex {v}: label {l}"
            );
            assert_eq!(cells.vertex_cell[v], cells.vertex_cell[l as usize]);
        }
        assert!(
            one.iter()
                .enumerate()
                .filter(|&(v, &l)| l as usize != v)
                .count()
                > v / 2
        );
        for _ in 0..4 {
            assert_eq!(labels(8), one);
        }
    }

    /// Taking clusters apart from the build before gives, bit for bit, what building again with
    /// their members locked gives: for any set of clusters (singletons among them), twice in a
    /// row, on a painted sphere whose colour steps split cells, on a grid whose border is
    /// locked from the start, and on a sphere with repeated, reversed and degenerate faces
    /// (whose clustered faces the deduplication drops).
    #[test]
    fn take_apart_equals_a_whole_build() {
        let mut painted = crate::mesh::noisy_sphere(5, 0.01, 7);
        crate::mesh::paint(&mut painted);
        let mut repeated = crate::mesh::noisy_sphere(5, 0.01, 9);
        let n = repeated.triangles.len();
        for f in (0..n).step_by(7) {
            let [a, b, c] = repeated.triangles[f];
            repeated.triangles.extend([[a, b, c], [a, c, b], [a, a, b]]);
        }
        let cases = [
            (painted, false, 0.5),
            (crate::mesh::grid(60), true, 0.0),
            (repeated, false, 0.0),
        ];
        for (mesh, lock_border, color) in cases {
            let mut opts = SimplifyOptions::with_ratio(mesh.triangles.len(), 0.1).unwrap();
            opts.lock_border = lock_border;
            opts.attributes.color = color;
            let mut pts = Points::new(&mesh);
            let mut work = prepare(&mut pts, &opts, true).unwrap();
            work.colors = super::super::colors::ColourSplit::of(&mesh, color);
            let mut report = ClusterReport::default();
            let target = opts.target_faces;
            let (grid, mut built, _) =
                cluster_to(&work, 3 * target, None, Some(target), &mut report).unwrap();
            let what = format!("{} faces, lock_border {lock_border}", mesh.triangles.len());
            if color > 0.0 {
                assert!(built.clusters > built.cells, "{what}: no cell was split");
            }
            for step in [5usize, 3] {
                // Every step-th cluster, and every locked vertex's singleton.
                let mut bad: Vec<u32> = (0..built.clusters as u32)
                    .filter(|&k| k as usize % step == 1)
                    .collect();
                bad.extend(
                    (0..work.locked.len())
                        .filter(|&v| work.locked[v])
                        .map(|v| built.vertex_cluster[v])
                        .step_by(2),
                );
                bad.sort_unstable();
                bad.dedup();
                let apart = take_apart(&mut work, &grid, &built, &bad);
                let whole = work.build(&grid).unwrap();
                assert_eq!(bits(&apart), bits(&whole), "{what}: every {step}th cluster");
                assert!(
                    whole.clusters > built.clusters,
                    "{what}: nothing taken apart"
                );
                built = whole;
            }
        }
    }
}
