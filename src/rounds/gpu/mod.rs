//! Backend `gpu`: the rounds as WGSL compute passes run by wgpu (shaders/core/ and
//! shaders/rounds/ hold one file per stage; `rounds::cpu` holds their twins), on the process's
//! device ([`shared`]) or a caller's.

pub mod costs;
pub mod prepare;
pub mod simplifier;

pub use crate::compute::context::GpuContext;
pub use simplifier::{GpuMesh, GpuRounds, GpuSimplifier};

/// A bind group's key: the stage and the buffers it binds (wgpu's handles compare by
/// identity), so that a stage whose buffers do not change with the half makes one group, not
/// one a half (the rounds' passes and the preparation's alike).
pub(crate) type BindKey = (&'static str, Vec<wgpu::Buffer>);

use crate::error::Result;
use crate::mesh::Mesh;
use crate::options::{SimplifyOptions, SimplifyReport};
use crate::rounds::{RoundsReport, SELECTION_PASSES, Upload, simplify_rounds};

/// Simplifies on the first GPU adapter found, made ready once per process ([`shared`]).
pub fn simplify_gpu(
    mesh: &Mesh,
    opts: &SimplifyOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<(Mesh, SimplifyReport)> {
    let (ctx, sim) = shared()?;
    simplify_with(ctx, sim, mesh, opts, progress)
}

/// The process's device and compiled pipelines, made on first use: later calls (the benchmark's
/// repeats) do not pay for adapter discovery and shader compilation again.
pub fn shared() -> Result<(&'static GpuContext, &'static GpuSimplifier)> {
    static SIMPLIFIER: std::sync::OnceLock<std::result::Result<GpuSimplifier, String>> =
        std::sync::OnceLock::new();
    let ctx = shared_context()?;
    let sim = SIMPLIFIER
        .get_or_init(|| GpuSimplifier::on(&ctx.pipelines, &ctx.queue).map_err(|e| e.to_string()))
        .as_ref()
        .map_err(|e| crate::Error::Gpu(e.trim_start_matches("GPU: ").to_string()))?;
    Ok((ctx, sim))
}

/// The process's device alone, without compiling the pipelines: enough to see which adapter
/// there is (`auto` looks before it pays for the shaders).
pub fn shared_context() -> Result<&'static GpuContext> {
    static CONTEXT: std::sync::OnceLock<std::result::Result<GpuContext, String>> =
        std::sync::OnceLock::new();
    CONTEXT
        .get_or_init(|| GpuContext::new().map_err(|e| e.to_string()))
        .as_ref()
        .map_err(|e| crate::Error::Gpu(e.trim_start_matches("GPU: ").to_string()))
}

/// Simplifies with pipelines already made on `ctx`'s device.
pub fn simplify_with(
    ctx: &GpuContext,
    sim: &GpuSimplifier,
    mesh: &Mesh,
    opts: &SimplifyOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<(Mesh, SimplifyReport)> {
    let t = std::time::Instant::now();
    // A plain mesh is prepared on the device where it has the preparation's stages; what the
    // host does then is look at the mesh and take its box (a tile's pinned border is the
    // host's to place). MESHSLIM_PREPARE=host keeps it on the host, to compare the two.
    let host_asked = std::env::var_os("MESHSLIM_PREPARE").is_some_and(|v| v == "host");
    let on_device = sim
        .prepare_kernels()
        .filter(|_| opts.pin.is_empty() && !host_asked)
        .and_then(|k| Some((k, crate::rounds::prepare::eligible(mesh)?)));
    if let Some((kernels, p)) = on_device {
        let prepare = t.elapsed().as_secs_f64();
        let adapter = Some(ctx.adapter_name.clone());
        let start = Start::Prepare(kernels, &p);
        let (out, mut rep, rounds) =
            run_rounds_from(sim, adapter, start, mesh, opts, false, progress)?;
        let retire = retire(rounds);
        if let Some(r) = rep.rounds.as_mut() {
            r.prepare_seconds = prepare;
            r.host_seconds += prepare + retire;
            r.prepared_on = Some("device".into());
        }
        return Ok((out, rep));
    }
    let up = Upload::pinned(mesh, &opts.pin).attributes(&opts.attributes);
    let prepare = t.elapsed().as_secs_f64();
    let (out, mut rep) = simplify_upload(ctx, sim, &up, mesh, opts, progress)?;
    if let Some(r) = rep.rounds.as_mut() {
        r.prepare_seconds = prepare;
        // Preparing is the host's own work, before the rounds' call.
        r.host_seconds += prepare;
        r.prepared_on = Some("host".into());
    }
    Ok((out, rep))
}

/// Where the rounds start from: an upload the host prepared, or the mesh itself, prepared on
/// the device with its preparation kernels and uniform.
enum Start<'u> {
    Upload(&'u Upload),
    Prepare(
        &'u crate::compute::gpu::Kernels,
        &'u crate::compute::types::PrepParams,
    ),
}

/// The rounds on a prepared upload (`hybrid` carries its clusters' quadrics in it); `mesh` is
/// the original the report and the output's attributes refer to.
pub fn simplify_upload(
    ctx: &GpuContext,
    sim: &GpuSimplifier,
    up: &Upload,
    mesh: &Mesh,
    opts: &SimplifyOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<(Mesh, SimplifyReport)> {
    let adapter = Some(ctx.adapter_name.clone());
    let (out, mut rep, rounds) = run_rounds(sim, adapter, up, mesh, opts, false, progress)?;
    let retire = retire(rounds);
    if let Some(r) = rep.rounds.as_mut() {
        r.host_seconds += retire;
    }
    Ok((out, rep))
}

/// Hands `rounds` to [`GpuRounds::retire`]; the seconds that took this thread, which are the
/// call's too.
fn retire(rounds: GpuRounds) -> f64 {
    let t = std::time::Instant::now();
    rounds.retire();
    t.elapsed().as_secs_f64()
}

/// The rounds on `up` with `sim`'s pipelines, the rounds given back with the result in their
/// buffers (a window draws from them). `share_queue`: see [`GpuRounds::share_queue`].
pub fn run_rounds<'a>(
    sim: &'a GpuSimplifier,
    adapter: Option<String>,
    up: &Upload,
    mesh: &Mesh,
    opts: &SimplifyOptions,
    share_queue: bool,
    progress: &mut dyn FnMut(f32),
) -> Result<(Mesh, SimplifyReport, GpuRounds<'a>)> {
    run_rounds_from(
        sim,
        adapter,
        Start::Upload(up),
        mesh,
        opts,
        share_queue,
        progress,
    )
}

/// [`run_rounds`] from either start.
fn run_rounds_from<'a>(
    sim: &'a GpuSimplifier,
    adapter: Option<String>,
    start: Start,
    mesh: &Mesh,
    opts: &SimplifyOptions,
    share_queue: bool,
    progress: &mut dyn FnMut(f32),
) -> Result<(Mesh, SimplifyReport, GpuRounds<'a>)> {
    let t = std::time::Instant::now();
    let prepared;
    let (mut rounds, up) = match start {
        Start::Upload(up) => (GpuRounds::new(sim, up, SELECTION_PASSES)?, up),
        Start::Prepare(kernels, p) => {
            let (r, up) = GpuRounds::prepared(sim, kernels, mesh, p, SELECTION_PASSES)?;
            prepared = up;
            (r, &prepared)
        }
    };
    rounds.share_queue = share_queue;
    let report = RoundsReport {
        adapter,
        gpu_timestamps: sim.has_timestamps(),
        pipeline_seconds: sim.pipeline_seconds,
        pipeline_cache: Some(sim.pipeline_cache.to_string()),
        ..Default::default()
    };
    let (out, mut rep) = simplify_rounds(&mut rounds, up, mesh, opts, progress, report)?;
    if let Some(r) = rep.rounds.as_mut() {
        r.transfer_seconds = rounds.transfer_seconds;
        r.wait_seconds = rounds.wait_seconds;
        rounds.costs.report(r, t.elapsed().as_secs_f64());
    }
    Ok((out, rep, rounds))
}
