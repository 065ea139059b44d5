//! The viewer's work on worker threads: reading a mesh, simplifying it, making the levels of
//! detail; the UI keeps drawing meanwhile, shows their progress, can cancel them, and takes
//! their results when they are done.

use super::app::{Done, Job, ViewerApp};
use super::front::Front;
use super::lod::LOD_RATIOS;
use super::panels::error_text;
use super::render::SceneMesh;
use super::scene::{self, Loaded, Model, Simplified};
use crate::error::{Error, Result};
use crate::options::{Cancel, SimplifyOptions};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::mpsc;
use std::time::Instant;

impl ViewerApp {
    /// Reads `path` on a worker thread: a mesh, or a manifest of `meshslim lods` (its levels
    /// go to the LOD scene) or `meshslim pareto` (its front to the panel) with its mesh.
    pub fn open(&mut self, path: PathBuf) {
        self.open_with(path, None);
    }

    /// As [`ViewerApp::open`], with the manifest's mesh already made.
    pub fn open_with(&mut self, path: PathBuf, model: Option<Model>) {
        let device = self.gpu.device.clone();
        let label = format!("reading {}", path.display());
        self.spawn(
            label,
            move |_, progress, _| scene::open(&device, &path, model, progress).map(Box::new),
            Done::Loaded,
        );
    }

    /// Searches the Pareto front of the model (NSGA-II, [`crate::lod::pareto_front`]) with
    /// [`ViewerApp::pareto`]'s settings on a worker thread.
    pub fn search_front(&mut self) {
        let Some(model) = self.model.clone() else {
            self.status = "nothing to search: open a mesh first".into();
            return;
        };
        let mut opts = self.pareto.clone();
        let label = format!(
            "searching the Pareto front (population {}, {} generations)",
            opts.population, opts.generations
        );
        let source = format!(
            "searched here: population {}, {} generations, seed {}",
            opts.population, opts.generations, opts.seed
        );
        self.spawn(
            label,
            move |cancel, progress, _| {
                opts.engine.cancel = cancel;
                let run = crate::lod::pareto_front(&model.mesh, &opts, progress)?;
                Ok(Box::new(Front::from_run(run, source)))
            },
            Done::Front,
        );
    }

    /// Shows member `k` of the front in the view (and the side-by-side) as the simplified mesh.
    pub fn show_member(&mut self, k: usize) {
        let (Some(model), Some(front)) = (self.model.clone(), &self.front) else {
            return;
        };
        let Some(member) = front.members.get(k).cloned() else {
            return;
        };
        let device = self.gpu.device.clone();
        let label = format!("showing the member of {} vertices", member.vertices);
        self.spawn(
            label,
            move |cancel, _, phase| {
                let mesh = member.mesh.load()?;
                let report = crate::SimplifyReport::counts(
                    crate::Backend::Cpu,
                    &model.mesh,
                    &mesh,
                    crate::options::StopReason::TargetReached,
                );
                let mesh = Arc::unwrap_or_clone(mesh);
                let mut s = scene::show(&device, &model, mesh, report, &cancel, phase)?;
                s.made_by = Some(format!(
                    "member {} of the Pareto front: error {:.3e} by its search",
                    k + 1,
                    member.error
                ));
                Ok(Box::new((k, s)))
            },
            Done::Member,
        );
    }

    /// The LOD scene from the chosen members of the front, the original first and then the
    /// members by falling face count.
    pub fn lod_from_front(&mut self) {
        let (Some(model), Some(front)) = (self.model.clone(), &self.front) else {
            return;
        };
        let mut members: Vec<_> = front
            .chosen
            .iter()
            .map(|&k| front.members[k].clone())
            .filter(|m| m.faces < model.faces())
            .collect();
        if members.is_empty() {
            self.status = "choose members of the front first (Ctrl+click)".into();
            return;
        }
        members.sort_by_key(|m| std::cmp::Reverse(m.faces));
        let device = self.gpu.device.clone();
        self.lod_source = format!("{} members of the Pareto front", members.len());
        // The original on the GPU already, shared rather than uploaded again.
        let original = self.original.as_deref().cloned();
        self.spawn(
            "making the LOD scene from the front".into(),
            move |cancel, progress, _| {
                let mut levels = vec![match original {
                    Some(o) => o,
                    None => model.original(&device)?,
                }];
                for (i, m) in members.iter().enumerate() {
                    cancel.check()?;
                    let mesh = m.mesh.load()?;
                    levels.push(model.level(&device, &mesh)?);
                    progress((i + 1) as f32 / members.len() as f32);
                }
                Ok(levels)
            },
            Done::Lod,
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
        self.lod_source = "GPU snapshots of one run".into();
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
                let Loaded {
                    model,
                    original,
                    levels,
                    front,
                } = *loaded;
                self.set_model(model, original);
                if let Some(levels) = levels {
                    self.lod_source =
                        format!("the {} levels of a meshslim lods run", levels.len() - 1);
                    self.show_levels(levels);
                }
                if let Some(f) = front {
                    self.status = format!(
                        "{}; Pareto front of {} members",
                        self.status,
                        f.members.len()
                    );
                    self.front = Some(f);
                }
            }
            Done::Front(Ok(f)) => {
                self.status = format!("Pareto front of {} members in {secs:.1} s", f.members.len());
                self.front = Some(*f);
            }
            Done::Member(Ok(m)) => {
                let (k, s) = *m;
                if let Some(f) = &mut self.front {
                    f.selected = Some(k);
                }
                self.status = format!(
                    "front member: {} faces, {} vertices, {}",
                    s.report.output_faces,
                    s.report.output_vertices,
                    error_text(s.error)
                );
                self.show_simplified(s);
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
                self.show_simplified(*s);
            }
            Done::Lod(Ok(levels)) => {
                let faces: Vec<String> = levels.iter().map(|l| l.faces.to_string()).collect();
                self.status = format!(
                    "levels of detail in {secs:.2} s: {} faces",
                    faces.join(" / ")
                );
                self.show_levels(levels);
            }
            Done::Loaded(Err(e))
            | Done::Simplified(Err(e))
            | Done::Lod(Err(e))
            | Done::Front(Err(e))
            | Done::Member(Err(e)) => self.status = failed(e),
        }
    }
}

impl ViewerApp {
    fn show_simplified(&mut self, s: Simplified) {
        self.style.error_scale = s.scene.max_error;
        self.simplified = Some(s);
        self.generation += 1;
        self.show_original = false;
    }

    fn show_levels(&mut self, levels: Vec<SceneMesh>) {
        self.lod = Some(levels);
        self.lod_frame = [None, None];
        self.generation += 1;
        self.lod_scene = true;
        self.camera = self.lod_home();
    }
}
