//! The viewer's work on worker threads: reading a mesh, simplifying it, making the levels of
//! detail; the UI keeps drawing meanwhile, shows their progress, can cancel them, and takes
//! their results when they are done.

use super::app::{Done, Job, ViewerApp};
use super::lod::LOD_RATIOS;
use super::panels::error_text;
use super::scene::{self, Model};
use crate::error::{Error, Result};
use crate::options::{Cancel, SimplifyOptions};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::mpsc;
use std::time::Instant;

impl ViewerApp {
    /// Reads `path` on a worker thread.
    pub fn open(&mut self, path: PathBuf) {
        let device = self.gpu.device.clone();
        let label = format!("reading {}", path.display());
        self.spawn(
            label,
            move |_, _, _| {
                let m = Model::open(&path, None)?;
                let original = m.original(&device)?;
                Ok(Box::new((m, original)))
            },
            Done::Loaded,
        );
    }

    /// Simplifies the model to the current target with the chosen backend on a worker thread.
    pub fn simplify(&mut self) {
        let Some(model) = self.model.clone() else {
            self.status = "nothing to simplify: open a mesh first".into();
            return;
        };
        let target = match self.faces_text.trim().parse::<usize>() {
            Ok(n) if n >= 1 => n,
            _ => {
                self.status = format!(
                    "target faces {:?}: write a whole number of at least 1",
                    self.faces_text
                );
                return;
            }
        };
        let backend = self.backend;
        let method = self.method;
        let device = self.gpu.device.clone();
        let sim = self.gpu.sim.clone();
        let clusterer = self.gpu.clusterer.clone();
        let label = format!(
            "simplifying to {target} faces ({}, {})",
            method.name(),
            backend.name()
        );
        self.spawn(
            label,
            move |cancel, progress, phase| {
                let mut opts = SimplifyOptions::with_faces(target);
                opts.backend = backend;
                opts.method = method;
                opts.cancel = cancel;
                scene::simplify(
                    &device,
                    scene::Pipelines {
                        rounds: sim.as_deref(),
                        cluster: clusterer.as_deref(),
                    },
                    &model,
                    &opts,
                    true,
                    progress,
                    phase,
                )
                .map(Box::new)
            },
            Done::Simplified,
        );
    }

    /// Makes the LOD levels (one GPU run) on a worker thread.
    pub fn make_lod(&mut self) {
        let (Some(model), Some(sim)) = (self.model.clone(), self.gpu.sim.clone()) else {
            self.status = "the LOD scene needs a mesh and the gpu backend".into();
            return;
        };
        let device = self.gpu.device.clone();
        self.spawn(
            "making levels of detail on the GPU".into(),
            move |cancel, progress, _| {
                scene::lod_levels(&device, &sim, &model, &LOD_RATIOS, &cancel, progress)
            },
            Done::Lod,
        );
    }

    fn spawn<T: Send + 'static>(
        &mut self,
        label: String,
        work: impl FnOnce(Cancel, &mut dyn FnMut(f32), &dyn Fn(&str)) -> Result<T> + Send + 'static,
        wrap: fn(Result<T>) -> Done,
    ) {
        if let Some(j) = &self.job {
            self.status = format!("busy: {} (cancel it first)", j.label);
            return;
        }
        let progress = Arc::new(AtomicU32::new(0));
        let phase = Arc::new(std::sync::Mutex::new(String::new()));
        let cancel = Cancel::default();
        let (tx, rx) = mpsc::channel();
        let (p, ph, c, ctx) = (
            progress.clone(),
            phase.clone(),
            cancel.clone(),
            self.ctx.clone(),
        );
        std::thread::spawn(move || {
            let mut report = |f: f32| {
                p.store(f.clamp(0.0, 1.0).to_bits(), Ordering::Relaxed);
            };
            let say = |s: &str| {
                if let Ok(mut g) = ph.lock() {
                    *g = s.to_string();
                }
            };
            // A panic in the worker must not take the window down with it: it becomes an error.
            let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                work(c, &mut report, &say)
            }))
            .unwrap_or_else(|_| Err(Error::Internal("the worker thread panicked".into())));
            let _ = tx.send(wrap(r));
            ctx.request_repaint();
        });
        self.status = format!("{label}...");
        self.job = Some(Job {
            label,
            progress,
            phase,
            cancel,
            rx,
            started: Instant::now(),
        });
    }

    /// Stops the running job; it ends at its next check (a round, a few thousand collapses).
    pub fn cancel(&mut self) {
        if let Some(j) = &self.job {
            j.cancel.cancel();
            self.status = format!("cancelling: {}", j.label);
        }
    }

    /// Takes a finished job's result, if any.
    pub fn poll_job(&mut self) {
        let Some(job) = &self.job else { return };
        let done = match job.rx.try_recv() {
            Ok(d) => d,
            Err(mpsc::TryRecvError::Empty) => return,
            Err(mpsc::TryRecvError::Disconnected) => {
                self.status = format!("{}: the worker stopped without a result", job.label);
                self.job = None;
                return;
            }
        };
        let job = self.job.take().expect("checked above");
        let secs = job.started.elapsed().as_secs_f64();
        if job.cancel.is_cancelled() {
            // Cancelled after its last check (measuring, uploading): dropped all the same.
            self.status = format!("{}: cancelled", job.label);
            return;
        }
        let failed = |e: Error| match e {
            Error::Cancelled => format!("{}: cancelled", job.label),
            e => format!("{} failed: {e}", job.label),
        };
        match done {
            Done::Loaded(Ok(loaded)) => {
                let (m, original) = *loaded;
                self.set_model(m, original)
            }
            Done::Simplified(Ok(s)) => {
                self.status = format!(
                    "{} -> {} faces in {:.2} s ({}), {}",
                    s.report.input_faces,
                    s.report.output_faces,
                    s.seconds,
                    s.report.backend.name(),
                    error_text(s.error)
                );
                self.style.error_scale = s.scene.max_error;
                self.simplified = Some(*s);
                self.generation += 1;
                self.show_original = false;
            }
            Done::Lod(Ok(levels)) => {
                let faces: Vec<String> = levels.iter().map(|l| l.faces.to_string()).collect();
                self.status = format!(
                    "levels of detail in {secs:.2} s: {} faces",
                    faces.join(" / ")
                );
                self.lod = Some(levels);
                self.generation += 1;
                self.lod_scene = true;
                self.camera = self.lod_home();
            }
            Done::Loaded(Err(e)) | Done::Simplified(Err(e)) | Done::Lod(Err(e)) => {
                self.status = failed(e)
            }
        }
    }
}
