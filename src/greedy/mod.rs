//! Backend `cpu`: greedy quadric edge collapse with a priority queue, in f64 — the quality
//! reference every other backend is held against.
//!
//! The queue is lazy: an edge enters keyed by its quadric error alone, which is a lower bound of
//! its full priority (error scaled up for poor triangle quality, MeshLab-style). When it comes out
//! on top, the full priority is computed (flips, needles, quality); if it grew, the edge goes
//! back in, else the link condition and the other topological checks decide. So the expensive
//! checks run once for the edge that really is cheapest, and the many edges a collapse touches
//! are only re-keyed cheaply.
//! Entries are stamped with their endpoints' versions; a collapse bumps the survivor's version,
//! which retires every older entry of its edges.
//!
//! [`simplify_greedy`] here drives the parts: `prepare` (welding, the Morton order, quadrics and
//! vertex mobility, with its per-vertex passes in `vertex_pass`), `state` (the collapse state and the faces around each vertex), `queue` (the
//! bucket queue and its keys), `evaluate` (placement and the checks on one edge), `collapse`
//! (applying collapses, the run to a target), `partition` (the partitioned levels), `epochs`
//! (their rising cost ceilings, run without a barrier after each), `output`
//! (the output mesh) and `vec` (f64 vector helpers).

mod collapse;
mod epochs;
mod evaluate;
pub(crate) mod output;
mod partition;
pub(crate) mod prepare;
pub(crate) mod queue;
pub(crate) mod state;
mod vec;
mod vertex_pass;

use crate::error::Result;
use crate::mesh::Mesh;
use crate::options::{SimplifyOptions, SimplifyReport, StopReason};
pub(crate) use evaluate::triangle_quality;
use output::{OutputNormals, build_output};
use partition::{Cuts, LevelStats, SECOND_LEVEL_REGIONS, partitioned_level, partitioned_stop};
pub(crate) use prepare::Carried;
use prepare::{Mobility, Prepared};
use state::State;

/// Meshes at least this large are simplified in parts at once (see [`simplify_greedy`]);
/// smaller ones in one sequential run.
const PARTITION_MIN_FACES: usize = 100_000;
/// Faces per region of the first level, between 8 and 32 regions: a function of the face
/// count, not of the thread count, so the result is the same on every machine. Smaller regions
/// are faster per collapse (their data stays in cache): measured on the 1M scan at 1%, 32
/// regions then 4 took 1.52 s against 1.76 s for 8 regions then the sequential phase.
const REGION_FACES: usize = 32_768;

/// Greedy simplification; `progress` receives the fraction of the needed collapses done.
///
/// Large meshes are simplified in levels, so that both cores (or more) work. The first level
/// cuts the vertices into runs of the Morton order (compact patches); each region runs its own
/// greedy queue on its faces, with the vertices on faces that cross regions pinned, so regions
/// never touch each other's data. The regions advance together through rising cost ceilings
/// (doubling each epoch): within a ceiling each region takes its cheapest collapses in order,
/// which is what one global queue would take across the mesh, up to the order between
/// independent regions, which does not change the result. A second level does the same with
/// fewer regions cut elsewhere, freeing the vertices the first pinned. The levels stop once
/// the mesh is within 20% of the target; then one sequential queue runs over the whole reduced
/// mesh, region borders included, with the quadrics accumulated so far, down to the exact
/// target.
pub fn simplify_greedy(
    input: &Mesh,
    opts: &SimplifyOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<(Mesh, SimplifyReport)> {
    simplify_prepared(Prepared::new(input, opts), input, opts, progress)
}

/// [`simplify_greedy`] from `input` in `carried`'s frame and with its reference normals (the
/// hybrid's clusters).
pub(crate) fn simplify_carried(
    input: &Mesh,
    opts: &SimplifyOptions,
    carried: &Carried,
    progress: &mut dyn FnMut(f32),
) -> Result<(Mesh, SimplifyReport)> {
    let p = Prepared::build(input, opts, Some(carried));
    simplify_prepared(p, input, opts, progress)
}

fn simplify_prepared(
    p: Prepared,
    input: &Mesh,
    opts: &SimplifyOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<(Mesh, SimplifyReport)> {
    let pinned_vertices = p
        .mobility
        .iter()
        .filter(|&&m| m == Mobility::Pinned)
        .count();
    let nf = p.faces.len();
    let target = opts.target_faces;
    let need = nf.saturating_sub(target).max(1) as f32;
    let mut levels = LevelStats::default();
    let mut s = reduce(p, opts, &mut levels, &mut |faces| {
        progress((nf - faces) as f32 / need)
    })?;
    progress(1.0);
    s.sync_faces();

    let stop_reason = stop_reason(&s, &levels);
    let out = build_output(
        &s.p,
        &s.face_alive,
        &s.alive,
        OutputNormals::recompute_if(input.normals.is_some()),
    );
    let report = SimplifyReport {
        backend: opts.backend,
        auto: None,
        input_faces: input.triangles.len(),
        target_faces: target,
        output_faces: out.triangles.len(),
        input_vertices: input.positions.len(),
        output_vertices: out.positions.len(),
        collapses: s.collapses + levels.collapses,
        max_collapse_error: max_error(&s, &levels),
        stop_reason,
        dropped_degenerate_faces: s.p.dropped_degenerate,
        pinned_vertices,
        rounds: None,
        blocked: None,
        clustering: None,
        decimation: None,
    };
    Ok((out, report))
}

/// The partitioned levels (on meshes large enough) and then the one sequential queue, from `p`
/// down to `opts.target_faces`; `progress` gets the face count now and then.
fn reduce<'a>(
    p: Prepared,
    opts: &'a SimplifyOptions,
    levels: &mut LevelStats,
    progress: &mut dyn FnMut(usize),
) -> Result<State<'a>> {
    let nf = p.faces.len();
    let target = opts.target_faces;
    let regions = opts.partitions.unwrap_or(if nf >= PARTITION_MIN_FACES {
        (nf / REGION_FACES).clamp(8, 32)
    } else {
        1
    });
    let p = if regions > 1 && target < nf {
        let first = Cuts::first(p.pos.len(), regions);
        let p = partitioned_level(p, opts, first, None, levels, progress);
        if p.faces.len() > partitioned_stop(target) && !opts.cancel.is_cancelled() {
            // The second level: fewer, larger regions, each cut half a first-level region
            // along the Morton order from a first-level cut, so the vertices the first level
            // had to pin are interior now and thin out with the rest.
            let second = first.second(SECOND_LEVEL_REGIONS);
            partitioned_level(p, opts, second, None, levels, progress)
        } else {
            p
        }
    } else {
        p
    };
    opts.cancel.check()?;
    let (mut s, mut heap) = State::new(p, opts);
    s.run(&mut heap, target, u32::MAX, progress);
    opts.cancel.check()?;
    Ok(s)
}

fn stop_reason(s: &State, levels: &LevelStats) -> StopReason {
    if s.faces <= s.opts.target_faces {
        StopReason::TargetReached
    } else if s.hit_max_error || levels.hit_max_error {
        StopReason::MaxError
    } else {
        StopReason::NoValidCollapse
    }
}

/// The largest collapse error so far, relative to the bounding-box diagonal.
fn max_error(s: &State, levels: &LevelStats) -> f64 {
    s.max_collapse_err2.max(levels.max_collapse_err2).sqrt()
}

/// Levels of detail by the greedy queue, one per target (falling): each level goes on from the
/// one before, positions and quadrics as they are (cut into regions again while it is large),
/// so the chain costs about what its smallest level alone does. `level` gets each level's
/// mesh, why it stopped and the largest collapse error so far.
/// With `carried`, the set-up takes its frame and reference normals (the hybrid's clusters).
pub(crate) fn chain_greedy(
    input: &Mesh,
    opts: &SimplifyOptions,
    carried: Option<&Carried>,
    targets: &[usize],
    progress: &mut dyn FnMut(f32),
    level: &mut dyn FnMut(Mesh, StopReason, f64) -> Result<()>,
) -> Result<()> {
    let mut p = Prepared::build(input, opts, carried);
    let nf = p.faces.len();
    let need = nf.saturating_sub(*targets.last().unwrap_or(&nf)).max(1) as f32;
    let mut levels = LevelStats::default();
    let mut err2 = 0.0f64;
    for &target in targets {
        let opts = SimplifyOptions {
            target_faces: target,
            ..opts.clone()
        };
        let mut s = reduce(p, &opts, &mut levels, &mut |faces| {
            progress((nf - faces) as f32 / need)
        })?;
        s.sync_faces();
        err2 = err2.max(s.max_collapse_err2);
        let out = build_output(
            &s.p,
            &s.face_alive,
            &s.alive,
            OutputNormals::recompute_if(input.normals.is_some()),
        );
        level(
            out,
            stop_reason(&s, &levels),
            err2.max(levels.max_collapse_err2).sqrt(),
        )?;
        p = s.into_prepared();
    }
    progress(1.0);
    Ok(())
}
