//! The window's panel and smaller behaviours, on the real eframe app driven headless by
//! egui_kittest (lavapipe in CI): the mode a painted or textured mesh opens in, what a mode key
//! the mesh cannot show says, the backend the window starts on and why, the ratio slider, Enter
//! in the faces field, the idle frame line. With CI=true a missing adapter fails.

use crate::common;
use crate::viewer_support;

use common::*;
use eframe::egui;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use meshslim::simplify::Backend;
use meshslim::viewer::{Mode, Model, Start, ViewerApp};
use viewer_support::*;

/// A painted mesh opens in the vertex-colour mode, also with the command line's style unless
/// its --mode says otherwise; `1` shades it, `6` shows its colours again, and the two frames
/// differ.
#[test]
fn a_coloured_mesh_opens_in_colour_mode() {
    if gpu_context().is_none() {
        return;
    }
    let mut m = meshslim::mesh::torus(1.0, 0.35, 48, 24);
    meshslim::mesh::paint(&mut m);
    let mut h = harness(Model::from_mesh("painted torus".into(), m).unwrap());
    h.step();
    assert_eq!(h.state().view.style.mode, Mode::Color);
    let coloured = h.state().pane_rgba(0).unwrap().0;
    h.key_press(egui::Key::Num1);
    h.step();
    assert_eq!(h.state().view.style.mode, Mode::Shaded);
    assert_ne!(
        h.state().pane_rgba(0).unwrap().0,
        coloured,
        "colours look shaded"
    );
    h.key_press(egui::Key::Num6);
    h.step();
    assert_eq!(h.state().view.style.mode, Mode::Color);
    // The command line's style keeps the mode the mesh picked unless --mode names one.
    let style = h.state().view.style;
    h.state_mut().set_style(style, None);
    assert_eq!(h.state().view.style.mode, Mode::Color);
    h.state_mut().set_style(style, Some(Mode::Shaded));
    assert_eq!(h.state().view.style.mode, Mode::Shaded);
}

/// A mesh with UVs and a texture opens in texture mode, as a painted one opens in colour mode.
#[test]
fn a_textured_mesh_opens_in_texture_mode() {
    if gpu_context().is_none() {
        return;
    }
    let mut model = Model::from_mesh("textured torus".into(), seamed_torus()).unwrap();
    // A 2x2 checker: the texture mode's frame differs from the shaded one.
    let texel = |on: bool| {
        if on {
            [250, 40, 40, 255]
        } else {
            [20, 20, 220, 255]
        }
    };
    model.texture = Some(meshslim::viewer::Image {
        rgba: [true, false, false, true]
            .iter()
            .flat_map(|&t| texel(t))
            .collect(),
        size: (2, 2),
    });
    let mut h = harness(model);
    h.step();
    assert_eq!(
        h.state().view.style.mode,
        Mode::Texture,
        "{}",
        h.state().status
    );
    let textured = h.state().pane_rgba(0).unwrap().0;
    h.key_press(egui::Key::Num1);
    h.step();
    assert_eq!(h.state().view.style.mode, Mode::Shaded);
    assert_ne!(
        h.state().pane_rgba(0).unwrap().0,
        textured,
        "the texture looks shaded"
    );
}

/// Keys 4 and 6 on a mesh with no texture and no colours change nothing and say why in the
/// status line, as the disabled buttons' hovers do.
#[test]
fn a_mode_key_the_mesh_cannot_show_says_why() {
    if gpu_context().is_none() {
        return;
    }
    let mut h = harness(
        Model::from_mesh("torus".into(), meshslim::mesh::torus(1.0, 0.35, 48, 24)).unwrap(),
    );
    h.step();
    assert_eq!(h.state().view.style.mode, Mode::Shaded);
    h.key_press(egui::Key::Num4);
    h.step();
    assert_eq!(h.state().view.style.mode, Mode::Shaded);
    let status = h.state().status.clone();
    assert!(
        status.starts_with("texture: ") && status.contains("no UVs"),
        "{status}"
    );
    h.key_press(egui::Key::Num6);
    h.step();
    assert_eq!(h.state().view.style.mode, Mode::Shaded);
    let status = h.state().status.clone();
    assert_eq!(status, "vertex colour: the mesh has no vertex colours");
    h.key_press(egui::Key::Num8);
    h.step();
    assert_eq!(h.state().view.style.mode, Mode::Shaded);
    assert!(
        h.state().status.starts_with("levels: only a cluster DAG"),
        "{}",
        h.state().status
    );
}

/// A cluster DAG opens in the window as its cut: the 3D view draws from the cut the device
/// chooses, the panel says what it draws, a larger threshold draws fewer triangles and a new
/// picture, and O shows the whole first level instead.
#[test]
fn a_dag_opens_as_its_cut_and_its_threshold_moves_it() {
    if gpu_context().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sphere.mslod");
    let m = meshslim::mesh::noisy_sphere(5, 0.01, 7);
    let (d, _) = meshslim::dag::build(&m, &Default::default()).unwrap();
    meshslim::dag::file::write(&path, &d).unwrap();
    let mut h = Harness::builder()
        .with_size(egui::vec2(900.0, 600.0))
        .wgpu_setup(meshslim::viewer::app::wgpu_setup())
        .build_eframe(|cc| ViewerApp::new(cc, Start::Open(path.clone())).expect("starts"));
    h.step();
    finish_job(&mut h);
    h.step();
    h.step();
    assert!(h.state().scene.dag.is_some(), "{}", h.state().status);
    let counts = |h: &Harness<'static, ViewerApp>| {
        let s = h.state();
        let d = s.scene.dag.as_ref().unwrap().lock().unwrap();
        d.counts(&s.eye.camera, s.view.pane_size(), s.view.pixels)
    };
    let fine = counts(&h);
    assert!(
        fine[2] > 0 && (fine[2] as usize) <= m.triangles.len(),
        "{fine:?}"
    );
    let label = format!("{} triangles drawn", fine[2]);
    assert!(
        h.query_by_label_contains(&label).is_some(),
        "the panel says {label}"
    );
    let picture = h.state().pane_rgba(0).unwrap().0;
    h.state_mut().view.pixels = 16.0;
    h.step();
    h.step();
    let coarse = counts(&h);
    assert!(coarse[2] < fine[2], "{coarse:?} against {fine:?}");
    let coarse_picture = h.state().pane_rgba(0).unwrap().0;
    assert!(coarse_picture != picture, "the cut moved");
    h.key_press(egui::Key::O);
    h.step();
    h.step();
    let first_level = h.state().pane_rgba(0).unwrap().0;
    assert!(first_level != coarse_picture, "O shows the first level");
    // Back to the cut, coloured by cluster (7) where the device numbers indirect draws.
    h.key_press(egui::Key::O);
    h.key_press(egui::Key::Num7);
    h.step();
    h.step();
    let numbered = h
        .state()
        .scene
        .dag
        .as_ref()
        .unwrap()
        .lock()
        .unwrap()
        .numbered;
    if numbered {
        assert_eq!(h.state().view.style.mode, Mode::Clusters);
        let clusters = h.state().pane_rgba(0).unwrap().0;
        assert!(clusters != coarse_picture, "the clusters in colours");
    } else {
        assert_eq!(h.state().view.style.mode, Mode::Shaded);
        assert!(
            h.state().status.contains("INDIRECT_FIRST_INSTANCE"),
            "{}",
            h.state().status
        );
    }
}

/// A mesh opened in the window becomes a DAG from the panel: a job on the panel's backend,
/// drawn as its cut when done, and saved as a .mslod that reads back as built.
#[test]
fn a_mesh_becomes_a_dag_from_the_panel_and_saves() {
    if gpu_context().is_none() {
        return;
    }
    let m = meshslim::mesh::noisy_sphere(4, 0.01, 3);
    let mut h = harness(Model::from_mesh("sphere".into(), m.clone()).unwrap());
    h.step();
    assert!(h.query_by_label("Make DAG").is_some());
    h.get_by_label("Make DAG").click();
    h.step();
    assert!(h.state().jobs.busy(), "{}", h.state().status);
    finish_job(&mut h);
    h.step();
    let s = h.state();
    assert!(s.scene.dag.is_some(), "{}", s.status);
    assert!(s.status.contains("clusters"), "{}", s.status);
    let built = s.scene.dag_built.clone().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sphere.mslod");
    h.state_mut().save_dag(Some(path.clone()));
    assert!(
        h.state().status.starts_with("saved the DAG"),
        "{}",
        h.state().status
    );
    let read = meshslim::dag::file::read(&path).unwrap();
    assert_eq!(read, *built, "the file holds the DAG as built");
    assert_eq!(read.mesh.triangles.len(), built.mesh.triangles.len());
}

/// A mesh of the window's auto-DAG size or more gets its DAG built as a job when it opens
/// (the command line's default builder), drawn whole until then and as its cut after; a
/// smaller one, or with the threshold 0, does not.
#[test]
fn a_large_mesh_is_drawn_as_its_dag_once_built() {
    if gpu_context().is_none() {
        return;
    }
    let m = meshslim::mesh::noisy_sphere(4, 0.01, 3);
    let faces = m.triangles.len();
    for (threshold, built) in [(faces, true), (faces + 1, false), (0, false)] {
        let mut h = harness(Model::from_mesh("sphere".into(), m.clone()).unwrap());
        h.state_mut().set_auto_dag(threshold);
        h.step();
        assert_eq!(h.state().jobs.busy(), built, "{}", h.state().status);
        if built {
            assert!(
                h.state().status.contains("moves like a small mesh"),
                "{}",
                h.state().status
            );
            finish_job(&mut h);
            h.step();
        }
        let s = h.state();
        assert_eq!(
            s.scene.dag.is_some(),
            built,
            "threshold {threshold}: {}",
            s.status
        );
        if built {
            let dag = s.scene.dag_built.clone().unwrap();
            let cli = meshslim::dag::build(&m, &meshslim::dag::DagOptions::default()).unwrap();
            assert_eq!(*dag, cli.0, "the command line's DAG");
        }
    }
}

/// On a software adapter (lavapipe here) the window starts on cpu-parallel, as the library's
/// `auto` would, and its panel says why; gpu stays one click away.
#[test]
fn the_window_starts_on_the_cores_over_a_software_adapter() {
    if gpu_context().is_none() {
        return;
    }
    let h = harness(
        Model::from_mesh("torus".into(), meshslim::mesh::torus(1.0, 0.35, 48, 24)).unwrap(),
    );
    let s = h.state();
    assert!(s.has_gpu_backend(), "{}", s.status);
    if s.adapter().to_lowercase().contains("llvmpipe") {
        assert_eq!(s.panel.backend, Backend::CpuParallel);
        assert!(
            s.panel.backend_why.contains("software rasterizer"),
            "{}",
            s.panel.backend_why
        );
    } else {
        assert_eq!(s.panel.backend, Backend::Gpu, "{}", s.panel.backend_why);
    }
}

/// A click on the ratio slider's track sets the ratio there (a logarithmic scale: near its
/// right end is near 1), and the face target follows it.
#[test]
fn a_click_on_the_ratio_track_sets_the_ratio() {
    if gpu_context().is_none() {
        return;
    }
    let model = Model::from_mesh("torus".into(), meshslim::mesh::torus(1.0, 0.35, 48, 24)).unwrap();
    let faces = model.faces();
    let mut h = harness(model);
    h.step();
    assert_eq!(h.state().panel.ratio, 0.1);
    // The slider's track, not its value field beside it (both are labelled "ratio").
    let track = h
        .get_all_by_label("ratio")
        .map(|n| n.rect())
        .max_by(|a, b| a.width().total_cmp(&b.width()))
        .expect("the ratio slider");
    assert!(track.width() > 150.0, "a narrow slider: {track:?}");
    let at = egui::pos2(track.left() + 0.9 * track.width(), track.center().y);
    click_at(&mut h, at, egui::Modifiers::NONE);
    let ratio = h.state().panel.ratio;
    assert!(ratio > 0.3, "the click set {ratio}");
    h.state_mut().simplify();
    finish_job(&mut h);
    let out = h
        .state()
        .scene
        .simplified
        .as_ref()
        .unwrap()
        .report
        .target_faces;
    assert_eq!(
        out,
        (faces as f64 * ratio).round() as usize,
        "{}",
        h.state().status
    );
    // Enter in the faces field simplifies at once (it took a second Enter once).
    h.state_mut().set_target_faces(200);
    h.step();
    h.get_all_by_value("200")
        .next()
        .expect("the faces field")
        .focus();
    h.step();
    h.key_press(egui::Key::Enter);
    h.step();
    finish_job(&mut h);
    let s = h.state().scene.simplified.as_ref().unwrap();
    assert_eq!(s.report.target_faces, 200, "{}", h.state().status);
}

/// An idle window says so, instead of a frame time of several seconds (0 FPS): it draws on
/// input then, and the gap between frames is the user's, not the renderer's.
#[test]
fn an_idle_window_says_it_draws_on_input() {
    if gpu_context().is_none() {
        return;
    }
    let mut h = Harness::builder()
        .with_size(egui::vec2(900.0, 600.0))
        .wgpu_setup(meshslim::viewer::app::wgpu_setup())
        .build_eframe(|cc| ViewerApp::new(cc, Start::Nothing).expect("the viewer starts"));
    h.step();
    h.step();
    assert!(h.query_by_label("frames: drawn on input (idle)").is_some());
    assert!(h.query_by_label_contains("FPS").is_none());
}

/// While a drag orbits the camera, the panel shows the time between the pictures drawn (a drag
/// draws one per move), not "drawn on input"; once it ends, the line goes back to idle.
#[test]
fn a_drag_shows_the_time_between_the_frames_it_draws() {
    if gpu_context().is_none() {
        return;
    }
    let mut h = harness(
        Model::from_mesh("torus".into(), meshslim::mesh::torus(1.0, 0.35, 48, 24)).unwrap(),
    );
    h.step();
    h.step();
    let camera = h.state().eye.camera;
    // The middle of the 3D view, right of the side panel.
    let at = egui::pos2(650.0, 300.0);
    h.hover_at(at);
    h.drag_at(at);
    h.step();
    for k in 1..=6 {
        h.hover_at(at + egui::vec2(12.0 * k as f32, 0.0));
        h.step();
    }
    assert_ne!(h.state().eye.camera, camera, "the drag orbits");
    assert!(h.state().eye.moving);
    assert!(
        h.query_by_label_contains("frames shown").is_some(),
        "the panel times the drag's frames"
    );
    h.drop_at(at + egui::vec2(72.0, 0.0));
    h.step();
    h.step();
    assert!(!h.state().eye.moving);
    assert!(h.query_by_label("frames: drawn on input (idle)").is_some());
}
