//! Backend `cpu-parallel`: the GPU's rounds, stage for stage, on the CPU with rayon.
//!
//! Each stage's twin is the file of its name: shaders/rounds/X.wgsl and shaders/core/X.wgsl
//! have theirs in X.rs, the first of a family's files telling the family whole (trim_histogram.rs
//! the trim, compact_mark.rs the compaction); what several twins share is in select.rs,
//! counters.rs and this file, the preparation's driver in prepare.rs. A stage takes the same buffers in the same order as the shader binds them, as
//! slices, and is written as a loop over invocation ids so that it reads like the shader. It
//! validates every GPU pass (tests diff the buffers) and is the fair CPU side of the CPU-vs-GPU
//! comparison.

pub mod adjacency_count;
pub mod adjacency_fill;
pub mod adjacency_sort;
pub mod attributes;
pub mod class_rank;
pub mod collapse;
pub mod compact_faces;
pub mod compact_mark;
pub mod compact_vertices;
pub mod cost_ceiling;
pub mod counters;
pub mod dispatch_args;
pub mod draw_args;
pub mod edge_costs;
pub mod edge_errors;
pub mod edges_count;
pub mod edges_fill;
pub mod face_keys;
pub mod face_planes;
pub mod group_errors;
pub mod group_faces;
pub mod group_flags;
pub mod group_open;
pub mod live_list;
pub mod morton_keys;
pub mod plan_round;
pub mod prefix_sum;
pub mod prep_faces;
pub mod prep_vertices;
pub mod prepare;
pub mod select;
pub mod select_cost;
pub mod select_id;
pub mod select_win;
pub mod trim_apply;
pub mod trim_ceiling;
pub mod trim_histogram;
pub mod trim_mark;
mod twins;
pub mod validate;
pub mod vertex_attributes;
pub mod vertex_flags;
pub mod vertex_quadrics;
pub mod weld_insert;
pub mod weld_resolve;

use crate::compute::schedule::Step as S;
use crate::compute::types::*;
use crate::error::{Error, Result};
use crate::options::{Blocked, SimplifyOptions};
use crate::rounds::schedule::{self, Buf, RoundStep, Stage, Step, When};
use crate::rounds::{Download, RoundRunner, Selection, StageTimes, Upload};
use counters::CounterField;
use rayon::prelude::*;
use std::marker::PhantomData;
use std::sync::atomic::AtomicU32;
use std::time::Instant;

/// Backend `cpu-parallel` on a prepared upload: the rounds on [`CpuRounds`] to the options'
/// target, the result and its report.
pub fn simplify_upload(
    up: &Upload,
    mesh: &crate::mesh::Mesh,
    opts: &SimplifyOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<(crate::mesh::Mesh, crate::options::SimplifyReport)> {
    let mut runner = CpuRounds::new(up, crate::rounds::SELECTION_PASSES);
    crate::rounds::simplify_rounds(&mut runner, up, mesh, opts, progress, Default::default())
}

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

/// Which corner of face `f` is on vertex `v` (the last when none), as
/// shaders/rounds/seams.inc.wgsl's `corner_attr` picks it.
#[inline]
pub fn corner_on(indices: &[u32], f: u32, v: u32) -> usize {
    face_of(indices, f)
        .iter()
        .position(|&u| u == v)
        .unwrap_or(2)
}

/// Twin of shaders/rounds/seams.inc.wgsl's `corner_attr`: the attribute vertex face `f` uses at its
/// corner on vertex `v`.
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
pub(crate) struct Scatter<'a, T> {
    ptr: *mut T,
    len: usize,
    _borrow: PhantomData<&'a mut [T]>,
}

// SAFETY: a Scatter is a `&mut [T]` split among threads; `T: Send` lets values cross threads,
// and the unsafe accessors make each caller promise its indices are not touched concurrently.
unsafe impl<T: Send> Send for Scatter<'_, T> {}
unsafe impl<T: Send> Sync for Scatter<'_, T> {}

impl<'a, T: Copy> Scatter<'a, T> {
    pub(crate) fn new(s: &'a mut [T]) -> Self {
        Scatter {
            ptr: s.as_mut_ptr(),
            len: s.len(),
            _borrow: PhantomData,
        }
    }

    /// # Safety
    /// No other invocation reads or writes index `i` during the stage.
    #[inline]
    pub(crate) unsafe fn write(&self, i: usize, v: T) {
        assert!(i < self.len, "scatter index {i} out of {}", self.len);
        // SAFETY: in bounds (asserted), exclusive per the caller's promise.
        unsafe { self.ptr.add(i).write(v) }
    }

    /// # Safety
    /// No other invocation writes index `i` during the stage.
    #[inline]
    pub(crate) unsafe fn read(&self, i: usize) -> T {
        assert!(i < self.len, "scatter index {i} out of {}", self.len);
        // SAFETY: in bounds (asserted), not written concurrently per the caller's promise.
        unsafe { self.ptr.add(i).read() }
    }

    /// # Safety
    /// No other invocation touches `lo..hi` during the stage.
    #[inline]
    #[allow(clippy::mut_from_ref)] // the point of a scatter: disjoint writes through a shared view
    pub(crate) unsafe fn range_mut(&self, lo: usize, hi: usize) -> &mut [T] {
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
    /// Per attribute vertex: weighted appearance values and attribute sums (empty without).
    pub attr_values: Vec<f32>,
    pub attr_sums: Vec<f32>,
    /// The indirect grids `dispatch_args` computes (four `(x, y, z, _)`), as the GPU's.
    pub dispatch: [u32; 16],
    /// The planner's state and its next round, between the rounds of a batch.
    pub plan: PlanState,
    pub planned: Planned,
    /// Grouped rounds ([`crate::rounds::UploadGroups`]; empty without): per input face its
    /// group, per group its target, faces (zero between rounds), closed flag and largest
    /// squared error's bits.
    pub face_group: Vec<u32>,
    pub group_target: Vec<u32>,
    pub group_count: Vec<u32>,
    pub group_closed: Vec<u32>,
    pub group_err: Vec<u32>,
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
    /// The quadrics came with the upload: the first round does not compute them.
    carried_quadrics: bool,
}

fn reset(v: &mut Vec<u32>, n: usize) {
    v.clear();
    v.resize(n, 0);
}

impl CpuRounds {
    pub fn new(up: &Upload, selection_passes: u32) -> CpuRounds {
        CpuRounds {
            positions: up.positions.clone(),
            quadrics: up
                .quadrics
                .clone()
                .unwrap_or_else(|| vec![Quadric::default(); up.positions.len()]),
            carried_quadrics: up.quadrics.is_some(),
            flags: up.flags.clone(),
            vertex_attr: up.vertex_attr.clone(),
            indices: up.indices.clone(),
            face_normals: up
                .face_planes
                .clone()
                .unwrap_or_else(|| vec![[0.0; 4]; up.face_extra.len()]),
            face_extra: up.face_extra.clone(),
            attr_values: up.attr_values(),
            attr_sums: vec![0.0; up.attr_sums_len()],
            selection_passes,
            face_group: up
                .groups
                .as_ref()
                .map_or(Vec::new(), |g| g.face_group.clone()),
            group_target: up.groups.as_ref().map_or(Vec::new(), |g| g.targets.clone()),
            group_count: up
                .groups
                .as_ref()
                .map_or(Vec::new(), |g| vec![0; g.targets.len()]),
            group_closed: up.groups.as_ref().map_or(Vec::new(), |g| g.closed.clone()),
            group_err: up
                .groups
                .as_ref()
                .map_or(Vec::new(), |g| vec![0; g.targets.len()]),
            ..Default::default()
        }
    }

    fn time<R>(&mut self, stage: &'static str, f: impl FnOnce(&mut Self) -> R) -> R {
        let t = Instant::now();
        let r = f(self);
        self.times.add(stage, t.elapsed().as_secs_f64());
        r
    }

    /// Runs `steps` of the schedule, each stage through its twin.
    pub fn run_steps(&mut self, p: &Params, steps: &[Step]) -> Result<()> {
        for step in steps {
            match *step {
                S::Clear(buf) => self.clear(p, buf)?,
                S::Own(RoundStep::ClearTentative) => {
                    self.counters[CounterField::Tentative as usize] = 0
                }
                S::Run(stage) => self.time(stage.entry, |s| s.run_stage(p, stage))?,
                S::PrefixSum { count, data } => {
                    let n = count.of(p);
                    let data = match data {
                        Buf::Offsets => &mut self.offsets,
                        Buf::EdgeOffsets => &mut self.edge_offsets,
                        Buf::Marks => &mut self.marks,
                        Buf::VertexKeep => &mut self.vertex_keep,
                        Buf::FaceKeep => &mut self.face_keep,
                        other => return Err(no_twin("a prefix sum over", other)),
                    };
                    let t = Instant::now();
                    prefix_sum::prefix_sum(n, data, &mut self.block_sums);
                    self.times.add("prefix_sum", t.elapsed().as_secs_f64());
                }
                S::Own(RoundStep::CheckWinners) => self.check_winners(p)?,
                // The next round's parameters go by value (`rounds` takes them from
                // `planned`); there are no uniforms to copy into.
                S::Own(RoundStep::ApplyPlan) => {}
                S::CopyBuffer(from, _) => return Err(no_twin("copying", from)),
            }
        }
        Ok(())
    }

    /// Zeroes `buf`, sized for the round as the GPU's is.
    fn clear(&mut self, p: &Params, buf: Buf) -> Result<()> {
        let (nv, nf) = (p.vertex_count as usize, p.face_count as usize);
        match buf {
            Buf::Offsets => reset(&mut self.offsets, nv + 1),
            Buf::Cursor => reset(&mut self.cursor, nv),
            Buf::Histogram => reset(&mut self.histogram, HIST_BINS as usize),
            Buf::TrimHistogram => reset(&mut self.trim_histogram, HIST_BINS as usize),
            Buf::VertexLock => reset(&mut self.vertex_lock, nv),
            Buf::FaceBest => reset(&mut self.face_best, nf),
            Buf::FaceId => reset(&mut self.face_id, nf),
            other => return Err(no_twin("clearing", other)),
        }
        Ok(())
    }

    /// One stage's twin ([`twins::TWINS`]), with the buffers the stage binds, in its binding order.
    fn run_stage(&mut self, p: &Params, stage: &'static Stage) -> Result<()> {
        let (_, twin) = twins::TWINS
            .iter()
            .find(|t| std::ptr::eq(t.0, stage))
            .ok_or_else(|| {
                Error::Internal(format!(
                    "the schedule runs stage {}, which has no CPU twin",
                    stage.entry
                ))
            })?;
        twin(self, p);
        Ok(())
    }

    /// `collapse` writes every winner's vertices and faces through Scatters on the promise that
    /// no two winners reach one face; checked every round, release builds included, so that a
    /// selection bug is an error, not a data race.
    fn check_winners(&mut self, p: &Params) -> Result<()> {
        let ne = self.edge_offsets[p.vertex_count as usize] as usize;
        let nf = p.face_count as usize;
        let shared = self.time("check_winners", |s| {
            select::shared_face(
                &s.offsets,
                &s.vertex_faces,
                &s.edges[..ne],
                &s.edge_state,
                &mut s.face_owner,
                nf,
            )
        });
        match shared {
            None => Ok(()),
            Some(shared) => Err(Error::Internal(format!(
                "round {}: winners {} and {} both reach face {}; the independent set is broken",
                self.rounds_run, shared.winners[0], shared.winners[1], shared.face
            ))),
        }
    }

    /// Vertex→face lists of the current faces ([`schedule::ADJACENCY`]).
    pub fn build_adjacency(&mut self, p: &Params) -> Result<()> {
        self.run_steps(p, schedule::ADJACENCY)
    }

    /// The first round's set-up: vertex flags ([`schedule::SETUP`]), the face planes and
    /// quadrics unless they were carried in ([`schedule::SETUP_QUADRICS`]), and the attribute
    /// quadrics when the round carries appearance channels ([`schedule::SETUP_ATTRIBUTES`]).
    pub fn setup(&mut self, p: &Params) -> Result<()> {
        for (when, steps) in [
            (When::FirstRound, schedule::SETUP),
            (When::FirstRoundQuadrics, schedule::SETUP_QUADRICS),
            (When::FirstRoundAttributes, schedule::SETUP_ATTRIBUTES),
        ] {
            if when.runs_once(true, self.carried_quadrics, p) {
                self.run_steps(p, steps)?;
            }
        }
        Ok(())
    }

    /// Unique edges ([`schedule::EDGES`]); returns their count.
    pub fn build_edges(&mut self, p: &Params) -> Result<u32> {
        self.run_steps(p, schedule::EDGES)?;
        Ok(self.edge_offsets[p.vertex_count as usize])
    }

    /// `edge_errors`: placements, errors and their histogram ([`schedule::ERRORS`]).
    pub fn errors(&mut self, p: &Params) -> Result<()> {
        self.run_steps(p, schedule::ERRORS)
    }

    /// `live_list` then `edge_costs`, with the ceiling in the counters
    /// ([`schedule::LISTED_COSTS`]).
    pub fn costs_under_ceiling(&mut self, p: &Params) -> Result<()> {
        self.run_steps(p, schedule::LISTED_COSTS)
    }

    /// The selection passes as `selection` says, the winners' check, then trimming when the
    /// round would overshoot: the middle of [`schedule::ROUND`], for tests that compare the
    /// GPU's buffers part by part.
    pub fn select(&mut self, p: &Params, selection: Selection) -> Result<()> {
        self.run_steps(p, schedule::UNLOCK)?;
        self.passes(p, schedule::SELECTION_PASS, selection)?;
        self.run_steps(p, schedule::CHECK)?;
        if p.trim != 0 {
            self.run_steps(p, schedule::TRIM)?;
        }
        Ok(())
    }

    /// The collapses and compaction ([`schedule::APPLY`]); the halves swap.
    pub fn apply_and_compact(&mut self, p: &Params) -> Result<()> {
        self.run_steps(p, schedule::APPLY)?;
        self.swap_halves();
        Ok(())
    }

    /// `steps` once per selection pass: a fixed count, or until a pass lists no tentative winner.
    fn passes(&mut self, p: &Params, steps: &[Step], selection: Selection) -> Result<()> {
        let tentative = CounterField::Tentative as usize;
        for pass in 0.. {
            match selection {
                Selection::Ordinary if pass == self.selection_passes => break,
                Selection::Exhaustive if pass > 0 && self.counters[tentative] == 0 => break,
                _ => {}
            }
            self.run_steps(p, steps)?;
        }
        Ok(())
    }

    /// Compaction wrote the other half; it becomes the current one.
    fn swap_halves(&mut self) {
        std::mem::swap(&mut self.positions, &mut self.out_positions);
        std::mem::swap(&mut self.quadrics, &mut self.out_quadrics);
        std::mem::swap(&mut self.flags, &mut self.out_flags);
        std::mem::swap(&mut self.vertex_attr, &mut self.out_vertex_attr);
        std::mem::swap(&mut self.indices, &mut self.out_indices);
        std::mem::swap(&mut self.face_normals, &mut self.out_face_normals);
        std::mem::swap(&mut self.face_extra, &mut self.out_face_extra);
    }
}

/// A step the schedule asks of a buffer the CPU twin does not handle that way.
fn no_twin(what: &str, buf: Buf) -> Error {
    Error::Internal(format!("the CPU twin has no {what} {buf:?}"))
}

impl RoundRunner for CpuRounds {
    fn round(&mut self, p: &Params, first: bool, selection: Selection) -> Result<Counters> {
        reset(&mut self.counters, std::mem::size_of::<Counters>() / 4);
        for &(when, steps) in schedule::ROUND {
            match when {
                When::EachSelectionPass => self.passes(p, steps, selection)?,
                w if w.runs_once(first, self.carried_quadrics, p) => self.run_steps(p, steps)?,
                _ => {}
            }
        }
        self.swap_halves();
        self.rounds_run += 1;
        Ok(*bytemuck::from_bytes::<Counters>(bytemuck::cast_slice(
            &self.counters,
        )))
    }

    /// Up to `most` rounds as the GPU runs a batch: after each, `plan_round` plans the next
    /// from its counters; the rounds the GPU would run past the batch's stop change nothing
    /// there, and are not run here.
    fn rounds(&mut self, p: &Params, first: bool, most: usize) -> Result<Vec<(Params, Counters)>> {
        self.plan = PlanState {
            vertices: p.vertex_count,
            faces: p.face_count,
            target_faces: p.target_faces,
            executed: 1,
            max_groups: u16::MAX as u32,
            ..Default::default()
        };
        let (mut p, mut first, mut out) = (*p, first, Vec::new());
        loop {
            let c = self.round(&p, first, Selection::Ordinary)?;
            first = false;
            out.push((p, c));
            if out.len() >= most {
                return Ok(out);
            }
            self.run_steps(&p, schedule::PLAN)?;
            if self.plan.stopped != 0 {
                return Ok(out);
            }
            p = self.planned.params;
        }
    }

    fn batch(&self) -> usize {
        crate::rounds::BATCH_ROUNDS
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
            attr_values: self.attr_values.clone(),
            group_err: self.group_err.clone(),
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
    let mut runner = CpuRounds::new(&up, crate::rounds::SELECTION_PASSES);
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
