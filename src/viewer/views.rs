//! The 3D view: pane textures drawn only when what they show changed, the overlays on them
//! (labels, the heatmap legend), the camera input, and the LOD scene's instances with the level
//! each draws.

use super::app::{DrawKey, View, ViewerApp};
use super::camera::Camera;
use super::lod::{LOD_GRID, LOD_SPACING, lod_level};
use super::render::{Mode, SceneMesh, Target};
use crate::error::Result;
use eframe::egui;
use glam::{Mat4, Vec3};

impl ViewerApp {
    /// The LOD scene's first view: low over one side of the grid, so that the nearest
    /// instances are large on screen and the farthest small — every level has its turn.
    pub(super) fn lod_home(&self) -> Camera {
        let half = LOD_GRID as f32 * LOD_SPACING * 0.5;
        let mut c = Camera {
            yaw: 0.6,
            pitch: 0.15,
            ..self.camera
        };
        // Low over the grid's edge, whatever the view's shape: the nearest instances in view
        // (about 4 diagonals away) draw the original, the far side the coarsest level.
        c.target = Vec3::ZERO;
        c.distance = half * 1.05;
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
        let full = levels[0].faces.max(1) as f64;
        let fractions: Vec<f64> = levels.iter().map(|l| l.faces as f64 / full).collect();
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
                    lod_level(px, &fractions)
                } else {
                    0
                };
                items.push((&levels[level], place));
            }
        }
        items
    }

    /// Draws the 3D view(s) into `rect` and handles the camera input on it.
    pub(super) fn view_ui(&mut self, ui: &mut egui::Ui) {
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
        // A refused draw becomes the status line, not a panic in wgpu's default handler.
        let scope = crate::compute::gpu::ErrorScope::push(&self.gpu.device);
        for (k, mesh) in shown.iter().enumerate() {
            let items: Vec<(&SceneMesh, Mat4)> = match (&lod_levels, lod) {
                (Some(levels), true) => self.lod_items(levels),
                _ => mesh
                    .map(|m| vec![(m, self.camera.model)])
                    .unwrap_or_default(),
            };
            let mut style = self.style;
            if style.mode == Mode::Texture && !mesh.is_some_and(|m| m.has_uvs)
                || style.mode == Mode::Color && !mesh.is_some_and(|m| m.has_colors)
            {
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
        if let Err(e) = scope.check("drawing the view") {
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
            let top = format!("{:.2e}", self.style.error_scale);
            legend(&painter, rect, [&top, "0"], "vertex distance / diagonal");
        }
        if self.style.mode == Mode::Quality {
            legend(&painter, rect, ["0°", "60°"], "smallest angle of each face");
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
}

/// A colour legend: the shader's ramp, its top (red) and bottom (blue) labelled.
fn legend(painter: &egui::Painter, rect: egui::Rect, ends: [&str; 2], caption: &str) {
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
        // The top of the bar is the ramp's red end.
        let r = egui::Rect::from_min_max(
            egui::pos2(bar.left(), bar.bottom() - t1 * h),
            egui::pos2(bar.right(), bar.bottom() - t0 * h),
        );
        painter.rect_filled(r, 0.0, ramp_color((t0 + t1) * 0.5));
    }
    let at = |p: egui::Pos2, align, text: &str| overlay_text(painter, p, align, text, 12.0);
    at(
        bar.right_top() + egui::vec2(4.0, 0.0),
        egui::Align2::LEFT_TOP,
        ends[0],
    );
    at(
        bar.right_bottom() + egui::vec2(4.0, 0.0),
        egui::Align2::LEFT_BOTTOM,
        ends[1],
    );
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_legend_ramp_is_the_shader_ramp() {
        // Blue at 0, green in the middle, red at 1, as `ramp` in shaders/viewer/mesh.wgsl.
        assert_eq!(ramp_color(0.0), egui::Color32::from_rgb(0, 0, 128));
        assert_eq!(ramp_color(0.5), egui::Color32::from_rgb(128, 255, 128));
        assert_eq!(ramp_color(1.0), egui::Color32::from_rgb(128, 0, 0));
    }
}
