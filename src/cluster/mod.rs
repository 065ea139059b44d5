//! Vertex clustering: `cluster` (a uniform grid, Rossignac & Borrel 1993, with one quadric per
//! cell placed at its minimum inside the cell, Lindstrom 2000 and Lindstrom & Silva 2001) and
//! `hybrid` (clustering to an intermediate count, then the QEM rounds with each cluster's
//! quadric carried over, Garland & Shaffer 2002). Every stage is a map, a sort or a gather
//! (stages.rs; `cell_labels`, the split by connectivity, in labels.rs); the grid's size is
//! searched by counting passes (grid.rs).
//!
//! Attributes are not kept apart: a cluster's vertex takes the UV and normal of its member
//! nearest to it, so UV seams inside a cell close (as meshoptimizer's sloppy simplifier's do),
//! and, with a colour weight above 0, the colour its cell's attribute quadric fits (colors.rs).
//! `qem` keeps seams.

mod colors;
pub mod floating;
// `floating-cell` on the gpu backend: its build on `gpu::GpuClusterMesh`.
pub mod floating_gpu;
// `cluster` on the gpu backend: the build's stage descriptions and uniforms, and the GPU
// driver. The stages' CPU twins (the GPU's gather order; the CPU driver, stages.rs, scatters
// its quadrics instead) are test code, in tests/cluster_twins: the library has one
// implementation of each stage for the CPU (stages.rs, floating.rs) and one in WGSL.
pub mod gpu;
pub mod gpu_schedule;
pub mod grid;
mod hybrid;
// The `cell_labels` stage (the connectivity split), public like the other stages in stages.rs.
pub mod labels;
mod output;
mod repair;
pub mod stages;
pub mod stream;

pub use floating::simplify_floating;
pub use hybrid::{HYBRID_EXTRA, HYBRID_FACTOR, HYBRID_MIN_SHARE, HYBRID_SKIP, simplify_hybrid};
pub(crate) use hybrid::{clustered, rounds_upload, second_phase};
use output::output;

use crate::compute::common::{V3, xyz};
use crate::compute::types::Quadric;
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::mesh::prepare::{frame_of_box, normalize};
use crate::options::{Backend, ClusterReport, Method, SimplifyOptions, SimplifyReport, StopReason};
use grid::CellGrid;
use rayon::prelude::*;
use stages::{Cells, Clusters, Csr, Marked, Placed, Placement};
use std::time::Instant;

/// `cluster` lands within this share of the target.
pub const BAND: f64 = 0.05;
/// The points clustering works on, in the unit-diagonal frame: the input's vertices one for
/// one, so a point's id is its input vertex's (its attributes, its exact position).
struct Points<'m> {
    positions: Vec<[f32; 4]>,
    faces: std::borrow::Cow<'m, [[u32; 3]]>,
    lo: V3,
    hi: V3,
    center: [f64; 3],
    scale: f64,
    area: f64,
    /// `--stream`: the faces stay in the file and are read a block at a time (`faces` is
    /// empty).
    stream: Option<crate::io::stream::FileFaces>,
}

/// `mesh`'s positions in the unit-diagonal frame (`mesh::prepare::frame_of`), w = 1, as every
/// clustering build takes them, and their box: what the GPU tests and examples upload too.
pub fn unit_frame_points(mesh: &Mesh) -> (Vec<[f32; 4]>, V3, V3) {
    let bounds = mesh.bounds();
    framed_points(mesh, bounds, frame_of_box(bounds))
}

/// [`unit_frame_points`] in the frame `(center, scale)` of `mesh`'s `bounds`. The box is the
/// input's box taken into the frame: `normalize` and the rounding to f32 never reverse two
/// coordinates' order, so the least of the normalized coordinates is the normalized least
/// one, bit for bit (the input's coordinates are finite, `Mesh::validate`), and no second pass
/// over the points is needed (one of its three passes, on a cold cache).
fn framed_points(
    mesh: &Mesh,
    bounds: Option<crate::mesh::Aabb>,
    (center, scale): ([f64; 3], f64),
) -> (Vec<[f32; 4]>, V3, V3) {
    let into = |p: [f32; 3]| normalize(p, center, scale).map(|x| x as f32);
    let positions: Vec<[f32; 4]> = mesh
        .positions
        .par_iter()
        .with_min_len(4096)
        .map(|&p| {
            let [x, y, z] = into(p);
            [x, y, z, 1.0]
        })
        .collect();
    let (lo, hi) = bounds.map_or(([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]), |b| {
        (into(b.min), into(b.max))
    });
    (positions, lo, hi)
}

impl<'m> Points<'m> {
    /// The input's vertices as they are: coincident ones share a cell anyway, and the
    /// connectivity split joins them.
    fn new(mesh: &'m Mesh) -> Points<'m> {
        Points::of(mesh, mesh.triangles.as_slice().into())
    }

    /// `mesh`'s vertices with `faces`.
    fn of(mesh: &Mesh, faces: std::borrow::Cow<'m, [[u32; 3]]>) -> Points<'m> {
        let bounds = mesh.bounds();
        let (center, scale) = frame_of_box(bounds);
        let (positions, lo, hi) = framed_points(mesh, bounds, (center, scale));
        Points {
            positions,
            faces,
            lo,
            hi,
            center,
            scale,
            area: 0.0,
            stream: None,
        }
    }

    /// Calls `f` with the faces in blocks, in face order, with each block's first face id: all
    /// at once in memory, a block at a time from the file when streaming.
    fn blocks(&self, f: &mut crate::io::stream::OnBlock) -> Result<()> {
        match &self.stream {
            None => f(0, &self.faces),
            Some(s) => s.blocks(f),
        }
    }

    /// How many faces there are.
    fn face_count(&self) -> usize {
        self.stream.as_ref().map_or(self.faces.len(), |s| s.faces)
    }
}

/// One clustering at a given grid.
struct Built {
    placed: Vec<Placed>,
    faces: Vec<(u32, [u32; 3])>,
    vertex_cluster: Vec<u32>,
    clusters: usize,
    cells: usize,
}

struct Work<'a, 'm> {
    pts: &'a Points<'m>,
    /// `hybrid`: the vertex→face lists and face planes its gather and its connectivity split
    /// read; `cluster` scatters its quadrics without them.
    gather: Option<Gather>,
    /// `hybrid`: cells split into their connected components.
    split: bool,
    border_weight: f32,
    /// Per point: clustered with nobody (a locked border; a hybrid cluster that made a
    /// non-manifold edge, taken apart).
    locked: Vec<bool>,
    /// The target and its probes, counted beside the vertex→face lists ([`prepare`]) for the
    /// first `cluster_to`, which takes them.
    probed: Option<(usize, Probes)>,
    /// `--backend gpu`: the points on the device, each build run there by the same stages.
    gpu: Option<std::sync::Mutex<gpu::GpuClusterMesh<'a>>>,
    /// `hybrid` on a coloured mesh: the colour step an edge may not cross inside a cell.
    colors: Option<colors::ColourSplit<'m>>,
}

struct Gather {
    csr: Csr,
    planes: Vec<[f32; 4]>,
}

impl Work<'_, '_> {
    fn build(&self, grid: &CellGrid) -> Result<Built> {
        if let Some(g) = &self.gpu {
            let b = g
                .lock()
                .map_err(|_| Error::Internal("the GPU clustering lock is poisoned".into()))?
                .build(grid)?;
            return Ok(Built {
                placed: b.placed,
                faces: b.faces,
                vertex_cluster: b.vertex_cluster,
                clusters: b.clusters,
                cells: b.cells,
            });
        }
        let keys = stages::cell_keys(grid, &self.pts.positions, &self.locked);
        let (sorted, members) = stages::radix_sort(keys);
        let mut cells: Cells = stages::cell_ranges(&sorted, members);
        // Not held through the quadrics, whose per-chunk sums set the peak (2 MB on 1M faces).
        drop(sorted);
        let (clusters, label) = if self.split {
            let label = match (&self.gather, &self.colors) {
                (Some(_), Some(c)) => labels::cell_labels_where(
                    &cells,
                    &self.pts.faces,
                    &self.pts.positions,
                    c.joins(grid.h),
                ),
                (Some(_), None) => {
                    labels::cell_labels(&cells, &self.pts.faces, &self.pts.positions)
                }
                // Streamed: the union-find fed block by block.
                (None, _) => {
                    let u = labels::CellUnion::new(cells.vertex_cell.len());
                    self.pts.blocks(&mut |_, faces| {
                        u.join_faces(&cells, faces);
                        Ok(())
                    })?;
                    u.labels(&cells, &self.pts.positions)
                }
            };
            (Clusters::split(&cells, &label), Some(label))
        } else {
            (Clusters::whole_cells(&mut cells), None)
        };
        // Each cluster's box: its cell's, or its vertex for a singleton.
        let boxes: Vec<(V3, V3)> = (0..clusters.len())
            .into_par_iter()
            .with_min_len(4096)
            .map(|k| {
                let key = cells.key[clusters.cell[k] as usize];
                if key == stages::SINGLETON {
                    let m = cells.members[cells.start[clusters.cell[k] as usize] as usize];
                    let p = xyz(self.pts.positions[m as usize]);
                    (p, p)
                } else {
                    grid.cell_box(key)
                }
            })
            .collect();
        let centre = |k: usize| [0, 1, 2].map(|i| 0.5 * (boxes[k].0[i] + boxes[k].1[i]));
        let (scattered, marked) = match &self.gather {
            Some(_) => (None, None),
            None => {
                let origins: Vec<V3> = (0..clusters.len()).map(centre).collect();
                let (q, marked) = self.scatter(&clusters.vertex_cluster, &origins)?;
                (Some(q), Some(marked))
            }
        };
        let surface = self.surface();
        let placed: Vec<Placed> = (0..clusters.len())
            .into_par_iter()
            .with_min_len(256)
            .map_init(Vec::new, |members, k| {
                let csr = surface.as_ref().map(|s| s.csr);
                stages::ask_ahead(&clusters, &cells, &self.pts.positions, csr, k);
                members.clear();
                members.extend(clusters.members(&cells, label.as_deref(), k));
                let ((lo, hi), o) = (boxes[k], centre(k));
                match (&surface, &scattered) {
                    (Some(s), _) => stages::cluster_quadric(s, members, o, lo, hi),
                    (None, Some(q)) => stages::place(&self.pts.positions, q[k], members, o, lo, hi),
                    (None, None) => unreachable!("cluster quadrics scattered without a gather"),
                }
            })
            .collect();
        let faces = match marked {
            Some(marked) => stages::dedupe_faces(marked, clusters.len(), self.split),
            None => stages::cluster_faces(
                &self.pts.faces,
                &clusters.vertex_cluster,
                clusters.len(),
                self.gather.is_some(),
            ),
        };
        Ok(Built {
            placed,
            faces,
            clusters: clusters.len(),
            vertex_cluster: clusters.vertex_cluster,
            cells: cells.key.len(),
        })
    }
}

impl Work<'_, '_> {
    /// What [`stages::cluster_quadric`] reads; `None` without vertex→face lists (`cluster`).
    fn surface(&self) -> Option<stages::ClusterSurface<'_>> {
        let g = self.gather.as_ref()?;
        Some(stages::ClusterSurface {
            positions: &self.pts.positions,
            faces: &self.pts.faces,
            planes: &g.planes,
            csr: &g.csr,
            border_weight: self.border_weight,
        })
    }

    /// [`stages::scatter_quadrics`] over the faces' blocks (one block in memory: the same
    /// sums), block after block, the marked faces' ids made global.
    fn scatter(&self, vertex_cluster: &[u32], origins: &[V3]) -> Result<(Vec<Quadric>, Marked)> {
        let mut sum: Option<Vec<Quadric>> = None;
        let mut kept = Vec::new();
        self.pts.blocks(&mut |first, faces| {
            let (q, marked) =
                stages::scatter_quadrics(&self.pts.positions, faces, vertex_cluster, origins);
            kept.extend(marked.into_iter().map(|(f, t)| (f + first as u32, t)));
            match &mut sum {
                None => sum = Some(q),
                Some(sum) => sum
                    .par_iter_mut()
                    .zip(q)
                    .with_min_len(4096)
                    .for_each(|(s, p)| *s = crate::compute::common::quadric_add(s, &p)),
            }
            Ok(())
        })?;
        Ok((
            sum.unwrap_or_else(|| vec![Quadric::default(); origins.len()]),
            kept,
        ))
    }
}

/// The grid size a face count suggests: on a surface about `3 area / h²` faces survive
/// (occupied cells ≈ 1.5 area / h², two faces a cell).
fn estimate(area: f64, faces: usize) -> f32 {
    (3.0 * area / faces.max(1) as f64).sqrt() as f32
}

/// Builds at most this many times to land in the band.
const MAX_BUILDS: usize = 6;

/// Clusters to about `target` faces: within [`BAND`] of it, or (`floor`, the hybrid) at least
/// `floor`. `--max-error` caps the cell so that no vertex moves farther than it. One counting
/// pass fits faces against cell size (a power law, faces ∝ h⁻² on a surface), unless `probes`
/// come counted already; then [`land`].
fn cluster_to(
    work: &Work,
    target: usize,
    max_error: Option<f64>,
    floor: Option<usize>,
    probes: Option<Probes>,
    report: &mut ClusterReport,
) -> Result<(CellGrid, Built, StopReason)> {
    let pts = work.pts;
    let (lo, hi) = (pts.lo, pts.hi);
    let (h0, probed) = match probes {
        Some(probes) => probes,
        None => probe(pts, pts.area, &work.locked, target)?,
    };
    report.sizes_counted += probed.len();
    let first = grid::fit(&probed, target.max(1) as f64).unwrap_or(h0);
    // A vertex moves at most a cell's diagonal, √3 h.
    let cap = max_error.map(|e| e / 3f64.sqrt());
    let (h, built, stop) = land(target, floor, first, Some(&probed), cap, report, &mut |h| {
        let g = CellGrid::new(lo, hi, h as f32);
        Ok((g.h as f64, work.build(&g)?))
    })?;
    Ok((CellGrid::new(lo, hi, h as f32), built, stop))
}

/// A first estimate of the cell size and the probes' (size, faces) pairs at four sizes around
/// it (see [`grid::probe_cells`]).
type Probes = (f64, Vec<(f64, f64)>);

/// The [`Probes`] for `target` faces on a surface of `area`.
fn probe(pts: &Points, area: f64, locked: &[bool], target: usize) -> Result<Probes> {
    let (lo, hi) = (pts.lo, pts.hi);
    let h0 = estimate(area, target) as f64;
    let grids: Vec<CellGrid> = [0.85, 0.95, 1.05, 1.15]
        .iter()
        .map(|k| CellGrid::new(lo, hi, (k * h0) as f32))
        .collect();
    let cells = grid::probe_cells(&grids, &pts.positions, locked);
    let mut counts = [0usize; 4];
    pts.blocks(&mut |_, faces| {
        let c = grid::probe_count(&cells, faces);
        counts = [0, 1, 2, 3].map(|i| counts[i] + c[i]);
        Ok(())
    })?;
    let probed = grids
        .iter()
        .zip(&counts)
        .map(|(g, &n)| (g.h as f64, n as f64))
        .collect();
    Ok((h0, probed))
}

/// Builds at sizes corrected by each build's own count until one lands: the first at `first`,
/// the next by the probes' slope through the last build (or, without probes, faces ∝ h⁻²), then
/// by the secant through the last two builds in log-log. `cap` bounds the size (`--max-error`);
/// `build` returns the size it used and its result.
fn land(
    target: usize,
    floor: Option<usize>,
    first: f64,
    probed: Option<&[(f64, f64)]>,
    cap: Option<f64>,
    report: &mut ClusterReport,
    build: &mut dyn FnMut(f64) -> Result<(f64, Built)>,
) -> Result<(f64, Built, StopReason)> {
    let t = target.max(1) as f64;
    let mut h = first;
    let mut stop = StopReason::TargetReached;
    let mut builds: Vec<(f64, f64)> = Vec::new();
    let mut best: Option<(f64, Built)> = None;
    let ok = |n: f64| match floor {
        Some(f) => n >= f as f64,
        None => (n - t).abs() <= BAND * t,
    };
    for _ in 0..MAX_BUILDS {
        if let Some(cap) = cap
            && (h > cap || target == 0)
        {
            h = cap;
            stop = StopReason::MaxError;
        }
        let (used, built) = build(h)?;
        report.builds += 1;
        let n = built.faces.len() as f64;
        let done = stop == StopReason::MaxError || ok(n);
        let closer = best.as_ref().is_none_or(|(_, b)| {
            let m = b.faces.len() as f64;
            match (ok(n), ok(m)) {
                (true, false) => true,
                (false, true) => false,
                _ => (n - t).abs() < (m - t).abs(),
            }
        });
        if closer {
            best = Some((used, built));
        }
        if done {
            break;
        }
        builds.push((used, n));
        let next = match (builds.len(), probed) {
            (1, Some(probed)) => {
                let shifted: Vec<(f64, f64)> = probed
                    .iter()
                    .map(|&(ph, pn)| (ph, pn * n.max(1.0) / count_at(probed, used)))
                    .collect();
                grid::fit(&shifted, t)
            }
            (1, None) => Some(used * (n.max(1.0) / t).sqrt()),
            _ => grid::fit(&builds[builds.len() - 2..], t),
        };
        // Keep inside the bracket of sizes seen: the count can jump (cells resonating with a
        // regular mesh's spacing), and a secant across a jump overshoots; bisect then.
        let above = builds
            .iter()
            .filter(|b| b.1 > t)
            .map(|b| b.0)
            .fold(0.0, f64::max);
        let below = builds
            .iter()
            .filter(|b| b.1 < t)
            .map(|b| b.0)
            .fold(f64::INFINITY, f64::min);
        let next = match next {
            Some(x) if x > above && x < below => Some(x),
            _ if above > 0.0 && below.is_finite() => Some((above * below).sqrt()),
            other => other,
        };
        let Some(next) = next.filter(|x| (x / used - 1.0).abs() > 1e-4) else {
            break;
        };
        h = next;
    }
    let (h, built) = best.expect("one build at least");
    let n = built.faces.len() as f64;
    if stop == StopReason::TargetReached && floor.is_none() && (n - t).abs() > BAND * t {
        stop = StopReason::ClusterBand;
    }
    Ok((h, built, stop))
}

/// The probes' count at `h`, interpolated in log-log between the nearest two.
fn count_at(probed: &[(f64, f64)], h: f64) -> f64 {
    let fitted = |target: f64| grid::fit(probed, target);
    // Invert the fit by bisection on the count (monotone where the fit exists).
    let (mut a, mut b) = (1.0f64, 1e9f64);
    for _ in 0..60 {
        let m = (a * b).sqrt();
        match fitted(m) {
            Some(hm) if hm > h => a = m,
            Some(_) => b = m,
            None => return 1.0,
        }
    }
    (a * b).sqrt()
}

fn tally(report: &mut ClusterReport, b: &Built) {
    report.clusters = b.clusters;
    report.split_clusters = b.clusters - b.cells;
    for p in &b.placed {
        match p.how {
            Placement::Single => report.placed_single += 1,
            Placement::Solve => report.placed_solve += 1,
            Placement::Member => report.placed_member += 1,
            Placement::Centroid => report.placed_centroid += 1,
        }
    }
}

/// The largest cluster error, as an RMS distance relative to the diagonal.
fn max_error(b: &Built) -> f64 {
    b.placed
        .iter()
        .filter(|p| p.quadric.q[2][2] > 0.0)
        .map(|p| (p.quadric.q[2][1].max(0.0) / p.quadric.q[2][2]) as f64)
        .fold(0.0, f64::max)
        .sqrt()
}

/// Faces [`area`] samples: one in this many (the area only seeds the size search, whose
/// counting pass corrects it; all faces took 0.013 s of 0.1 s on the 1M scan).
const AREA_STRIDE: usize = 8;
/// Sampled faces [`area`] sums apart, a fixed number so the sum does not depend on the thread
/// count.
const AREA_CHUNK: usize = 16384;

/// The surface area in the unit-diagonal frame, estimated from every [`AREA_STRIDE`]-th face
/// and summed in fixed chunks (the same for any thread count, as the grid search that starts
/// from it must be).
/// The faces' area (from a sample of them), and how many faces there are (a streamed file's
/// count comes from this pass).
fn area(pts: &Points) -> Result<(f64, usize)> {
    let (mut sum, mut sampled, mut count) = (0.0f64, 0usize, 0usize);
    pts.blocks(&mut |first, faces| {
        count += faces.len();
        // Every AREA_STRIDE-th face of the whole, whatever the blocks.
        let skip = (AREA_STRIDE - first % AREA_STRIDE) % AREA_STRIDE;
        // The picked faces read where they lie: copying them out first wrote 1.5 MB of fresh
        // pages on a 1M-face mesh.
        let picked = faces.len().saturating_sub(skip).div_ceil(AREA_STRIDE);
        sampled += picked;
        let parts: Vec<f64> = (0..picked.div_ceil(AREA_CHUNK))
            .into_par_iter()
            .map(|c| {
                (c * AREA_CHUNK..picked.min((c + 1) * AREA_CHUNK))
                    .map(|j| {
                        let t = faces[skip + j * AREA_STRIDE];
                        let p = t.map(|v| xyz(pts.positions[v as usize]));
                        let c = crate::compute::common::cross(
                            crate::compute::common::sub(p[1], p[0]),
                            crate::compute::common::sub(p[2], p[0]),
                        );
                        0.5 * crate::compute::common::length(c) as f64
                    })
                    .sum::<f64>()
            })
            .collect();
        sum += parts.iter().sum::<f64>();
        Ok(())
    })?;
    Ok((sum * count as f64 / sampled.max(1) as f64, count))
}

/// `split` (hybrid): build the vertex→face lists and face planes; with `probe_for`, count the
/// probes for that target beside them (`cluster_to` then takes them).
fn prepare<'a, 'm>(
    pts: &'a mut Points<'m>,
    opts: &SimplifyOptions,
    split: bool,
    probe_for: Option<usize>,
) -> Result<Work<'a, 'm>> {
    // Streamed faces have no vertex→face lists: a streamed hybrid scatters its quadrics.
    let lists = pts.stream.is_none() && (split || opts.lock_border);
    // Without border locks nothing is locked before the first build, so the probes need not
    // wait for the lists.
    let unlocked = vec![false; pts.positions.len()];
    let probe_for = probe_for.filter(|_| lists && !opts.lock_border);
    let (gather, early) = if lists {
        // One core's counting sort, the planes beside it: 0.050 s one after the other on the
        // 1M scan at 10% (`hybrid` took 0.5 s), 0.013-0.024 s side by side. The area and the
        // probes join the planes there, which is a little cheaper still (medians of 21 calls,
        // two cores: 0.097 s for the lists, the probes and the first build, against 0.101 s).
        let at: &Points = pts;
        let (csr, beside) = rayon::join(
            || Csr::new(at.positions.len(), &at.faces),
            || -> Result<_> {
                let planes = stages::face_planes(&at.positions, &at.faces);
                let early = match probe_for {
                    Some(target) => {
                        let (area, _) = area(at)?;
                        Some((area, target, probe(at, area, &unlocked, target)?))
                    }
                    None => None,
                };
                Ok((planes, early))
            },
        );
        let (planes, early) = beside?;
        (Some(Gather { csr, planes }), early)
    } else {
        (None, None)
    };
    let probed = match early {
        Some((area, target, probes)) => {
            pts.area = area;
            Some((target, probes))
        }
        None => {
            let (area, faces) = area(pts)?;
            pts.area = area;
            if let Some(s) = pts.stream.as_mut() {
                s.faces = faces;
            }
            None
        }
    };
    let locked = match &gather {
        Some(g) if opts.lock_border => border_vertices(&g.csr, &pts.faces),
        _ => unlocked,
    };
    Ok(Work {
        pts,
        gather: gather.filter(|_| split),
        split,
        border_weight: opts.border_weight as f32,
        locked,
        probed,
        gpu: None,
        colors: None,
    })
}

/// Vertices on an edge of one face ([`stages::on_border`]), for `--lock-border`'s locks; the
/// gather ([`stages::cluster_quadric`]) tests its members itself, with their faces at hand.
fn border_vertices(csr: &Csr, faces: &[[u32; 3]]) -> Vec<bool> {
    (0..csr.offsets.len() as u32 - 1)
        .into_par_iter()
        .with_min_len(1024)
        .map(|v| {
            if (v as usize + BORDER_AHEAD) < csr.offsets.len() - 1 {
                for &f in csr.faces_of(v + BORDER_AHEAD as u32) {
                    crate::prefetch::prefetch(faces, f as usize);
                }
            }
            stages::on_border(faces, csr.faces_of(v), v)
        })
        .collect()
}

/// How many vertices ahead [`border_vertices`] asks the cache for a vertex's faces: the 1M
/// scan's faces are not in vertex order, so each list reads scattered faces. Measured on the
/// 1M scan at 10% (`hybrid`, two cores, median of 15 calls): 0.024 s without, 0.018 s 8 ahead,
/// 0.020 s 16 ahead.
const BORDER_AHEAD: usize = 8;

/// The backend a clustering method runs on: the GPU when asked (`auto` takes the CPU: on
/// lavapipe a build is several times slower, docs/PERFORMANCE.md), else the CPU's cores.
/// `hybrid`'s clustering runs on the CPU either way; its rounds follow the backend.
fn check_backend(opts: &SimplifyOptions) -> Result<Backend> {
    Ok(match opts.backend {
        Backend::Gpu => Backend::Gpu,
        Backend::Cpu | Backend::CpuParallel | Backend::Auto => Backend::CpuParallel,
    })
}

/// The process's shared clusterer when `opts` asks for the GPU; `None`: the CPU's cores.
fn device_for(opts: &SimplifyOptions) -> Result<Option<&'static gpu::GpuClusterer>> {
    Ok(match check_backend(opts)? {
        Backend::Gpu => Some(gpu::shared()?),
        _ => None,
    })
}

/// `--method cluster`.
pub fn simplify_cluster(
    mesh: &Mesh,
    opts: &SimplifyOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<(Mesh, SimplifyReport)> {
    let (out, report, _) = cluster_on(device_for(opts)?, mesh, opts, progress)?;
    Ok((out, report))
}

/// `--method cluster` or `floating-cell` on `clusterer`'s device, its result also left there as
/// a mesh a renderer draws (the viewer's: its own device, its own pipelines).
pub fn simplify_drawn(
    clusterer: &gpu::GpuClusterer,
    mesh: &Mesh,
    opts: &SimplifyOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<(Mesh, SimplifyReport, Drawn)> {
    let opts = &SimplifyOptions {
        backend: Backend::Gpu,
        ..opts.clone()
    };
    let (out, report, drawn) = match opts.method {
        Method::Cluster => cluster_on(Some(clusterer), mesh, opts, progress)?,
        Method::FloatingCell => floating::floating_on(Some(clusterer), mesh, opts, progress)?,
        m => {
            return Err(Error::InvalidOption(format!(
                "--method {} leaves no mesh on the device (cluster and floating-cell do)",
                m.name()
            )));
        }
    };
    let drawn = drawn.ok_or_else(|| Error::Internal("a GPU clustering left no mesh".into()))?;
    Ok((out, report, drawn))
}

/// A clustering's result on the device ([`crate::rounds::gpu::GpuMesh`]: one vertex per cluster,
/// the kept faces as indices) and the same arrays on the host, in its order, for a renderer's
/// per-vertex extras (normals, the error heatmap).
pub struct Drawn {
    pub gpu: crate::rounds::gpu::GpuMesh,
    /// Per cluster, in the unit-diagonal frame (w = 1).
    pub positions: Vec<[f32; 4]>,
    pub indices: Vec<u32>,
}

impl Drawn {
    /// The last build on `g` (the one `built` read back) as drawn.
    fn of(g: &mut gpu::GpuClusterMesh, built: &Built, pts: &Points) -> Result<Drawn> {
        Ok(Drawn {
            gpu: g.drawable(pts.center, pts.scale)?,
            positions: built
                .placed
                .iter()
                .map(|p| [p.pos[0], p.pos[1], p.pos[2], 1.0])
                .collect(),
            indices: built.faces.iter().flat_map(|(_, t)| *t).collect(),
        })
    }
}

fn cluster_on(
    on: Option<&gpu::GpuClusterer>,
    mesh: &Mesh,
    opts: &SimplifyOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<(Mesh, SimplifyReport, Option<Drawn>)> {
    let backend = check_backend(opts)?;
    let t = Instant::now();
    let mut pts = Points::new(mesh);
    let mut work = prepare(&mut pts, opts, false, None)?;
    if let Some(sim) = on {
        let g = gpu::GpuClusterMesh::new(sim, &work.pts.positions, &work.pts.faces, &work.locked)?;
        work.gpu = Some(std::sync::Mutex::new(g));
    }
    progress(0.2);
    let mut report = ClusterReport {
        method: Method::Cluster,
        ..Default::default()
    };
    let (grid, built, stop) = cluster_to(
        &work,
        opts.target_faces,
        opts.max_error,
        None,
        None,
        &mut report,
    )?;
    opts.cancel.check()?;
    progress(0.9);
    tally(&mut report, &built);
    report.cell_size = grid.h as f64;
    // `cluster_to` may have kept an earlier build than the device's last one: build the kept
    // grid again before drawing from the device's buffers.
    let drawn = match work.gpu.take() {
        Some(g) => {
            let mut g = g
                .into_inner()
                .map_err(|_| Error::Internal("the GPU clustering lock is poisoned".into()))?;
            if g.last_grid() != Some(grid) {
                g.build(&grid)?;
            }
            Some(Drawn::of(&mut g, &built, work.pts)?)
        }
        None => None,
    };
    let (out, _) = output(mesh, work.pts, &built, opts.attributes.color > 0.0);
    report.seconds = t.elapsed().as_secs_f64();
    let report = clustered_report(mesh, opts, backend, &out, &built, stop, report);
    Ok((out, report, drawn))
}

/// The report of a clustering that ends in clustering (`cluster`, `floating-cell`).
fn clustered_report(
    mesh: &Mesh,
    opts: &SimplifyOptions,
    backend: Backend,
    out: &Mesh,
    built: &Built,
    stop: StopReason,
    report: ClusterReport,
) -> SimplifyReport {
    SimplifyReport {
        target_faces: opts.target_faces,
        max_collapse_error: max_error(built),
        clustering: Some(report),
        ..SimplifyReport::counts(backend, mesh, out, stop)
    }
}
