//! The Open dialog: a small file browser of folders and mesh files.

use eframe::egui;
use std::path::{Path, PathBuf};

/// A small file browser for Open…: egui has no native dialog, and the file-dialog crates lag
/// egui's releases (egui-file-dialog 0.15 needs egui 0.36).
pub(super) struct Browser {
    dir: PathBuf,
    path_text: String,
    entries: Vec<(String, bool)>,
    error: Option<String>,
}

pub(super) enum BrowserResult {
    Open(PathBuf),
    Close,
    Stay,
}

/// Meshes, and cluster DAGs (`meshslim dag build`), which open as their cut.
const MESH_EXTENSIONS: [&str; 6] = ["obj", "ply", "stl", "gltf", "glb", "mslod"];

impl Browser {
    pub(super) fn new(current: Option<PathBuf>) -> Browser {
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
                    // The manifests of `meshslim lods` and `pareto` open with their mesh.
                    let is_manifest =
                        crate::lod::manifest::ManifestKind::of(Path::new(&name)).is_some();
                    if (is_dir || is_mesh || is_manifest) && !name.starts_with('.') {
                        self.entries.push((name, is_dir));
                    }
                }
                self.entries.sort_by(|a, b| (!a.1, &a.0).cmp(&(!b.1, &b.0)));
            }
            Err(e) => self.error = Some(format!("{}: {e}", self.dir.display())),
        }
    }

    pub(super) fn ui(&mut self, ctx: &egui::Context) -> BrowserResult {
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
                    "{} (.obj .ply .stl .gltf .glb .mslod)",
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
