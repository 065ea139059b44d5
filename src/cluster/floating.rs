//! Floating cells (Low & Tan, "Model Simplification Using Vertex-Clustering", 1997): vertices
//! graded by importance; the most important unclaimed vertex becomes a cell centre and claims
//! the unclaimed vertices within a radius. Run as parallel rounds: a vertex becomes a centre
//! when it outranks every unclaimed vertex within twice the radius, found through a hash grid
//! of cells twice the radius wide (the sorted cell keys of the uniform grid, searched by
//! binary search). Two centres of one round are then more than twice the radius apart, so
//! their claims never meet, and the rounds pick the centres the sequential greedy picks
//! (tests/cluster.rs checks it). Each centre's radius is the nominal one spread by ±10%
//! ([`radius`]); "within twice the radius" is then within the sum of the two radii. On the gpu
//! backend the same rounds run as WGSL stages (`floating_gpu.rs`; their twins are test code,
//! tests/cluster_twins/floating.rs).

use super::grid::CellGrid;
use super::stages::{self, Csr, Placed};
use super::{
    Built, ClusterReport, Points, Work, check_backend, clustered_report, device_for, land, output,
    prepare, tally,
};
use crate::compute::common::{V3, dot, length, sub, tie_rank, xyz};
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::mesh::morton::morton3;
use crate::options::{Method, SimplifyOptions, SimplifyReport};
use rayon::prelude::*;
use std::time::Instant;

/// Low & Tan's grade of every vertex ([`grade`]).
pub fn grades(positions: &[[f32; 4]], faces: &[[u32; 3]], csr: &Csr) -> Vec<f32> {
    (0..positions.len() as u32)
        .into_par_iter()
        .with_min_len(1024)
        .map_init(Vec::new, |dirs: &mut Vec<V3>, v| {
            grade(positions, faces, csr.faces_of(v), v, dirs)
        })
        .collect()
}

/// Low & Tan's grade of `v`, whose faces are `list`: `cos(θ/2)` for the widest angle θ between
/// two edges at the vertex (a flat or straight-through vertex has θ near 180° and grades near
/// 0, a tip or a crease corner grades high), times the longest edge there (a vertex among large
/// faces stands for more surface). `dirs` is scratch. The twin of shaders/cluster/fc_grades.wgsl, which
/// recomputes each direction per pair instead of keeping the list (the same values; min and
/// max do not depend on the order).
pub fn grade(
    positions: &[[f32; 4]],
    faces: &[[u32; 3]],
    list: &[u32],
    v: u32,
    dirs: &mut Vec<V3>,
) -> f32 {
    let pv = xyz(positions[v as usize]);
    dirs.clear();
    let mut longest = 0.0f32;
    for &f in list {
        for u in faces[f as usize] {
            if u == v {
                continue;
            }
            let e = sub(xyz(positions[u as usize]), pv);
            let l = length(e);
            if l > 0.0 {
                longest = longest.max(l);
                dirs.push([e[0] / l, e[1] / l, e[2] / l]);
            }
        }
    }
    // The widest angle has the least cosine.
    let mut least = 1.0f32;
    for i in 0..dirs.len() {
        for j in i + 1..dirs.len() {
            least = least.min(dot(dirs[i], dirs[j]));
        }
    }
    // cos(θ/2) = sqrt((1 + cos θ) / 2).
    ((1.0 + least.clamp(-1.0, 1.0)) * 0.5).sqrt() * longest
}

/// Each vertex's rank ([`rank`]).
pub fn ranks(grades: &[f32]) -> Vec<u64> {
    grades
        .par_iter()
        .enumerate()
        .map(|(v, &g)| rank(g, v as u32))
        .collect()
}

/// The rank of vertex `v` of grade `g`, all distinct: the grade's top bits (a non-negative f32
/// orders as its bits), then a hash of the id to break ties among equal grades without a
/// monotone id wave (as the rounds' `tie_rank`), then the id. The GPU keeps the top word
/// (`fc_rank`) and compares the id beside it.
#[inline]
pub fn rank(g: f32, v: u32) -> u64 {
    let g = g.max(0.0).to_bits() >> 8;
    ((g as u64) << 40) | ((tie_rank(v) as u64 & 0xff) << 32) | v as u64
}

/// A vertex no centre has claimed yet (`fc_centre`). Keep in sync with `UNCLAIMED` in
/// shaders/cluster/cluster.inc.wgsl.
pub const UNCLAIMED: u32 = u32::MAX;

/// Centres' radii spread over ±[`JITTER`]/2 about the nominal radius, by a hash of the centre:
/// with one radius for all, a regular mesh's count jumps as the radius crosses a spacing of
/// its lattice (a 40×40-a-side cube from 3,120 to 1,762 faces between two radii 5% apart,
/// nothing in the ±5% band of 1,920 between); spread radii cross it one centre at a time.
pub const JITTER: f32 = 0.2;

/// The radius of centre `v` for the nominal radius `r`.
#[inline]
pub fn radius(r: f32, v: u32) -> f32 {
    let u = tie_rank(v ^ 0x9e37_79b9) as f32 / u32::MAX as f32;
    r * (1.0 + JITTER * (u - 0.5))
}

/// The hash grid of the rounds at nominal radius `r`: cells twice the largest radius wide, so
/// two vertices within the sum of their radii lie in neighbouring cells.
pub fn hash_grid(lo: V3, hi: V3, r: f32) -> CellGrid {
    let r_max = r * (1.0 + 0.5 * JITTER);
    CellGrid::new(lo, hi, 2.0 * r_max)
}

/// The cells around `p`'s (3×3×3) present in `keys` (sorted, each once), as ranges of members
/// (`start[i]..start[i + 1]` for cell `i`), nearest first, and how many there are.
pub fn cells_around(
    grid: &CellGrid,
    keys: &[u32],
    start: &[u32],
    p: V3,
) -> ([(u32, u32); 27], usize) {
    let c = grid.coords(p);
    let mut out = [(0u32, 0u32); 27];
    let mut k = 0;
    for d in AROUND {
        let q = [0, 1, 2].map(|i| c[i] as i32 + d[i]);
        if (0..3).any(|i| q[i] < 0 || q[i] >= grid.dims[i] as i32) {
            continue;
        }
        let key = morton3(q[0] as u32, q[1] as u32, q[2] as u32);
        if let Ok(i) = keys.binary_search(&key) {
            out[k] = (start[i], start[i + 1]);
            k += 1;
        }
    }
    (out, k)
}

/// The 3×3×3 cells around a cell, nearest first: the vertex's own cell most often holds a
/// vertex that outranks it, and the search stops at the first.
const AROUND: [[i32; 3]; 27] = {
    let mut out = [[0i32; 3]; 27];
    let mut k = 0;
    let mut ring = 0;
    while ring <= 3 {
        let mut i: i32 = 0;
        while i < 27 {
            let d = [i % 3 - 1, (i / 3) % 3 - 1, i / 9 - 1];
            if d[0].abs() + d[1].abs() + d[2].abs() == ring {
                out[k] = d;
                k += 1;
            }
            i += 1;
        }
        ring += 1;
    }
    out
};

/// Every vertex's centre (a centre is its own) after the rounds, and the rounds taken.
/// Locked vertices are centres of themselves alone.
pub fn claim(
    positions: &[[f32; 4]],
    ranks: &[u64],
    locked: &[bool],
    lo: V3,
    hi: V3,
    r: f32,
) -> (Vec<u32>, usize) {
    let n = positions.len();
    // Two centres are independent beyond the sum of their radii, at most twice the largest.
    let grid = hash_grid(lo, hi, r);
    let keys = stages::cell_keys(&grid, positions, &vec![false; n]);
    let (sorted, members) = stages::radix_sort(keys);
    let mut cells = stages::cell_ranges(&sorted, members);
    // Each cell's members by rank, highest first: a vertex looking for one that outranks it
    // stops at the first that does not.
    let vertex_cell = &cells.vertex_cell;
    cells
        .members
        .par_sort_unstable_by_key(|&v| (vertex_cell[v as usize], u64::MAX - ranks[v as usize]));
    let mut centre: Vec<u32> = (0..n as u32)
        .map(|v| if locked[v as usize] { v } else { UNCLAIMED })
        .collect();
    let mut live: Vec<u32> = (0..n as u32).filter(|&v| !locked[v as usize]).collect();
    // The cells around `p` (3×3×3), as ranges of `cells.members`.
    let around = |start: &[u32], p: V3| cells_around(&grid, &cells.key, start, p);
    let mut rounds = 0;
    while !live.is_empty() {
        rounds += 1;
        // `fc_decide`: a live vertex outranked by no live vertex within 2r becomes a centre.
        let new: Vec<u32> = live
            .par_iter()
            .with_min_len(256)
            .copied()
            .filter(|&v| {
                let p = xyz(positions[v as usize]);
                let (ranges, k) = around(&cells.start, p);
                let rank = ranks[v as usize];
                let rv = radius(r, v);
                !ranges[..k].iter().any(|&(a, b)| {
                    cells.members[a as usize..b as usize]
                        .iter()
                        .take_while(|&&u| ranks[u as usize] > rank)
                        .any(|&u| {
                            centre[u as usize] == UNCLAIMED && {
                                let d = sub(xyz(positions[u as usize]), p);
                                let reach = rv + radius(r, u);
                                dot(d, d) <= reach * reach
                            }
                        })
                })
            })
            .collect();
        // `fc_claim`: each new centre claims the live vertices within r; the balls of one
        // round's centres are disjoint (checked), so the claims are the same in any order.
        let claims: Vec<(u32, u32)> = new
            .par_iter()
            .flat_map_iter(|&c| {
                let p = xyz(positions[c as usize]);
                let (ranges, k) = around(&cells.start, p);
                let rc = radius(r, c);
                let mut out = vec![(c, c)];
                for &(a, b) in &ranges[..k] {
                    for &u in &cells.members[a as usize..b as usize] {
                        if u != c && centre[u as usize] == UNCLAIMED {
                            let d = sub(xyz(positions[u as usize]), p);
                            if dot(d, d) <= rc * rc {
                                out.push((u, c));
                            }
                        }
                    }
                }
                out
            })
            .collect();
        for (u, c) in claims {
            assert_eq!(
                centre[u as usize], UNCLAIMED,
                "floating cells: vertex {u} claimed twice in one round"
            );
            centre[u as usize] = c;
        }
        live.retain(|&v| centre[v as usize] == UNCLAIMED);
        // Keep only unclaimed vertices in the cells' lists (in rank order): later rounds scan
        // nothing else, and claimed high-ranked vertices would be scanned again every round.
        let mut at = 0usize;
        let mut begin = 0u32;
        for c in 0..cells.key.len() {
            let end = cells.start[c + 1];
            for i in begin as usize..end as usize {
                let u = cells.members[i];
                if centre[u as usize] == UNCLAIMED {
                    cells.members[at] = u;
                    at += 1;
                }
            }
            begin = end;
            cells.start[c + 1] = at as u32;
        }
        cells.members.truncate(at);
    }
    (centre, rounds)
}

/// Per vertex its cluster (centres numbered in vertex order), and the cluster count.
pub fn clusters_of(centre: &[u32]) -> (Vec<u32>, usize) {
    let mut id = vec![u32::MAX; centre.len()];
    let mut n = 0u32;
    for (v, &c) in centre.iter().enumerate() {
        if c == v as u32 {
            id[v] = n;
            n += 1;
        }
    }
    (centre.iter().map(|&c| id[c as usize]).collect(), n as usize)
}

/// One floating-cell clustering at radius `r`, and the rounds its centres took: on the device
/// when the work has one (the same stages, `floating_gpu.rs`), else here.
fn build_floating(work: &Work, ranks: &[u64], r: f32) -> Result<(Built, usize)> {
    let pts = work.pts;
    if let Some(g) = &work.gpu {
        let (b, rounds) = g
            .lock()
            .map_err(|_| Error::Internal("the GPU clustering lock is poisoned".into()))?
            .build_floating(pts.lo, pts.hi, r)?;
        let built = Built {
            placed: b.placed,
            faces: b.faces,
            vertex_cluster: b.vertex_cluster,
            clusters: b.clusters,
            cells: b.cells,
        };
        return Ok((built, rounds));
    }
    let (centre, rounds) = claim(&pts.positions, ranks, &work.locked, pts.lo, pts.hi, r);
    let (vertex_cluster, n) = clusters_of(&centre);
    let centres: Vec<u32> = (0..centre.len() as u32)
        .filter(|&v| centre[v as usize] == v)
        .collect();
    let origins: Vec<V3> = centres
        .iter()
        .map(|&c| xyz(pts.positions[c as usize]))
        .collect();
    let (quadrics, marked) =
        stages::scatter_quadrics(&pts.positions, &pts.faces, &vertex_cluster, &origins);
    let (order, start) =
        crate::mesh::prepare::counting_sort(n, centre.len(), |v| vertex_cluster[v]);
    let placed: Vec<Placed> = (0..n)
        .into_par_iter()
        .with_min_len(256)
        .map(|k| {
            let members = &order[start[k] as usize..start[k + 1] as usize];
            let o = origins[k];
            // The vertex stays in the centre's box of half-side r (a locked centre: itself).
            let half = if work.locked[centres[k] as usize] {
                0.0
            } else {
                r
            };
            let lo = o.map(|x| x - half);
            let hi = o.map(|x| x + half);
            stages::place(&pts.positions, quadrics[k], members, o, lo, hi)
        })
        .collect();
    let faces = stages::dedupe_faces(marked, n, false);
    let built = Built {
        placed,
        faces,
        vertex_cluster,
        clusters: n,
        cells: n,
    };
    Ok((built, rounds))
}

/// `--method floating-cell`.
pub fn simplify_floating(
    mesh: &Mesh,
    opts: &SimplifyOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<(Mesh, SimplifyReport)> {
    let (out, report, _) = floating_on(device_for(opts)?, mesh, opts, progress)?;
    Ok((out, report))
}

/// `--method floating-cell`, on `on`'s device when given (its result then also left there,
/// [`super::Drawn`]), else on the CPU's cores.
pub(super) fn floating_on(
    on: Option<&super::gpu::GpuClusterer>,
    mesh: &Mesh,
    opts: &SimplifyOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<(Mesh, SimplifyReport, Option<super::Drawn>)> {
    let backend = check_backend(opts)?;
    let t = Instant::now();
    let mut pts = Points::new(mesh);
    let mut work = prepare(&mut pts, opts, false, None)?;
    // On the GPU the mesh and its buffers stay on the device between the search's builds, and
    // the ranks are made there on the first.
    let ranks = if let Some(sim) = on {
        let g = super::gpu::GpuClusterMesh::new(
            sim,
            &work.pts.positions,
            &work.pts.faces,
            &work.locked,
        )?;
        work.gpu = Some(std::sync::Mutex::new(g));
        Vec::new()
    } else {
        let csr = Csr::new(work.pts.positions.len(), &work.pts.faces);
        ranks(&grades(&work.pts.positions, &work.pts.faces, &csr))
    };
    progress(0.2);
    let mut report = ClusterReport {
        method: Method::FloatingCell,
        ..Default::default()
    };
    // Centres are at least r apart, about one per 1.5 r² of surface, two faces each.
    let target = opts.target_faces;
    let first = (4.0 / 3.0 * work.pts.area / target.max(1) as f64).sqrt();
    // A member is within its centre's radius (at most 1.1 r) of the centre, the vertex within
    // the box of that half-side about it.
    let cap = opts
        .max_error
        .map(|e| e / ((1.0 + 3f64.sqrt()) * (1.0 + 0.5 * JITTER as f64)));
    let mut rounds = 0;
    let mut last = None;
    let (r, built, stop) = land(target, None, first, None, cap, &mut report, &mut |r| {
        let (b, n) = build_floating(&work, &ranks, r as f32)?;
        rounds = n;
        last = Some(r as f32);
        Ok((r as f32 as f64, b))
    })?;
    opts.cancel.check()?;
    progress(0.9);
    tally(&mut report, &built);
    report.split_clusters = 0;
    report.cell_size = r;
    report.centre_rounds = Some(rounds);
    // The search may have kept an earlier build than the device's last: build it again
    // before drawing from the device's buffers.
    if work.gpu.is_some() && last != Some(r as f32) {
        build_floating(&work, &ranks, r as f32)?;
    }
    let drawn = match work.gpu.take() {
        Some(g) => {
            let mut g = g.into_inner().map_err(|_| {
                crate::error::Error::Internal("the GPU clustering lock is poisoned".into())
            })?;
            Some(super::Drawn::of(&mut g, &built, work.pts)?)
        }
        None => None,
    };
    let (out, _) = output(mesh, work.pts, &built, opts.attributes.color > 0.0);
    report.seconds = t.elapsed().as_secs_f64();
    let report = clustered_report(mesh, opts, backend, &out, &built, stop, report);
    Ok((out, report, drawn))
}
