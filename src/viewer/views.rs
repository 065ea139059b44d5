//! The 3D view: its panes' textures, drawn only when what they show changed, the overlays on
//! them (labels, the heatmap legend), the frame clock, and the LOD scene's instances with the
//! level each draws. It reads the scene and moves the camera; it changes nothing else.

use super::camera::{Camera, Eye};
use super::device::Device;
use super::lod::{LOD_GRID, LOD_SPACING, lod_level};
use super::render::{Mode, Renderer, SceneMesh, Style, Target};
use super::scene::Scene;
use crate::error::{Error, Result};
use eframe::egui;
use glam::{Mat4, Vec3};
use std::time::Instant;

/// What a drawn frame showed: the panes are drawn again only when it changes.
#[derive(Debug, Clone, PartialEq)]
struct DrawKey {
    camera: Camera,
    style: Style,
    split: bool,
    show_original: bool,
    lod_on: bool,
    sizes: Vec<(u32, u32)>,
    generation: u64,
    pixels: f64,
}

/// A texture the 3D view draws into and egui shows.
struct Pane {
    target: Target,
    id: egui::TextureId,
}

/// Frame time, smoothed: the window's frames (`smoothed`, egui's cadence) and the frames the
/// user sees (`shown`, the 3D view's renders as the device finishes them). On a slow device the
/// two differ: lavapipe drew a 4.3M-face scan about once a second while egui's frames came at
/// 15 FPS, so the window's cadence said nothing of what was on the screen.
#[derive(Debug, Default)]
pub struct FrameClock {
    last: Option<Instant>,
    /// Seconds per frame, exponentially smoothed.
    pub smoothed: f64,
    /// The 3D view's renders submitted...
    submitted: u64,
    /// ...and finished, written by the device's callback.
    shown: std::sync::Arc<std::sync::Mutex<Shown>>,
    /// When the oldest render still on the device was submitted.
    waiting_since: Option<Instant>,
}

/// A render on the device this long has the user looking at an old picture; a shorter one is
/// the ordinary latency of any frame.
const STALLED: f64 = 0.2;

/// The renders the device has finished: when the last was, and the smoothed gap between them.
#[derive(Debug, Default, Clone, Copy)]
struct Shown {
    last: Option<Instant>,
    smoothed: f64,
    done: u64,
}

/// `smoothed` moved a tenth of the way to `dt` (to `dt` itself at first).
fn smooth(smoothed: f64, dt: f64) -> f64 {
    if smoothed == 0.0 {
        dt
    } else {
        0.9 * smoothed + 0.1 * dt
    }
}

impl Shown {
    fn finished(&mut self, now: Instant) {
        if let Some(l) = self.last {
            self.smoothed = smooth(self.smoothed, (now - l).as_secs_f64());
        }
        self.last = Some(now);
        self.done += 1;
    }
}

impl FrameClock {
    fn tick(&mut self) {
        let now = Instant::now();
        if let Some(l) = self.last {
            self.smoothed = smooth(self.smoothed, (now - l).as_secs_f64());
        }
        self.last = Some(now);
    }

    /// A render of the 3D view was submitted: its end is timed when the device has done it.
    fn submitted(&mut self, queue: &wgpu::Queue) {
        self.submitted_at(Instant::now());
        let shown = self.shown.clone();
        queue.on_submitted_work_done(move || {
            let mut s = shown.lock().unwrap_or_else(|p| p.into_inner());
            s.finished(Instant::now());
        });
    }

    /// The bookkeeping of a render submitted at `now`. One submitted well after the last
    /// picture with none on the device follows idle time (nothing asked for a frame): the gap
    /// it ends is timed from its submission, so that the user's pause is not a slow frame.
    fn submitted_at(&mut self, now: Instant) {
        if !self.pending() {
            self.waiting_since = Some(now);
            let mut s = self.shown.lock().unwrap_or_else(|p| p.into_inner());
            if s.last.is_some_and(|l| (now - l).as_secs_f64() > STALLED) {
                s.last = Some(now);
            }
        }
        self.submitted += 1;
    }

    /// Whether a render is still on the device: the screen shows an older picture.
    pub fn pending(&self) -> bool {
        self.shown.lock().map_or(0, |s| s.done) < self.submitted
    }

    /// Whether a render has been on the device for longer than a frame's usual latency, at
    /// `now` (a drag on a large mesh on a slow device).
    pub fn stalled(&self, now: Instant) -> bool {
        self.pending()
            && self
                .waiting_since
                .is_some_and(|t| (now - t).as_secs_f64() > STALLED)
    }

    /// Seconds between the pictures the user sees, at `now`: the smoothed gap between finished
    /// renders, or the time since the last one while a later one is still drawing, if longer.
    pub fn shown_gap(&self, now: Instant) -> Option<f64> {
        let s = *self.shown.lock().unwrap_or_else(|p| p.into_inner());
        let waiting = (s.done < self.submitted)
            .then(|| s.last.map(|l| (now - l).as_secs_f64()))
            .flatten();
        let gap = s.smoothed.max(waiting.unwrap_or(0.0));
        (gap > 0.0).then_some(gap)
    }
}

/// The 3D view's state: the renderer, how it draws (style, side by side, the LOD scene), its
/// panes and what they last showed, and the frame counts the panel and the tests read.
pub struct View3d {
    pub(super) renderer: Renderer,
    panes: Vec<Pane>,
    drawn: Option<DrawKey>,
    pub style: Style,
    /// Original on the left, simplified on the right, one camera.
    pub side_by_side: bool,
    /// Draw the original even when a result exists.
    pub show_original: bool,
    pub lod_scene: bool,
    pub lod_on: bool,
    pub clock: FrameClock,
    /// Smoothed frame seconds of the LOD scene with LOD on and off, as last measured.
    pub lod_frame: [Option<f64>; 2],
    /// A DAG's threshold: the projected error a drawn cluster may show, in pixels.
    pub pixels: f64,
    /// Frames drawn since the start (the tests count them while a job runs).
    pub frames: u64,
    /// Times the 3D view was rendered (only when what it shows changed).
    pub renders: u64,
}

impl View3d {
    pub(super) fn new(renderer: Renderer) -> View3d {
        View3d {
            renderer,
            panes: Vec::new(),
            drawn: None,
            style: Style::default(),
            side_by_side: false,
            show_original: false,
            lod_scene: false,
            lod_on: true,
            clock: FrameClock::default(),
            lod_frame: [None, None],
            pixels: 1.0,
            frames: 0,
            renders: 0,
        }
    }

    /// A frame begins: the clock, the count, and the LOD scene's frame time with LOD on or off.
    pub(super) fn tick(&mut self, scene: &Scene) {
        self.clock.tick();
        self.frames += 1;
        if self.lod_shown(scene) {
            self.lod_frame[if self.lod_on { 0 } else { 1 }] = Some(self.clock.smoothed);
        }
    }

    /// The LOD scene is on and has levels.
    pub fn lod_shown(&self, scene: &Scene) -> bool {
        self.lod_scene && scene.lod.is_some()
    }

    /// A new model: framed again at the next frame, for the view's real shape; a new LOD
    /// scene's frame times are measured anew.
    pub(super) fn reframe(&mut self) {
        self.drawn = None;
        self.lod_frame = [None, None];
    }

    /// The first pane's size in pixels (640x480 before the first frame).
    pub fn pane_size(&self) -> (u32, u32) {
        self.panes.first().map_or((640, 480), |v| v.target.size)
    }

    /// The first pane's width over its height (4:3 before the first frame).
    pub fn aspect(&self) -> f32 {
        self.panes.first().map_or(4.0 / 3.0, |v| {
            v.target.size.0 as f32 / v.target.size.1 as f32
        })
    }

    /// Whether `mode` can draw the scene: textures need UVs and a texture, colours colours.
    pub fn mode_available(&self, mode: Mode, scene: &Scene) -> bool {
        match mode {
            Mode::Texture => {
                self.renderer.has_texture() && scene.original.as_ref().is_some_and(|o| o.has_uvs)
            }
            Mode::Color => scene.original.as_ref().is_some_and(|o| o.has_colors),
            Mode::Clusters | Mode::Levels => scene
                .dag
                .as_ref()
                .is_some_and(|d| d.lock().is_ok_and(|d| d.numbered)),
            _ => true,
        }
    }

    /// Why `mode` cannot draw the scene, for the status line and the button's hover; `None`
    /// when it can.
    pub fn mode_unavailable(&self, mode: Mode, scene: &Scene) -> Option<String> {
        if self.mode_available(mode, scene) {
            return None;
        }
        Some(match mode {
            Mode::Texture => scene
                .texture_note
                .clone()
                .unwrap_or_else(|| "the mesh has no UVs or no texture".into()),
            Mode::Color => "the mesh has no vertex colours".into(),
            Mode::Clusters | Mode::Levels if scene.dag.is_some() => {
                "this device cannot number indirect draws (INDIRECT_FIRST_INSTANCE)".into()
            }
            Mode::Clusters | Mode::Levels => {
                "only a cluster DAG has clusters: open a .mslod or Make DAG".into()
            }
            _ => "nothing to draw".into(),
        })
    }

    /// The pixels of pane `k` as last drawn (RGBA8 rows) and its size.
    pub fn pane_rgba(&self, gpu: &Device, k: usize) -> Result<(Vec<u8>, (u32, u32))> {
        let v = self
            .panes
            .get(k)
            .ok_or_else(|| Error::InvalidOption(format!("no pane {k} drawn")))?;
        Ok((v.target.read_rgba(&gpu.device, &gpu.queue)?, v.target.size))
    }

    /// What the 3D view shows as one image (RGBA8 rows) and its size: side by side, both panes
    /// with their labels.
    pub fn rgba(&self, gpu: &Device, scene: &Scene) -> Result<(Vec<u8>, (u32, u32))> {
        let panes = (0..self.panes.len().max(1))
            .map(|k| self.pane_rgba(gpu, k))
            .collect::<Result<Vec<_>>>()?;
        if panes.len() == 1 {
            return Ok(panes.into_iter().next().expect("one pane"));
        }
        side_by_side(panes, &pane_labels(scene.simplified.is_some()))
    }

    /// How many instances of the LOD scene draw each level (with `camera`).
    pub fn lod_histogram(&self, scene: &Scene, camera: &Camera) -> Vec<usize> {
        let Some(levels) = &scene.lod else {
            return Vec::new();
        };
        let mut h = vec![0; levels.len()];
        for (mesh, _) in self.lod_items(levels, camera) {
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
    fn lod_items<'a>(
        &self,
        levels: &'a [SceneMesh],
        camera: &Camera,
    ) -> Vec<(&'a SceneMesh, Mat4)> {
        let eye = camera.eye();
        let view_px = self.panes.first().map_or(600.0, |v| v.target.size.1 as f32);
        // Pixels per unit of length at distance 1.
        let px_per_unit = view_px / (2.0 * (0.5 * camera.fov_y).tan());
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
                let place = Mat4::from_translation(at) * camera.model;
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

    /// Frames what is shown: the LOD scene from its home, else the model to fit.
    pub(super) fn frame_to_fit(&self, scene: &Scene, eye: &mut Eye) {
        if self.lod_shown(scene) {
            eye.lod_home();
        } else {
            eye.fit(self.aspect());
        }
    }

    /// Draws the 3D view(s) into the rest of the window and moves `eye` by the input on it; an
    /// error (a pane refused by the device) is given back for the status line.
    pub(super) fn ui(
        &mut self,
        ui: &mut egui::Ui,
        gpu: &Device,
        scene: &Scene,
        eye: &mut Eye,
    ) -> std::result::Result<(), String> {
        let rect = ui.available_rect_before_wrap();
        let response = ui.allocate_rect(rect, egui::Sense::click_and_drag());
        eye.input(ui, &response);
        let ppp = ui.ctx().pixels_per_point();
        let lod = self.lod_shown(scene);
        let split = self.side_by_side && !lod && scene.original.is_some();
        let panes: Vec<egui::Rect> = if split {
            let (l, r) = rect.split_left_right_at_fraction(0.5);
            vec![
                l.shrink2(egui::vec2(1.0, 0.0)),
                r.shrink2(egui::vec2(1.0, 0.0)),
            ]
        } else {
            vec![rect]
        };
        self.ensure_panes(gpu, &panes, ppp)
            .map_err(|e| format!("cannot draw: {e}"))?;
        // Going into or out of side by side halves or doubles each pane's width: frame the
        // mesh again for the new shape (a model's first frame too, now that the size is known).
        if self.drawn.as_ref().is_none_or(|d| d.split != split) && !lod {
            self.frame_to_fit(scene, eye);
        }
        // The 3D view is drawn again only when what it shows changed (the LOD scene always, it
        // measures frame rates): frames that only move the progress bar stay cheap, which on a
        // software rasterizer leaves the cores to a running simplification.
        let key = DrawKey {
            camera: eye.camera,
            style: self.style,
            split,
            show_original: self.show_original,
            lod_on: self.lod_on,
            sizes: self.panes.iter().map(|v| v.target.size).collect(),
            generation: scene.generation,
            pixels: self.pixels,
        };
        let drawn = if lod || self.drawn.as_ref() != Some(&key) {
            let r = self.draw(gpu, scene, &eye.camera, split, lod);
            self.drawn = Some(key);
            r
        } else {
            Ok(())
        };
        self.paint(ui, rect, &panes, scene, (split, lod, eye.fly));
        drawn.map_err(|e| e.to_string())
    }

    /// Renders the pane textures.
    fn draw(
        &mut self,
        gpu: &Device,
        scene: &Scene,
        camera: &Camera,
        split: bool,
        lod: bool,
    ) -> Result<()> {
        self.renders += 1;
        let shown: Vec<Option<&SceneMesh>> = if split {
            vec![scene.original.as_deref(), scene.shown(false)]
        } else {
            vec![scene.shown(self.show_original)]
        };
        // A refused draw becomes the status line, not a panic in wgpu's default handler.
        let scope = crate::compute::gpu::ErrorScope::push(&gpu.device);
        for (k, mesh) in shown.iter().enumerate() {
            // A DAG's pane draws its cut, chosen on the device in this frame's encoder, where
            // the original would be (O shows the whole first level instead).
            let mut dag = scene
                .dag
                .as_ref()
                .filter(|_| !lod && !self.show_original && scene.simplified.is_none())
                .filter(|_| !split || k == 1)
                .map(|d| d.lock().unwrap_or_else(|p| p.into_inner()));
            let mut enc = gpu.device.create_command_encoder(&Default::default());
            if let Some(d) = dag.as_mut() {
                let size = self.panes[k].target.size;
                let p = d.cut_params(camera, size, self.pixels);
                d.cut.record(&mut enc, &p);
                // The heatmap tops at the cut's own largest distance, as a result's at its own.
                if self.style.mode == Mode::Heatmap {
                    self.style.error_scale = d.heat_top(camera, size, self.pixels);
                }
            }
            let items: Vec<(&SceneMesh, Mat4)> = match (&scene.lod, lod, &dag) {
                (Some(levels), true, _) => self.lod_items(levels, camera),
                (_, _, Some(d)) => vec![(&d.scene, camera.model)],
                _ => mesh.map(|m| vec![(m, camera.model)]).unwrap_or_default(),
            };
            let mut style = self.style;
            if style.mode == Mode::Texture && !mesh.is_some_and(|m| m.has_uvs)
                || style.mode == Mode::Color && !mesh.is_some_and(|m| m.has_colors)
                || matches!(style.mode, Mode::Clusters | Mode::Levels) && dag.is_none()
            {
                style.mode = Mode::Shaded;
            }
            // One submission per pane: the renderer's uniforms are written through the queue,
            // and a second pane's writes would land before the first pane's draw otherwise.
            self.renderer.draw(
                &gpu.device,
                &gpu.queue,
                &mut enc,
                &self.panes[k].target,
                camera,
                &style,
                &items,
            );
            gpu.queue.submit([enc.finish()]);
        }
        self.clock.submitted(&gpu.queue);
        scope.check("drawing the view")
    }

    /// Shows the pane textures and the overlays (labels, legend).
    fn paint(
        &self,
        ui: &egui::Ui,
        rect: egui::Rect,
        panes: &[egui::Rect],
        scene: &Scene,
        (split, lod, fly): (bool, bool, bool),
    ) {
        let painter = ui.painter_at(rect);
        for (k, pane) in panes.iter().enumerate() {
            painter.image(
                self.panes[k].id,
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
            let names = pane_labels(scene.simplified.is_some());
            for (pane, name) in panes.iter().zip(names) {
                label(pane.left_top() + egui::vec2(8.0, 6.0), top_left, name);
            }
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
        // The ramp's top is the farthest vertex's distance to the original; the panel's max is
        // the two-sided distance sampled over both surfaces, which can lie between vertices.
        if self.style.mode == Mode::Heatmap && scene.original.is_some() {
            let top = format!("{:.2e}", self.style.error_scale);
            let caption = "each vertex's distance / diagonal (top: the farthest)";
            legend(&painter, rect, [&top, "0"], caption);
        }
        if self.style.mode == Mode::Quality && scene.original.is_some() {
            legend(&painter, rect, ["0°", "60°"], "smallest angle of each face");
        }
        if fly {
            label(
                rect.left_bottom() + egui::vec2(8.0, -8.0),
                egui::Align2::LEFT_BOTTOM,
                "fly: W A S D move, Q E down/up, drag to look, G to leave",
            );
        }
    }

    /// One texture per pane, of the pane's size in pixels, registered with egui.
    fn ensure_panes(&mut self, gpu: &Device, panes: &[egui::Rect], ppp: f32) -> Result<()> {
        for v in self.panes.drain(panes.len().min(self.panes.len())..) {
            gpu.egui_renderer.write().free_texture(&v.id);
        }
        for (k, pane) in panes.iter().enumerate() {
            let size = (
                ((pane.width() * ppp).round() as u32).max(1),
                ((pane.height() * ppp).round() as u32).max(1),
            );
            if self.panes.get(k).is_some_and(|v| v.target.size == size) {
                continue;
            }
            let target = Target::new(&gpu.device, size)?;
            let mut r = gpu.egui_renderer.write();
            let id = match self.panes.get(k) {
                Some(v) => {
                    r.update_egui_texture_from_wgpu_texture(
                        &gpu.device,
                        &target.color_view,
                        wgpu::FilterMode::Linear,
                        v.id,
                    );
                    v.id
                }
                None => r.register_native_texture(
                    &gpu.device,
                    &target.color_view,
                    wgpu::FilterMode::Linear,
                ),
            };
            let v = Pane { target, id };
            if k < self.panes.len() {
                self.panes[k] = v;
            } else {
                self.panes.push(v);
            }
        }
        Ok(())
    }
}

/// The side-by-side panes' labels, as the window draws them over each.
pub fn pane_labels(simplified: bool) -> [&'static str; 2] {
    let right = if simplified {
        "simplified"
    } else {
        "original (not simplified yet)"
    };
    ["original", right]
}

/// Panes (RGBA8 rows and size each) side by side as one image, each with its label in its top
/// left corner as the window shows it: what a screenshot of two panes saves.
pub fn side_by_side(
    panes: Vec<(Vec<u8>, (u32, u32))>,
    labels: &[&str],
) -> Result<(Vec<u8>, (u32, u32))> {
    let w: u32 = panes.iter().map(|p| p.1.0).sum();
    let h = panes.iter().map(|p| p.1.1).max().unwrap_or(1);
    // Opaque black where a pane is a pixel shorter than the other (rounding of the split).
    let mut out = [0, 0, 0, 255].repeat((w * h) as usize);
    let mut svg = format!(r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}">"#);
    let mut x0 = 0;
    for ((px, (pw, ph)), text) in panes.iter().zip(labels) {
        let row = 4 * *pw as usize;
        for y in 0..*ph as usize {
            let at = 4 * (y * w as usize + x0);
            out[at..at + row].copy_from_slice(&px[y * row..(y + 1) * row]);
        }
        // The window's overlay: light 13-point text, outlined dark so it reads on any mesh.
        svg += &format!(
            r##"<text x="{}" y="19" font-family="DejaVu Sans, sans-serif" font-size="13" fill="#dcdcdc" stroke="#000000" stroke-opacity="0.7" stroke-width="3" paint-order="stroke">{}</text>"##,
            x0 + 8,
            text.replace('&', "&amp;").replace('<', "&lt;")
        );
        x0 += *pw as usize;
    }
    svg += "</svg>";
    let labels = crate::raster::svg_pixmap(&svg, None).map_err(Error::Internal)?;
    // Source over: the pixmap is premultiplied, the panes opaque.
    for (d, s) in out.chunks_exact_mut(4).zip(labels.data().chunks_exact(4)) {
        let keep = 255 - s[3] as u32;
        for i in 0..3 {
            d[i] = (s[i] as u32 + d[i] as u32 * keep / 255) as u8;
        }
    }
    Ok((out, (w, h)))
}

/// A colour legend: the shader's ramp, its top (red) and bottom (blue) labelled.
fn legend(painter: &egui::Painter, rect: egui::Rect, ends: [&str; 2], caption: &str) {
    let w = 18.0;
    let h = (rect.height() * 0.4).min(220.0);
    let bar = egui::Rect::from_min_size(
        rect.right_top() + egui::vec2(-w - 70.0, 16.0),
        egui::vec2(w, h),
    );
    painter.rect_filled(bar.expand(2.0), 2.0, egui::Color32::from_black_alpha(150));
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
    // Right-aligned under the bar, so a long caption stays inside the view.
    at(
        egui::pos2(rect.right() - 8.0, bar.bottom() + 6.0),
        egui::Align2::RIGHT_TOP,
        caption,
    );
}

/// Light text over the 3D view, on a dark plate so it reads over a light mesh too.
fn overlay_text(
    painter: &egui::Painter,
    at: egui::Pos2,
    align: egui::Align2,
    text: &str,
    size: f32,
) {
    let color = egui::Color32::from_gray(220);
    let galley = painter.layout_no_wrap(text.to_string(), egui::FontId::proportional(size), color);
    let rect = align.anchor_size(at, galley.size());
    painter.rect_filled(rect.expand(2.0), 3.0, egui::Color32::from_black_alpha(150));
    painter.galley(rect.min, galley, color);
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
    fn the_frames_shown_are_timed_from_the_renders_finished() {
        let clock = FrameClock::default();
        let t0 = Instant::now();
        let at = |s: f64| t0 + std::time::Duration::from_secs_f64(s);
        assert_eq!(clock.shown_gap(at(0.0)), None, "nothing drawn yet");
        let mut clock = clock;
        clock.submitted = 2;
        clock.shown.lock().unwrap().finished(at(0.0));
        clock.shown.lock().unwrap().finished(at(0.1));
        let gap = clock.shown_gap(at(0.1)).unwrap();
        assert!((gap - 0.1).abs() < 1e-9, "{gap}");
        assert!(!clock.pending());
        // A third render on the device for 1.8 s: the screen has shown one picture that long.
        clock.submitted = 3;
        clock.waiting_since = Some(at(0.1));
        assert!(clock.pending());
        assert!(!clock.stalled(at(0.2)), "a frame's usual latency");
        assert!(clock.stalled(at(1.9)));
        let gap = clock.shown_gap(at(1.9)).unwrap();
        assert!((gap - 1.8).abs() < 1e-9, "{gap}");
    }

    #[test]
    fn a_pause_between_inputs_is_not_a_slow_frame() {
        let mut clock = FrameClock::default();
        let t0 = Instant::now();
        let at = |s: f64| t0 + std::time::Duration::from_secs_f64(s);
        for (k, t) in [0.0, 0.02, 0.04].into_iter().enumerate() {
            clock.submitted_at(at(t));
            clock.shown.lock().unwrap().finished(at(t + 0.02));
            assert_eq!(clock.shown.lock().unwrap().done, k as u64 + 1);
        }
        // Five idle seconds, then a drag's frame drawn in 20 ms: the gap is that frame's.
        clock.submitted_at(at(5.06));
        clock.shown.lock().unwrap().finished(at(5.08));
        let gap = clock.shown_gap(at(5.08)).unwrap();
        assert!((gap - 0.02).abs() < 1e-9, "{gap}");
        // Frames submitted back to back are timed from the picture before, however slow.
        clock.submitted_at(at(5.09));
        clock.shown.lock().unwrap().finished(at(6.08));
        let gap = clock.shown_gap(at(6.08)).unwrap();
        assert!((gap - (0.9 * 0.02 + 0.1 * 1.0)).abs() < 1e-9, "{gap}");
    }

    #[test]
    fn the_legend_ramp_is_the_shader_ramp() {
        // Blue at 0, green in the middle, red at 1, as `ramp` in shaders/viewer/mesh.wgsl.
        assert_eq!(ramp_color(0.0), egui::Color32::from_rgb(0, 0, 128));
        assert_eq!(ramp_color(0.5), egui::Color32::from_rgb(128, 255, 128));
        assert_eq!(ramp_color(1.0), egui::Color32::from_rgb(128, 0, 0));
    }
}
