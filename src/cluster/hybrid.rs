//! `--method hybrid`: clustering (cells split by connectivity, clusters that pinch a
//! non-manifold edge taken apart) to an intermediate count, then QEM to the exact target
//! (Garland & Shaffer's multiphase simplification, 2002). On `cpu` (the default) the second
//! phase is the greedy queue on the clustered surface, faster and lower in error than the
//! rounds (docs/PERFORMANCE.md, "`hybrid`"); on `cpu-parallel` and `gpu` it is the rounds from
//! the clusters' quadrics, the same upload on both (twins). The clustering stays on the CPU on
//! every backend: its split of cells by connectivity is a union-find, and its repairs
//! ([`super::repair`]) are worked out from the build before.

use super::repair::cluster_repaired;
use super::{ClusterReport, Points, check_backend, max_error, output, prepare, tally};
use crate::compute::types::Quadric;
use crate::error::Result;
use crate::mesh::Mesh;
use crate::options::{Backend, Method, SimplifyOptions, SimplifyReport};
use std::time::Instant;

/// `hybrid` clusters to this many times the target...
pub const HYBRID_FACTOR: f64 = 2.0;
/// ...plus this many faces: how much clustering costs in error depends on how coarse its cells
/// are against the surface's features, that is on the faces it keeps, not on the ratio. At 2×
/// the target alone the mean error at 10% was 1.07× the greedy's on the oversampled 1M scan but
/// 1.33× on horse and 1.25× on igea; at 3× the 1M scan's hybrid fell below meshoptimizer's
/// speed; 2× + 20,000 gave 1.06×, 1.09× and 1.13× with the 1M scan 1.18× meshoptimizer's
/// speed (docs/PERFORMANCE.md, "`hybrid`").
pub const HYBRID_EXTRA: f64 = 20_000.0;
/// ...but to no fewer than this share of the input's faces: cells coarse enough for 2% of the
/// 1M scan left errors the rounds could not undo (mean 1.38× the greedy's at 1%, against
/// 1.10× from 5%; docs/PERFORMANCE.md, "`hybrid`").
pub const HYBRID_MIN_SHARE: f64 = 0.05;
/// ...unless that is more than this share of the input: merging only pairs of vertices costs a
/// clustering without saving rounds, so the rounds start from the input.
pub const HYBRID_SKIP: f64 = 0.5;

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
/// greedy's colour error was up to 1.05× the rounds' (docs/PERFORMANCE.md, "`hybrid`"). Without
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
        let mut work = prepare(&mut pts, opts, true, Some(intermediate))?;
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
    use super::super::grid::CellGrid;
    use super::*;

    /// The border vertices are the grid's outline and none of its inside; a closed sphere has
    /// none, and a face that repeats a vertex adds none (its edges lie on the sphere's own); a
    /// fan's centre is inside when the fan is closed.
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
        // Fans around vertex 0 of 7 and 12 faces, both sides of the counting's width: closed,
        // the centre is inside; one face short, it is on the border too.
        for n in [7u32, 12] {
            let mut fan = Mesh::new(
                (0..=n)
                    .map(|i| {
                        let a = i as f32 * std::f32::consts::TAU / n as f32;
                        if i == 0 {
                            [0.0; 3]
                        } else {
                            [a.cos(), a.sin(), 0.1]
                        }
                    })
                    .collect(),
                (1..=n).map(|i| [0, i, i % n + 1]).collect(),
            );
            let rim = |centre: bool| {
                let mut b = vec![true; n as usize + 1];
                b[0] = centre;
                b
            };
            assert_eq!(border(&fan), rim(false), "closed fan of {n}");
            fan.triangles.pop();
            assert_eq!(border(&fan), rim(true), "open fan of {n}");
        }
    }

    /// The gather tests its members for the border itself: a vertex's quadric gains border
    /// planes (with a border weight) at the grid's outline and nowhere inside it.
    #[test]
    fn the_gather_adds_border_planes_at_the_outline_only() {
        use super::super::stages::{ClusterSurface, Csr, cluster_quadric, face_planes};
        let g = crate::mesh::grid(9);
        let (positions, _, _) = super::super::unit_frame_points(&g);
        let csr = Csr::new(positions.len(), &g.triangles);
        let planes = face_planes(&positions, &g.triangles);
        let b = g.bounds().unwrap();
        let quadric = |v: usize, border_weight: f32| {
            let s = ClusterSurface {
                positions: &positions,
                faces: &g.triangles,
                planes: &planes,
                csr: &csr,
                border_weight,
            };
            let p = super::super::xyz(positions[v]);
            cluster_quadric(&s, &[v as u32], p, p, p).quadric
        };
        let mut outline = 0;
        for (v, p) in g.positions.iter().enumerate() {
            let on_outline = (0..2).any(|k| p[k] == b.min[k] || p[k] == b.max[k]);
            outline += on_outline as usize;
            let differs = quadric(v, 1.0).q != quadric(v, 0.0).q;
            assert_eq!(differs, on_outline, "vertex {v} at {p:?}");
        }
        assert_eq!(outline, 4 * 9);
    }

    /// The cells' labels are each vertex's lowest in-cell component id, the same on one thread
    /// and on eight, where big cells (tens of vertices each) make the threads link the same
    /// trees at once.
    #[test]
    fn cell_labels_are_the_same_on_any_thread_count() {
        use super::super::labels::cell_labels;
        use super::super::stages::{cell_keys, cell_ranges, radix_sort};
        let mut m = crate::mesh::noisy_sphere(6, 0.02, 11);
        // Two sides of a seam: coincident vertices, joined by position.
        m.positions.push(m.positions[0]);
        let (positions, lo, hi) = super::super::unit_frame_points(&m);
        let grid = CellGrid::new(lo, hi, 0.04);
        let keys = cell_keys(&grid, &positions, &vec![false; positions.len()]);
        let (sorted, members) = radix_sort(keys);
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

    /// The cells are the runs of equal sorted keys, a singleton key a cell per vertex, found
    /// alike on one thread and on eight over enough keys for many tasks; each vertex's cell
    /// holds it.
    #[test]
    fn cell_ranges_are_the_runs_of_equal_keys_on_any_thread_count() {
        use super::super::grid::SINGLETON;
        use super::super::stages::{cell_ranges, radix_sort};
        let keys: Vec<u32> = (0..100_000u32)
            .map(|i| match i.wrapping_mul(2_654_435_761) % 97 {
                0 => SINGLETON,
                k => k * 31 + i % 7,
            })
            .collect();
        let (sorted, members) = radix_sort(keys.clone());
        let on = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| cell_ranges(&sorted, members.clone()))
        };
        let one = on(1);
        // One pass, as the cells are defined.
        let mut start = vec![];
        for i in 0..sorted.len() {
            if i == 0 || sorted[i] != sorted[i - 1] || sorted[i] == SINGLETON {
                start.push(i as u32);
            }
        }
        let key: Vec<u32> = start.iter().map(|&i| sorted[i as usize]).collect();
        start.push(sorted.len() as u32);
        assert_eq!(one.start, start);
        assert_eq!(one.key, key);
        assert!(key.iter().filter(|&&k| k == SINGLETON).count() > 500);
        for c in 0..key.len() {
            for &m in &one.members[start[c] as usize..start[c + 1] as usize] {
                assert_eq!(one.vertex_cell[m as usize], c as u32);
                assert_eq!(keys[m as usize], key[c]);
            }
        }
        let eight = on(8);
        assert_eq!(
            (eight.start, eight.key, eight.vertex_cell),
            (one.start, one.key, one.vertex_cell)
        );
    }

    /// The probes the hybrid counts beside its vertex→face lists are those `cluster_to` counts
    /// itself, and the build from them is the same.
    #[test]
    fn probes_beside_the_lists_equal_the_probes_after() {
        let m = crate::mesh::noisy_sphere(6, 0.02, 5);
        let opts = SimplifyOptions::with_ratio(m.triangles.len(), 0.2).unwrap();
        let target = opts.target_faces;
        let (mut early_pts, mut late_pts) = (Points::new(&m), Points::new(&m));
        let early = prepare(&mut early_pts, &opts, true, Some(target)).unwrap();
        let late = prepare(&mut late_pts, &opts, true, None).unwrap();
        assert!(late.probed.is_none());
        let (t, probes) = early.probed.clone().expect("probed beside the lists");
        assert_eq!(t, target);
        let after = super::super::probe(late.pts, late.pts.area, &late.locked, target).unwrap();
        assert_eq!(probes, after);
        assert_eq!(early.pts.area, late.pts.area);
        let built = |w: &super::super::Work, probes| {
            let mut report = ClusterReport::default();
            let (grid, b, _) =
                super::super::cluster_to(w, target, None, None, probes, &mut report).unwrap();
            (grid.h, b.faces, b.vertex_cluster, report.sizes_counted)
        };
        let (a, b) = (built(&early, Some(probes)), built(&late, None));
        assert!(!a.1.is_empty());
        assert_eq!(a, b);
    }
}
