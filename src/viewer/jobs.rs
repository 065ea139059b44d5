//! The window's one worker job at a time: started on a thread, watched (progress, phase),
//! cancelled, and collected when done. What a job does and what its result changes are the
//! app's business (`actions.rs`); this type only runs it, so that the UI keeps drawing frames.

use super::front::Front;
use super::render::SceneMesh;
use super::scene::{Loaded, Simplified};
use crate::error::{Error, Result};
use crate::options::Cancel;
use eframe::egui;
use std::sync::Arc;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::mpsc;
use std::time::Instant;

/// A finished job's result (boxed: the variants differ in size by hundreds of bytes).
pub(super) enum Done {
    Loaded(Result<Box<Loaded>>),
    Simplified(Result<Box<Simplified>>),
    Lod(Result<Vec<SceneMesh>>),
    /// A search's front.
    Front(Result<Box<Front>>),
    /// Member `k` of the front, ready to show.
    Member(Result<Box<(usize, Simplified)>>),
    /// A cluster DAG of the model, on the device and as built (for saving).
    Dag(Result<Box<(super::dag::DagScene, std::sync::Arc<crate::dag::Dag>)>>),
}

/// Work on a worker thread.
pub struct Job {
    pub label: String,
    progress: Arc<AtomicU32>,
    /// What the job is doing now, when it says.
    phase: Arc<std::sync::Mutex<String>>,
    cancel: Cancel,
    rx: mpsc::Receiver<Done>,
    pub started: Instant,
}

impl Job {
    pub fn progress(&self) -> f32 {
        f32::from_bits(self.progress.load(Ordering::Relaxed))
    }

    pub fn phase(&self) -> String {
        self.phase.lock().map(|p| p.clone()).unwrap_or_default()
    }
}

/// How a job ended, as [`Jobs::poll`] collects it.
pub(super) enum Finished {
    /// Its result, and the seconds it took.
    Done(String, f64, Done),
    /// Cancelled after its last check (measuring, uploading): dropped all the same.
    Cancelled(String),
    /// The worker ended without sending a result.
    Lost(String),
}

/// The running job, if any, and the window's context to wake when it ends.
pub struct Jobs {
    job: Option<Job>,
    ctx: egui::Context,
}

impl Jobs {
    pub(super) fn new(ctx: egui::Context) -> Jobs {
        Jobs { job: None, ctx }
    }

    pub fn running(&self) -> Option<&Job> {
        self.job.as_ref()
    }

    pub fn busy(&self) -> bool {
        self.job.is_some()
    }

    /// Runs `work` on a worker thread, its result wrapped by `wrap`; refused, with the running
    /// job's label, while another runs.
    pub(super) fn spawn<T: Send + 'static>(
        &mut self,
        label: String,
        work: impl FnOnce(Cancel, &mut dyn FnMut(f32), &dyn Fn(&str)) -> Result<T> + Send + 'static,
        wrap: fn(Result<T>) -> Done,
    ) -> std::result::Result<(), String> {
        if let Some(j) = &self.job {
            return Err(j.label.clone());
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
        self.job = Some(Job {
            label,
            progress,
            phase,
            cancel,
            rx,
            started: Instant::now(),
        });
        Ok(())
    }

    /// Asks the running job to stop (it ends at its next check: a round, a few thousand
    /// collapses) and gives its label.
    pub(super) fn cancel(&mut self) -> Option<&str> {
        let j = self.job.as_ref()?;
        j.cancel.cancel();
        Some(&j.label)
    }

    /// Takes the finished job, if one has finished.
    pub(super) fn poll(&mut self) -> Option<Finished> {
        let job = self.job.as_ref()?;
        let done = match job.rx.try_recv() {
            Ok(d) => d,
            Err(mpsc::TryRecvError::Empty) => return None,
            Err(mpsc::TryRecvError::Disconnected) => {
                let label = self.job.take()?.label;
                return Some(Finished::Lost(label));
            }
        };
        let job = self.job.take()?;
        Some(if job.cancel.is_cancelled() {
            Finished::Cancelled(job.label)
        } else {
            Finished::Done(job.label, job.started.elapsed().as_secs_f64(), done)
        })
    }
}
