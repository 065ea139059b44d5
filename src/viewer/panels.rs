//! The side panel (target, backend, view options, LOD scene, Pareto front, statistics, save
//! and screenshot), the keyboard shortcuts, the help window and dropped files. The panel owns
//! its settings; it reads the scene, the job and the device, toggles how the view draws, and
//! asks for everything else as [`Action`]s, which the app carries out.

use super::camera::{Eye, Up};
use super::device::Device;
use super::file_browser::Browser;
use super::front::FrontClick;
use super::jobs::Jobs;
use super::lod::LOD_GRID;
use super::render::Mode;
use super::scene::Scene;
use super::views::View3d;
use crate::Method;
use crate::options::Backend;
use eframe::egui;
use std::path::PathBuf;

/// What the panel, the keys and dropped files ask the app to do.
#[derive(Debug, Clone, PartialEq)]
pub enum Action {
    Open(PathBuf),
    Simplify,
    Cancel,
    Save,
    Screenshot,
    MakeLod,
    SearchFront,
    /// Show member `k` of the front.
    ShowMember(usize),
    /// Choose member `k` for the LOD scene, or take it back.
    ChooseMember(usize),
    ClearChosen,
    LodFromFront,
    FrameToFit,
    ResetView,
    /// Draw the model with this axis up (None: its file's).
    SetUp(Option<Up>),
    /// Build the model's cluster DAG (a job) and draw it as its cut.
    MakeDag,
    /// Write the DAG beside the model as X.mslod.
    SaveDag,
    /// Put this in the status line (a key that could not do what it names says why).
    Say(String),
}

/// What the panel reads of the other owners.
pub(super) struct Seen<'a> {
    pub scene: &'a Scene,
    pub jobs: &'a Jobs,
    pub gpu: &'a Device,
}

/// The panel's own settings: the target, the method and backend, the search, the paths.
pub struct Panel {
    pub ratio: f64,
    pub(super) faces_text: String,
    pub backend: Backend,
    /// Why the window started on its backend (the panel says it): the library's `auto` choice,
    /// on the window's own adapter.
    pub backend_why: String,
    /// The algorithm (the clustering methods run on the CPU).
    pub method: Method,
    /// The search the window runs.
    pub pareto: crate::lod::ParetoOptions,
    /// Where the front's plot was last drawn.
    pub front_rect: Option<egui::Rect>,
    pub save_path: String,
    pub shot_path: String,
    pub show_help: bool,
    pub(super) browser: Option<Browser>,
    /// A mesh of at least this many faces is drawn as its cluster DAG, built as a job when it
    /// opens (0: never): drawn whole, a 4M-face scan takes a second a frame on a software
    /// rasterizer, as its cut at 1 px a fiftieth of that (docs/PERFORMANCE.md, the DAG's cut).
    pub auto_dag_faces: usize,
}

/// The window's default [`Panel::auto_dag_faces`].
pub const AUTO_DAG_FACES: usize = 1_000_000;

impl Panel {
    pub(super) fn new(backend: Backend, backend_why: String) -> Panel {
        Panel {
            ratio: 0.1,
            faces_text: String::new(),
            backend,
            backend_why,
            method: Method::Qem,
            pareto: super::front::window_search(),
            front_rect: None,
            save_path: String::new(),
            shot_path: "meshslim-view.png".into(),
            show_help: false,
            browser: None,
            auto_dag_faces: AUTO_DAG_FACES,
        }
    }

    /// The face-count field for `ratio` of `input_faces`.
    pub(super) fn set_ratio(&mut self, ratio: f64, input_faces: Option<usize>) {
        self.ratio = ratio.clamp(0.001, 1.0);
        if let Some(n) = input_faces {
            self.faces_text = ((n as f64 * self.ratio).round() as usize)
                .max(1)
                .to_string();
        }
    }

    /// Sets the algorithm; a method the gpu backend cannot draw moves it to `cpu-parallel`,
    /// and decimate (sequential) to `cpu`.
    pub(super) fn set_method(&mut self, method: Method, gpu: &Device) {
        self.method = method;
        if method == Method::Decimate {
            self.backend = Backend::Cpu;
        } else if !gpu.draws(method) && self.backend == Backend::Gpu {
            self.backend = Backend::CpuParallel;
        }
    }

    /// The target in faces, as the field holds it, or why it is not one.
    pub(super) fn target(&self) -> std::result::Result<usize, String> {
        match self.faces_text.trim().parse::<usize>() {
            Ok(n) if n >= 1 => Ok(n),
            _ => Err(format!(
                "target faces {:?}: write a whole number of at least 1",
                self.faces_text
            )),
        }
    }

    fn open_browser(&mut self, scene: &Scene) {
        self.browser = Some(Browser::new(
            scene.model.as_ref().and_then(|m| m.path.clone()),
        ));
    }

    /// Shortcuts, ignored while a text field has the keyboard.
    pub(super) fn shortcuts(
        &mut self,
        ctx: &egui::Context,
        view: &mut View3d,
        eye: &mut Eye,
        seen: &Seen,
    ) -> Vec<Action> {
        let mut act = Vec::new();
        if ctx.egui_wants_keyboard_input() {
            return act;
        }
        use egui::{Key, Modifiers};
        let pressed = |k| ctx.input_mut(|i| i.consume_key(Modifiers::NONE, k));
        let command = |k| ctx.input_mut(|i| i.consume_key(Modifiers::COMMAND, k));
        if command(Key::O) {
            self.open_browser(seen.scene);
        }
        if command(Key::S) {
            act.push(Action::Save);
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
                act.push(Action::Cancel);
            }
        }
        let keys = [
            (Key::F, Action::FrameToFit),
            (Key::R, Action::ResetView),
            (Key::P, Action::Screenshot),
            (Key::Enter, Action::Simplify),
        ];
        for (k, a) in keys {
            if pressed(k) {
                act.push(a);
            }
        }
        if pressed(Key::G) {
            eye.fly = !eye.fly;
        }
        if pressed(Key::X) {
            view.style.wireframe = !view.style.wireframe && view.renderer.has_wireframe();
        }
        if pressed(Key::M) {
            view.style.smooth = !view.style.smooth;
        }
        if pressed(Key::B) {
            view.side_by_side = !view.side_by_side;
        }
        if pressed(Key::O) {
            view.show_original = !view.show_original;
        }
        if pressed(Key::L) && seen.scene.lod.is_some() {
            view.lod_on = !view.lod_on;
        }
        let modes = [
            Key::Num1,
            Key::Num2,
            Key::Num3,
            Key::Num4,
            Key::Num5,
            Key::Num6,
            Key::Num7,
            Key::Num8,
        ];
        for (k, mode) in modes.into_iter().zip(Mode::ALL) {
            if pressed(k) {
                // A key that changes nothing says why, as the disabled button's hover does.
                match view.mode_unavailable(mode, seen.scene) {
                    None => view.style.mode = mode,
                    Some(why) => act.push(Action::Say(format!("{}: {why}", mode.label()))),
                }
            }
        }
        act
    }

    pub(super) fn controls_ui(
        &mut self,
        ui: &mut egui::Ui,
        view: &mut View3d,
        eye: &mut Eye,
        seen: &Seen,
    ) -> Vec<Action> {
        let mut act = Vec::new();
        let scene = seen.scene;
        ui.heading("meshslim");
        ui.horizontal(|ui| {
            if ui
                .button("Open...")
                .on_hover_text("Ctrl+O; or drop a file on the window")
                .clicked()
            {
                self.open_browser(scene);
            }
            if ui.button("Help").on_hover_text("F1").clicked() {
                self.show_help = !self.show_help;
            }
        });
        ui.separator();
        self.target_ui(ui, seen, &mut act);
        ui.separator();
        ui.label("View");
        ui.horizontal_wrapped(|ui| {
            for m in Mode::ALL {
                let ok = view.mode_available(m, scene);
                let r = ui.add_enabled(
                    ok,
                    egui::Button::selectable(view.style.mode == m, m.label()),
                );
                if r.clicked() {
                    view.style.mode = m;
                }
                if let Some(why) = view.mode_unavailable(m, scene) {
                    r.on_disabled_hover_text(why);
                }
            }
        });
        ui.checkbox(&mut view.style.smooth, "smooth shading (M)");
        ui.add_enabled_ui(view.renderer.has_wireframe(), |ui| {
            ui.checkbox(&mut view.style.wireframe, "wireframe (X)")
                .on_disabled_hover_text("this device cannot draw line polygons");
        });
        ui.checkbox(&mut view.side_by_side, "side by side (B)");
        ui.add_enabled_ui(scene.simplified.is_some() && !view.side_by_side, |ui| {
            ui.checkbox(&mut view.show_original, "show the original (O)");
        });
        ui.horizontal(|ui| {
            let file_up = scene.model.as_ref().map_or(Up::Y, |m| m.up_axis);
            let current = eye.up.unwrap_or(file_up);
            let mut chosen = current;
            egui::ComboBox::from_label("up")
                .selected_text(current.label())
                .show_ui(ui, |ui| {
                    for u in Up::ALL {
                        ui.selectable_value(&mut chosen, u, u.label());
                    }
                })
                .response
                .on_hover_text("this mesh's axis drawn up (default: its file's convention)");
            if chosen != current {
                act.push(Action::SetUp(Some(chosen)));
            }
        });
        ui.horizontal(|ui| {
            if ui.button("Fit").on_hover_text("F").clicked() {
                act.push(Action::FrameToFit);
            }
            if ui.button("Reset").on_hover_text("R").clicked() {
                act.push(Action::ResetView);
            }
            ui.checkbox(&mut eye.fly, "fly (G)");
        });
        if eye.fly {
            ui.add(
                egui::Slider::new(&mut eye.fly_speed, 0.05..=20.0)
                    .logarithmic(true)
                    .text("speed"),
            );
        }
        ui.separator();
        dag_ui(ui, view, eye, seen, &mut act);
        ui.separator();
        self.lod_ui(ui, view, seen, &mut act);
        ui.separator();
        self.front_ui(ui, seen, &mut act);
        ui.separator();
        let animating = seen.jobs.busy() || view.lod_shown(scene) || eye.fly || eye.moving;
        stats_ui(ui, view, seen, animating);
        ui.separator();
        ui.horizontal(|ui| {
            let l = ui.label("mesh");
            ui.add(egui::TextEdit::singleline(&mut self.save_path).desired_width(150.0))
                .labelled_by(l.id);
            if ui
                .add_enabled(scene.simplified.is_some(), egui::Button::new("Save"))
                .on_hover_text("Ctrl+S")
                .clicked()
            {
                act.push(Action::Save);
            }
        });
        ui.horizontal(|ui| {
            let l = ui.label("PNG");
            ui.add(egui::TextEdit::singleline(&mut self.shot_path).desired_width(150.0))
                .labelled_by(l.id);
            if ui
                .button("Screenshot")
                .on_hover_text("P: what the 3D view shows, both panes side by side")
                .clicked()
            {
                act.push(Action::Screenshot);
            }
        });
        act
    }

    /// The target (ratio and faces), the method and backend, Simplify and Cancel, the job's
    /// progress.
    fn target_ui(&mut self, ui: &mut egui::Ui, seen: &Seen, act: &mut Vec<Action>) {
        let input_faces = seen.scene.model.as_ref().map(|m| m.faces());
        ui.label("Target");
        // Three decades of ratio want room: at egui's 100 points, 0.1 to 0.002 took 50.
        ui.spacing_mut().slider_width = 190.0;
        let old_ratio = self.ratio;
        ui.add(
            egui::Slider::new(&mut self.ratio, 0.001..=1.0)
                .logarithmic(true)
                .text("ratio"),
        );
        if self.ratio != old_ratio {
            self.set_ratio(self.ratio, input_faces);
        }
        ui.horizontal(|ui| {
            let l = ui.label("faces");
            let r = ui
                .add(egui::TextEdit::singleline(&mut self.faces_text).desired_width(90.0))
                .labelled_by(l.id);
            if r.changed()
                && let Ok(n) = self.faces_text.trim().parse::<usize>()
                && let Some(f) = input_faces.filter(|&f| f > 0)
            {
                self.ratio = (n as f64 / f as f64).clamp(0.001, 1.0);
            }
            // Enter in the field simplifies at once (it also gives the keyboard back).
            if r.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter)) {
                act.push(Action::Simplify);
            }
        });
        ui.horizontal(|ui| {
            ui.label("method");
            let mut method = self.method;
            for (m, about) in METHODS {
                ui.selectable_value(&mut method, m, m.name())
                    .on_hover_text(about);
            }
            // hybrid runs on the CPU's cores here; decimate on one core (it is sequential).
            self.set_method(method, seen.gpu);
        });
        ui.horizontal(|ui| {
            ui.label("backend");
            for b in [Backend::Gpu, Backend::CpuParallel, Backend::Cpu] {
                let enabled = if self.method == Method::Decimate {
                    b == Backend::Cpu
                } else {
                    b != Backend::Gpu || seen.gpu.draws(self.method)
                };
                ui.add_enabled_ui(enabled, |ui| {
                    ui.selectable_value(&mut self.backend, b, b.name());
                });
            }
        });
        // Which backend the window started on, and why (a software adapter is no GPU).
        ui.small(format!("started on {}", self.backend_why));
        let job = seen.jobs.running();
        ui.horizontal(|ui| {
            let simplify = egui::Button::new("Simplify");
            if ui
                .add_enabled(job.is_none() && input_faces.is_some(), simplify)
                .on_hover_text("Enter")
                .clicked()
            {
                act.push(Action::Simplify);
            }
            let cancel = egui::Button::new("Cancel");
            if ui
                .add_enabled(job.is_some(), cancel)
                .on_hover_text("Esc")
                .clicked()
            {
                act.push(Action::Cancel);
            }
        });
        if let Some(j) = job {
            ui.add(egui::ProgressBar::new(j.progress()).text(format!(
                "{} - {:.1} s",
                match j.phase() {
                    p if p.is_empty() => j.label.clone(),
                    p => p,
                },
                j.started.elapsed().as_secs_f64()
            )));
        }
    }

    /// The LOD scene's section: make the levels, show the grid, LOD on or off, frame times.
    fn lod_ui(&mut self, ui: &mut egui::Ui, view: &mut View3d, seen: &Seen, act: &mut Vec<Action>) {
        ui.label("LOD scene");
        let scene = seen.scene;
        ui.horizontal(|ui| {
            let can = !seen.jobs.busy() && scene.model.is_some() && seen.gpu.sim.is_some();
            if ui
                .add_enabled(can, egui::Button::new("Make levels"))
                .clicked()
            {
                act.push(Action::MakeLod);
            }
            ui.add_enabled_ui(scene.lod.is_some(), |ui| {
                if ui
                    .checkbox(&mut view.lod_scene, format!("{0}x{0} grid", LOD_GRID))
                    .changed()
                {
                    act.push(Action::ResetView);
                }
                ui.checkbox(&mut view.lod_on, "LOD (L)");
            });
        });
        if let Some(levels) = &scene.lod {
            let f: Vec<String> = levels.iter().map(|l| l.faces.to_string()).collect();
            ui.label(format!("levels: {} faces", f.join(" / ")));
            ui.label(format!("from {}", scene.lod_source));
            let ms = |v: Option<f64>| {
                v.map_or("-".into(), |s| {
                    format!("{:.1} ms ({:.1} FPS)", s * 1e3, 1.0 / s)
                })
            };
            ui.label(format!("LOD on: {}", ms(view.lod_frame[0])));
            ui.label(format!("LOD off: {}", ms(view.lod_frame[1])));
        }
    }

    /// The side panel's front section: the search, the plot, the member shown and the LOD
    /// scene from the chosen ones.
    fn front_ui(&mut self, ui: &mut egui::Ui, seen: &Seen, act: &mut Vec<Action>) {
        ui.label("Pareto front (vertex removal)");
        let idle = !seen.jobs.busy();
        ui.horizontal(|ui| {
            if ui
                .add_enabled(
                    idle && seen.scene.model.is_some(),
                    egui::Button::new("Search"),
                )
                .on_hover_text(
                    "NSGA-II over which vertices to remove, as meshslim pareto: vertices \
                     against error; or open a .pareto.json it wrote",
                )
                .clicked()
            {
                act.push(Action::SearchFront);
            }
            ui.add(
                egui::DragValue::new(&mut self.pareto.population)
                    .range(2..=1000)
                    .prefix("pop "),
            );
            ui.add(
                egui::DragValue::new(&mut self.pareto.generations)
                    .range(0..=500)
                    .prefix("gen "),
            );
        });
        let Some(front) = &seen.scene.front else {
            return;
        };
        let (click, rect) = front.plot_ui(ui);
        self.front_rect = Some(rect);
        ui.label(format!(
            "{} members; click one to show it, Ctrl+click to choose levels",
            front.members.len()
        ));
        if let Some(k) = front.selected {
            let m = &front.members[k];
            ui.label(format!(
                "shown: {} vertices, {} faces, error {:.3e}",
                m.vertices, m.faces, m.error
            ));
        }
        let chosen = front.chosen.len();
        ui.horizontal(|ui| {
            let from = egui::Button::new(format!("LOD scene from {chosen} chosen"));
            if ui
                .add_enabled(chosen > 0 && idle, from)
                .on_disabled_hover_text("Ctrl+click points of the front to choose them")
                .clicked()
            {
                act.push(Action::LodFromFront);
            }
            if ui
                .add_enabled(chosen > 0, egui::Button::new("Clear"))
                .clicked()
            {
                act.push(Action::ClearChosen);
            }
        });
        match click {
            Some(FrontClick::Show(k)) => act.push(Action::ShowMember(k)),
            Some(FrontClick::Choose(k)) => act.push(Action::ChooseMember(k)),
            None => {}
        }
    }

    pub(super) fn help_ui(&mut self, ctx: &egui::Context) {
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
}

/// A file dropped on the window, to open.
pub(super) fn dropped_file(ctx: &egui::Context) -> Option<Action> {
    ctx.input(|i| i.raw.dropped_files.first().map(|f| f.path().to_path_buf()))
        .map(Action::Open)
}

/// The methods the panel offers, each with what it is for.
const METHODS: [(Method, &str); 5] = [
    (
        Method::Qem,
        "edge collapse: best surface, exact target, topology kept",
    ),
    (
        Method::Cluster,
        "uniform grid: fastest, within 5%, topology may change",
    ),
    (
        Method::FloatingCell,
        "floating cells: keeps tips and corners, within 5%, topology may change",
    ),
    (
        Method::Hybrid,
        "grid to 2x the target + 20k faces, then edge collapse: near-qem quality, faster",
    ),
    (
        Method::Decimate,
        "vertex removal: keeps a subset of the input's vertices, unmoved; topology kept; exact \
         target (cpu)",
    ),
];

/// A DAG's threshold and what its cut draws from the current view (counted by the cut's twin
/// on the host: the device's counts are not read back while drawing).
fn dag_ui(ui: &mut egui::Ui, view: &mut View3d, eye: &Eye, seen: &Seen, act: &mut Vec<Action>) {
    let scene = seen.scene;
    ui.label("Cluster DAG");
    ui.horizontal(|ui| {
        let can = !seen.jobs.busy() && scene.model.is_some();
        let make = ui
            .add_enabled(can, egui::Button::new("Make DAG"))
            .on_hover_text(
                "meshlets of 128 triangles, each group simplified to half, on the panel's backend",
            );
        if make.clicked() {
            act.push(Action::MakeDag);
        }
        let save = ui
            .add_enabled(scene.dag_built.is_some(), egui::Button::new("Save DAG"))
            .on_hover_text("as X.mslod beside the mesh");
        if save.clicked() {
            act.push(Action::SaveDag);
        }
    });
    let Some(dag) = &scene.dag else { return };
    ui.add(
        egui::Slider::new(&mut view.pixels, 0.25..=16.0)
            .logarithmic(true)
            .text("error (pixels)"),
    )
    .on_hover_text("each cluster is drawn at the coarsest level whose error projects under this");
    let d = dag.lock().unwrap_or_else(|p| p.into_inner());
    let [in_cut, drawn, triangles, _] = d.counts(&eye.camera, view.pane_size(), view.pixels);
    ui.label(format!(
        "cut: {in_cut} clusters, {drawn} in view, {triangles} triangles drawn"
    ));
}

/// The device, the frame time, the counts before and after, and the result's run.
fn stats_ui(ui: &mut egui::Ui, view: &View3d, seen: &Seen, animating: bool) {
    ui.label(format!("device: {}", seen.gpu.adapter));
    // The time between the pictures the user sees, while the window draws on its own (a few
    // times a second during a job, continuously in the LOD scene and fly mode), while the camera
    // moves (a drag draws a frame per move) or a picture has been drawing for long (a drag on a
    // large mesh). Otherwise it draws on input alone, and the gap between frames is the user's,
    // not the renderer's.
    // A poll that does not wait runs the callbacks of the renders the device has finished.
    let _ = seen.gpu.device.poll(wgpu::PollType::Poll);
    let now = std::time::Instant::now();
    ui.label(match view.clock.shown_gap(now) {
        Some(dt) if animating || view.clock.stalled(now) => {
            format!(
                "frames shown: {:.1} ms apart ({:.1} FPS)",
                dt * 1e3,
                1.0 / dt
            )
        }
        _ => "frames: drawn on input (idle)".into(),
    });
    let Some(m) = &seen.scene.model else { return };
    let simplified = seen.scene.simplified.as_ref();
    egui::Grid::new("stats").striped(true).show(ui, |ui| {
        ui.label("");
        ui.label("faces");
        ui.label("vertices");
        ui.end_row();
        ui.label("before");
        ui.label(m.faces().to_string());
        ui.label(m.mesh.positions.len().to_string());
        ui.end_row();
        if let Some(s) = simplified {
            ui.label("after");
            ui.label(s.report.output_faces.to_string());
            ui.label(s.report.output_vertices.to_string());
            ui.end_row();
        }
    });
    let Some(s) = simplified else { return };
    match &s.made_by {
        Some(m) => ui.label(m),
        None => ui.label(format!(
            "{}: {:.3} s, stop: {:?}",
            s.report.backend.name(),
            s.seconds,
            s.report.stop_reason
        )),
    };
    ui.label(error_text(s.error));
    if let Some(r) = &s.report.rounds {
        // Folded: a GPU run's ~30 stage rows would push Save and Screenshot out of sight.
        egui::CollapsingHeader::new(format!("{} rounds: time per stage", r.rounds))
            .default_open(false)
            .show(ui, |ui| {
                egui::Grid::new("stages").striped(true).show(ui, |ui| {
                    for (name, secs) in &r.stage_seconds.0 {
                        ui.label(name);
                        ui.label(format!("{:.1} ms", secs * 1e3));
                        ui.end_row();
                    }
                });
            });
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
    (
        "1 2 3 4 5 6",
        "shaded, normals, error heatmap, texture, triangle quality, vertex colour",
    ),
    ("7 8", "a DAG's cut: by cluster, by level"),
    ("M", "smooth / flat shading"),
    ("X", "wireframe overlay"),
    ("B", "side by side: original | simplified"),
    ("O", "show the original instead of the result"),
    ("L", "LOD on/off in the LOD scene"),
    (
        "click a front point",
        "show that member of the Pareto front",
    ),
    ("Ctrl+click", "choose a front member for the LOD scene"),
    ("Enter", "simplify to the target"),
    ("Esc", "cancel the running job (or close this)"),
    ("Ctrl+O", "open a mesh (or drop a file on the window)"),
    ("Ctrl+S", "save the simplified mesh"),
    (
        "P",
        "screenshot of the 3D view (both panes side by side) to PNG",
    ),
    ("F1", "this help"),
];

/// The two-sided error as the window shows it.
pub(super) fn error_text(error: Option<(f64, f64)>) -> String {
    match error {
        Some((mean, max)) => {
            format!("two-sided distance: mean {mean:.2e}, max {max:.2e} of the diagonal")
        }
        None => "no faces left to measure".into(),
    }
}
