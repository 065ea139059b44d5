//! The interactive viewer: an eframe app on eframe's wgpu device. The simplifier's pipelines are
//! made on that device ([`ViewerApp::new`]); a `gpu` simplification leaves its result in the
//! rounds' own buffers, and [`Renderer`] binds those buffers as they are, drawing with the
//! indirect arguments the rounds wrote — nothing goes back through the CPU to be drawn. Loading,
//! simplifying and making levels of detail run on worker threads; the UI keeps drawing frames
//! (their time is shown) and can cancel them.
//!
//! This file holds the app's state, its set-up and the eframe `App` that runs each frame; the
//! rest of its methods live beside it: `jobs` (work on worker threads), `views` (the 3D view and
//! the LOD scene's instances), `panels` (the side panel, shortcuts, help), with `lod` the LOD
//! scene's layout and `file_browser` the Open dialog.

use super::camera::{Camera, Up};
use super::file_browser::{Browser, BrowserResult};
// The tests name the levels' ratios through the app, as before the LOD scene had a file.
use super::front::Front;
pub use super::lod::LOD_RATIOS;
use super::render::{Mode, Renderer, SceneMesh, Style, Target};
use super::scene::{Loaded, Model, Simplified};
use crate::error::{Error, Result};
use crate::gpu::GpuSimplifier;
use crate::options::{Backend, Cancel};
use eframe::egui;
use eframe::egui_wgpu;
use glam::Vec3;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::mpsc;
use std::time::Instant;

/// How often the window redraws on its own while a job runs.
const JOB_FRAME_INTERVAL: std::time::Duration = std::time::Duration::from_millis(250);

/// What the window starts with.
pub enum Start {
    Nothing,
    Model(Model),
    /// Read on a worker thread once the window is up: a mesh, or a `meshslim lods` or
    /// `meshslim pareto` manifest with the mesh it names.
    Open(PathBuf),
    /// A manifest whose mesh the command line has made (a `builtin:` input).
    Manifest(PathBuf, Model),
}

/// The device the window draws with, and the simplifier's pipelines on it.
pub(super) struct Gpu {
    pub(super) device: wgpu::Device,
    pub(super) queue: wgpu::Queue,
    pub(super) egui_renderer: Arc<egui::mutex::RwLock<egui_wgpu::Renderer>>,
    pub(super) sim: Option<Arc<GpuSimplifier>>,
    /// `--method cluster`'s pipelines on the same device, so its result is drawn from the
    /// buffers the build wrote.
    pub(super) clusterer: Option<Arc<crate::cluster::gpu::GpuClusterer>>,
    pub(super) adapter: String,
}

/// A finished job's result (boxed: the variants differ in size by hundreds of bytes).
pub(super) enum Done {
    Loaded(Result<Box<Loaded>>),
    Simplified(Result<Box<Simplified>>),
    Lod(Result<Vec<SceneMesh>>),
    /// A search's front.
    Front(Result<Box<Front>>),
    /// Member `k` of the front, ready to show.
    Member(Result<Box<(usize, Simplified)>>),
}

/// Work on a worker thread.
pub struct Job {
    pub label: String,
    pub(super) progress: Arc<AtomicU32>,
    /// What the job is doing now, when it says.
    pub(super) phase: Arc<std::sync::Mutex<String>>,
    pub(super) cancel: Cancel,
    pub(super) rx: mpsc::Receiver<Done>,
    pub(super) started: Instant,
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
pub(super) struct DrawKey {
    pub(super) camera: Camera,
    pub(super) style: Style,
    pub(super) split: bool,
    pub(super) show_original: bool,
    pub(super) lod_on: bool,
    pub(super) sizes: Vec<(u32, u32)>,
    pub(super) generation: u64,
}

/// A texture the 3D view draws into and egui shows.
pub(super) struct View {
    pub(super) target: Target,
    pub(super) id: egui::TextureId,
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
    pub(super) gpu: Gpu,
    pub(super) renderer: Renderer,
    pub model: Option<Arc<Model>>,
    pub original: Option<Arc<SceneMesh>>,
    pub simplified: Option<Simplified>,
    /// The LOD scene's levels, the original first.
    pub lod: Option<Vec<SceneMesh>>,
    /// Where the levels came from (shown in the panel).
    pub lod_source: String,
    /// A Pareto front of the model: searched here or read from a manifest.
    pub front: Option<Front>,
    /// The search the window runs.
    pub pareto: crate::lod::ParetoOptions,
    /// Where the front's plot was last drawn.
    pub front_rect: Option<egui::Rect>,
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
    pub(super) faces_text: String,
    pub backend: Backend,
    /// Why the window started on its backend (the panel says it): the library's `auto` choice,
    /// on the window's own adapter.
    pub backend_why: String,
    /// The algorithm (the clustering methods run on the CPU).
    pub method: crate::Method,
    pub fly: bool,
    /// Fly speed in diagonals per second.
    pub fly_speed: f32,
    pub(super) views: Vec<View>,
    pub clock: FrameClock,
    /// Smoothed frame seconds of the LOD scene with LOD on and off, as last measured.
    pub lod_frame: [Option<f64>; 2],
    /// Frames drawn since the start (the tests count them while a job runs).
    pub frames: u64,
    /// Times the 3D view was rendered (only when what it shows changed).
    pub renders: u64,
    /// Bumped whenever a mesh or texture to show changes.
    pub(super) generation: u64,
    pub(super) drawn: Option<DrawKey>,
    pub status: String,
    pub show_help: bool,
    pub(super) browser: Option<Browser>,
    pub save_path: String,
    pub shot_path: String,
    pub texture_note: Option<String>,
    /// The axis drawn up for every mesh, when the user chose one; else each file's convention.
    pub up: Option<Up>,
    pub(super) ctx: egui::Context,
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
        // One pipeline cache for the window's device: the rounds and the clustering share it.
        let cache = crate::compute::gpu::Pipelines::new(&rs.device);
        let (sim, status) = match GpuSimplifier::on(&cache, &rs.queue) {
            Ok(s) => (Some(Arc::new(s)), String::new()),
            Err(e) => (
                None,
                format!("gpu backend unavailable on this device ({e}); cpu backends work"),
            ),
        };
        // The library's `auto` choice on the window's own adapter: a software rasterizer
        // (lavapipe, llvmpipe) runs the rounds slower than the CPU's cores (the 1M scan to 1%:
        // 33 s on gpu against 4.4 s on cpu), so the window starts on cpu-parallel there, gpu one
        // click away.
        let info = rs.adapter.get_info();
        let (backend, backend_why) = match &sim {
            Some(_) if info.device_type != wgpu::DeviceType::Cpu => {
                (Backend::Gpu, format!("gpu on {}", info.name))
            }
            Some(_) => (
                Backend::CpuParallel,
                format!(
                    "cpu-parallel: the adapter, {}, is a software rasterizer, slower than the \
                     CPU's cores (gpu runs on it when chosen)",
                    info.name
                ),
            ),
            None => (
                Backend::CpuParallel,
                "cpu-parallel: the gpu backend is unavailable on this device".into(),
            ),
        };
        let clusterer = sim.as_ref().and_then(|_| {
            crate::cluster::gpu::GpuClusterer::on(&cache, &rs.queue)
                .ok()
                .map(Arc::new)
        });
        let scope = crate::compute::gpu::ErrorScope::push(&rs.device);
        let renderer = Renderer::new(&rs.device, &rs.queue);
        scope.check("making the renderer")?;
        let mut app = ViewerApp {
            gpu: Gpu {
                device: rs.device.clone(),
                queue: rs.queue.clone(),
                egui_renderer: rs.renderer.clone(),
                adapter: rs.adapter.get_info().name,
                sim: sim.clone(),
                clusterer,
            },
            renderer,
            model: None,
            original: None,
            simplified: None,
            lod: None,
            lod_source: String::new(),
            front: None,
            pareto: super::front::window_search(),
            front_rect: None,
            job: None,
            camera: Camera::default(),
            style: Style::default(),
            side_by_side: false,
            show_original: false,
            lod_scene: false,
            lod_on: true,
            ratio: 0.1,
            faces_text: String::new(),
            backend,
            backend_why,
            method: crate::Method::Qem,
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
            Start::Manifest(p, m) => app.open_with(p, Some(m)),
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

    /// How the view draws (the command line's --smooth, --wireframe, and --mode when it was
    /// given: `None` keeps the mode the mesh picked, vertex colours for a painted one).
    pub fn set_style(&mut self, style: Style, mode: Option<Mode>) {
        let picked = self.style.mode;
        self.style = Style {
            mode: mode.unwrap_or(picked),
            ..style
        };
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

    /// Sets the algorithm; a method the gpu backend cannot draw moves it to `cpu-parallel`.
    pub fn set_method(&mut self, method: crate::Method) {
        self.method = method;
        if !self.gpu_draws(method) && self.backend == Backend::Gpu {
            self.backend = Backend::CpuParallel;
        }
    }

    /// The gpu backend runs `method` on the window's device and leaves its result there: the
    /// rounds (`qem`), `cluster` and `floating-cell`; `hybrid` runs on the CPU's cores here.
    pub(super) fn gpu_draws(&self, method: crate::Method) -> bool {
        match method {
            crate::Method::Qem => self.gpu.sim.is_some(),
            crate::Method::Cluster | crate::Method::FloatingCell => self.gpu.clusterer.is_some(),
            _ => false,
        }
    }

    pub fn has_gpu_backend(&self) -> bool {
        self.gpu.sim.is_some()
    }

    pub(super) fn set_model(&mut self, m: Model, original: SceneMesh) {
        self.generation += 1;
        // Framed again at the next frame, for the view's real shape.
        self.drawn = None;
        self.texture_note = m.texture_note.clone();
        let tex = m.texture.as_ref().map(|i| (&i.rgba[..], i.size));
        let max = self.gpu.device.limits().max_texture_dimension_2d;
        let scope = crate::compute::gpu::ErrorScope::push(&self.gpu.device);
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
        if let Err(e) = scope.check("uploading the texture") {
            self.texture_note = Some(e.to_string());
        }
        if self.style.mode == Mode::Texture && !self.renderer.has_texture() {
            self.style.mode = Mode::Shaded;
        }
        // A painted scan is looked at for its colours: shown by default, and a mesh without
        // them falls back to shading.
        match (original.has_colors, self.style.mode) {
            (true, Mode::Shaded) => self.style.mode = Mode::Color,
            (false, Mode::Color) => self.style.mode = Mode::Shaded,
            _ => {}
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
        self.front = None;
        self.front_rect = None;
    }

    pub(super) fn aspect(&self) -> f32 {
        self.views.first().map_or(4.0 / 3.0, |v| {
            v.target.size.0 as f32 / v.target.size.1 as f32
        })
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
        let png = super::render::encode_png(&rgba, size)?;
        crate::io::write_atomic(path, |w| std::io::Write::write_all(w, &png))
    }

    pub fn mode_available(&self, mode: Mode) -> bool {
        match mode {
            Mode::Texture => {
                self.renderer.has_texture() && self.original.as_ref().is_some_and(|o| o.has_uvs)
            }
            Mode::Color => self.original.as_ref().is_some_and(|o| o.has_colors),
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
}

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
