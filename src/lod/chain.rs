//! The LOD chain: one run through falling targets, each level going on from the one before with
//! the simplifier's state (quadrics, positions, the queue's or the rounds' history) kept, never
//! from the original again.

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::options::{Backend, Method, SimplifyOptions, StopReason};
use crate::rounds::{Driver, RoundRunner, SELECTION_PASSES, Upload};
use std::time::Instant;

/// One level of a chain.
#[derive(Debug, Clone)]
pub struct LodLevel {
    /// The ratio asked for and the face target it made.
    pub ratio: f64,
    pub target_faces: usize,
    pub mesh: Mesh,
    pub stop_reason: StopReason,
    /// The largest collapse (or removal) error of the chain so far, relative to the bounding
    /// box diagonal: an upper bound of this level's error as the simplifier measures it.
    pub max_error: f64,
    /// Seconds from the start of the chain until this level was ready.
    pub seconds: f64,
}

/// Checks a chain's ratios: at least one, each in (0, 1], strictly falling.
pub fn check_ratios(ratios: &[f64]) -> Result<()> {
    if ratios.is_empty() {
        return Err(Error::InvalidOption(
            "no ratios: give at least one level".into(),
        ));
    }
    if let Some(r) = ratios.iter().find(|r| !(**r > 0.0 && **r <= 1.0)) {
        return Err(Error::InvalidOption(format!(
            "ratio {r} is outside (0, 1]: each level keeps a fraction of the input's faces"
        )));
    }
    if let Some(w) = ratios.windows(2).find(|w| w[1] >= w[0]) {
        return Err(Error::InvalidOption(format!(
            "the ratios must fall, each level coarser than the one before: {} then {}",
            w[0], w[1]
        )));
    }
    Ok(())
}

/// The levels of detail of `mesh` at `ratios` of its faces (falling), by `opts.method` (`qem`
/// on any backend, `decimate` on the CPU, `hybrid`) in one run: each level continues from the
/// previous one. `opts.target_faces` is ignored; `progress` gets the fraction done. Returns
/// the levels and the backend that ran them.
pub fn lod_chain(
    mesh: &Mesh,
    opts: &SimplifyOptions,
    ratios: &[f64],
    progress: &mut dyn FnMut(f32),
) -> Result<(Vec<LodLevel>, Backend)> {
    check_ratios(ratios)?;
    opts.check()?;
    mesh.validate()?;
    if mesh.triangles.is_empty() {
        return Err(Error::InvalidMesh(
            "the mesh has no faces, so it has no levels of detail".into(),
        ));
    }
    let nf = mesh.triangles.len();
    let targets: Vec<usize> = ratios
        .iter()
        .map(|r| (nf as f64 * r).round() as usize)
        .collect();
    let start = Instant::now();
    let mut levels = Vec::with_capacity(ratios.len());
    let mut level = |m: Mesh, stop: StopReason, err: f64| -> Result<()> {
        let k = levels.len();
        levels.push(LodLevel {
            ratio: ratios[k],
            target_faces: targets[k],
            mesh: m,
            stop_reason: stop,
            max_error: err,
            seconds: start.elapsed().as_secs_f64(),
        });
        Ok(())
    };
    let first = SimplifyOptions {
        target_faces: targets[0],
        ..opts.clone()
    };
    let backend = match opts.method {
        Method::Qem => {
            let backend = match opts.backend {
                Backend::Auto => crate::simplify::auto_backend().0,
                b => b,
            };
            if backend == Backend::Cpu {
                crate::greedy::chain_greedy(mesh, opts, None, &targets, progress, &mut level)?;
            } else {
                let up = Upload::pinned(mesh, &opts.pin).attributes(&opts.attributes);
                let o = SimplifyOptions { backend, ..first };
                chain_rounds(&up, mesh, &o, &targets, 0.0, progress, &mut level)?;
            }
            backend
        }
        Method::Hybrid => {
            let mut report = Default::default();
            match crate::cluster::clustered(mesh, &first, &mut report)? {
                // On `cpu` the greedy queue goes on from the clusters, as `simplify_hybrid`.
                Some(c) if crate::cluster::second_phase(&c, opts) == Backend::Cpu => {
                    crate::greedy::chain_greedy(
                        &c.mesh,
                        opts,
                        Some(&c.carried()),
                        &targets,
                        progress,
                        &mut |m, stop, err| level(m, stop, err.max(c.error)),
                    )?;
                    Backend::Cpu
                }
                phase => {
                    let (up, built, o) =
                        crate::cluster::rounds_upload(phase.as_ref(), mesh, &first)?;
                    chain_rounds(&up, mesh, &o, &targets, built, progress, &mut level)?;
                    o.backend
                }
            }
        }
        Method::Decimate => {
            if !matches!(opts.backend, Backend::Cpu | Backend::Auto) {
                return Err(Error::InvalidOption(format!(
                    "--method decimate runs on the CPU only; use --backend cpu or auto, not {}",
                    opts.backend.name()
                )));
            }
            let mut d = crate::decimate::Decimator::new(mesh, opts);
            let need = nf.saturating_sub(*targets.last().expect("checked")).max(1) as f32;
            let mut err = 0.0f64;
            for &t in &targets {
                let run = d.run(t, &mut |f| progress((nf - f) as f32 / need), &opts.cancel)?;
                err = run.order.iter().map(|o| o.1).fold(err, f64::max);
                level(d.mesh(), run.stop, err)?;
            }
            Backend::Cpu
        }
        m @ (Method::Cluster | Method::FloatingCell) => {
            return Err(Error::InvalidOption(format!(
                "--method {} keeps no state from one level to the next (each level is a new \
                 grid); use qem, decimate or hybrid, or simplify once per level",
                m.name()
            )));
        }
    };
    progress(1.0);
    Ok((levels, backend))
}

/// The rounds (`cpu-parallel` or `gpu`) from `up` through `targets`: the driver runs to each in
/// turn and the mesh is read back after each; `built` is an error already made (the hybrid's
/// clustering).
fn chain_rounds(
    up: &Upload,
    mesh: &Mesh,
    opts: &SimplifyOptions,
    targets: &[usize],
    built: f64,
    progress: &mut dyn FnMut(f32),
    level: &mut dyn FnMut(Mesh, StopReason, f64) -> Result<()>,
) -> Result<()> {
    let mut cpu;
    let mut gpu;
    let runner: &mut dyn RoundRunner = if opts.backend == Backend::Gpu {
        let (_, sim) = crate::rounds::gpu::shared()?;
        gpu = crate::rounds::gpu::GpuRounds::new(sim, up, SELECTION_PASSES)?;
        &mut gpu
    } else {
        cpu = crate::rounds::cpu::CpuRounds::new(up, SELECTION_PASSES);
        &mut cpu
    };
    let mut d = Driver::new(up, opts);
    let n = targets.len() as f32;
    for (i, &t) in targets.iter().enumerate() {
        let stop = d.run_to(runner, t, &mut |f| progress((i as f32 + f) / n))?;
        let out = up.build_output(&runner.download()?, mesh.normals.is_some());
        level(out, stop, d.max_error().max(built))?;
    }
    Ok(())
}
