//! The interactive viewer: an eframe app on eframe's wgpu device. The simplifier's pipelines are
//! made on that device ([`ViewerApp::new`]); a `gpu` simplification leaves its result in the
//! rounds' own buffers, and [`super::Renderer`] binds those buffers as they are, drawing with the
//! indirect arguments the rounds wrote — nothing goes back through the CPU to be drawn. Loading,
//! simplifying and making levels of detail run on worker threads; the UI keeps drawing frames
//! (their time is shown) and can cancel them.
//!
//! The state has one owner per concern, each its own type: the device and its pipelines
//! (`device`), what is shown (`scene::Scene`), the 3D view (`views::View3d`), the camera
//! (`camera::Eye`), the side panel's settings (`panels::Panel`) and the worker job
//! (`jobs::Jobs`). This file holds them, the set-up, and the frame; `actions` carries out what
//! the panel and the keys ask for, the one place that changes several owners at once.

use super::camera::Eye;
use super::device::Device;
use super::file_browser::BrowserResult;
use super::jobs::Jobs;
// The tests name the levels' ratios through the app, as before the LOD scene had a file.
pub use super::lod::LOD_RATIOS;
use super::panels::{self, Action, Panel, Seen};
use super::render::{Mode, Renderer, Style};
use super::scene::{Model, Scene};
use super::views::View3d;
use crate::error::{Error, Result};
use crate::options::Backend;
use eframe::egui;
use eframe::egui_wgpu;
use std::path::PathBuf;
use std::sync::Arc;

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

pub struct ViewerApp {
    pub(super) gpu: Device,
    pub scene: Scene,
    pub view: View3d,
    pub eye: Eye,
    pub panel: Panel,
    pub jobs: Jobs,
    /// The status line: what was done last, or why it failed.
    pub status: String,
}

/// The device descriptor eframe (and the viewer's tests) create their device with: the same as
/// the simplifier's own, so that million-triangle meshes fit and the wireframe can be drawn.
pub fn wgpu_setup() -> egui_wgpu::WgpuSetup {
    let mut setup = egui_wgpu::WgpuSetupCreateNew::without_display_handle();
    setup.instance_descriptor.backends = wgpu::Backends::PRIMARY;
    setup.power_preference = wgpu::PowerPreference::HighPerformance;
    setup.device_descriptor = Arc::new(crate::compute::context::device_descriptor);
    egui_wgpu::WgpuSetup::CreateNew(setup)
}

impl ViewerApp {
    /// Made by eframe (or a test harness) with its wgpu render state: the simplifier's
    /// pipelines are created on that same device.
    pub fn new(cc: &eframe::CreationContext<'_>, start: Start) -> Result<ViewerApp> {
        let rs = cc.wgpu_render_state.as_ref().ok_or_else(|| {
            Error::Gpu("the window has no wgpu device (eframe runs on wgpu here)".into())
        })?;
        let (gpu, (backend, backend_why), status) = Device::new(rs);
        let scope = crate::compute::gpu::ErrorScope::push(&rs.device);
        let renderer = Renderer::new(&rs.device, &rs.queue);
        scope.check("making the renderer")?;
        let mut app = ViewerApp {
            gpu,
            scene: Scene::default(),
            view: View3d::new(renderer),
            eye: Eye::default(),
            panel: Panel::new(backend, backend_why),
            jobs: Jobs::new(cc.egui_ctx.clone()),
            status,
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
        let faces = self.scene.model.as_ref().map(|m| m.faces());
        self.panel.set_ratio(ratio, faces);
    }

    /// How the view draws (the command line's --smooth, --wireframe, and --mode when it was
    /// given: `None` keeps the mode the mesh picked, vertex colours for a painted one).
    pub fn set_style(&mut self, style: Style, mode: Option<Mode>) {
        let picked = self.view.style.mode;
        self.view.style = Style {
            mode: mode.unwrap_or(picked),
            ..style
        };
        if !self.mode_available(style.mode) {
            self.view.style.mode = Mode::Shaded;
        }
        if !self.view.renderer.has_wireframe() {
            self.view.style.wireframe = false;
        }
    }

    /// The faces from which a mesh opened is drawn as its cluster DAG (0: never); the model
    /// shown is checked again against it.
    pub fn set_auto_dag(&mut self, faces: usize) {
        self.panel.auto_dag_faces = faces;
        self.scene.dag_unchecked = self.scene.model.is_some();
    }

    /// The target in faces, as the face-count field holds it.
    pub fn set_target_faces(&mut self, faces: usize) {
        self.panel.faces_text = faces.to_string();
    }

    /// Sets the algorithm; a method the gpu backend cannot draw moves it to `cpu-parallel`.
    pub fn set_method(&mut self, method: crate::Method) {
        self.panel.set_method(method, &self.gpu);
    }

    pub fn mode_available(&self, mode: Mode) -> bool {
        self.view.mode_available(mode, &self.scene)
    }

    /// The pixels of pane `k` of the 3D view as last drawn (RGBA8 rows) and its size.
    pub fn pane_rgba(&self, k: usize) -> Result<(Vec<u8>, (u32, u32))> {
        self.view.pane_rgba(&self.gpu, k)
    }

    /// How many instances of the LOD scene draw each level (with the current camera).
    pub fn lod_histogram(&self) -> Vec<usize> {
        self.view.lod_histogram(&self.scene, &self.eye.camera)
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

    /// The backend the next simplification runs on.
    pub fn backend(&self) -> Backend {
        self.panel.backend
    }
}

impl eframe::App for ViewerApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        self.view.tick(&self.scene);
        self.poll_job();
        self.auto_dag();
        let mut actions: Vec<Action> = panels::dropped_file(&ctx).into_iter().collect();
        let seen = Seen {
            scene: &self.scene,
            jobs: &self.jobs,
            gpu: &self.gpu,
        };
        actions.extend(
            self.panel
                .shortcuts(&ctx, &mut self.view, &mut self.eye, &seen),
        );
        let (panel, view, eye) = (&mut self.panel, &mut self.view, &mut self.eye);
        egui::Panel::left("controls")
            .resizable(true)
            .default_size(270.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| {
                    actions.extend(panel.controls_ui(ui, view, eye, &seen));
                });
            });
        egui::Panel::bottom("status").show(ui, |ui| {
            ui.label(&self.status);
        });
        let mut drawn = Ok(());
        egui::CentralPanel::default()
            .frame(egui::Frame::NONE)
            .show(ui, |ui| {
                drawn = view.ui(ui, &self.gpu, &self.scene, eye);
            });
        if let Err(e) = drawn {
            self.status = e;
        }
        self.panel.help_ui(&ctx);
        if let Some(b) = &mut self.panel.browser {
            match b.ui(&ctx) {
                BrowserResult::Open(p) => {
                    self.panel.browser = None;
                    actions.push(Action::Open(p));
                }
                BrowserResult::Close => self.panel.browser = None,
                BrowserResult::Stay => {}
            }
        }
        for a in actions {
            self.apply(a);
        }
        // Frames on and on in the LOD scene (it measures them) and in fly mode. While a job
        // runs, a few per second for the progress bar: input still gets a frame at once, but
        // idle frames would take turns with the job's passes on the GPU queue (on lavapipe,
        // continuous frames made a 1M-face run three times slower).
        if self.view.lod_shown(&self.scene) || self.eye.fly {
            ctx.request_repaint();
        } else if self.jobs.busy() {
            ctx.request_repaint_after(JOB_FRAME_INTERVAL);
        }
    }
}
