//! The egui side panel (target, backend, view options, LOD scene, Pareto front, statistics,
//! save and screenshot), the keyboard shortcuts, the help window and dropped files.

use super::app::ViewerApp;
use super::camera::Up;
use super::file_browser::Browser;
use super::front::FrontClick;
use super::lod::LOD_GRID;
use super::render::Mode;
use crate::options::Backend;
use eframe::egui;

impl ViewerApp {
    /// Shortcuts, ignored while a text field has the keyboard.
    pub(super) fn shortcuts(&mut self, ctx: &egui::Context) {
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
        for (k, mode) in [
            Key::Num1,
            Key::Num2,
            Key::Num3,
            Key::Num4,
            Key::Num5,
            Key::Num6,
        ]
        .into_iter()
        .zip(Mode::ALL)
        {
            if pressed(k) && self.mode_available(mode) {
                self.style.mode = mode;
            }
        }
    }

    pub(super) fn controls_ui(&mut self, ui: &mut egui::Ui) {
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
            use crate::Method;
            ui.label("method");
            let methods = [
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
                    "vertex removal: keeps a subset of the input's vertices, unmoved; topology \
                     kept; exact target (cpu)",
                ),
            ];
            for (m, about) in methods {
                ui.selectable_value(&mut self.method, m, m.name())
                    .on_hover_text(about);
            }
            // hybrid runs on the CPU's cores here; decimate on one core (it is sequential).
            if self.method == Method::Decimate {
                self.backend = Backend::Cpu;
            } else if !self.gpu_draws(self.method) && self.backend == Backend::Gpu {
                self.backend = Backend::CpuParallel;
            }
        });
        ui.horizontal(|ui| {
            ui.label("backend");
            for b in [Backend::Gpu, Backend::CpuParallel, Backend::Cpu] {
                let enabled = if self.method == crate::Method::Decimate {
                    b == Backend::Cpu
                } else {
                    b != Backend::Gpu || self.gpu_draws(self.method)
                };
                ui.add_enabled_ui(enabled, |ui| {
                    ui.selectable_value(&mut self.backend, b, b.name());
                });
            }
        });
        // Which backend the window started on, and why (a software adapter is no GPU).
        ui.small(format!("started on {}", self.backend_why));
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
                } else if !ok && m == Mode::Color {
                    r.on_disabled_hover_text("the mesh has no vertex colours");
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
            ui.label(format!("from {}", self.lod_source));
            let ms = |v: Option<f64>| {
                v.map_or("-".into(), |s| {
                    format!("{:.1} ms ({:.1} FPS)", s * 1e3, 1.0 / s)
                })
            };
            ui.label(format!("LOD on: {}", ms(self.lod_frame[0])));
            ui.label(format!("LOD off: {}", ms(self.lod_frame[1])));
        }
        ui.separator();
        self.front_ui(ui);
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

    /// The side panel's front section: the search, the plot, the member shown and the LOD
    /// scene from the chosen ones.
    pub(super) fn front_ui(&mut self, ui: &mut egui::Ui) {
        ui.label("Pareto front (vertex removal)");
        ui.horizontal(|ui| {
            let can = self.job.is_none() && self.model.is_some();
            if ui
                .add_enabled(can, egui::Button::new("Search"))
                .on_hover_text(
                    "NSGA-II over which vertices to remove, as meshslim pareto: vertices \
                     against error; or open a .pareto.json it wrote",
                )
                .clicked()
            {
                self.search_front();
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
        let Some(front) = &self.front else { return };
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
            let can = chosen > 0 && self.job.is_none();
            if ui
                .add_enabled(
                    can,
                    egui::Button::new(format!("LOD scene from {chosen} chosen")),
                )
                .on_disabled_hover_text("Ctrl+click points of the front to choose them")
                .clicked()
            {
                self.lod_from_front();
            }
            if ui
                .add_enabled(chosen > 0, egui::Button::new("Clear"))
                .clicked()
                && let Some(f) = &mut self.front
            {
                f.chosen.clear();
            }
        });
        match click {
            Some(FrontClick::Show(k)) => self.show_member(k),
            Some(FrontClick::Choose(k)) => self.choose_member(k),
            None => {}
        }
    }

    /// Chooses member `k` for the LOD scene, or takes it back.
    pub fn choose_member(&mut self, k: usize) {
        if let Some(f) = &mut self.front
            && k < f.members.len()
            && !f.chosen.remove(&k)
        {
            f.chosen.insert(k);
        }
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

    pub(super) fn dropped_files(&mut self, ctx: &egui::Context) {
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
    (
        "1 2 3 4 5 6",
        "shaded, normals, error heatmap, texture, triangle quality, vertex colour",
    ),
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
    ("P", "screenshot of the 3D view to PNG"),
    ("F1", "this help"),
];

/// The two-sided error as the window shows it.
pub(super) fn error_text(error: Option<(f64, f64)>) -> String {
    match error {
        Some((mean, max)) => format!("mean error {mean:.2e}, max {max:.2e} of the diagonal"),
        None => "no faces left to measure".into(),
    }
}
