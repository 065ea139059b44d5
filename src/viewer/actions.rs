//! What the window does: the [`Action`]s the panel, the keys and dropped files ask for, the
//! jobs they start on worker threads (reading, simplifying, levels of detail, the Pareto front),
//! and each finished job's result put into the scene. The owners (scene, view, camera, panel,
//! jobs) each keep their own state; this is the one place that changes several at once.

use super::app::ViewerApp;
use super::camera::Up;
use super::front::Front;
use super::jobs::{Done, Finished};
use super::lod::LOD_RATIOS;
use super::panels::{Action, error_text};
use super::render::{Mode, SceneMesh};
use super::scene::{self, Loaded, Model, Simplified};
use crate::error::{Error, Result};
use crate::options::{Backend, Cancel, SimplifyOptions};
use crate::simplify::OnDevice;
use std::path::{Path, PathBuf};
use std::sync::Arc;

impl ViewerApp {
    pub(super) fn apply(&mut self, action: Action) {
        match action {
            Action::Open(p) => self.open(p),
            Action::Simplify => self.simplify(),
            Action::Cancel => self.cancel(),
            Action::Save => self.save(),
            Action::Screenshot => self.screenshot(),
            Action::MakeLod => self.make_lod(),
            Action::SearchFront => self.search_front(),
            Action::ShowMember(k) => self.show_member(k),
            Action::ChooseMember(k) => self.choose_member(k),
            Action::ClearChosen => {
                if let Some(f) = &mut self.scene.front {
                    f.chosen.clear();
                }
            }
            Action::LodFromFront => self.lod_from_front(),
            Action::FrameToFit => self.view.frame_to_fit(&self.scene, &mut self.eye),
            Action::ResetView => self.reset_view(),
            Action::SetUp(up) => self.set_up(up),
            Action::Say(line) => self.status = line,
            Action::MakeDag => self.make_dag(self.panel.backend),
            Action::SaveDag => self.save_dag(None),
        }
    }

    /// Runs `work` as the window's job, or says which job is in the way.
    fn spawn<T: Send + 'static>(
        &mut self,
        label: String,
        work: impl FnOnce(Cancel, &mut dyn FnMut(f32), &dyn Fn(&str)) -> Result<T> + Send + 'static,
        wrap: fn(Result<T>) -> Done,
    ) {
        self.status = match self.jobs.spawn(label.clone(), work, wrap) {
            Ok(()) => format!("{label}..."),
            Err(busy) => format!("busy: {busy} (cancel it first)"),
        };
    }

    /// Reads `path` on a worker thread: a mesh, or a manifest of `meshslim lods` (its levels
    /// go to the LOD scene) or `meshslim pareto` (its front to the panel) with its mesh.
    pub fn open(&mut self, path: PathBuf) {
        self.open_with(path, None);
    }

    /// As [`ViewerApp::open`], with the manifest's mesh already made.
    pub fn open_with(&mut self, path: PathBuf, model: Option<Model>) {
        let (pipelines, queue) = (self.gpu.pipelines.clone(), self.gpu.queue.clone());
        let label = format!("reading {}", path.display());
        self.spawn(
            label,
            move |_, progress, _| {
                scene::open((&pipelines, &queue), &path, model, progress).map(Box::new)
            },
            Done::Loaded,
        );
    }

    /// Searches the Pareto front of the model (NSGA-II, [`crate::lod::pareto_front`]) with
    /// the panel's settings on a worker thread.
    pub fn search_front(&mut self) {
        let Some(model) = self.scene.model.clone() else {
            self.status = "nothing to search: open a mesh first".into();
            return;
        };
        let mut opts = self.panel.pareto.clone();
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
        let (Some(model), Some(front)) = (self.scene.model.clone(), &self.scene.front) else {
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

    /// Chooses member `k` for the LOD scene, or takes it back.
    pub fn choose_member(&mut self, k: usize) {
        if let Some(f) = &mut self.scene.front
            && k < f.members.len()
            && !f.chosen.remove(&k)
        {
            f.chosen.insert(k);
        }
    }

    /// The LOD scene from the chosen members of the front, the original first and then the
    /// members by falling face count.
    pub fn lod_from_front(&mut self) {
        let (Some(model), Some(front)) = (self.scene.model.clone(), &self.scene.front) else {
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
        self.scene.lod_source = format!("{} members of the Pareto front", members.len());
        // The original on the GPU already, shared rather than uploaded again.
        let original = self.scene.original.as_deref().cloned();
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
        let Some(model) = self.scene.model.clone() else {
            self.status = "nothing to simplify: open a mesh first".into();
            return;
        };
        let target = match self.panel.target() {
            Ok(n) => n,
            Err(why) => {
                self.status = why;
                return;
            }
        };
        let (backend, method) = (self.panel.backend, self.panel.method);
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
                // The window draws on this device: a run shares its queue.
                let on = OnDevice {
                    rounds: sim.as_deref(),
                    cluster: clusterer.as_deref(),
                    upload: None,
                    share_queue: true,
                };
                scene::simplify(&device, on, &model, &opts, progress, phase).map(Box::new)
            },
            Done::Simplified,
        );
    }

    /// Makes the LOD levels (one GPU run) on a worker thread.
    pub fn make_lod(&mut self) {
        let (Some(model), Some(sim)) = (self.scene.model.clone(), self.gpu.sim.clone()) else {
            self.status = "the LOD scene needs a mesh and the gpu backend".into();
            return;
        };
        let device = self.gpu.device.clone();
        self.scene.lod_source = "GPU snapshots of one run".into();
        self.spawn(
            "making levels of detail on the GPU".into(),
            move |cancel, progress, _| {
                scene::lod_levels(&device, &sim, &model, &LOD_RATIOS, &cancel, progress)
            },
            Done::Lod,
        );
    }

    /// Builds the model's cluster DAG on a worker thread, on `backend` (the panel's, for its
    /// button; `gpu` runs the grouped rounds on the process's device), and uploads it to draw
    /// as its cut.
    pub fn make_dag(&mut self, backend: Backend) {
        let Some(model) = self.scene.model.clone() else {
            self.status = "nothing to build: open a mesh first".into();
            return;
        };
        let (pipelines, queue) = (self.gpu.pipelines.clone(), self.gpu.queue.clone());
        self.spawn(
            format!("building the cluster DAG ({})", backend.name()),
            move |cancel, progress, _| {
                let opts = crate::dag::DagOptions {
                    backend,
                    cancel,
                    ..Default::default()
                };
                let (dag, _) = crate::dag::build_with_progress(&model.mesh, &opts, progress)?;
                let frame = (model.up.center, model.up.scale);
                let error = model.dag_errors(&dag);
                let d = super::dag::DagScene::new(&pipelines, &queue, &dag, frame, error)?;
                Ok(Box::new((d, Arc::new(dag))))
            },
            Done::Dag,
        );
    }

    /// A model just shown that is large (at least the panel's `auto_dag_faces`) and came
    /// without a DAG gets one, built as `meshslim dag build` builds it by default (on this
    /// host's 2 cores its `cpu` builds the 4.3M-face scan's in 7.5 s, `cpu-parallel` in 18 s):
    /// drawn whole until then, as its cut after (O still shows it whole). Checked once per
    /// model, when no job runs.
    pub fn auto_dag(&mut self) {
        if !self.scene.dag_unchecked || self.jobs.busy() {
            return;
        }
        self.scene.dag_unchecked = false;
        let Some(faces) = self.scene.model.as_ref().map(|m| m.faces()) else {
            return;
        };
        let wanted = self.panel.auto_dag_faces;
        if wanted == 0 || faces < wanted || self.scene.dag.is_some() || self.scene.lod.is_some() {
            return;
        }
        self.make_dag(crate::dag::DagOptions::default().backend);
        if self.jobs.busy() {
            self.status = format!(
                "{faces} faces: {} so that it moves like a small mesh; drawn whole until then \
                 (Esc cancels; 'view --auto-dag 0' never builds one)",
                self.status.trim_end_matches("...")
            );
        }
    }

    /// Writes the DAG built in the window to `path`, or beside the model as X.mslod.
    pub fn save_dag(&mut self, path: Option<PathBuf>) {
        let (Some(dag), Some(model)) = (&self.scene.dag_built, &self.scene.model) else {
            self.status = "nothing to save: make the DAG first".into();
            return;
        };
        let path = path.unwrap_or_else(|| {
            let from = model.path.clone().unwrap_or_else(|| PathBuf::from("mesh"));
            from.with_extension("mslod")
        });
        self.status = match crate::dag::file::write(&path, dag) {
            Ok(()) => format!("saved the DAG to {}", path.display()),
            Err(e) => format!("cannot save the DAG: {e}"),
        };
    }

    /// Stops the running job; it ends at its next check (a round, a few thousand collapses).
    pub fn cancel(&mut self) {
        if let Some(label) = self.jobs.cancel() {
            self.status = format!("cancelling: {label}");
        }
    }

    /// Takes a finished job's result, if any, into the scene.
    pub fn poll_job(&mut self) {
        let (label, secs, done) = match self.jobs.poll() {
            None => return,
            Some(Finished::Lost(label)) => {
                self.status = format!("{label}: the worker stopped without a result");
                return;
            }
            Some(Finished::Cancelled(label)) => {
                self.status = format!("{label}: cancelled");
                return;
            }
            Some(Finished::Done(label, secs, done)) => (label, secs, done),
        };
        let failed = |e: Error| match e {
            Error::Cancelled => format!("{label}: cancelled"),
            e => format!("{label} failed: {e}"),
        };
        match done {
            Done::Loaded(Ok(loaded)) => {
                let Loaded {
                    model,
                    original,
                    levels,
                    front,
                    dag,
                } = *loaded;
                self.set_model(model, original);
                self.scene.dag = dag.map(std::sync::Mutex::new);
                if let Some(levels) = levels {
                    self.scene.lod_source =
                        format!("the {} levels of a meshslim lods run", levels.len() - 1);
                    self.show_levels(levels);
                }
                if let Some(f) = front {
                    self.status = format!(
                        "{}; Pareto front of {} members",
                        self.status,
                        f.members.len()
                    );
                    self.scene.front = Some(f);
                }
            }
            Done::Dag(Ok(built)) => {
                let (d, dag) = *built;
                self.status = format!(
                    "{label}: done, {} clusters, {} levels in {secs:.1} s",
                    dag.clusters.len(),
                    dag.levels()
                );
                // The cut is what the window shows now, in place of a simplified result.
                self.scene.simplified = None;
                self.scene.dag = Some(std::sync::Mutex::new(d));
                self.scene.dag_built = Some(dag);
                self.scene.generation += 1;
            }
            Done::Front(Ok(f)) => {
                self.status = format!("Pareto front of {} members in {secs:.1} s", f.members.len());
                self.scene.front = Some(*f);
            }
            Done::Member(Ok(m)) => {
                let (k, s) = *m;
                if let Some(f) = &mut self.scene.front {
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
            | Done::Member(Err(e))
            | Done::Dag(Err(e)) => self.status = failed(e),
        }
    }

    fn show_simplified(&mut self, s: Simplified) {
        self.view.style.error_scale = s.scene.max_error;
        self.scene.set_simplified(s);
        self.view.show_original = false;
    }

    fn show_levels(&mut self, levels: Vec<SceneMesh>) {
        self.scene.set_levels(levels);
        self.view.reframe();
        self.view.lod_scene = true;
        self.eye.lod_home();
    }

    /// A model read or made: its texture to the renderer, the mode it is best seen in, its
    /// own up axis and first view, the panel's target and save path for it.
    pub(super) fn set_model(&mut self, m: Model, original: SceneMesh) {
        self.view.reframe();
        self.view.lod_scene = false;
        let note = self.upload_texture(&m);
        let has_colors = original.has_colors;
        self.scene.set_model(m, original);
        self.scene.texture_changed(note);
        let textured = self.view.mode_available(Mode::Texture, &self.scene);
        if self.view.style.mode == Mode::Texture && !textured {
            self.view.style.mode = Mode::Shaded;
        }
        // A textured or painted scan is looked at for its appearance: shown by default (the
        // texture first, as its file names it), and a mesh without it falls back to shading.
        match (textured, has_colors, self.view.style.mode) {
            (true, _, Mode::Shaded) => self.view.style.mode = Mode::Texture,
            (false, true, Mode::Shaded) => self.view.style.mode = Mode::Color,
            (_, false, Mode::Color) => self.view.style.mode = Mode::Shaded,
            // A new model has no DAG (yet): nothing has clusters to colour.
            (_, _, Mode::Clusters | Mode::Levels) => self.view.style.mode = Mode::Shaded,
            _ => {}
        }
        let m = self.scene.model.clone().expect("set just above");
        self.panel.save_path = save_name(m.path.as_deref());
        // An axis chosen for the previous file is not this one's: each file opens with its own
        // (or the command line's, for the first).
        self.eye.up = self.eye.up_for_next.take();
        self.eye
            .home(m.up_axis, m.stood, m.extent(), self.view.aspect());
        self.panel.set_ratio(self.panel.ratio, Some(m.faces()));
        self.scene.front = None;
        self.panel.front_rect = None;
        self.status = format!(
            "{}: {} faces, {} vertices, read in {:.2} s",
            m.name,
            m.faces(),
            m.mesh.positions.len(),
            m.load_seconds
        );
    }

    /// The model's texture to the renderer; a note when the device refuses it.
    fn upload_texture(&mut self, m: &Model) -> Option<String> {
        let tex = m.texture.as_ref().map(|i| (&i.rgba[..], i.size));
        let max = self.gpu.device.limits().max_texture_dimension_2d;
        let scope = crate::compute::gpu::ErrorScope::push(&self.gpu.device);
        let mut note = None;
        if let Some((_, (w, h))) = tex.filter(|(_, (w, h))| *w > max || *h > max) {
            note = Some(format!(
                "texture {w}x{h} is larger than this device's {max} pixels a side"
            ));
            self.view
                .renderer
                .set_texture(&self.gpu.device, &self.gpu.queue, None);
        } else {
            self.view
                .renderer
                .set_texture(&self.gpu.device, &self.gpu.queue, tex);
        }
        if let Err(e) = scope.check("uploading the texture") {
            note = Some(e.to_string());
        }
        note
    }

    /// Writes the simplified mesh to the panel's path (never over its input).
    pub fn save(&mut self) {
        let Some(s) = &self.scene.simplified else {
            self.status = "nothing to save: simplify first".into();
            return;
        };
        let out = PathBuf::from(self.panel.save_path.trim());
        let input = self.scene.model.as_ref().and_then(|m| m.path.as_ref());
        let same_as_input = input.is_some_and(|p| {
            p == &out
                || (out.exists()
                    && std::fs::canonicalize(p).ok() == std::fs::canonicalize(&out).ok())
        });
        self.status = if same_as_input {
            format!("{}: that is the input; choose another file", out.display())
        } else {
            let written = match input {
                Some(from) => crate::io::write_from(&out, &s.mesh, from),
                None => crate::io::write(&out, &s.mesh),
            };
            match written {
                Ok(()) => {
                    let mut msg =
                        format!("saved {} ({} faces)", out.display(), s.mesh.triangles.len());
                    let format = crate::io::Format::from_path(&out);
                    for lost in format.map_or(Vec::new(), |f| crate::io::not_kept(&s.mesh, f)) {
                        msg += &format!("; not kept: {lost}");
                    }
                    msg
                }
                Err(e) => format!("save failed: {e}"),
            }
        };
    }

    /// Writes what the 3D view shows to the screenshot path: both panes, side by side, when
    /// it is split.
    pub fn screenshot(&mut self) {
        let path = PathBuf::from(self.panel.shot_path.trim());
        self.status = match self.write_screenshot(&path) {
            Ok(()) => format!("wrote {}", path.display()),
            Err(e) => format!("screenshot failed: {e}"),
        };
    }

    fn write_screenshot(&self, path: &Path) -> Result<()> {
        let (rgba, size) = self.view.rgba(&self.gpu, &self.scene)?;
        let png = super::render::encode_png(&rgba, size)?;
        crate::io::write_atomic(path, |w| std::io::Write::write_all(w, &png))
    }

    /// Draws every mesh with `up` up (None: its file's convention) and resets the view.
    pub fn set_up(&mut self, up: Option<Up>) {
        self.eye.up = up;
        if self.scene.model.is_none() {
            self.eye.up_for_next = up;
        }
        self.reset_view();
    }

    /// The model's first view again (the LOD scene's, when it is shown), out of fly mode.
    pub fn reset_view(&mut self) {
        if let Some(m) = &self.scene.model {
            self.eye
                .home(m.up_axis, m.stood, m.extent(), self.view.aspect());
        }
        if self.view.lod_shown(&self.scene) {
            self.eye.lod_home();
        }
        self.eye.fly = false;
    }
}

/// Where Save writes by default: `<stem>-simplified.<ext>` in the working directory (the
/// input's folder is often read-only: a download, a mounted dataset). A glTF is saved as glTF,
/// which keeps its materials and textures; anything else as PLY (fast, and it keeps normals,
/// UVs and colours).
fn save_name(input: Option<&Path>) -> String {
    let Some(p) = input else {
        return "simplified.ply".into();
    };
    let stem = p.file_stem().map_or("mesh".into(), |s| s.to_string_lossy());
    let ext = match crate::io::Format::from_path(p) {
        Ok(f @ (crate::io::Format::Glb | crate::io::Format::Gltf)) => f.extension(),
        _ => "ply",
    };
    format!("{stem}-simplified.{ext}")
}
