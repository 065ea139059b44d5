//! The Pareto front in the side panel: error against the share of vertices kept, as
//! `meshslim pareto`'s SVG draws it (the same axes, [`Axes`]). It comes from a search run in the
//! window on the loaded mesh, or from a `X.pareto.json` opened like a mesh. Clicking a point
//! shows that member in the view (and in the side-by-side); Ctrl+click chooses members, from
//! which the LOD scene can take its levels.

use crate::error::{Error, Result};
use crate::lod::manifest::{self, ParetoManifest};
use crate::lod::nsga::Point;
use crate::lod::svg::Axes;
use crate::lod::{ParetoOptions, ParetoRun};
use crate::mesh::Mesh;
use eframe::egui;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Where a member's mesh is: made by a search in the window, or a file a manifest names.
#[derive(Clone)]
pub enum MemberMesh {
    Made(Arc<Mesh>),
    File(PathBuf),
}

impl MemberMesh {
    pub fn load(&self) -> Result<Arc<Mesh>> {
        match self {
            MemberMesh::Made(m) => Ok(m.clone()),
            MemberMesh::File(p) => Ok(Arc::new(crate::io::read(p)?)),
        }
    }
}

/// One member of the front.
#[derive(Clone)]
pub struct Member {
    pub vertices: usize,
    pub faces: usize,
    /// The search's objective (relative to the diagonal).
    pub error: f64,
    pub mesh: MemberMesh,
}

/// A Pareto front as the window shows it.
#[derive(Clone)]
pub struct Front {
    /// Where it came from: the manifest, or the search's settings.
    pub source: String,
    /// The vertices the shares are of.
    pub input_vertices: usize,
    /// Fewest vertices first.
    pub members: Vec<Member>,
    /// The greedy decimation chain at the members' counts, when it was measured: drawn dashed.
    pub baseline: Vec<Point>,
    /// The member shown in the view.
    pub selected: Option<usize>,
    /// Members chosen for the LOD scene.
    pub chosen: BTreeSet<usize>,
}

/// What a click on the plot asked for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrontClick {
    Show(usize),
    Choose(usize),
}

/// Points this close (in points) to the pointer are hit.
const HIT_RADIUS: f32 = 10.0;
/// The plot's height in the side panel.
const PLOT_HEIGHT: f32 = 170.0;

impl Front {
    /// The front of a search run in the window.
    pub fn from_run(run: ParetoRun, source: String) -> Front {
        let n = run.input_vertices.max(1) as f64;
        let members = run
            .front
            .iter()
            .zip(run.front_meshes)
            .map(|(c, m)| Member {
                vertices: c.vertices,
                faces: c.faces,
                error: c.error,
                mesh: MemberMesh::Made(Arc::new(m)),
            })
            .collect();
        let baseline = run
            .baseline
            .iter()
            .map(|b| [b.vertices as f64 / n, b.objective])
            .collect();
        Front {
            source,
            input_vertices: run.input_vertices,
            members,
            baseline,
            selected: None,
            chosen: BTreeSet::new(),
        }
    }

    /// The front `meshslim pareto` wrote to `path`; its members' files must be there (beside
    /// the manifest, or where they were written).
    pub fn from_manifest(path: &Path, m: &ParetoManifest) -> Result<Front> {
        if m.front.is_empty() {
            return Err(Error::InvalidOption(format!(
                "{}: the front has no members",
                path.display()
            )));
        }
        let n = m.vertices.max(1) as f64;
        let members = m
            .front
            .iter()
            .map(|e| {
                Ok(Member {
                    vertices: e.vertices,
                    faces: e.faces,
                    error: e.objective,
                    mesh: MemberMesh::File(manifest::resolve(path, &e.file)?),
                })
            })
            .collect::<Result<Vec<_>>>()?;
        let baseline = m
            .front
            .iter()
            .filter_map(|e| e.greedy_at_same_vertices.as_ref())
            .map(|g| [g.vertices as f64 / n, g.objective])
            .collect();
        Ok(Front {
            source: path.display().to_string(),
            input_vertices: m.vertices,
            members,
            baseline,
            selected: None,
            chosen: BTreeSet::new(),
        })
    }

    pub fn points(&self) -> Vec<Point> {
        let n = self.input_vertices.max(1) as f64;
        self.members
            .iter()
            .map(|m| [m.vertices as f64 / n, m.error])
            .collect()
    }

    /// The member nearest to `at` within [`HIT_RADIUS`], the plot being drawn in `rect`.
    pub fn hit(&self, rect: egui::Rect, at: egui::Pos2) -> Option<usize> {
        let axes = self.axes();
        self.points()
            .iter()
            .enumerate()
            .map(|(k, &p)| (k, to_screen(&axes, rect, p).distance(at)))
            .filter(|&(_, d)| d <= HIT_RADIUS)
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(k, _)| k)
    }

    /// Where member `k` is drawn in a plot in `rect`.
    pub fn member_at(&self, rect: egui::Rect, k: usize) -> Option<egui::Pos2> {
        let p = *self.points().get(k)?;
        Some(to_screen(&self.axes(), rect, p))
    }

    fn axes(&self) -> Axes {
        let pts = self.points();
        Axes::fit(pts.iter().chain(&self.baseline))
    }

    /// Draws the plot in the width available; returns the click on a member, if any, and the
    /// rectangle drawn in.
    pub fn plot_ui(&self, ui: &mut egui::Ui) -> (Option<FrontClick>, egui::Rect) {
        let size = egui::vec2(ui.available_width().max(120.0), PLOT_HEIGHT);
        let (rect, response) = ui.allocate_exact_size(size, egui::Sense::click());
        let painter = ui.painter_at(rect);
        let visuals = ui.visuals();
        painter.rect_filled(rect, 2.0, visuals.extreme_bg_color);
        let axes = self.axes();
        let plot = plot_rect(rect);
        let faint = egui::Stroke::new(1.0, visuals.weak_text_color());
        let font = egui::FontId::proportional(10.0);
        let (l0, l1) = axes.decades;
        for d in l0 as i32..=l1 as i32 {
            let y = to_screen(&axes, rect, [0.0, 10f64.powi(d)]).y;
            painter.hline(plot.x_range(), y, egui::Stroke::new(0.5, faint.color));
            painter.text(
                egui::pos2(plot.left() - 3.0, y),
                egui::Align2::RIGHT_CENTER,
                format!("1e{d}"),
                font.clone(),
                visuals.text_color(),
            );
        }
        painter.text(
            plot.right_bottom() + egui::vec2(0.0, 3.0),
            egui::Align2::RIGHT_TOP,
            format!("{:.3} of the vertices", axes.x_max),
            font.clone(),
            visuals.text_color(),
        );
        painter.text(
            plot.left_bottom() + egui::vec2(0.0, 3.0),
            egui::Align2::LEFT_TOP,
            "0",
            font,
            visuals.text_color(),
        );
        painter.line_segment([plot.left_top(), plot.left_bottom()], faint);
        painter.line_segment([plot.left_bottom(), plot.right_bottom()], faint);
        let greedy: Vec<egui::Pos2> = self
            .baseline
            .iter()
            .map(|&p| to_screen(&axes, rect, p))
            .collect();
        let orange = egui::Color32::from_rgb(230, 120, 0);
        painter.extend(egui::Shape::dashed_line(
            &greedy,
            egui::Stroke::new(1.5, orange),
            5.0,
            3.0,
        ));
        let blue = egui::Color32::from_rgb(90, 140, 255);
        let pts: Vec<egui::Pos2> = self
            .points()
            .iter()
            .map(|&p| to_screen(&axes, rect, p))
            .collect();
        painter.add(egui::Shape::line(pts.clone(), egui::Stroke::new(1.0, blue)));
        for (k, &p) in pts.iter().enumerate() {
            painter.circle_filled(p, 2.5, blue);
            if self.chosen.contains(&k) {
                painter.circle_stroke(p, 5.0, egui::Stroke::new(1.5, egui::Color32::GREEN));
            }
            if self.selected == Some(k) {
                painter.circle_filled(p, 4.5, egui::Color32::WHITE);
            }
        }
        let hovered = response.hover_pos().and_then(|at| self.hit(rect, at));
        let click = if response.clicked() {
            let choose = ui.input(|i| i.modifiers.command || i.modifiers.shift);
            response
                .interact_pointer_pos()
                .and_then(|at| self.hit(rect, at))
                .map(|k| {
                    if choose {
                        FrontClick::Choose(k)
                    } else {
                        FrontClick::Show(k)
                    }
                })
        } else {
            None
        };
        if let Some(k) = hovered {
            let m = &self.members[k];
            response.on_hover_text_at_pointer(format!(
                "{} vertices, {} faces, error {:.3e}\nclick: show it; Ctrl+click: choose it \
                 for the LOD scene",
                m.vertices, m.faces, m.error
            ));
        }
        (click, rect)
    }
}

/// The plot's area inside the widget: room for the error's labels on the left and the
/// share's below, and on the right for the side panel's scroll bar, which lies over its
/// content and would take the clicks on the last points.
fn plot_rect(rect: egui::Rect) -> egui::Rect {
    egui::Rect::from_min_max(
        rect.min + egui::vec2(34.0, 8.0),
        rect.max - egui::vec2(22.0, 18.0),
    )
}

fn to_screen(axes: &Axes, rect: egui::Rect, p: Point) -> egui::Pos2 {
    let plot = plot_rect(rect);
    let (u, v) = axes.unit(p);
    egui::pos2(
        plot.left() + u as f32 * plot.width(),
        plot.bottom() - v as f32 * plot.height(),
    )
}

/// The search the window runs: `meshslim pareto`'s defaults, without measuring the front and
/// the greedy chain by Metro afterwards (that takes as long again; the command does it).
pub fn window_search() -> ParetoOptions {
    ParetoOptions {
        measure: false,
        ..ParetoOptions::default()
    }
}
