//! The interactive viewer: an eframe app on eframe's wgpu device. The simplifier's pipelines are
//! made on that device ([`ViewerApp::new`]); a `gpu` simplification leaves its result in the
//! rounds' own buffers, and [`Renderer`] binds those buffers as they are, drawing with the
//! indirect arguments the rounds wrote — nothing goes back through the CPU to be drawn. Loading,
//! simplifying and making levels of detail run on worker threads; the UI keeps drawing frames
//! (their time is shown) and can cancel them.

use super::camera::{Camera, Up};
use super::render::{Mode, Renderer, SceneMesh, Style, Target};
use super::scene::{self, Model, Simplified};
use crate::error::{Error, Result};
use crate::gpu::GpuSimplifier;
use crate::simplify::{Backend, Cancel, SimplifyOptions};
use eframe::egui;
use eframe::egui_wgpu;
use glam::{Mat4, Vec3};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::mpsc;
use std::time::Instant;

/// The LOD scene: a grid of instances, as in the seed that measured 13.5 → 26.5 FPS.
pub const LOD_GRID: usize = 21;
/// Fractions of the faces kept by levels 1, 2, 3 (level 0 is the original).
pub const LOD_RATIOS: [f64; 3] = [0.25, 0.06, 0.015];
/// How often the window redraws on its own while a job runs.
const JOB_FRAME_INTERVAL: std::time::Duration = std::time::Duration::from_millis(250);
/// Instances this many diagonals apart.
const LOD_SPACING: f32 = 1.25;

/// What the window starts with.
pub enum Start {
    Nothing,
    Model(Model),
    /// Read on a worker thread once the window is up.
    Open(PathBuf),
}

/// The device the window draws with, and the simplifier's pipelines on it.
struct Gpu {
    device: wgpu::Device,
    queue: wgpu::Queue,
    egui_renderer: Arc<egui::mutex::RwLock<egui_wgpu::Renderer>>,
    sim: Option<Arc<GpuSimplifier>>,
    adapter: String,
}

/// A finished job's result (boxed: the variants differ in size by hundreds of bytes).
enum Done {
    Loaded(Result<Box<(Model, SceneMesh)>>),
    Simplified(Result<Box<Simplified>>),
    Lod(Result<Vec<SceneMesh>>),
}

/// Work on a worker thread.
pub struct Job {
    pub label: String,
    progress: Arc<AtomicU32>,
    /// What the job is doing now, when it says.
    phase: Arc<std::sync::Mutex<String>>,
    cancel: Cancel,
    rx: mpsc::Receiver<Done>,
    started: Instant,
}

impl Job {
    pub fn progress(&self) -> f32 {
        f32::from_bits(self.progress.load(Ordering::Relaxed))
    }

    pub fn phase(&self) -> String {
        self.phase.lock().map(|p| p.clone()).unwrap_or_default()
    }
}

/// What a drawn frame showed: the views are drawn again only when it changes.
#[derive(Debug, Clone, PartialEq)]
struct DrawKey {
    camera: Camera,
    style: Style,
    split: bool,
    show_original: bool,
    lod_on: bool,
    sizes: Vec<(u32, u32)>,
    generation: u64,
}

/// A texture the 3D view draws into and egui shows.
struct View {
    target: Target,
    id: egui::TextureId,
}

/// Frame time, smoothed.
#[derive(Debug, Default, Clone, Copy)]
pub struct FrameClock {
    last: Option<Instant>,
    /// Seconds per frame, exponentially smoothed.
    pub smoothed: f64,
}

impl FrameClock {
    fn tick(&mut self) {
        let now = Instant::now();
        if let Some(l) = self.last {
            let dt = (now - l).as_secs_f64();
            self.smoothed = if self.smoothed == 0.0 {
                dt
            } else {
                0.9 * self.smoothed + 0.1 * dt
            };
        }
        self.last = Some(now);
    }
}

pub struct ViewerApp {
    gpu: Gpu,
    renderer: Renderer,
    pub model: Option<Arc<Model>>,
    pub original: Option<Arc<SceneMesh>>,
    pub simplified: Option<Simplified>,
    pub lod: Option<Vec<SceneMesh>>,
    pub job: Option<Job>,
    pub camera: Camera,
    pub style: Style,
    /// Original on the left, simplified on the right, one camera.
    pub side_by_side: bool,
    /// Draw the original even when a result exists.
    pub show_original: bool,
    pub lod_scene: bool,
    pub lod_on: bool,
    pub ratio: f64,
    faces_text: String,
    pub backend: Backend,
    pub fly: bool,
    /// Fly speed in diagonals per second.
    pub fly_speed: f32,
    views: Vec<View>,
    pub clock: FrameClock,
    /// Smoothed frame seconds of the LOD scene with LOD on and off, as last measured.
    pub lod_frame: [Option<f64>; 2],
    /// Frames drawn since the start (the tests count them while a job runs).
    pub frames: u64,
    /// Times the 3D view was rendered (only when what it shows changed).
    pub renders: u64,
    /// Bumped whenever a mesh or texture to show changes.
    generation: u64,
    drawn: Option<DrawKey>,
    pub status: String,
    pub show_help: bool,
    browser: Option<Browser>,
    pub save_path: String,
    pub shot_path: String,
    pub texture_note: Option<String>,
    /// The axis drawn up for every mesh, when the user chose one; else each file's convention.
    pub up: Option<Up>,
    ctx: egui::Context,
}

/// The device descriptor eframe (and the viewer's tests) create their device with: the same as
/// the simplifier's own, so that million-triangle meshes fit and the wireframe can be drawn.
pub fn wgpu_setup() -> egui_wgpu::WgpuSetup {
    let mut setup = egui_wgpu::WgpuSetupCreateNew::without_display_handle();
    setup.instance_descriptor.backends = wgpu::Backends::PRIMARY;
    setup.power_preference = wgpu::PowerPreference::HighPerformance;
    setup.device_descriptor = Arc::new(crate::gpu::context::device_descriptor);
    egui_wgpu::WgpuSetup::CreateNew(setup)
}

impl ViewerApp {
    /// Made by eframe (or a test harness) with its wgpu render state: the simplifier's
    /// pipelines are created on that same device.
    pub fn new(cc: &eframe::CreationContext<'_>, start: Start) -> Result<ViewerApp> {
        let rs = cc.wgpu_render_state.as_ref().ok_or_else(|| {
            Error::Gpu("the window has no wgpu device (eframe runs on wgpu here)".into())
        })?;
        let (sim, status) = match GpuSimplifier::new(&rs.device, &rs.queue) {
            Ok(s) => (Some(Arc::new(s)), String::new()),
            Err(e) => (
                None,
                format!("gpu backend unavailable on this device ({e}); cpu backends work"),
            ),
        };
        let renderer = Renderer::new(&rs.device, &rs.queue);
        let mut app = ViewerApp {
            gpu: Gpu {
                device: rs.device.clone(),
                queue: rs.queue.clone(),
                egui_renderer: rs.renderer.clone(),
                adapter: rs.adapter.get_info().name,
                sim: sim.clone(),
            },
            renderer,
            model: None,
            original: None,
            simplified: None,
            lod: None,
            job: None,
            camera: Camera::default(),
            style: Style::default(),
            side_by_side: false,
            show_original: false,
            lod_scene: false,
            lod_on: true,
            ratio: 0.1,
            faces_text: String::new(),
            backend: if sim.is_some() {
                Backend::Gpu
            } else {
                Backend::CpuParallel
            },
            fly: false,
            fly_speed: 0.5,
            views: Vec::new(),
            clock: FrameClock::default(),
            lod_frame: [None, None],
            frames: 0,
            renders: 0,
            generation: 0,
            drawn: None,
            status,
            show_help: false,
            browser: None,
            save_path: String::new(),
            shot_path: "meshslim-view.png".into(),
            texture_note: None,
            up: None,
            ctx: cc.egui_ctx.clone(),
        };
        match start {
            Start::Nothing => {
                app.status = "Open a mesh (Ctrl+O) or drop one on the window".into();
            }
            Start::Model(m) => {
                let original = m.original(&app.gpu.device)?;
                app.set_model(m, original);
            }
            Start::Open(p) => app.open(p),
        }
        Ok(app)
    }

    /// The target as a fraction of the input's faces.
    pub fn set_ratio(&mut self, ratio: f64) {
        self.ratio = ratio.clamp(0.001, 1.0);
        if let Some(m) = &self.model {
            self.faces_text = ((m.faces() as f64 * self.ratio).round() as usize)
                .max(1)
                .to_string();
        }
    }

    /// How the view draws (the command line's --mode, --smooth, --wireframe).
    pub fn set_style(&mut self, style: Style) {
        self.style = style;
        if !self.mode_available(style.mode) {
            self.style.mode = Mode::Shaded;
        }
        if !self.renderer.has_wireframe() {
            self.style.wireframe = false;
        }
    }

    /// The target in faces, as the face-count field holds it.
    pub fn set_target_faces(&mut self, faces: usize) {
        self.faces_text = faces.to_string();
    }

    /// The pixels of pane `k` of the 3D view as last drawn (RGBA8 rows) and its size: what the
    /// screenshot writes.
    pub fn pane_rgba(&self, k: usize) -> Result<(Vec<u8>, (u32, u32))> {
        let v = self
            .views
            .get(k)
            .ok_or_else(|| Error::InvalidOption(format!("no pane {k} drawn")))?;
        Ok((
            v.target.read_rgba(&self.gpu.device, &self.gpu.queue)?,
            v.target.size,
        ))
    }

    /// The device the window draws with — eframe's — on which the simplifier also runs.
    pub fn device(&self) -> (&wgpu::Device, &wgpu::Queue) {
        (&self.gpu.device, &self.gpu.queue)
    }

    pub fn adapter(&self) -> &str {
        &self.gpu.adapter
    }

    pub fn has_gpu_backend(&self) -> bool {
        self.gpu.sim.is_some()
    }

    fn set_model(&mut self, m: Model, original: SceneMesh) {
        self.generation += 1;
        // Framed again at the next frame, for the view's real shape.
        self.drawn = None;
        self.texture_note = m.texture_note.clone();
        let tex = m.texture.as_ref().map(|i| (&i.rgba[..], i.size));
        let max = self.gpu.device.limits().max_texture_dimension_2d;
        if let Some((_, (w, h))) = tex.filter(|(_, (w, h))| *w > max || *h > max) {
            self.texture_note = Some(format!(
                "texture {w}x{h} is larger than this device's {max} pixels a side"
            ));
            self.renderer
                .set_texture(&self.gpu.device, &self.gpu.queue, None);
        } else {
            self.renderer
                .set_texture(&self.gpu.device, &self.gpu.queue, tex);
        }
        if self.style.mode == Mode::Texture && !self.renderer.has_texture() {
            self.style.mode = Mode::Shaded;
        }
        self.save_path = m.path.as_ref().map_or("simplified.ply".into(), |p| {
            let stem = p.file_stem().map_or("mesh".into(), |s| s.to_string_lossy());
            // A glTF is saved as glTF, which keeps its materials and textures; anything else as
            // PLY (fast, and it keeps normals, UVs and colours).
            let ext = match crate::io::Format::from_path(p) {
                Ok(f @ (crate::io::Format::Glb | crate::io::Format::Gltf)) => f.extension(),
                _ => "ply",
            };
            p.with_file_name(format!("{stem}-simplified.{ext}"))
                .display()
                .to_string()
        });
        self.camera = home_camera(&m, self.aspect(), self.up);
        self.faces_text = ((m.faces() as f64 * self.ratio).round() as usize)
            .max(1)
            .to_string();
        self.status = format!(
            "{}: {} faces, {} vertices, read in {:.2} s",
            m.name,
            m.faces(),
            m.mesh.positions.len(),
            m.load_seconds
        );
        self.model = Some(Arc::new(m));
        self.original = Some(Arc::new(original));
        self.simplified = None;
        self.lod = None;
        self.lod_scene = false;
        self.lod_frame = [None, None];
    }

    fn aspect(&self) -> f32 {
        self.views.first().map_or(4.0 / 3.0, |v| {
            v.target.size.0 as f32 / v.target.size.1 as f32
        })
    }

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
        let device = self.gpu.device.clone();
        let sim = self.gpu.sim.clone();
        let label = format!("simplifying to {target} faces ({})", backend_name(backend));
        self.spawn(
            label,
            move |cancel, progress, phase| {
                let mut opts = SimplifyOptions::with_faces(target);
                opts.backend = backend;
                opts.cancel = cancel;
                scene::simplify(
                    &device,
                    sim.as_deref(),
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
                    backend_name(s.report.backend),
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

    pub fn save(&mut self) {
        let Some(s) = &self.simplified else {
            self.status = "nothing to save: simplify first".into();
            return;
        };
        let out = PathBuf::from(self.save_path.trim());
        let same_as_input = self
            .model
            .as_ref()
            .and_then(|m| m.path.as_ref())
            .is_some_and(|p| {
                p == &out
                    || (out.exists()
                        && std::fs::canonicalize(p).ok() == std::fs::canonicalize(&out).ok())
            });
        self.status = if same_as_input {
            format!("{}: that is the input; choose another file", out.display())
        } else {
            let input = self.model.as_ref().and_then(|m| m.path.as_ref());
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

    /// Writes what the 3D view shows (its left half when side by side) to the screenshot path.
    pub fn screenshot(&mut self) {
        let path = PathBuf::from(self.shot_path.trim());
        self.status = match self.write_screenshot(&path) {
            Ok(()) => format!("wrote {}", path.display()),
            Err(e) => format!("screenshot failed: {e}"),
        };
    }

    fn write_screenshot(&self, path: &Path) -> Result<()> {
        let (rgba, size) = self.pane_rgba(0)?;
        let png = super::encode_png(&rgba, size)?;
        crate::io::write_atomic(path, |w| std::io::Write::write_all(w, &png))
    }

    /// The camera that frames the LOD grid from above one corner.
    /// The LOD scene's first view: low over one side of the grid, so that the nearest
    /// instances are large on screen and the farthest small — every level has its turn.
    fn lod_home(&self) -> Camera {
        let half = LOD_GRID as f32 * LOD_SPACING * 0.5;
        let mut c = Camera {
            yaw: 0.6,
            pitch: 0.3,
            ..self.camera
        };
        c.fit(Vec3::ZERO, half * 0.6, self.aspect());
        c
    }

    /// How many instances of the LOD scene draw each level (with the current camera).
    pub fn lod_histogram(&self) -> Vec<usize> {
        let Some(levels) = &self.lod else {
            return Vec::new();
        };
        let mut h = vec![0; levels.len()];
        for (mesh, _) in self.lod_items(levels) {
            let k = levels
                .iter()
                .position(|l| std::ptr::eq(l, mesh))
                .expect("an item draws one of the levels");
            h[k] += 1;
        }
        h
    }

    /// The scene's instances: (mesh, placement), each choosing its level by its size on screen
    /// when LOD is on.
    fn lod_items<'a>(&self, levels: &'a [SceneMesh]) -> Vec<(&'a SceneMesh, Mat4)> {
        let eye = self.camera.eye();
        let view_px = self.views.first().map_or(600.0, |v| v.target.size.1 as f32);
        // Pixels per unit of length at distance 1.
        let px_per_unit = view_px / (2.0 * (0.5 * self.camera.fov_y).tan());
        let n = LOD_GRID as f32;
        let mut items = Vec::with_capacity(LOD_GRID * LOD_GRID);
        for i in 0..LOD_GRID {
            for j in 0..LOD_GRID {
                let at = Vec3::new(
                    (i as f32 - (n - 1.0) * 0.5) * LOD_SPACING,
                    0.0,
                    (j as f32 - (n - 1.0) * 0.5) * LOD_SPACING,
                );
                let place = Mat4::from_translation(at) * self.camera.model;
                let level = if self.lod_on {
                    // An instance's diagonal is 1: its height on screen in pixels.
                    let px = px_per_unit / eye.distance(at).max(1e-3);
                    lod_level(px, levels.len())
                } else {
                    0
                };
                items.push((&levels[level], place));
            }
        }
        items
    }

    /// Draws the 3D view(s) into `rect` and handles the camera input on it.
    fn view_ui(&mut self, ui: &mut egui::Ui) {
        let rect = ui.available_rect_before_wrap();
        let response = ui.allocate_rect(rect, egui::Sense::click_and_drag());
        self.camera_input(ui, &response);
        let ppp = ui.ctx().pixels_per_point();
        let lod = self.lod_scene && self.lod.is_some();
        let split = self.side_by_side && !lod && self.original.is_some();
        let panes: Vec<egui::Rect> = if split {
            let (l, r) = rect.split_left_right_at_fraction(0.5);
            vec![
                l.shrink2(egui::vec2(1.0, 0.0)),
                r.shrink2(egui::vec2(1.0, 0.0)),
            ]
        } else {
            vec![rect]
        };
        if let Err(e) = self.ensure_views(&panes, ppp) {
            self.status = format!("cannot draw: {e}");
            return;
        }
        // Going into or out of side by side halves or doubles each pane's width: frame the
        // mesh again for the new shape (a model's first frame too, now that the size is known).
        if self.drawn.as_ref().is_none_or(|d| d.split != split) && !lod {
            self.frame_to_fit();
        }
        // The 3D view is drawn again only when what it shows changed (the LOD scene always, it
        // measures frame rates): frames that only move the progress bar stay cheap, which on a
        // software rasterizer leaves the cores to a running simplification.
        let key = DrawKey {
            camera: self.camera,
            style: self.style,
            split,
            show_original: self.show_original,
            lod_on: self.lod_on,
            sizes: self.views.iter().map(|v| v.target.size).collect(),
            generation: self.generation,
        };
        if lod || self.drawn.as_ref() != Some(&key) {
            self.draw_views(split, lod);
            self.drawn = Some(key);
        }
        self.paint_views(ui, rect, &panes, split, lod);
    }

    /// Renders the pane textures.
    fn draw_views(&mut self, split: bool, lod: bool) {
        self.renders += 1;
        let original = self.original.clone();
        let shown: Vec<Option<&SceneMesh>> = if split {
            vec![
                original.as_deref(),
                self.simplified
                    .as_ref()
                    .map(|s| &s.scene)
                    .or(original.as_deref()),
            ]
        } else {
            let main = match (&self.simplified, self.show_original) {
                (Some(s), false) => Some(&s.scene),
                _ => original.as_deref(),
            };
            vec![main]
        };
        let lod_levels = self.lod.take();
        for (k, mesh) in shown.iter().enumerate() {
            let items: Vec<(&SceneMesh, Mat4)> = match (&lod_levels, lod) {
                (Some(levels), true) => self.lod_items(levels),
                _ => mesh
                    .map(|m| vec![(m, self.camera.model)])
                    .unwrap_or_default(),
            };
            let mut style = self.style;
            if style.mode == Mode::Texture && !mesh.is_some_and(|m| m.has_uvs) {
                style.mode = Mode::Shaded;
            }
            // One submission per pane: the renderer's uniforms are written through the queue,
            // and a second pane's writes would land before the first pane's draw otherwise.
            let mut enc = self.gpu.device.create_command_encoder(&Default::default());
            self.renderer.draw(
                &self.gpu.device,
                &self.gpu.queue,
                &mut enc,
                &self.views[k].target,
                &self.camera,
                &style,
                &items,
            );
            self.gpu.queue.submit([enc.finish()]);
        }
        self.lod = lod_levels;
        if let Some(sim) = &self.gpu.sim
            && let Err(e) = sim.check_errors("drawing the view")
        {
            self.status = e.to_string();
        }
    }

    /// Shows the pane textures and the overlays (labels, legend).
    fn paint_views(
        &self,
        ui: &egui::Ui,
        rect: egui::Rect,
        panes: &[egui::Rect],
        split: bool,
        lod: bool,
    ) {
        let painter = ui.painter_at(rect);
        for (k, pane) in panes.iter().enumerate() {
            painter.image(
                self.views[k].id,
                *pane,
                egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0)),
                egui::Color32::WHITE,
            );
        }
        let label = |at: egui::Pos2, align: egui::Align2, text: &str| {
            overlay_text(&painter, at, align, text, 13.0);
        };
        let top_left = egui::Align2::LEFT_TOP;
        if split {
            label(
                panes[0].left_top() + egui::vec2(8.0, 6.0),
                top_left,
                "original",
            );
            let right = if self.simplified.is_some() {
                "simplified"
            } else {
                "original (not simplified yet)"
            };
            label(panes[1].left_top() + egui::vec2(8.0, 6.0), top_left, right);
        }
        if lod {
            let text = format!(
                "LOD scene {0}x{0}: LOD {1}, {2:.1} ms / frame",
                LOD_GRID,
                if self.lod_on { "on" } else { "off" },
                self.clock.smoothed * 1e3
            );
            label(rect.left_top() + egui::vec2(8.0, 6.0), top_left, &text);
        }
        if self.style.mode == Mode::Heatmap {
            heatmap_legend(&painter, rect, self.style.error_scale);
        }
        if self.fly {
            label(
                rect.left_bottom() + egui::vec2(8.0, -8.0),
                egui::Align2::LEFT_BOTTOM,
                "fly: W A S D move, Q E down/up, drag to look, G to leave",
            );
        }
    }

    /// One texture per pane, of the pane's size in pixels, registered with egui.
    fn ensure_views(&mut self, panes: &[egui::Rect], ppp: f32) -> Result<()> {
        for v in self.views.drain(panes.len().min(self.views.len())..) {
            self.gpu.egui_renderer.write().free_texture(&v.id);
        }
        for (k, pane) in panes.iter().enumerate() {
            let size = (
                ((pane.width() * ppp).round() as u32).max(1),
                ((pane.height() * ppp).round() as u32).max(1),
            );
            if self.views.get(k).is_some_and(|v| v.target.size == size) {
                continue;
            }
            let target = Target::new(&self.gpu.device, size)?;
            let mut r = self.gpu.egui_renderer.write();
            let id = match self.views.get(k) {
                Some(v) => {
                    r.update_egui_texture_from_wgpu_texture(
                        &self.gpu.device,
                        &target.color_view,
                        wgpu::FilterMode::Linear,
                        v.id,
                    );
                    v.id
                }
                None => r.register_native_texture(
                    &self.gpu.device,
                    &target.color_view,
                    wgpu::FilterMode::Linear,
                ),
            };
            let v = View { target, id };
            if k < self.views.len() {
                self.views[k] = v;
            } else {
                self.views.push(v);
            }
        }
        Ok(())
    }

    fn camera_input(&mut self, ui: &egui::Ui, r: &egui::Response) {
        let size = r.rect.size().max(egui::vec2(1.0, 1.0));
        let d = r.drag_delta();
        // Radians per point: a drag across the view turns about half a turn.
        let turn = std::f32::consts::PI / size.y;
        if r.dragged_by(egui::PointerButton::Primary) {
            if self.fly {
                self.camera.look(-d.x * turn * 0.5, -d.y * turn * 0.5);
            } else {
                self.camera.orbit(-d.x * turn, d.y * turn);
            }
        }
        if r.dragged_by(egui::PointerButton::Secondary) || r.dragged_by(egui::PointerButton::Middle)
        {
            self.camera.pan(d.x / size.y, d.y / size.y);
        }
        if r.hovered() {
            let scroll = ui.input(|i| i.smooth_scroll_delta.y);
            if scroll != 0.0 {
                // Zoom scaled by distance: the same wheel step moves 10% closer at any range.
                self.camera.zoom((-scroll * 0.002).exp());
            }
            let pinch = ui.input(|i| i.zoom_delta());
            if pinch != 1.0 {
                self.camera.zoom(1.0 / pinch);
            }
        }
        // Keys only when no text field has the keyboard.
        if ui.ctx().egui_wants_keyboard_input() {
            return;
        }
        if self.fly {
            let (dt, held) = ui.input(|i| {
                let k = |key| if i.key_down(key) { 1.0f32 } else { 0.0 };
                (
                    i.stable_dt.min(0.1),
                    [
                        k(egui::Key::W) - k(egui::Key::S),
                        k(egui::Key::D) - k(egui::Key::A),
                        k(egui::Key::E) - k(egui::Key::Q),
                    ],
                )
            });
            if held != [0.0; 3] {
                let step = self.fly_speed * dt;
                self.camera
                    .fly(held[0] * step, held[1] * step, held[2] * step);
                ui.ctx().request_repaint();
            }
        }
    }

    /// Shortcuts, ignored while a text field has the keyboard.
    fn shortcuts(&mut self, ctx: &egui::Context) {
        if ctx.egui_wants_keyboard_input() {
            return;
        }
        use egui::{Key, Modifiers};
        let pressed = |k| ctx.input_mut(|i| i.consume_key(Modifiers::NONE, k));
        let command = |k| ctx.input_mut(|i| i.consume_key(Modifiers::COMMAND, k));
        if command(Key::O) {
            self.browser = Some(Browser::new(
                self.model.as_ref().and_then(|m| m.path.clone()),
            ));
        }
        if command(Key::S) {
            self.save();
        }
        if pressed(Key::F1)
            || ctx.input_mut(|i| i.consume_key(Modifiers::SHIFT, Key::Questionmark))
            || pressed(Key::Questionmark)
        {
            self.show_help = !self.show_help;
        }
        if pressed(Key::Escape) {
            if self.show_help {
                self.show_help = false;
            } else {
                self.cancel();
            }
        }
        if pressed(Key::F) {
            self.frame_to_fit();
        }
        if pressed(Key::R) {
            self.reset_view();
        }
        if pressed(Key::G) {
            self.fly = !self.fly;
        }
        if pressed(Key::X) {
            self.style.wireframe = !self.style.wireframe && self.renderer.has_wireframe();
        }
        if pressed(Key::M) {
            self.style.smooth = !self.style.smooth;
        }
        if pressed(Key::B) {
            self.side_by_side = !self.side_by_side;
        }
        if pressed(Key::O) {
            self.show_original = !self.show_original;
        }
        if pressed(Key::L) && self.lod.is_some() {
            self.lod_on = !self.lod_on;
        }
        if pressed(Key::P) {
            self.screenshot();
        }
        if pressed(Key::Enter) {
            self.simplify();
        }
        for (k, mode) in [Key::Num1, Key::Num2, Key::Num3, Key::Num4]
            .into_iter()
            .zip(Mode::ALL)
        {
            if pressed(k) && self.mode_available(mode) {
                self.style.mode = mode;
            }
        }
    }

    pub fn mode_available(&self, mode: Mode) -> bool {
        match mode {
            Mode::Texture => {
                self.renderer.has_texture() && self.original.as_ref().is_some_and(|o| o.has_uvs)
            }
            _ => true,
        }
    }

    pub fn frame_to_fit(&mut self) {
        if self.lod_scene && self.lod.is_some() {
            self.camera = self.lod_home();
        } else {
            let aspect = self.aspect();
            self.camera.fit(Vec3::ZERO, 0.5, aspect);
        }
    }

    /// Draws every mesh with `up` up (None: each file's convention) and resets the view.
    pub fn set_up(&mut self, up: Option<Up>) {
        self.up = up;
        self.reset_view();
    }

    pub fn reset_view(&mut self) {
        if let Some(m) = &self.model {
            self.camera = home_camera(m, self.aspect(), self.up);
        }
        if self.lod_scene && self.lod.is_some() {
            self.camera = self.lod_home();
        }
        self.fly = false;
    }

    fn controls_ui(&mut self, ui: &mut egui::Ui) {
        ui.heading("meshslim");
        ui.horizontal(|ui| {
            if ui
                .button("Open...")
                .on_hover_text("Ctrl+O; or drop a file on the window")
                .clicked()
            {
                self.browser = Some(Browser::new(
                    self.model.as_ref().and_then(|m| m.path.clone()),
                ));
            }
            if ui.button("Help").on_hover_text("F1").clicked() {
                self.show_help = !self.show_help;
            }
        });
        ui.separator();
        let input_faces = self.model.as_ref().map_or(0, |m| m.faces());
        ui.label("Target");
        let old_ratio = self.ratio;
        ui.add(
            egui::Slider::new(&mut self.ratio, 0.001..=1.0)
                .logarithmic(true)
                .text("ratio"),
        );
        if self.ratio != old_ratio && input_faces > 0 {
            self.faces_text = ((input_faces as f64 * self.ratio).round() as usize)
                .max(1)
                .to_string();
        }
        ui.horizontal(|ui| {
            let l = ui.label("faces");
            let r = ui
                .add(egui::TextEdit::singleline(&mut self.faces_text).desired_width(90.0))
                .labelled_by(l.id);
            if r.changed()
                && let Ok(n) = self.faces_text.trim().parse::<usize>()
                && input_faces > 0
            {
                self.ratio = (n as f64 / input_faces as f64).clamp(0.001, 1.0);
            }
        });
        ui.horizontal(|ui| {
            ui.label("backend");
            for b in [Backend::Gpu, Backend::CpuParallel, Backend::Cpu] {
                let enabled = b != Backend::Gpu || self.gpu.sim.is_some();
                ui.add_enabled_ui(enabled, |ui| {
                    ui.selectable_value(&mut self.backend, b, backend_name(b));
                });
            }
        });
        ui.horizontal(|ui| {
            let busy = self.job.is_some();
            if ui
                .add_enabled(!busy && self.model.is_some(), egui::Button::new("Simplify"))
                .on_hover_text("Enter")
                .clicked()
            {
                self.simplify();
            }
            if ui
                .add_enabled(busy, egui::Button::new("Cancel"))
                .on_hover_text("Esc")
                .clicked()
            {
                self.cancel();
            }
        });
        if let Some(j) = &self.job {
            ui.add(egui::ProgressBar::new(j.progress()).text(format!(
                "{} - {:.1} s",
                match j.phase() {
                    p if p.is_empty() => j.label.clone(),
                    p => p,
                },
                j.started.elapsed().as_secs_f64()
            )));
        }
        ui.separator();
        ui.label("View");
        ui.horizontal_wrapped(|ui| {
            for m in Mode::ALL {
                let ok = self.mode_available(m);
                let r = ui.add_enabled(
                    ok,
                    egui::Button::selectable(self.style.mode == m, m.label()),
                );
                if r.clicked() {
                    self.style.mode = m;
                }
                if !ok && m == Mode::Texture {
                    r.on_disabled_hover_text(
                        self.texture_note
                            .clone()
                            .unwrap_or_else(|| "the mesh has no UVs or no texture".into()),
                    );
                }
            }
        });
        ui.checkbox(&mut self.style.smooth, "smooth shading (M)");
        ui.add_enabled_ui(self.renderer.has_wireframe(), |ui| {
            ui.checkbox(&mut self.style.wireframe, "wireframe (X)")
                .on_disabled_hover_text("this device cannot draw line polygons");
        });
        ui.checkbox(&mut self.side_by_side, "side by side (B)");
        ui.add_enabled_ui(self.simplified.is_some() && !self.side_by_side, |ui| {
            ui.checkbox(&mut self.show_original, "show the original (O)");
        });
        ui.horizontal(|ui| {
            let file_up = self.model.as_ref().map_or(Up::Y, |m| m.up_axis);
            let current = self.up.unwrap_or(file_up);
            let mut chosen = current;
            egui::ComboBox::from_label("up")
                .selected_text(current.label())
                .show_ui(ui, |ui| {
                    for u in Up::ALL {
                        ui.selectable_value(&mut chosen, u, u.label());
                    }
                })
                .response
                .on_hover_text("the mesh's axis drawn up (default: its file's convention)");
            if chosen != current {
                self.set_up(Some(chosen));
            }
        });
        ui.horizontal(|ui| {
            if ui.button("Fit").on_hover_text("F").clicked() {
                self.frame_to_fit();
            }
            if ui.button("Reset").on_hover_text("R").clicked() {
                self.reset_view();
            }
            ui.checkbox(&mut self.fly, "fly (G)");
        });
        if self.fly {
            ui.add(
                egui::Slider::new(&mut self.fly_speed, 0.05..=20.0)
                    .logarithmic(true)
                    .text("speed"),
            );
        }
        ui.separator();
        ui.label("LOD scene");
        ui.horizontal(|ui| {
            let can = self.job.is_none() && self.model.is_some() && self.gpu.sim.is_some();
            if ui
                .add_enabled(can, egui::Button::new("Make levels"))
                .clicked()
            {
                self.make_lod();
            }
            ui.add_enabled_ui(self.lod.is_some(), |ui| {
                if ui
                    .checkbox(&mut self.lod_scene, format!("{0}x{0} grid", LOD_GRID))
                    .changed()
                {
                    self.reset_view();
                }
                ui.checkbox(&mut self.lod_on, "LOD (L)");
            });
        });
        if let Some(levels) = &self.lod {
            let f: Vec<String> = levels.iter().map(|l| l.faces.to_string()).collect();
            ui.label(format!("levels: {} faces", f.join(" / ")));
            let ms = |v: Option<f64>| {
                v.map_or("-".into(), |s| {
                    format!("{:.1} ms ({:.1} FPS)", s * 1e3, 1.0 / s)
                })
            };
            ui.label(format!("LOD on: {}", ms(self.lod_frame[0])));
            ui.label(format!("LOD off: {}", ms(self.lod_frame[1])));
        }
        ui.separator();
        self.stats_ui(ui);
        ui.separator();
        ui.horizontal(|ui| {
            let l = ui.label("mesh");
            ui.add(egui::TextEdit::singleline(&mut self.save_path).desired_width(150.0))
                .labelled_by(l.id);
            if ui
                .add_enabled(self.simplified.is_some(), egui::Button::new("Save"))
                .on_hover_text("Ctrl+S")
                .clicked()
            {
                self.save();
            }
        });
        ui.horizontal(|ui| {
            let l = ui.label("PNG");
            ui.add(egui::TextEdit::singleline(&mut self.shot_path).desired_width(150.0))
                .labelled_by(l.id);
            if ui.button("Screenshot").on_hover_text("P").clicked() {
                self.screenshot();
            }
        });
    }

    fn stats_ui(&self, ui: &mut egui::Ui) {
        ui.label(format!("device: {}", self.gpu.adapter));
        // The time between the last frames drawn: the window redraws on input, on its own a few
        // times a second during a job, and continuously in the LOD scene and fly mode.
        ui.label(format!(
            "frames: {:.1} ms apart ({:.0} FPS)",
            self.clock.smoothed * 1e3,
            if self.clock.smoothed > 0.0 {
                1.0 / self.clock.smoothed
            } else {
                0.0
            }
        ));
        let Some(m) = &self.model else { return };
        egui::Grid::new("stats").striped(true).show(ui, |ui| {
            ui.label("");
            ui.label("faces");
            ui.label("vertices");
            ui.end_row();
            ui.label("before");
            ui.label(m.faces().to_string());
            ui.label(m.mesh.positions.len().to_string());
            ui.end_row();
            if let Some(s) = &self.simplified {
                ui.label("after");
                ui.label(s.report.output_faces.to_string());
                ui.label(s.report.output_vertices.to_string());
                ui.end_row();
            }
        });
        let Some(s) = &self.simplified else { return };
        ui.label(format!(
            "{}: {:.3} s, stop: {:?}",
            backend_name(s.report.backend),
            s.seconds,
            s.report.stop_reason
        ));
        ui.label(error_text(s.error));
        if let Some(r) = &s.report.rounds {
            ui.label(format!("{} rounds; time per stage:", r.rounds));
            egui::Grid::new("stages").striped(true).show(ui, |ui| {
                for (name, secs) in &r.stage_seconds.0 {
                    ui.label(name);
                    ui.label(format!("{:.1} ms", secs * 1e3));
                    ui.end_row();
                }
            });
        }
    }

    fn help_ui(&mut self, ctx: &egui::Context) {
        let mut open = self.show_help;
        egui::Window::new("Help: shortcuts")
            .open(&mut open)
            .collapsible(false)
            .show(ctx, |ui| {
                egui::Grid::new("keys").show(ui, |ui| {
                    for (k, what) in HELP {
                        ui.monospace(*k);
                        ui.label(*what);
                        ui.end_row();
                    }
                });
            });
        self.show_help = open && self.show_help;
    }

    fn dropped_files(&mut self, ctx: &egui::Context) {
        let dropped = ctx.input(|i| i.raw.dropped_files.first().map(|f| f.path().to_path_buf()));
        if let Some(p) = dropped {
            self.open(p);
        }
    }
}

/// The shortcuts, as the help window lists them. (UI text stays within the glyphs of egui's
/// default fonts: anything else draws as a box.)
pub const HELP: &[(&str, &str)] = &[
    ("left drag", "orbit (fly mode: look around)"),
    ("right / middle drag", "pan"),
    ("wheel, pinch", "zoom (scaled by distance)"),
    ("G", "fly mode on/off; W A S D move, Q E down/up"),
    ("F", "frame the mesh"),
    ("R", "reset the view"),
    ("1 2 3 4", "shaded, normals, error heatmap, texture"),
    ("M", "smooth / flat shading"),
    ("X", "wireframe overlay"),
    ("B", "side by side: original | simplified"),
    ("O", "show the original instead of the result"),
    ("L", "LOD on/off in the LOD scene"),
    ("Enter", "simplify to the target"),
    ("Esc", "cancel the running job (or close this)"),
    ("Ctrl+O", "open a mesh (or drop a file on the window)"),
    ("Ctrl+S", "save the simplified mesh"),
    ("P", "screenshot of the 3D view to PNG"),
    ("F1", "this help"),
];

impl eframe::App for ViewerApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        self.clock.tick();
        self.frames += 1;
        if self.lod_scene && self.lod.is_some() {
            self.lod_frame[if self.lod_on { 0 } else { 1 }] = Some(self.clock.smoothed);
        }
        self.poll_job();
        self.dropped_files(&ctx);
        self.shortcuts(&ctx);
        egui::Panel::left("controls")
            .resizable(true)
            .default_size(270.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| self.controls_ui(ui));
            });
        egui::Panel::bottom("status").show(ui, |ui| {
            ui.label(&self.status);
        });
        egui::CentralPanel::default()
            .frame(egui::Frame::NONE)
            .show(ui, |ui| self.view_ui(ui));
        self.help_ui(&ctx);
        if let Some(b) = &mut self.browser {
            match b.ui(&ctx) {
                BrowserResult::Open(p) => {
                    self.browser = None;
                    self.open(p);
                }
                BrowserResult::Close => self.browser = None,
                BrowserResult::Stay => {}
            }
        }
        // Frames on and on in the LOD scene (it measures them) and in fly mode. While a job
        // runs, a few per second for the progress bar: input still gets a frame at once, but
        // idle frames would take turns with the job's passes on the GPU queue (on lavapipe,
        // continuous frames made a 1M-face run three times slower).
        if (self.lod_scene && self.lod.is_some()) || self.fly {
            ctx.request_repaint();
        } else if self.job.is_some() {
            ctx.request_repaint_after(JOB_FRAME_INTERVAL);
        }
    }
}

/// The camera a model opens with: its up axis (`up`, else its file's) up, framed.
fn home_camera(m: &Model, aspect: f32, up: Option<Up>) -> Camera {
    let mut cam = Camera {
        model: up.unwrap_or(m.up_axis).model(m.extent()),
        yaw: 0.35,
        pitch: 0.2,
        ..Camera::default()
    };
    // The normalized frame: centred, bounding-box diagonal 1, so a sphere of radius 0.5 holds it.
    cam.fit(Vec3::ZERO, 0.5, aspect);
    cam
}

/// The level an instance `pixels` tall on screen draws: the original from
/// [`LOD_FULL_PIXELS`] up, each coarser level below half the size of the one before (the levels'
/// face counts fall about 4× apart, so the faces per pixel stay about even).
pub fn lod_level(pixels: f32, levels: usize) -> usize {
    let mut level = 0;
    let mut size = LOD_FULL_PIXELS;
    while pixels < size && level + 1 < levels {
        level += 1;
        size *= 0.5;
    }
    level
}

/// On-screen height from which the LOD scene draws the original.
pub const LOD_FULL_PIXELS: f32 = 240.0;

/// The two-sided error as the window shows it.
fn error_text(error: Option<(f64, f64)>) -> String {
    match error {
        Some((mean, max)) => format!("mean error {mean:.2e}, max {max:.2e} of the diagonal"),
        None => "no faces left to measure".into(),
    }
}

pub fn backend_name(b: Backend) -> &'static str {
    match b {
        Backend::Gpu => "gpu",
        Backend::CpuParallel => "cpu-parallel",
        Backend::Cpu => "cpu",
    }
}

/// The heatmap's colour legend: the shader's ramp from 0 to the largest error.
fn heatmap_legend(painter: &egui::Painter, rect: egui::Rect, top: f32) {
    let w = 18.0;
    let h = (rect.height() * 0.4).min(220.0);
    let bar = egui::Rect::from_min_size(
        rect.right_top() + egui::vec2(-w - 70.0, 16.0),
        egui::vec2(w, h),
    );
    let steps = 32;
    for s in 0..steps {
        let t0 = s as f32 / steps as f32;
        let t1 = (s + 1) as f32 / steps as f32;
        // Top of the bar is the largest error.
        let r = egui::Rect::from_min_max(
            egui::pos2(bar.left(), bar.bottom() - t1 * h),
            egui::pos2(bar.right(), bar.bottom() - t0 * h),
        );
        painter.rect_filled(r, 0.0, ramp_color((t0 + t1) * 0.5));
    }
    let top = format!("{top:.2e}");
    let at = |p: egui::Pos2, align, text: &str| overlay_text(painter, p, align, text, 12.0);
    at(
        bar.right_top() + egui::vec2(4.0, 0.0),
        egui::Align2::LEFT_TOP,
        &top,
    );
    at(
        bar.right_bottom() + egui::vec2(4.0, 0.0),
        egui::Align2::LEFT_BOTTOM,
        "0",
    );
    let caption = "vertex distance / diagonal";
    at(
        bar.center_bottom() + egui::vec2(0.0, 4.0),
        egui::Align2::CENTER_TOP,
        caption,
    );
}

/// Light text over the 3D view.
fn overlay_text(
    painter: &egui::Painter,
    at: egui::Pos2,
    align: egui::Align2,
    text: &str,
    size: f32,
) {
    let color = egui::Color32::from_gray(220);
    painter.text(at, align, text, egui::FontId::proportional(size), color);
}

/// `ramp` in shaders/viewer/mesh.wgsl.
pub fn ramp_color(t: f32) -> egui::Color32 {
    let x = t.clamp(0.0, 1.0);
    let c = |k: f32| ((1.5 - (4.0 * x - k).abs()).clamp(0.0, 1.0) * 255.0).round() as u8;
    egui::Color32::from_rgb(c(3.0), c(2.0), c(1.0))
}

/// A small file browser for Open…: egui has no native dialog, and the file-dialog crates lag
/// egui's releases (egui-file-dialog 0.15 needs egui 0.36).
struct Browser {
    dir: PathBuf,
    path_text: String,
    entries: Vec<(String, bool)>,
    error: Option<String>,
}

enum BrowserResult {
    Open(PathBuf),
    Close,
    Stay,
}

const MESH_EXTENSIONS: [&str; 5] = ["obj", "ply", "stl", "gltf", "glb"];

impl Browser {
    fn new(current: Option<PathBuf>) -> Browser {
        let dir = current
            .and_then(|p| p.parent().map(Path::to_path_buf))
            .filter(|d| d.is_dir())
            .or_else(|| std::env::current_dir().ok())
            .unwrap_or_else(|| PathBuf::from("."));
        let mut b = Browser {
            path_text: dir.display().to_string(),
            dir,
            entries: Vec::new(),
            error: None,
        };
        b.list();
        b
    }

    fn list(&mut self) {
        self.entries.clear();
        self.error = None;
        match std::fs::read_dir(&self.dir) {
            Ok(rd) => {
                for e in rd.flatten() {
                    let name = e.file_name().to_string_lossy().to_string();
                    let is_dir = e.path().is_dir();
                    let is_mesh = Path::new(&name)
                        .extension()
                        .and_then(|x| x.to_str())
                        .is_some_and(|x| {
                            MESH_EXTENSIONS.contains(&x.to_ascii_lowercase().as_str())
                        });
                    if (is_dir || is_mesh) && !name.starts_with('.') {
                        self.entries.push((name, is_dir));
                    }
                }
                self.entries.sort_by(|a, b| (!a.1, &a.0).cmp(&(!b.1, &b.0)));
            }
            Err(e) => self.error = Some(format!("{}: {e}", self.dir.display())),
        }
    }

    fn ui(&mut self, ctx: &egui::Context) -> BrowserResult {
        let mut result = BrowserResult::Stay;
        let mut open = true;
        egui::Window::new("Open a mesh")
            .open(&mut open)
            .default_size([420.0, 360.0])
            .show(ctx, |ui| {
                ui.horizontal(|ui| {
                    if ui.button("Up").on_hover_text("parent folder").clicked()
                        && let Some(p) = self.dir.parent()
                    {
                        self.dir = p.to_path_buf();
                        self.path_text = self.dir.display().to_string();
                        self.list();
                    }
                    let r = ui
                        .add(egui::TextEdit::singleline(&mut self.path_text).desired_width(300.0))
                        .on_hover_text("a folder or a mesh file")
                        .labelled_by(ui.label("path").id);
                    let go = ui.button("Go").clicked()
                        || (r.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter)));
                    if go {
                        let p = PathBuf::from(self.path_text.trim());
                        if p.is_dir() {
                            self.dir = p;
                            self.list();
                        } else {
                            result = BrowserResult::Open(p);
                        }
                    }
                });
                if let Some(e) = &self.error {
                    ui.colored_label(egui::Color32::LIGHT_RED, e);
                }
                ui.label(format!(
                    "{} (.obj .ply .stl .gltf .glb)",
                    self.dir.display()
                ));
                egui::ScrollArea::vertical()
                    .max_height(260.0)
                    .show(ui, |ui| {
                        let mut go_to = None;
                        for (name, is_dir) in &self.entries {
                            let label = if *is_dir {
                                format!("{name}/")
                            } else {
                                name.clone()
                            };
                            if ui.selectable_label(false, label).clicked() {
                                go_to = Some((self.dir.join(name), *is_dir));
                            }
                        }
                        match go_to {
                            Some((p, true)) => {
                                self.dir = p;
                                self.path_text = self.dir.display().to_string();
                                self.list();
                            }
                            Some((p, false)) => result = BrowserResult::Open(p),
                            None => {}
                        }
                    });
            });
        if !open {
            result = BrowserResult::Close;
        }
        result
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn larger_instances_draw_finer_levels() {
        let levels = 4;
        assert_eq!(lod_level(1e4, levels), 0, "large on screen: the original");
        let mut last = 0;
        for px in [500.0, 240.0, 200.0, 100.0, 50.0, 20.0, 1.0, 0.0] {
            let l = lod_level(px, levels);
            assert!(l >= last && l < levels, "{px} px: level {l}");
            last = l;
        }
        assert_eq!(last, levels - 1, "tiny is the coarsest");
        assert_eq!(lod_level(0.0, 1), 0, "one level only");
    }

    #[test]
    fn the_legend_ramp_is_the_shader_ramp() {
        // Blue at 0, green in the middle, red at 1, as `ramp` in shaders/viewer/mesh.wgsl.
        assert_eq!(ramp_color(0.0), egui::Color32::from_rgb(0, 0, 128));
        assert_eq!(ramp_color(0.5), egui::Color32::from_rgb(128, 255, 128));
        assert_eq!(ramp_color(1.0), egui::Color32::from_rgb(128, 0, 0));
    }
}
