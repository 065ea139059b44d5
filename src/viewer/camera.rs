//! An orbit camera in the mesh's normalized frame (centred, unit bounding-box diagonal): a target,
//! a distance and two angles. Orbiting keeps the distance; framing fits the bounding sphere.

use eframe::egui;
use glam::{Mat4, Vec3};

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    pub target: Vec3,
    pub distance: f32,
    /// Around the vertical axis, radians.
    pub yaw: f32,
    /// Above the horizontal plane, radians, kept inside (-90°, 90°).
    pub pitch: f32,
    /// Vertical field of view, radians.
    pub fov_y: f32,
    /// Turns the mesh before viewing (see [`Camera::upright`]).
    pub model: Mat4,
}

const PITCH_LIMIT: f32 = 1.55;

impl Default for Camera {
    fn default() -> Self {
        Camera {
            target: Vec3::ZERO,
            distance: 2.0,
            yaw: 0.6,
            pitch: 0.35,
            fov_y: 45f32.to_radians(),
            model: Mat4::IDENTITY,
        }
    }
}

impl Camera {
    pub fn eye(&self) -> Vec3 {
        let dir = Vec3::new(
            self.pitch.cos() * self.yaw.sin(),
            self.pitch.sin(),
            self.pitch.cos() * self.yaw.cos(),
        );
        self.target + dir * self.distance
    }

    /// Turns around the target by the given angles; the distance stays.
    pub fn orbit(&mut self, d_yaw: f32, d_pitch: f32) {
        self.yaw += d_yaw;
        self.pitch = (self.pitch + d_pitch).clamp(-PITCH_LIMIT, PITCH_LIMIT);
    }

    /// Moves toward the target by a factor (< 1 closer), never through it.
    pub fn zoom(&mut self, factor: f32) {
        self.distance = (self.distance * factor).max(1e-4);
    }

    /// Looks at a sphere of `radius` around `center` so that it fills the view.
    pub fn fit(&mut self, center: Vec3, radius: f32, aspect: f32) {
        self.target = center;
        let half_v = 0.5 * self.fov_y;
        let half_h = (half_v.tan() * aspect.max(1e-3)).atan();
        let half = half_v.min(half_h);
        self.distance = radius / half.sin() * 1.05;
    }

    /// Unit vector from the target to the eye.
    fn back(&self) -> Vec3 {
        (self.eye() - self.target) / self.distance
    }

    /// Screen right and up in world terms.
    fn right_up(&self) -> (Vec3, Vec3) {
        let back = self.back();
        let right = Vec3::Y.cross(back).normalize_or(Vec3::X);
        (right, back.cross(right))
    }

    /// Slides the view by a fraction of the view's height (`dx` right, `dy` down, as a mouse
    /// drags): the surface under the pointer follows it at the target's depth.
    pub fn pan(&mut self, dx: f32, dy: f32) {
        let (right, up) = self.right_up();
        // The visible height at the target's distance.
        let h = 2.0 * self.distance * (0.5 * self.fov_y).tan();
        self.target += (-dx * right + dy * up) * h;
    }

    /// Fly mode: turns the view around the eye (the eye stays; the target swings).
    pub fn look(&mut self, d_yaw: f32, d_pitch: f32) {
        let eye = self.eye();
        self.yaw += d_yaw;
        self.pitch = (self.pitch + d_pitch).clamp(-PITCH_LIMIT, PITCH_LIMIT);
        self.target = eye - self.back() * self.distance;
    }

    /// Fly mode: moves eye and target together, `forward` along the view, `right` across it,
    /// `up` along the world's vertical.
    pub fn fly(&mut self, forward: f32, right: f32, up: f32) {
        let (r, _) = self.right_up();
        self.target += -self.back() * forward + r * right + Vec3::Y * up;
    }

    /// Clip space from the mesh's frame: [`Camera::proj_view`] after [`Camera::model`].
    pub fn view_proj(&self, aspect: f32) -> Mat4 {
        self.proj_view(aspect) * self.model
    }

    /// Clip space from the world (the model turn not included): a renderer places each
    /// instance with its own matrix, the turn included.
    pub fn proj_view(&self, aspect: f32) -> Mat4 {
        let near = (self.distance * 0.01).max(1e-5);
        let far = self.distance * 10.0 + 10.0;
        let proj = Mat4::perspective_rh(self.fov_y, aspect, near, far);
        proj * Mat4::look_at_rh(self.eye(), self.target, Vec3::Y)
    }

    /// A rotation that shows a box of these `extent`s by its largest silhouette: the longest
    /// axis across the screen, the middle one up, the shortest toward the viewer ([`Up::Auto`]).
    pub fn upright(extent: Vec3) -> Mat4 {
        let mut axes = [
            (extent.x, Vec3::X),
            (extent.y, Vec3::Y),
            (extent.z, Vec3::Z),
        ];
        axes.sort_by(|a, b| b.0.total_cmp(&a.0));
        let (across, up) = (axes[0].1, axes[1].1);
        rotation_onto_screen(across, up)
    }
}

/// How a mesh stands, read from its data where its file format fixes no up axis (PLY, OBJ and
/// STL do not; horse.ply is +Z up, bunny.obj +Y): the side of its bounding box it rests on, as
/// an object on a table — a side whose contact (the vertices within 1% of the diagonal from
/// it) spans at least [`MIN_SUPPORT`] of it with the surface's centroid over it: the file's
/// `convention` when it rests so, else the side it rests on most — and across the screen its
/// longer horizontal axis, pointing to
/// the end that rises higher (an animal's head, a bunny's ears), so it is seen from the side,
/// that end a little toward the camera. `None` when nothing rests: a head, a mask (the file's
/// convention holds then).
pub fn stands(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    convention: Up,
) -> Option<(Up, Vec3)> {
    let p = |v: u32| Vec3::from(positions[v as usize]).as_dvec3();
    let (mut lo, mut hi) = (glam::DVec3::splat(f64::MAX), glam::DVec3::splat(f64::MIN));
    for q in positions {
        let q = Vec3::from(*q).as_dvec3();
        (lo, hi) = (lo.min(q), hi.max(q));
    }
    let (ext, diag) = (hi - lo, (hi - lo).length());
    // The surface's centroid, by area: what rests over the support.
    let (mut sum, mut area) = (glam::DVec3::ZERO, 0.0);
    for t in triangles {
        let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
        let w = 0.5 * (b - a).cross(c - a).length();
        sum += w * (a + b + c) / 3.0;
        area += w;
    }
    if !(area > 0.0 && diag > 0.0) {
        return None;
    }
    let centroid = sum / area;
    let mut best: Option<(f64, usize, f64)> = None;
    for axis in 0..3 {
        let (j, k) = ((axis + 1) % 3, (axis + 2) % 3);
        for sign in [1.0, -1.0] {
            let floor = if sign > 0.0 { lo[axis] } else { hi[axis] };
            let (mut a, mut b) = ([f64::MAX; 2], [f64::MIN; 2]);
            for q in positions.iter().map(|q| Vec3::from(*q).as_dvec3()) {
                if (q[axis] - floor).abs() < 0.01 * diag {
                    (a[0], a[1]) = (a[0].min(q[j]), a[1].min(q[k]));
                    (b[0], b[1]) = (b[0].max(q[j]), b[1].max(q[k]));
                }
            }
            let over = (a[0]..=b[0]).contains(&centroid[j]) && (a[1]..=b[1]).contains(&centroid[k]);
            let share = (b[0] - a[0]) * (b[1] - a[1]) / (ext[j] * ext[k]).max(f64::MIN_POSITIVE);
            let conventional = convention.vector().is_some_and(|v| v[axis] == sign as f32);
            // The convention, when it rests, ranks above every other side.
            let rank = share + if conventional { 1.0 } else { 0.0 };
            if over && share >= MIN_SUPPORT && best.is_none_or(|(r, ..)| rank > r) {
                best = Some((rank, axis, sign));
            }
        }
    }
    let (_, axis, sign) = best?;
    let up = [[Up::X, Up::NegX], [Up::Y, Up::NegY], [Up::Z, Up::NegZ]][axis][(sign < 0.0) as usize];
    let (j, k) = ((axis + 1) % 3, (axis + 2) % 3);
    let long = if ext[j] >= ext[k] { j } else { k };
    // The higher of the two ends (the outer quarters of the length).
    let top = |end: f64| {
        positions
            .iter()
            .map(|q| Vec3::from(*q).as_dvec3())
            .filter(|q| (q[long] - end).abs() < 0.25 * ext[long])
            .map(|q| sign * q[axis])
            .fold(f64::MIN, f64::max)
    };
    let front = if top(hi[long]) >= top(lo[long]) {
        1.0
    } else {
        -1.0
    };
    let mut across = Vec3::ZERO;
    across[long] = front;
    Some((up, across))
}

/// The least share of its bounding box's side a mesh must rest on to be stood on it: the
/// shared models that rest (horse, bunny, teapot, spot, nefertiti) span 0.30–0.96 of it, the
/// ones that do not (a head, a mask) at most 0.11.
const MIN_SUPPORT: f64 = 0.2;

/// The rotation whose rows map the mesh's `across` and `up` axes onto screen x and y (and
/// their cross product toward the viewer): a rotation, never a mirror.
fn rotation_onto_screen(across: Vec3, up: Vec3) -> Mat4 {
    let toward = across.cross(up);
    Mat4::from_cols(
        Vec3::new(across.x, up.x, toward.x).extend(0.0),
        Vec3::new(across.y, up.y, toward.y).extend(0.0),
        Vec3::new(across.z, up.z, toward.z).extend(0.0),
        glam::Vec4::W,
    )
}

/// Which of the mesh's axes points up on screen. Files carry a convention, not a tag: OBJ and
/// most PLY scans are +Y up and glTF is +Y up by its specification, while STL (CAD, 3D printing)
/// is +Z up; where the format does not fix it, the side a mesh rests on ([`stands`]) decides
/// (horse.ply is a +Z-up PLY).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum Up {
    #[cfg_attr(feature = "cli", value(name = "x", alias = "+x"))]
    X,
    #[cfg_attr(feature = "cli", value(name = "-x"))]
    NegX,
    #[default]
    #[cfg_attr(feature = "cli", value(name = "y", alias = "+y"))]
    Y,
    #[cfg_attr(feature = "cli", value(name = "-y"))]
    NegY,
    #[cfg_attr(feature = "cli", value(name = "z", alias = "+z"))]
    Z,
    #[cfg_attr(feature = "cli", value(name = "-z"))]
    NegZ,
    /// The largest silhouette: the longest axis across, the middle one up, whatever the file
    /// calls up (a lying scan is seen from the side).
    Auto,
}

impl Up {
    pub const ALL: [Up; 7] = [Up::Y, Up::Z, Up::X, Up::NegY, Up::NegZ, Up::NegX, Up::Auto];

    /// The convention of the file's format: +Z for STL, +Y for the rest (and generated meshes).
    pub fn of_file(path: Option<&std::path::Path>) -> Up {
        let ext = path
            .and_then(|p| p.extension())
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("stl") => Up::Z,
            _ => Up::Y,
        }
    }

    pub fn label(self) -> &'static str {
        match self {
            Up::X => "+X",
            Up::NegX => "-X",
            Up::Y => "+Y",
            Up::NegY => "-Y",
            Up::Z => "+Z",
            Up::NegZ => "-Z",
            Up::Auto => "auto",
        }
    }

    /// The axis as a unit vector (`None` for [`Up::Auto`], which depends on the extents).
    pub fn vector(self) -> Option<Vec3> {
        Some(match self {
            Up::X => Vec3::X,
            Up::NegX => Vec3::NEG_X,
            Up::Y => Vec3::Y,
            Up::NegY => Vec3::NEG_Y,
            Up::Z => Vec3::Z,
            Up::NegZ => Vec3::NEG_Z,
            Up::Auto => return None,
        })
    }

    /// The turn that puts this axis up on screen; its front faces the viewer (for +Z up, the
    /// -Y side, as CAD front views have it). `extent` is used by [`Up::Auto`] alone.
    pub fn model(self, extent: Vec3) -> Mat4 {
        let (across, up) = match self {
            Up::Y => (Vec3::X, Vec3::Y),
            Up::NegY => (Vec3::X, Vec3::NEG_Y),
            Up::Z => (Vec3::X, Vec3::Z),
            Up::NegZ => (Vec3::X, Vec3::NEG_Z),
            Up::X => (Vec3::NEG_Y, Vec3::X),
            Up::NegX => (Vec3::Y, Vec3::NEG_X),
            Up::Auto => return Camera::upright(extent),
        };
        rotation_onto_screen(across, up)
    }
}

/// The window's camera concern: the orbit (or fly) camera, fly mode and its speed, and the axis
/// drawn up for the model shown when the user chose one. Input on the 3D view moves it; the app
/// sends it home when a model or the LOD scene comes.
#[derive(Debug, Clone)]
pub struct Eye {
    pub camera: Camera,
    pub fly: bool,
    /// Fly speed in diagonals per second.
    pub fly_speed: f32,
    /// The axis drawn up for the model shown, when the user chose one; else its file's.
    pub up: Option<Up>,
    /// An axis chosen before any model was shown (the command line's `--up` for a file read
    /// once the window is up): the first model takes it, later ones their own.
    pub(super) up_for_next: Option<Up>,
    /// Whether the last frame's input dragged, zoomed or flew the camera: the panel then shows
    /// the time between the pictures the user sees, not "drawn on input".
    pub moving: bool,
}

impl Default for Eye {
    fn default() -> Self {
        Eye {
            camera: Camera::default(),
            fly: false,
            fly_speed: 0.5,
            up: None,
            up_for_next: None,
            moving: false,
        }
    }
}

impl Eye {
    /// A model's first view: `up` (chosen, else the model's own `model_up`) up, framed; seen
    /// from the side [`stands`] found (`stood`) when it is that up.
    pub fn home(&mut self, model_up: Up, stood: Option<(Up, Vec3)>, extent: Vec3, aspect: f32) {
        let up = self.up.unwrap_or(model_up);
        let model = match (stood, up.vector()) {
            (Some((u, across)), Some(v)) if u == up => rotation_onto_screen(across, v),
            _ => up.model(extent),
        };
        self.camera = Camera {
            model,
            yaw: 0.35,
            pitch: 0.2,
            ..Camera::default()
        };
        self.fit(aspect);
    }

    /// Frames the normalized frame: centred, bounding-box diagonal 1, so a sphere of radius 0.5
    /// holds it.
    pub fn fit(&mut self, aspect: f32) {
        self.camera.fit(Vec3::ZERO, 0.5, aspect);
    }

    /// The LOD scene's first view: low over one side of the grid, so that the nearest
    /// instances are large on screen and the farthest small — every level has its turn.
    pub fn lod_home(&mut self) {
        let half = super::lod::LOD_GRID as f32 * super::lod::LOD_SPACING * 0.5;
        // Low over the grid's edge, whatever the view's shape: the nearest instances in view
        // (about 4 diagonals away) draw the original, the far side the coarsest level.
        self.camera = Camera {
            yaw: 0.6,
            pitch: 0.15,
            target: Vec3::ZERO,
            distance: half * 1.05,
            ..self.camera
        };
    }

    /// Drags, wheel and pinch on the 3D view (`r`), and the fly keys when no text field has
    /// the keyboard.
    pub fn input(&mut self, ui: &egui::Ui, r: &egui::Response) {
        let before = self.camera;
        self.input_camera(ui, r);
        self.moving = self.camera != before || r.dragged();
    }

    fn input_camera(&mut self, ui: &egui::Ui, r: &egui::Response) {
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
        if !self.fly || ui.ctx().egui_wants_keyboard_input() {
            return;
        }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A ring lying flat rests on its side whatever the file's convention says; stood on its
    /// rim it rests on the convention's side when that side holds it; a ball rests on nothing;
    /// a long ring is seen from the side, its length across.
    #[test]
    fn a_mesh_stands_on_the_side_it_rests_on() {
        let ring = crate::mesh::torus(1.0, 0.3, 48, 16); // its axis is Z
        let stood = |m: &crate::mesh::Mesh, c| stands(&m.positions, &m.triangles, c);
        let (up, across) = stood(&ring, Up::Y).expect("a flat ring rests");
        assert!(matches!(up, Up::Z | Up::NegZ), "{up:?}");
        assert_eq!(across.z, 0.0, "across is horizontal: {across}");
        assert_eq!(
            stood(&ring, Up::NegZ).unwrap().0,
            Up::NegZ,
            "the convention ranks first"
        );
        let ball = crate::mesh::icosphere(3);
        assert_eq!(stood(&ball, Up::Y), None);
        let mut long = ring.clone();
        for p in &mut long.positions {
            p[1] *= 3.0;
        }
        let (_, across) = stood(&long, Up::Z).unwrap();
        assert_eq!(
            across.y.abs(),
            1.0,
            "the longer horizontal axis across: {across}"
        );
    }

    #[test]
    fn orbit_keeps_the_target_distance() {
        let mut c = Camera::default();
        let d0 = (c.eye() - c.target).length();
        c.orbit(1.3, -0.4);
        c.orbit(-3.0, 2.0); // pitch clamps below the pole
        assert!(((c.eye() - c.target).length() - d0).abs() < 1e-5);
        assert!(c.pitch <= PITCH_LIMIT);
    }

    #[test]
    fn pan_and_fly_move_eye_and_target_together() {
        let mut c = Camera::default();
        let (e0, t0) = (c.eye(), c.target);
        c.pan(0.25, -0.1);
        let moved = c.target - t0;
        assert!(moved.length() > 1e-3);
        assert!(
            ((c.eye() - e0) - moved).length() < 1e-5,
            "pan does not turn the view"
        );
        let (e1, d) = (c.eye(), c.distance);
        c.fly(0.3, 0.0, 0.0);
        let step = c.eye() - e1;
        assert!((step.length() - 0.3).abs() < 1e-5);
        assert!(
            step.dot(c.target - c.eye()) > 0.0,
            "forward goes toward what is seen"
        );
        assert_eq!(c.distance, d);
    }

    #[test]
    fn look_turns_around_the_eye() {
        let mut c = Camera::default();
        let e0 = c.eye();
        c.look(0.7, -0.3);
        assert!((c.eye() - e0).length() < 1e-5, "the eye stays");
        assert!(((c.eye() - c.target).length() - c.distance).abs() < 1e-5);
    }

    #[test]
    fn upright_shows_the_largest_silhouette() {
        // Long in z, tall in x, thin in y: z goes across, x up, y toward the viewer.
        let m = Camera::upright(Vec3::new(0.5, 0.1, 0.8));
        assert!((m.transform_vector3(Vec3::Z) - Vec3::X).length() < 1e-6);
        assert!((m.transform_vector3(Vec3::X) - Vec3::Y).length() < 1e-6);
        assert!((m.transform_vector3(Vec3::Y).abs() - Vec3::Z).length() < 1e-6);
        assert!(
            (m.determinant() - 1.0).abs() < 1e-6,
            "a rotation, not a mirror"
        );
    }

    #[test]
    fn every_up_axis_turns_onto_screen_up_without_a_mirror() {
        let extent = Vec3::new(0.3, 0.9, 0.2);
        for (up, axis) in [
            (Up::X, Vec3::X),
            (Up::NegX, Vec3::NEG_X),
            (Up::Y, Vec3::Y),
            (Up::NegY, Vec3::NEG_Y),
            (Up::Z, Vec3::Z),
            (Up::NegZ, Vec3::NEG_Z),
        ] {
            let m = up.model(extent);
            assert!(
                (m.transform_vector3(axis) - Vec3::Y).length() < 1e-6,
                "{up:?}"
            );
            assert!((m.determinant() - 1.0).abs() < 1e-6, "{up:?} mirrors");
        }
        // +Y is the file's own frame; +Z up shows the -Y side to the viewer.
        assert_eq!(Up::Y.model(extent), Mat4::IDENTITY);
        assert!((Up::Z.model(extent).transform_vector3(Vec3::NEG_Y) - Vec3::Z).length() < 1e-6);
        // A standing figure (tall in y) drawn by its largest silhouette would lie on its side.
        assert!((Up::Auto.model(extent).transform_vector3(Vec3::Y) - Vec3::X).length() < 1e-6);
    }

    #[test]
    fn up_follows_the_file_format() {
        use std::path::Path;
        assert_eq!(Up::of_file(Some(Path::new("part.STL"))), Up::Z);
        for f in ["a.obj", "b.ply", "c.glb", "d.gltf"] {
            assert_eq!(Up::of_file(Some(Path::new(f))), Up::Y, "{f}");
        }
        assert_eq!(Up::of_file(None), Up::Y);
    }

    #[test]
    fn fit_frames_the_bounding_box() {
        for aspect in [0.5f32, 1.0, 2.0] {
            let mut c = Camera::default();
            let (lo, hi) = (Vec3::new(-0.4, -0.2, -0.1), Vec3::new(0.3, 0.25, 0.2));
            let center = 0.5 * (lo + hi);
            c.fit(center, 0.5 * (hi - lo).length(), aspect);
            let vp = c.view_proj(aspect);
            for i in 0..8 {
                let p = Vec3::new(
                    if i & 1 == 0 { lo.x } else { hi.x },
                    if i & 2 == 0 { lo.y } else { hi.y },
                    if i & 4 == 0 { lo.z } else { hi.z },
                );
                let q = vp.project_point3(p);
                assert!(
                    q.x.abs() <= 1.0 && q.y.abs() <= 1.0 && (0.0..=1.0).contains(&q.z),
                    "{aspect}: {q}"
                );
            }
        }
    }
}
