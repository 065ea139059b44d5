//! The entry point: check the input, pick the backend (`auto` included), run it, fall back from
//! a failed GPU to `cpu-parallel` under `auto`, and explain a stop above the target.

use crate::error::{Error, Result};
use crate::mesh::Mesh;
pub use crate::options::{
    Backend, Blocked, Cancel, Method, SimplifyOptions, SimplifyReport, StopReason,
};

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
    match opts.method {
        Method::Qem => {}
        Method::Cluster => return crate::cluster::simplify_cluster(mesh, opts, progress),
        Method::Hybrid => return crate::cluster::simplify_hybrid(mesh, opts, progress),
        Method::FloatingCell => return crate::cluster::simplify_floating(mesh, opts, progress),
        Method::Decimate => {
            return match opts.backend {
                Backend::Cpu | Backend::Auto => {
                    crate::decimate::simplify_decimate(mesh, opts, progress)
                }
                b => Err(Error::InvalidOption(format!(
                    "--method decimate runs on the CPU only (it removes one vertex at a time); \
                     use --backend cpu or auto, not {}",
                    b.name()
                ))),
            };
        }
    }
    let (chosen, mut auto) = match opts.backend {
        Backend::Auto => {
            let (b, why) = auto_backend();
            (b, Some(why))
        }
        b => (b, None),
    };
    let mut result = run(mesh, opts, chosen, progress);
    if opts.backend == Backend::Auto
        && chosen == Backend::Gpu
        && let Err(e @ (Error::Gpu(_) | Error::BufferTooLarge { .. })) = &result
    {
        auto = Some(format!("the GPU failed ({e}); fell back to cpu-parallel"));
        result = run(mesh, opts, Backend::CpuParallel, progress);
    }
    let (out, mut report) = result?;
    report.auto = auto;
    if report.output_faces > opts.target_faces && report.stop_reason != StopReason::TargetReached {
        report.blocked = Some(crate::cpu::blocked_edges(&out, opts)?);
    }
    Ok((out, report))
}

/// One backend on `mesh`, with `opts` but for the backend.
fn run(
    mesh: &Mesh,
    opts: &SimplifyOptions,
    backend: Backend,
    progress: &mut dyn FnMut(f32),
) -> Result<(Mesh, SimplifyReport)> {
    let opts = &SimplifyOptions {
        backend,
        ..opts.clone()
    };
    match backend {
        Backend::Cpu => crate::greedy::simplify_greedy(mesh, opts, progress),
        Backend::CpuParallel => crate::cpu::simplify_upload(
            &crate::parallel::Upload::pinned(mesh, &opts.pin).attributes(&opts.attributes),
            mesh,
            opts,
            progress,
        ),
        Backend::Gpu => crate::gpu::simplify_gpu(mesh, opts, progress),
        Backend::Auto => Err(Error::Internal(
            "Backend::Auto reached a backend unresolved".into(),
        )),
    }
}

/// What [`Backend::Auto`] picks on this machine, and why, in one line: the process's shared GPU
/// device when its adapter is hardware, else `cpu-parallel`.
pub fn auto_backend() -> (Backend, String) {
    match crate::gpu::shared_context() {
        Ok(ctx) if ctx.software => (
            Backend::CpuParallel,
            format!(
                "cpu-parallel (the only GPU adapter, {}, is a software rasterizer, slower than \
                 the CPU's cores; the gpu backend runs on it when asked)",
                ctx.adapter_name
            ),
        ),
        // The shared device: the adapter found here is the one that simplifies.
        Ok(_) => match crate::gpu::shared() {
            Ok((ctx, _)) => (Backend::Gpu, format!("gpu on {}", ctx.adapter_name)),
            Err(e) => (Backend::CpuParallel, format!("cpu-parallel ({e})")),
        },
        Err(e) => (Backend::CpuParallel, format!("cpu-parallel ({e})")),
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
