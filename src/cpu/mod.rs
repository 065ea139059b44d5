//! Backend `cpu-parallel`: the GPU's rounds, stage for stage, on the CPU with rayon.
//!
//! Each file here is the twin of the WGSL stage of the same name in `shaders/` (a family of
//! stages shares a file: `adjacency_count`, `adjacency_fill` and `adjacency_sort` live in
//! adjacency.rs). A stage takes the same buffers in the same order as the shader binds them, as
//! slices, and is written as a loop over invocation ids so that it reads like the shader. It
//! validates every GPU pass (tests diff the buffers) and is the fair CPU side of the CPU-vs-GPU
//! comparison.

pub mod adjacency;
pub mod collapse;
pub mod common;
pub mod compact;
pub mod cost_ceiling;
pub mod dispatch_args;
pub mod edge_costs;
pub mod edge_errors;
pub mod edges;
pub mod face_planes;
pub mod live_list;
pub mod prefix_sum;
pub mod select;
pub mod trim;
pub mod validate;
pub mod vertex_flags;
pub mod vertex_quadrics;

use crate::error::{Error, Result};
use crate::gpu::types::*;
use crate::parallel::{Download, RoundRunner, Selection, StageTimes, Upload};
use crate::simplify::{Blocked, SimplifyOptions};
use rayon::prelude::*;
use std::marker::PhantomData;
use std::sync::atomic::AtomicU32;
use std::time::Instant;

/// Runs `body(id)` for every invocation id in `0..n`, in parallel.
pub fn par_for(n: u32, body: impl Fn(u32) + Sync + Send) {
    (0..n).into_par_iter().with_min_len(512).for_each(body);
}

/// Runs `body(id, &mut out[id])` for every element, in parallel: the invocation writes its own
/// slot only.
pub fn par_for_mut<T: Send>(out: &mut [T], body: impl Fn(u32, &mut T) + Sync + Send) {
    out.par_iter_mut()
        .with_min_len(512)
        .enumerate()
        .for_each(|(i, x)| body(i as u32, x));
}

/// Faces around vertex `v` in the CSR lists.
#[inline]
pub fn faces_of<'a>(offsets: &[u32], vertex_faces: &'a [u32], v: u32) -> &'a [u32] {
    &vertex_faces[offsets[v as usize] as usize..offsets[v as usize + 1] as usize]
}

#[inline]
pub fn face_of(indices: &[u32], f: u32) -> [u32; 3] {
    let i = 3 * f as usize;
    [indices[i], indices[i + 1], indices[i + 2]]
}

/// Which corner of face `f` is on vertex `v` (the last when none), as shaders/seams.wgsl's
/// `corner_attr` picks it.
#[inline]
pub fn corner_on(indices: &[u32], f: u32, v: u32) -> usize {
    face_of(indices, f)
        .iter()
        .position(|&u| u == v)
        .unwrap_or(2)
}

/// Twin of shaders/seams.wgsl's `corner_attr`: the attribute vertex face `f` uses at its corner
/// on vertex `v`.
#[inline]
pub fn corner_attr(indices: &[u32], face_extra: &[FaceExtra], f: u32, v: u32) -> u32 {
    face_extra[f as usize].attr[corner_on(indices, f, v)]
}

/// A u32 buffer seen as atomics, as the shaders declare it `array<atomic<u32>>`.
pub fn atomics(s: &mut [u32]) -> &[AtomicU32] {
    // SAFETY: AtomicU32 has the same size and bit validity as u32 and an alignment of 4, which
    // u32 has on every target with 32-bit atomics (asserted); the exclusive borrow of `s` for the
    // returned lifetime means all access goes through the atomics.
    assert_eq!(
        std::mem::align_of::<u32>(),
        std::mem::align_of::<AtomicU32>()
    );
    unsafe { std::slice::from_raw_parts(s.as_mut_ptr() as *const AtomicU32, s.len()) }
}

/// A buffer that parallel invocations write at indices the algorithm proves distinct (prefix-sum
/// slots, winners' own vertices): what a shader's plain `buf[i] = x` does.
pub struct Scatter<'a, T> {
    ptr: *mut T,
    len: usize,
    _borrow: PhantomData<&'a mut [T]>,
}

// SAFETY: a Scatter is a `&mut [T]` split among threads; `T: Send` lets values cross threads,
// and the unsafe accessors make each caller promise its indices are not touched concurrently.
unsafe impl<T: Send> Send for Scatter<'_, T> {}
unsafe impl<T: Send> Sync for Scatter<'_, T> {}

impl<'a, T: Copy> Scatter<'a, T> {
    pub fn new(s: &'a mut [T]) -> Self {
        Scatter {
            ptr: s.as_mut_ptr(),
            len: s.len(),
            _borrow: PhantomData,
        }
    }

    /// # Safety
    /// No other invocation reads or writes index `i` during the stage.
    #[inline]
    pub unsafe fn write(&self, i: usize, v: T) {
        assert!(i < self.len, "scatter index {i} out of {}", self.len);
        // SAFETY: in bounds (asserted), exclusive per the caller's promise.
        unsafe { self.ptr.add(i).write(v) }
    }

    /// # Safety
    /// No other invocation writes index `i` during the stage.
    #[inline]
    pub unsafe fn read(&self, i: usize) -> T {
        assert!(i < self.len, "scatter index {i} out of {}", self.len);
        // SAFETY: in bounds (asserted), not written concurrently per the caller's promise.
        unsafe { self.ptr.add(i).read() }
    }

    /// # Safety
    /// No other invocation touches `lo..hi` during the stage.
    #[inline]
    #[allow(clippy::mut_from_ref)] // the point of a scatter: disjoint writes through a shared view
    pub unsafe fn range_mut(&self, lo: usize, hi: usize) -> &mut [T] {
        assert!(
            lo <= hi && hi <= self.len,
            "scatter range {lo}..{hi} out of {}",
            self.len
        );
        // SAFETY: in bounds (asserted), exclusive per the caller's promise.
        unsafe { std::slice::from_raw_parts_mut(self.ptr.add(lo), hi - lo) }
    }
}

/// The buffers of the rounds, as the GPU holds them, plus the ping-pong outputs of compaction.
#[derive(Default)]
pub struct CpuRounds {
    pub positions: Vec<[f32; 4]>,
    pub quadrics: Vec<Quadric>,
    pub flags: Vec<u32>,
    pub vertex_attr: Vec<u32>,
    pub indices: Vec<u32>,
    pub face_normals: Vec<[f32; 4]>,
    pub face_extra: Vec<FaceExtra>,
    pub offsets: Vec<u32>,
    pub cursor: Vec<u32>,
    pub vertex_faces: Vec<u32>,
    pub edge_offsets: Vec<u32>,
    pub edges: Vec<[u32; 2]>,
    pub candidates: Vec<EdgeCandidate>,
    pub edge_state: Vec<u32>,
    /// The edge errors' histogram, kept through the round (tests read it).
    pub histogram: Vec<u32>,
    pub trim_histogram: Vec<u32>,
    pub live: Vec<u32>,
    pub face_best: Vec<u32>,
    pub face_id: Vec<u32>,
    pub vertex_lock: Vec<u32>,
    pub remap: Vec<u32>,
    pub vertex_keep: Vec<u32>,
    pub face_keep: Vec<u32>,
    pub marks: Vec<u32>,
    pub tentative: Vec<u32>,
    pub neighbours: Vec<u32>,
    pub block_sums: Vec<u32>,
    pub counters: Vec<u32>,
    pub draw: DrawArgs,
    out_positions: Vec<[f32; 4]>,
    out_quadrics: Vec<Quadric>,
    out_flags: Vec<u32>,
    out_vertex_attr: Vec<u32>,
    out_indices: Vec<u32>,
    out_face_normals: Vec<[f32; 4]>,
    out_face_extra: Vec<FaceExtra>,
    times: StageTimes,
    selection_passes: u32,
    /// Per face, the winner that reaches it: `select::shared_face`'s scratch, kept between rounds.
    face_owner: Vec<u32>,
    /// Rounds run so far, to name the round in an internal error.
    rounds_run: u32,
}

fn reset(v: &mut Vec<u32>, n: usize) {
    v.clear();
    v.resize(n, 0);
}

impl CpuRounds {
    pub fn new(up: &Upload, selection_passes: u32) -> CpuRounds {
        CpuRounds {
            positions: up.positions.clone(),
            quadrics: vec![Quadric::default(); up.positions.len()],
            flags: up.flags.clone(),
            vertex_attr: up.vertex_attr.clone(),
            indices: up.indices.clone(),
            face_normals: vec![[0.0; 4]; up.face_extra.len()],
            face_extra: up.face_extra.clone(),
            selection_passes,
            ..Default::default()
        }
    }

    fn time<R>(&mut self, stage: &'static str, f: impl FnOnce(&mut Self) -> R) -> R {
        let t = Instant::now();
        let r = f(self);
        self.times.add(stage, t.elapsed().as_secs_f64());
        r
    }

    /// Vertex→face lists of the current faces (three stages and a prefix sum).
    pub fn build_adjacency(&mut self, p: &Params) {
        let (nv, nf) = (p.vertex_count as usize, p.face_count as usize);
        self.time("adjacency_count", |s| {
            reset(&mut s.offsets, nv + 1);
            adjacency::adjacency_count(p, &s.indices, atomics(&mut s.offsets));
        });
        self.time("prefix_sum", |s| {
            prefix_sum::prefix_sum(nv as u32, &mut s.offsets, &mut s.block_sums)
        });
        self.time("adjacency_fill", |s| {
            reset(&mut s.cursor, nv);
            s.vertex_faces.resize(3 * nf, 0);
            adjacency::adjacency_fill(
                p,
                &s.indices,
                &s.offsets,
                atomics(&mut s.cursor),
                Scatter::new(&mut s.vertex_faces),
            );
        });
        self.time("adjacency_sort", |s| {
            adjacency::adjacency_sort(p, &s.offsets, Scatter::new(&mut s.vertex_faces))
        });
    }

    /// The first round's set-up: face normals, vertex flags, quadrics.
    pub fn setup(&mut self, p: &Params) {
        self.time("face_planes", |s| {
            face_planes::face_planes(p, &s.positions, &s.indices, &mut s.face_normals)
        });
        self.time("vertex_flags", |s| {
            vertex_flags::vertex_flags(p, &s.indices, &s.offsets, &s.vertex_faces, &mut s.flags)
        });
        self.time("vertex_quadrics", |s| {
            vertex_quadrics::vertex_quadrics(
                p,
                &s.positions,
                &s.indices,
                &s.offsets,
                &s.vertex_faces,
                &s.face_normals,
                &mut s.quadrics,
                &s.face_extra,
            )
        });
    }

    /// Unique edges and their costs, with the cost histogram.
    pub fn build_edges(&mut self, p: &Params) -> u32 {
        let nv = p.vertex_count as usize;
        self.time("edges_count", |s| {
            reset(&mut s.edge_offsets, nv + 1);
            s.remap.resize(nv, 0);
            s.neighbours.resize(2 * s.vertex_faces.len(), 0);
            edges::edges_count(
                p,
                &s.indices,
                &s.offsets,
                &s.vertex_faces,
                Scatter::new(&mut s.edge_offsets),
                Scatter::new(&mut s.remap),
                Scatter::new(&mut s.neighbours),
            );
        });
        let ne = self.time("prefix_sum", |s| {
            prefix_sum::prefix_sum(nv as u32, &mut s.edge_offsets, &mut s.block_sums)
        });
        self.time("edges_fill", |s| {
            s.edges.resize(ne as usize, [0; 2]);
            edges::edges_fill(
                p,
                &s.offsets,
                &s.neighbours,
                &s.edge_offsets,
                Scatter::new(&mut s.edges),
            );
        });
        ne
    }

    /// Edge errors, the round's cost ceiling from their histogram, and the costs of the edges
    /// under it.
    pub fn costs(&mut self, p: &Params, ne: u32) {
        self.errors(p, ne);
        self.time("cost_ceiling", |s| {
            cost_ceiling::cost_ceiling(p, &s.histogram, atomics(&mut s.counters))
        });
        self.costs_under_ceiling(p);
    }

    /// `live_list` then `edge_costs`, with the ceiling in the counters.
    pub fn costs_under_ceiling(&mut self, p: &Params) {
        self.time("live_list", |s| {
            live_list::live_list(
                p,
                &s.edge_offsets,
                &s.candidates,
                &mut s.edge_state,
                atomics(&mut s.counters),
                &mut s.live,
            )
        });
        self.listed_costs(p);
    }

    /// `edge_errors`: placements, errors and their histogram.
    pub fn errors(&mut self, p: &Params, ne: u32) {
        self.time("edge_errors", |s| {
            s.candidates.resize(ne as usize, EdgeCandidate::default());
            s.edge_state.resize(ne as usize, 0);
            reset(&mut s.histogram, HIST_BINS as usize);
            edge_errors::edge_errors(
                p,
                &s.positions,
                &s.quadrics,
                &s.flags,
                &s.indices,
                &s.offsets,
                &s.vertex_faces,
                &s.edges,
                &s.edge_offsets,
                &mut s.candidates,
                &mut s.edge_state,
                atomics(&mut s.histogram),
                atomics(&mut s.counters),
                &s.face_extra,
            );
        });
    }

    /// `edge_costs` over the live list.
    pub fn listed_costs(&mut self, p: &Params) {
        self.time("edge_costs", |s| {
            edge_costs::edge_costs(
                p,
                &s.positions,
                &s.indices,
                &s.offsets,
                &s.vertex_faces,
                &s.face_normals,
                &s.live,
                Scatter::new(&mut s.candidates),
                Scatter::new(&mut s.edge_state),
                atomics(&mut s.counters),
            );
        });
    }

    /// The selection passes, then trimming when the round would overshoot.
    pub fn select(&mut self, p: &Params, ne: u32, selection: Selection) -> Result<()> {
        let nf = p.face_count as usize;
        reset(&mut self.vertex_lock, p.vertex_count as usize);
        self.tentative.resize(ne as usize, 0);
        let tentative = edge_costs::CounterField::Tentative as usize;
        for pass in 0.. {
            match selection {
                Selection::Ordinary if pass == self.selection_passes => break,
                Selection::Exhaustive if pass > 0 && self.counters[tentative] == 0 => break,
                _ => {}
            }
            reset(&mut self.face_best, nf);
            reset(&mut self.face_id, nf);
            self.counters[edge_costs::CounterField::Tentative as usize] = 0;
            let s = &mut *self;
            let t = Instant::now();
            let (lock, st, counters) = (
                atomics(&mut s.vertex_lock),
                atomics(&mut s.edge_state),
                atomics(&mut s.counters),
            );
            let (best, id) = (atomics(&mut s.face_best), atomics(&mut s.face_id));
            select::select_cost(
                &s.offsets,
                &s.vertex_faces,
                &s.edges,
                &s.live,
                &s.candidates,
                lock,
                counters,
                st,
                best,
            );
            let t1 = Instant::now();
            select::select_id(
                &s.offsets,
                &s.vertex_faces,
                &s.edges,
                &s.live,
                &s.candidates,
                best,
                st,
                id,
                counters,
            );
            let t2 = Instant::now();
            select::select_win(
                &s.offsets,
                &s.vertex_faces,
                &s.edges,
                &s.live,
                id,
                st,
                Scatter::new(&mut s.tentative),
                counters,
            );
            let t3 = Instant::now();
            validate::validate(
                p,
                &s.flags,
                &s.indices,
                &s.offsets,
                &s.vertex_faces,
                &s.edges,
                &s.tentative,
                Scatter::new(&mut s.candidates),
                st,
                lock,
                counters,
            );
            s.times.add("select_cost", (t1 - t).as_secs_f64());
            s.times.add("select_id", (t2 - t1).as_secs_f64());
            s.times.add("select_win", (t3 - t2).as_secs_f64());
            s.times.add("validate", t3.elapsed().as_secs_f64());
        }
        // Always on, release builds included: `collapse` below writes through Scatters on this
        // promise, and a selection bug must be an error, not a data race.
        let shared = self.time("check_winners", |s| {
            select::shared_face(
                &s.offsets,
                &s.vertex_faces,
                &s.edges[..ne as usize],
                &s.edge_state,
                &mut s.face_owner,
                nf,
            )
        });
        if let Some(shared) = shared {
            return Err(Error::Internal(format!(
                "round {}: winners {} and {} both reach face {}; the independent set is broken",
                self.rounds_run, shared.winners[0], shared.winners[1], shared.face
            )));
        }
        if p.trim != 0 {
            self.time("trim_histogram", |s| {
                reset(&mut s.trim_histogram, HIST_BINS as usize);
                trim::trim_histogram(
                    p,
                    &s.candidates,
                    &s.edge_state,
                    &s.edge_offsets,
                    atomics(&mut s.trim_histogram),
                )
            });
            self.time("trim_ceiling", |s| {
                trim::trim_ceiling(p, &s.trim_histogram, atomics(&mut s.counters))
            });
            self.time("trim_mark", |s| {
                reset(&mut s.marks, p.edge_capacity as usize + 1);
                trim::trim_mark(
                    p,
                    &s.candidates,
                    &s.edge_state,
                    &s.edge_offsets,
                    atomics(&mut s.counters),
                    &mut s.marks,
                )
            });
            self.time("prefix_sum", |s| {
                prefix_sum::prefix_sum(p.edge_capacity, &mut s.marks, &mut s.block_sums)
            });
            self.time("trim_apply", |s| {
                trim::trim_apply(
                    p,
                    &s.candidates,
                    &s.marks,
                    atomics(&mut s.counters),
                    &s.edge_offsets,
                    &mut s.edge_state,
                )
            });
        }
        Ok(())
    }

    pub fn apply_and_compact(&mut self, p: &Params) {
        let (nv, nf) = (p.vertex_count as usize, p.face_count as usize);
        self.time("collapse", |s| {
            collapse::collapse(
                p,
                &s.candidates,
                &s.edge_state,
                &s.edge_offsets,
                Scatter::new(&mut s.positions),
                Scatter::new(&mut s.quadrics),
                Scatter::new(&mut s.flags),
                Scatter::new(&mut s.remap),
                &s.indices,
                &s.offsets,
                &s.vertex_faces,
                Scatter::new(&mut s.face_extra),
            )
        });
        self.time("compact_mark", |s| {
            reset(&mut s.vertex_keep, nv + 1);
            reset(&mut s.face_keep, nf + 1);
            compact::compact_mark(
                p,
                &s.indices,
                &s.remap,
                &mut s.vertex_keep,
                &mut s.face_keep,
            )
        });
        let (nv2, nf2) = self.time("prefix_sum", |s| {
            let a = prefix_sum::prefix_sum(nv as u32, &mut s.vertex_keep, &mut s.block_sums);
            let b = prefix_sum::prefix_sum(nf as u32, &mut s.face_keep, &mut s.block_sums);
            (a as usize, b as usize)
        });
        self.time("compact_vertices", |s| {
            s.out_positions.resize(nv2, [0.0; 4]);
            s.out_quadrics.resize(nv2, Quadric::default());
            s.out_flags.resize(nv2, 0);
            s.out_vertex_attr.resize(nv2, 0);
            compact::compact_vertices(
                p,
                &s.vertex_keep,
                &s.positions,
                &s.quadrics,
                &s.flags,
                &s.vertex_attr,
                Scatter::new(&mut s.out_positions),
                Scatter::new(&mut s.out_quadrics),
                Scatter::new(&mut s.out_flags),
                Scatter::new(&mut s.out_vertex_attr),
            );
        });
        self.time("compact_faces", |s| {
            s.out_indices.resize(3 * nf2, 0);
            s.out_face_normals.resize(nf2, [0.0; 4]);
            s.out_face_extra.resize(nf2, FaceExtra::default());
            compact::compact_faces(
                p,
                &s.indices,
                &s.face_normals,
                &s.face_extra,
                &s.remap,
                &s.vertex_keep,
                &s.face_keep,
                Scatter::new(&mut s.out_indices),
                Scatter::new(&mut s.out_face_normals),
                Scatter::new(&mut s.out_face_extra),
            );
        });
        self.time("draw_args", |s| {
            let mut draw = DrawArgs::default();
            compact::draw_args(
                p,
                &s.vertex_keep,
                &s.face_keep,
                atomics(&mut s.counters),
                &mut draw,
            );
            s.draw = draw;
        });
        std::mem::swap(&mut self.positions, &mut self.out_positions);
        std::mem::swap(&mut self.quadrics, &mut self.out_quadrics);
        std::mem::swap(&mut self.flags, &mut self.out_flags);
        std::mem::swap(&mut self.vertex_attr, &mut self.out_vertex_attr);
        std::mem::swap(&mut self.indices, &mut self.out_indices);
        std::mem::swap(&mut self.face_normals, &mut self.out_face_normals);
        std::mem::swap(&mut self.face_extra, &mut self.out_face_extra);
    }
}

impl RoundRunner for CpuRounds {
    fn round(&mut self, p: &Params, first: bool, selection: Selection) -> Result<Counters> {
        reset(&mut self.counters, std::mem::size_of::<Counters>() / 4);
        self.build_adjacency(p);
        if first {
            self.setup(p);
        }
        let ne = self.build_edges(p);
        self.costs(p, ne);
        self.select(p, ne, selection)?;
        self.apply_and_compact(p);
        self.rounds_run += 1;
        Ok(*bytemuck::from_bytes::<Counters>(bytemuck::cast_slice(
            &self.counters,
        )))
    }

    fn download(&mut self) -> Result<Download> {
        // A copy, as the GPU's read-back is: the rounds can go on afterwards (a resumed run
        // reads each level). The mesh is compacted by then, so this is a small part of a run.
        Ok(Download {
            positions: self.positions.clone(),
            flags: self.flags.clone(),
            vertex_attr: self.vertex_attr.clone(),
            indices: self.indices.clone(),
            face_extra: self.face_extra.clone(),
        })
    }

    fn stage_times(&self) -> &StageTimes {
        &self.times
    }
}

/// Why no collapse is left on `mesh` (a backend's result that stopped above its target): one
/// round of the rounds' checks over every edge, every edge competing through exhaustive
/// selection, counted by the first check each edge fails. The same checks judge every backend's
/// result, so a stop is explained in one vocabulary whichever backend stopped.
pub fn blocked_edges(mesh: &crate::mesh::Mesh, opts: &SimplifyOptions) -> Result<Blocked> {
    let up = Upload::new(mesh);
    let nf = up.face_count() as u32;
    let mut runner = CpuRounds::new(&up, crate::parallel::SELECTION_PASSES);
    let needed = nf.saturating_sub(opts.target_faces as u32).max(1);
    let params = Params {
        edge_capacity: 3 * nf,
        needed_faces: needed,
        ceiling_wanted: u32::MAX,
        trim: 0,
        ..up.base_params(opts)
    };
    let c = runner.round(&params, true, Selection::Exhaustive)?;
    let edges = runner
        .edge_offsets
        .get(up.positions.len())
        .copied()
        .unwrap_or(0);
    let geometry = edges.saturating_sub(c.over_max_error + c.candidates);
    Ok(Blocked {
        edges: edges as usize,
        over_max_error: c.over_max_error as usize,
        geometry: geometry as usize,
        topology: c.candidates.saturating_sub(c.winners) as usize,
        allowed: c.winners as usize,
    })
}
