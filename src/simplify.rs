//! The entry point: check the input, pick the backend (`auto` included), run it, fall back from
//! a failed GPU to `cpu-parallel` under `auto`, and explain a stop above the target.

use crate::cluster::gpu::GpuClusterer;
use crate::error::{Error, Result};
use crate::mesh::Mesh;
pub use crate::options::{
    Backend, Blocked, Cancel, Method, SimplifyOptions, SimplifyReport, StopReason,
};
use crate::rounds::Upload;
use crate::rounds::gpu::{GpuRounds, GpuSimplifier};
use std::borrow::Cow;

/// Pipelines a caller made on a device of its own (a window's), for [`simplify_on`]: the `gpu`
/// backend runs there, and its result stays there to be drawn from the buffers it wrote.
#[derive(Clone, Copy, Default)]
pub struct OnDevice<'a> {
    pub rounds: Option<&'a GpuSimplifier>,
    pub cluster: Option<&'a GpuClusterer>,
    /// The input's upload, made once by the caller: `qem` on this device starts from it (with
    /// the run's appearance weights, when it carries others).
    pub upload: Option<&'a Upload>,
    /// The device also draws a window: see [`GpuRounds::share_queue`].
    pub share_queue: bool,
}

/// A `gpu` result left on the caller's device by [`simplify_on`].
pub enum Kept<'a> {
    /// The rounds after their last, the result in their buffers, and the upload they ran on.
    /// (Boxed: the rounds and an owned upload are large beside a clustering's handles.)
    Rounds(Box<(GpuRounds<'a>, Cow<'a, Upload>)>),
    /// A clustering (`cluster`, `floating-cell`), drawable.
    Cluster(crate::cluster::Drawn),
}

/// Simplifies `mesh` with the backend and targets in `opts`.
pub fn simplify(mesh: &Mesh, opts: &SimplifyOptions) -> Result<(Mesh, SimplifyReport)> {
    simplify_with_progress(mesh, opts, &mut |_| {})
}

/// As [`simplify`], calling `progress` now and then with the fraction of the work done (0..=1).
pub fn simplify_with_progress(
    mesh: &Mesh,
    opts: &SimplifyOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<(Mesh, SimplifyReport)> {
    let (out, report, _) = simplify_on(OnDevice::default(), mesh, opts, progress)?;
    Ok((out, report))
}

/// As [`simplify_with_progress`], the `gpu` backend on `on`'s device when it has the method's
/// pipelines (else on the process's shared device), its result left there: the one method ×
/// backend dispatch, for the command line, the library and the window alike.
pub fn simplify_on<'a>(
    on: OnDevice<'a>,
    mesh: &Mesh,
    opts: &SimplifyOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<(Mesh, SimplifyReport, Option<Kept<'a>>)> {
    opts.check()?;
    mesh.validate()?;
    if mesh.triangles.is_empty() {
        return Err(Error::InvalidMesh(format!(
            "the mesh has no faces ({} vertices: a point cloud?), so there is nothing to simplify",
            mesh.positions.len()
        )));
    }
    if let Some(&v) = opts
        .pin
        .iter()
        .find(|&&v| v as usize >= mesh.positions.len())
    {
        return Err(Error::InvalidOption(format!(
            "pinned vertex {v} is past the mesh's {} vertices",
            mesh.positions.len()
        )));
    }
    if !opts.pin.is_empty() && opts.method != Method::Qem {
        return Err(Error::InvalidOption(format!(
            "--method {} cannot pin vertices (a cell merges whatever falls in it); use qem",
            opts.method.name()
        )));
    }
    if opts.method != Method::Qem {
        return run(on, mesh, opts, opts.backend, progress);
    }
    let (chosen, mut auto) = match opts.backend {
        Backend::Auto => {
            let (b, why) = auto_backend();
            (b, Some(why))
        }
        b => (b, None),
    };
    let mut result = run(on, mesh, opts, chosen, progress);
    if opts.backend == Backend::Auto
        && chosen == Backend::Gpu
        && let Err(e @ (Error::Gpu(_) | Error::BufferTooLarge { .. })) = &result
    {
        auto = Some(format!("the GPU failed ({e}); fell back to cpu-parallel"));
        result = run(on, mesh, opts, Backend::CpuParallel, progress);
    }
    let (out, mut report, kept) = result?;
    report.auto = auto;
    if report.output_faces > opts.target_faces && report.stop_reason != StopReason::TargetReached {
        report.blocked = Some(crate::rounds::cpu::blocked_edges(&out, opts)?);
    }
    Ok((out, report, kept))
}

/// One method on one backend (`Auto` left to the clustering methods, which choose their own),
/// with `opts` but for the backend.
fn run<'a>(
    on: OnDevice<'a>,
    mesh: &Mesh,
    opts: &SimplifyOptions,
    backend: Backend,
    progress: &mut dyn FnMut(f32),
) -> Result<(Mesh, SimplifyReport, Option<Kept<'a>>)> {
    let opts = &SimplifyOptions {
        backend,
        ..opts.clone()
    };
    let none = |(m, r)| (m, r, None);
    match (opts.method, backend) {
        (Method::Cluster | Method::FloatingCell, Backend::Gpu) if on.cluster.is_some() => {
            let c = on.cluster.expect("checked by the guard");
            let (m, r, drawn) = crate::cluster::simplify_drawn(c, mesh, opts, progress)?;
            Ok((m, r, Some(Kept::Cluster(drawn))))
        }
        (Method::Cluster, _) => crate::cluster::simplify_cluster(mesh, opts, progress).map(none),
        (Method::Hybrid, _) => crate::cluster::simplify_hybrid(mesh, opts, progress).map(none),
        (Method::FloatingCell, _) => {
            crate::cluster::simplify_floating(mesh, opts, progress).map(none)
        }
        (Method::Decimate, Backend::Cpu | Backend::Auto) => {
            crate::decimate::simplify_decimate(mesh, opts, progress).map(none)
        }
        (Method::Decimate, b) => Err(Error::InvalidOption(format!(
            "--method decimate runs on the CPU only (it removes one vertex at a time); use \
             --backend cpu or auto, not {}",
            b.name()
        ))),
        (Method::Qem, Backend::Cpu) => {
            crate::greedy::simplify_greedy(mesh, opts, progress).map(none)
        }
        (Method::Qem, Backend::CpuParallel) => crate::rounds::cpu::simplify_upload(
            &Upload::pinned(mesh, &opts.pin).attributes(&opts.attributes),
            mesh,
            opts,
            progress,
        )
        .map(none),
        (Method::Qem, Backend::Gpu) => match on.rounds {
            Some(sim) => {
                let up = match on.upload {
                    Some(u) if opts.pin.is_empty() && u.carries(&opts.attributes) => {
                        Cow::Borrowed(u)
                    }
                    Some(u) if opts.pin.is_empty() => {
                        Cow::Owned(u.clone().attributes(&opts.attributes))
                    }
                    _ => Cow::Owned(Upload::pinned(mesh, &opts.pin).attributes(&opts.attributes)),
                };
                let (m, r, rounds) = crate::rounds::gpu::run_rounds(
                    sim,
                    None,
                    &up,
                    mesh,
                    opts,
                    on.share_queue,
                    progress,
                )?;
                Ok((m, r, Some(Kept::Rounds(Box::new((rounds, up))))))
            }
            None => crate::rounds::gpu::simplify_gpu(mesh, opts, progress).map(none),
        },
        (Method::Qem, Backend::Auto) => Err(Error::Internal(
            "Backend::Auto reached a backend unresolved".into(),
        )),
    }
}

/// What [`Backend::Auto`] picks on this machine, and why, in one line: the process's shared GPU
/// device when its adapter is hardware, else `cpu-parallel`.
pub fn auto_backend() -> (Backend, String) {
    match crate::rounds::gpu::shared_context() {
        Ok(ctx) if ctx.software => auto_on(&ctx.adapter_name, true),
        // The shared device: the adapter found here is the one that simplifies.
        Ok(_) => match crate::rounds::gpu::shared() {
            Ok((ctx, _)) => (Backend::Gpu, format!("gpu on {}", ctx.adapter_name)),
            Err(e) => (Backend::CpuParallel, format!("cpu-parallel ({e})")),
        },
        Err(e) => (Backend::CpuParallel, format!("cpu-parallel ({e})")),
    }
}

/// What [`Backend::Auto`] picks on an adapter named `adapter`, and why: `gpu` on hardware,
/// `cpu-parallel` on a software rasterizer (lavapipe, llvmpipe), which runs the rounds slower
/// than the CPU's cores (the 1M scan to 1%: 33 s on gpu against 4.4 s on cpu). The window asks
/// this of its own adapter.
pub fn auto_on(adapter: &str, software: bool) -> (Backend, String) {
    if software {
        (
            Backend::CpuParallel,
            format!(
                "cpu-parallel (the only GPU adapter, {adapter}, is a software rasterizer, slower \
                 than the CPU's cores; the gpu backend runs on it when asked)"
            ),
        )
    } else {
        (Backend::Gpu, format!("gpu on {adapter}"))
    }
}

/// Whether simplifying the file at `path` should stream it (read its faces in blocks, pass by
/// pass) instead of reading it whole, and why: for `cluster` and `hybrid` (the methods that
/// stream; not with `lock_border`, and `cluster` not on the `gpu` backend, which holds the mesh
/// on the device) when reading it whole would take more than `memory` bytes (default
/// [`crate::memory::default_budget`], half the machine's memory). The estimate is the PLY
/// header's face count or the OBJ's size times the method's bytes per face. Then
/// [`crate::cluster::stream::simplify_file`] simplifies it.
pub fn stream_reason(
    path: &std::path::Path,
    opts: &SimplifyOptions,
    memory: Option<u64>,
) -> Option<String> {
    use crate::memory::{default_budget, mib, whole_mesh_estimate};
    let method = opts.method;
    if !(matches!(method, Method::Cluster | Method::Hybrid)
        && !opts.lock_border
        && (method == Method::Hybrid || opts.backend != Backend::Gpu))
    {
        return None;
    }
    let budget = memory.unwrap_or_else(default_budget);
    whole_mesh_estimate(path, method)
        .filter(|&need| need > budget)
        .map(|need| {
            format!(
                "reading it whole would take about {}, over the {} of --memory",
                mib(need),
                mib(budget)
            )
        })
}
