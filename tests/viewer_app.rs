//! The interactive viewer's real eframe app, driven headless by egui_kittest on the machine's
//! adapter (lavapipe in CI): the simplifier runs on the window's own device and the window draws
//! the rounds' buffers; the UI keeps drawing frames while a simplification runs and can cancel
//! it; modes, side by side and the LOD scene change what is drawn; shortcuts are ignored while a
//! text field has the keyboard. With CI=true a missing adapter fails.

use crate::common;
use crate::viewer_support;

use common::*;
use eframe::egui;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use meshslim::simplify::Backend;
use meshslim::viewer::{Mode, Model, Start, ViewerApp};
use viewer_support::*;

/// The faces of the LOD scene's levels, the original first.
fn level_faces(h: &Harness<'static, ViewerApp>) -> Vec<usize> {
    h.state()
        .scene
        .lod
        .as_ref()
        .unwrap_or_else(|| panic!("no levels: {}", h.state().status))
        .iter()
        .map(|l| l.faces)
        .collect()
}

fn read_buffer(app: &ViewerApp, buf: &wgpu::Buffer, bytes: u64) -> Vec<u8> {
    let (device, queue) = app.device();
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("test.readback"),
        size: bytes,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut enc = device.create_command_encoder(&Default::default());
    enc.copy_buffer_to_buffer(buf, 0, &staging, 0, bytes);
    queue.submit([enc.finish()]);
    staging.map_async(wgpu::MapMode::Read, .., |r| r.expect("map"));
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .expect("poll");
    let v = staging.get_mapped_range(..).expect("mapped").to_vec();
    staging.unmap();
    v
}

/// Share of pixels of the 3D view (right of the side panel, above the status line) that differ
/// from the clear colour.
fn drawn_share(img: &image::RgbaImage) -> f64 {
    let (w, h) = img.dimensions();
    let (x0, x1, y0, y1) = (w * 2 / 5, w, 0, h * 9 / 10);
    let mut drawn = 0;
    for y in y0..y1 {
        for x in x0..x1 {
            let p = img.get_pixel(x, y).0;
            if [28u8, 31, 36]
                .iter()
                .zip(p)
                .any(|(&b, a)| a.abs_diff(b) > 3)
            {
                drawn += 1;
            }
        }
    }
    drawn as f64 / ((x1 - x0) * (y1 - y0)) as f64
}

#[test]
fn simplifies_on_the_window_device_and_keeps_drawing() {
    if gpu_context().is_none() {
        return;
    }
    // 327,680 faces: long enough on lavapipe that frames are drawn while it runs.
    let mesh = meshslim::mesh::noisy_sphere(7, 0.01, 3);
    let input_vertices = mesh.positions.len();
    let model = Model::from_mesh("noisy sphere".into(), mesh).unwrap();
    let mut h = harness(model);
    assert!(h.state().has_gpu_backend(), "{}", h.state().status);
    h.state_mut().panel.backend = Backend::Gpu;
    h.state_mut().set_target_faces(3000);
    h.step();
    let before = h.render().expect("render");
    assert!(drawn_share(&before) > 0.05, "the original is drawn");

    h.get_by_label("Simplify").click();
    h.step();
    assert!(
        h.state().jobs.running().is_some(),
        "a job runs: {}",
        h.state().status
    );
    let frames = finish_job(&mut h);
    assert!(
        frames >= 2,
        "only {frames} frames drawn while simplifying: the UI was blocked"
    );
    assert!(h.state().view.clock.smoothed > 0.0, "frame time measured");
    let s = h
        .state()
        .scene
        .simplified
        .as_ref()
        .unwrap_or_else(|| panic!("{}", h.state().status));
    assert!(
        (3000..=3001).contains(&s.report.output_faces),
        "{}",
        s.report.output_faces
    );
    let (mean, max) = s.error.expect("the result is measured");
    assert!(mean > 0.0 && max < 0.05, "{mean} {max}");
    // Drawn from the rounds' own buffers: the positions buffer is the one uploaded for the
    // input (sized for every input vertex), not a fresh upload of the result…
    assert!(s.scene.gpu.positions.size() >= input_vertices as u64 * 16);
    // …and the draw takes its count from the arguments the last round wrote.
    let args = read_buffer(h.state(), &s.scene.gpu.draw_args, 20);
    let index_count = u32::from_le_bytes(args[0..4].try_into().unwrap());
    assert_eq!(index_count as usize, 3 * s.report.output_faces);
    let after = h.render().expect("render");
    assert!(drawn_share(&after) > 0.05, "the result is drawn");
    // The stage times are folded under one header, so Save and Screenshot stay in sight.
    let simplified = h.state().scene.simplified.as_ref().unwrap();
    let stages = simplified
        .report
        .rounds
        .as_ref()
        .unwrap()
        .stage_seconds
        .0
        .clone();
    assert!(stages.len() > 10);
    h.step();
    assert!(h.query_by_label_contains("time per stage").is_some());
    assert!(
        h.query_by_label(&stages[0].0).is_none(),
        "the stage rows unfolded"
    );

    // Side by side: the original and the result, two panes of half the width.
    let (_, full) = h.state().pane_rgba(0).unwrap();
    h.state_mut().view.side_by_side = true;
    h.step();
    let (left, size) = h.state().pane_rgba(0).unwrap();
    let (right, _) = h.state().pane_rgba(1).expect("a second pane");
    assert!(size.0 < full.0 * 6 / 10, "{size:?} vs {full:?}");
    assert_ne!(left, right, "the original and 3000 faces look the same");
}

#[test]
fn modes_change_the_frame_and_keys_respect_text_fields() {
    if gpu_context().is_none() {
        return;
    }
    let model = Model::from_mesh("torus".into(), meshslim::mesh::torus(1.0, 0.35, 48, 24)).unwrap();
    let mut h = harness(model);
    h.step();
    // The 3D view's own pixels (the panels around it change every frame: the frame time).
    let mut frames = Vec::new();
    for mode in [Mode::Shaded, Mode::Normals] {
        h.state_mut().view.style.mode = mode;
        h.step();
        frames.push(h.state().pane_rgba(0).unwrap().0);
    }
    h.state_mut().view.style.mode = Mode::Shaded;
    h.state_mut().view.style.wireframe = true;
    h.step();
    frames.push(h.state().pane_rgba(0).unwrap().0);
    h.state_mut().view.style.wireframe = false;
    h.step();
    assert_eq!(
        h.state().pane_rgba(0).unwrap().0,
        frames[0],
        "the same view twice"
    );
    assert_ne!(frames[0], frames[1], "normals look shaded");
    assert_ne!(frames[0], frames[2], "no wireframe drawn");
    // No texture and no colours on this mesh: those modes stay off.
    assert!(!h.state().mode_available(Mode::Texture));
    assert!(!h.state().mode_available(Mode::Color));

    // Keys act on the view…
    assert!(!h.state().view.side_by_side);
    h.key_press(egui::Key::B);
    h.step();
    assert!(h.state().view.side_by_side, "B toggles side by side");
    let cam = h.state().eye.camera;
    h.key_press(egui::Key::G);
    h.step();
    assert!(h.state().eye.fly);
    h.key_down(egui::Key::W);
    h.step();
    h.step();
    h.key_up(egui::Key::W);
    h.step();
    assert_ne!(h.state().eye.camera.target, cam.target, "W flies forward");
    // …but not while a text field has the keyboard.
    h.get_all_by_value("simplified.ply")
        .next()
        .expect("the save path field")
        .focus();
    h.step();
    h.key_press(egui::Key::B);
    h.step();
    assert!(
        h.state().view.side_by_side,
        "B typed into a field toggled the view"
    );
}

#[test]
fn cancel_stops_a_running_simplification() {
    if gpu_context().is_none() {
        return;
    }
    // The greedy queue checks every 4096 collapses, the rounds every round.
    for backend in [Backend::Cpu, Backend::Gpu] {
        let mesh = meshslim::mesh::noisy_sphere(7, 0.01, 2);
        let model = Model::from_mesh("sphere".into(), mesh).unwrap();
        let mut h = harness(model);
        h.state_mut().panel.backend = backend;
        h.state_mut().set_target_faces(100);
        h.step();
        h.state_mut().simplify();
        h.step();
        h.get_by_label("Cancel").click();
        finish_job(&mut h);
        assert!(h.state().scene.simplified.is_none(), "{backend:?}");
        assert!(
            h.state().status.contains("cancelled"),
            "{backend:?}: {}",
            h.state().status
        );
    }
}
#[test]
fn lod_levels_come_from_one_gpu_run_and_switch_by_size_on_screen() {
    if gpu_context().is_none() {
        return;
    }
    let model =
        Model::from_mesh("sphere".into(), meshslim::mesh::noisy_sphere(5, 0.01, 4)).unwrap();
    let input = model.faces();
    let mut h = harness(model);
    h.step();
    h.state_mut().make_lod();
    finish_job(&mut h);
    let faces = level_faces(&h);
    assert_eq!(faces.len(), 1 + meshslim::viewer::app::LOD_RATIOS.len());
    assert_eq!(faces[0], input);
    for (f, r) in faces[1..].iter().zip(meshslim::viewer::app::LOD_RATIOS) {
        let target = (input as f64 * r).round() as usize;
        assert!((target - 1..=target).contains(f), "{f} faces for ratio {r}");
    }
    assert!(h.state().view.lod_scene);
    h.step();
    let on = h.render().unwrap();
    assert!(drawn_share(&on) > 0.05, "the grid is drawn");
    // From the first view, near instances are large and far ones small: several levels drawn,
    // finer ones nearer (by size on screen).
    let hist = h.state().lod_histogram();
    assert_eq!(hist.iter().sum::<usize>(), 21 * 21);
    assert!(
        hist.iter().filter(|&&n| n > 0).count() >= 2,
        "one level for the whole grid: {hist:?}"
    );
    let pixels_on = h.state().pane_rgba(0).unwrap().0;
    h.state_mut().view.lod_on = false;
    h.step();
    assert_eq!(h.state().lod_histogram()[0], 21 * 21, "LOD off: all full");
    let pixels_off = h.state().pane_rgba(0).unwrap().0;
    assert_ne!(pixels_on, pixels_off, "LOD off draws the same meshes");
    let st = h.state();
    assert!(st.view.lod_frame[0].is_some() && st.view.lod_frame[1].is_some());
}

/// A file dropped on the window, as winit hands it to egui.
#[derive(Debug)]
struct Dropped(std::path::PathBuf);

impl egui::DroppedFile for Dropped {
    fn path(&self) -> &std::path::Path {
        &self.0
    }
    fn bytes(&self) -> Result<Vec<u8>, String> {
        std::fs::read(&self.0).map_err(|e| e.to_string())
    }
}

#[test]
fn a_dropped_file_opens_and_the_result_saves_and_screenshots() {
    if gpu_context().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("ball.ply");
    meshslim::io::write(&input, &meshslim::mesh::icosphere(4)).unwrap();
    let mut h = Harness::builder()
        .with_size(egui::vec2(900.0, 600.0))
        .wgpu_setup(meshslim::viewer::app::wgpu_setup())
        .build_eframe(|cc| ViewerApp::new(cc, Start::Nothing).expect("the viewer starts"));
    assert!(h.state().scene.model.is_none());
    h.input_mut()
        .dropped_files
        .push(std::sync::Arc::new(Dropped(input.clone())));
    h.step();
    finish_job(&mut h);
    let faces = h
        .state()
        .scene
        .model
        .as_ref()
        .unwrap_or_else(|| panic!("{}", h.state().status))
        .faces();
    assert_eq!(faces, 5120);
    // Save writes into the working directory by default: the input's is often read-only.
    assert_eq!(h.state().panel.save_path, "ball-simplified.ply");
    // An axis chosen for one file is that file's: the next opens with its own.
    h.state_mut().set_up(Some(meshslim::viewer::camera::Up::X));
    assert_eq!(h.state().eye.up, Some(meshslim::viewer::camera::Up::X));
    h.state_mut().open(input.clone());
    finish_job(&mut h);
    assert!(h.state().scene.model.is_some(), "{}", h.state().status);
    assert_eq!(h.state().eye.up, None, "the chosen axis carried over");

    h.state_mut().set_target_faces(500);
    h.state_mut().panel.backend = Backend::CpuParallel;
    h.state_mut().simplify();
    finish_job(&mut h);
    // Saving over the input is refused; elsewhere it writes the result.
    h.state_mut().panel.save_path = input.display().to_string();
    h.state_mut().save();
    assert!(h.state().status.contains("input"), "{}", h.state().status);
    assert_eq!(meshslim::io::read(&input).unwrap().triangles.len(), 5120);
    let out = dir.path().join("ball-500.obj");
    h.state_mut().panel.save_path = out.display().to_string();
    h.state_mut().save();
    let saved = meshslim::io::read(&out).unwrap_or_else(|_| panic!("{}", h.state().status));
    assert!((499..=500).contains(&saved.triangles.len()));

    let png = dir.path().join("shot.png");
    h.state_mut().panel.shot_path = png.display().to_string();
    h.step();
    h.state_mut().screenshot();
    let img = resvg::tiny_skia::Pixmap::decode_png(
        &std::fs::read(&png).unwrap_or_else(|_| panic!("{}", h.state().status)),
    )
    .expect("a PNG");
    let drawn = img
        .data()
        .chunks(4)
        .filter(|p| {
            p[..3]
                .iter()
                .zip([28u8, 31, 36])
                .any(|(&a, b)| a.abs_diff(b) > 3)
        })
        .count();
    // The 3D view only (no panels): the ball covers a good part of it.
    assert!(drawn as f64 / (img.width() * img.height()) as f64 > 0.05);

    // Side by side, the screenshot is what the window shows: both panes, the original on the
    // left and the result on the right (P after B once saved the original's pane alone).
    h.state_mut().view.side_by_side = true;
    h.step();
    let (left, (lw, lh)) = h.state().pane_rgba(0).unwrap();
    let (right, (rw, _)) = h.state().pane_rgba(1).unwrap();
    h.state_mut().screenshot();
    let both = resvg::tiny_skia::Pixmap::decode_png(&std::fs::read(&png).unwrap()).unwrap();
    assert_eq!((both.width(), both.height()), (lw + rw, lh));
    let row =
        |px: &[u8], w: u32, y: u32| px[(4 * w * y) as usize..(4 * w * (y + 1)) as usize].to_vec();
    let y = lh / 2;
    let shot = row(both.data(), lw + rw, y);
    assert_eq!(
        shot[..(4 * lw) as usize],
        row(&left, lw, y)[..],
        "the left pane"
    );
    assert_eq!(
        shot[(4 * lw) as usize..],
        row(&right, rw, y)[..],
        "the right pane"
    );
    // Each pane's label is in the image, as the window draws it over the pane.
    for (x0, pane, w) in [(0, &left, lw), (lw, &right, rw)] {
        let y = 14;
        let at = (4 * (y * (lw + rw) + x0)) as usize;
        let labelled = &both.data()[at..at + 4 * 60];
        assert_ne!(
            labelled,
            &row(pane, w, y)[..60 * 4],
            "no label over the pane at {x0}"
        );
    }
}

/// `--method cluster` and `floating-cell` on the gpu backend run on the window's device and the
/// window draws the buffers the build wrote (sized for every input vertex, not a fresh upload of the result),
/// with the kept faces' count in the draw arguments; a method the device does not run moves
/// the backend to cpu-parallel.
#[test]
fn clustering_on_the_window_device_is_drawn_from_its_buffers() {
    if gpu_context().is_none() {
        return;
    }
    let mesh = meshslim::mesh::noisy_sphere(6, 0.01, 4);
    let input_vertices = mesh.positions.len();
    let model = Model::from_mesh("noisy sphere".into(), mesh).unwrap();
    let mut h = harness(model);
    assert!(h.state().has_gpu_backend(), "{}", h.state().status);
    h.state_mut().panel.backend = Backend::Gpu;
    h.state_mut().set_method(meshslim::Method::Hybrid);
    assert_eq!(h.state().panel.backend, Backend::CpuParallel);
    for method in [meshslim::Method::Cluster, meshslim::Method::FloatingCell] {
        h.state_mut().panel.backend = Backend::Gpu;
        h.state_mut().set_method(method);
        assert_eq!(h.state().panel.backend, Backend::Gpu);
        h.state_mut().set_target_faces(2000);
        h.step();
        h.get_by_label("Simplify").click();
        h.step();
        finish_job(&mut h);
        let s = h
            .state()
            .scene
            .simplified
            .as_ref()
            .unwrap_or_else(|| panic!("{}", h.state().status));
        assert_eq!(s.report.backend, Backend::Gpu);
        let faces = s.report.output_faces;
        assert!((1900..=2100).contains(&faces), "{faces}");
        assert!(s.scene.gpu.positions.size() >= input_vertices as u64 * 16);
        let args = read_buffer(h.state(), &s.scene.gpu.draw_args, 20);
        assert_eq!(
            u32::from_le_bytes(args[0..4].try_into().unwrap()) as usize,
            3 * faces
        );
        // The drawn faces are the output's, up to the numbering of their vertices: the same
        // positions corner by corner.
        let idx: Vec<u32> = bytemuck::pod_collect_to_vec(&read_buffer(
            h.state(),
            &s.scene.gpu.indices,
            12 * faces as u64,
        ));
        let clusters = idx.iter().max().map_or(0, |&m| m as u64 + 1);
        let pos: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&read_buffer(
            h.state(),
            &s.scene.gpu.positions,
            16 * clusters,
        ));
        let g = &s.scene.gpu;
        for (c, &v) in s.mesh.triangles.iter().flatten().enumerate() {
            let p = pos[idx[c] as usize];
            let world = [0, 1, 2].map(|i| p[i] as f64 / g.scale + g.center[i]);
            let out = s.mesh.positions[v as usize];
            for i in 0..3 {
                assert!(
                    (world[i] - out[i] as f64).abs() < 1e-4,
                    "corner {c}: drawn {world:?}, written {out:?}"
                );
            }
        }
        let after = h.render().expect("render");
        assert!(
            drawn_share(&after) > 0.05,
            "{method:?}: the result is drawn"
        );
    }
}

/// Where member `k` of the front is drawn, checked to be on screen and to hit that member.
fn front_point(h: &Harness<'static, ViewerApp>, k: usize) -> egui::Pos2 {
    let st = h.state();
    let rect = st.panel.front_rect.expect("the front's plot is drawn");
    let front = st.scene.front.as_ref().expect("a front");
    let at = front.member_at(rect, k).expect("a member");
    assert!(
        egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(1000.0, 900.0)).contains(at),
        "member {k} at {at:?}, off the screen"
    );
    assert_eq!(front.hit(rect, at), Some(k), "member {k} at {at:?}");
    at
}

/// `meshslim lods` and `meshslim pareto` manifests open in the window with the mesh they name,
/// from another folder: the levels go to the LOD scene (each instance drawing the level its
/// size calls for), the front to the side panel's plot. Clicking a point shows that member;
/// Ctrl+click chooses members, and the LOD scene takes its levels from the chosen ones. A
/// manifest of a generated mesh says how to open it.
#[test]
fn manifests_open_into_the_lod_scene_and_the_front_plot() {
    if gpu_context().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let ball = meshslim::mesh::noisy_sphere(4, 0.01, 7);
    meshslim::io::write(&dir.path().join("ball.ply"), &ball).unwrap();
    let run = |args: &[&str]| expect_code(&meshslim(args, dir.path()), 0);
    run(&["lods", "ball.ply", "out", "--ratios", "0.5,0.2,0.05", "-q"]);
    run(&[
        "pareto",
        "ball.ply",
        "front",
        "--population",
        "12",
        "--generations",
        "2",
        "--offspring",
        "4",
        "-q",
    ]);
    run(&["lods", "builtin:sphere:500", "made", "-q"]);
    let json = |p: &str| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(dir.path().join(p)).unwrap()).unwrap()
    };
    let mut h = Harness::builder()
        .with_size(egui::vec2(1000.0, 900.0))
        .wgpu_setup(meshslim::viewer::app::wgpu_setup())
        .build_eframe(|cc| ViewerApp::new(cc, Start::Nothing).expect("the viewer starts"));

    h.state_mut().open(dir.path().join("out/ball.lods.json"));
    finish_job(&mut h);
    let manifest = json("out/ball.lods.json");
    let mut want = vec![ball.triangles.len()];
    for l in manifest["levels"].as_array().unwrap() {
        want.push(l["faces"].as_u64().unwrap() as usize);
    }
    let st = h.state();
    let levels = st
        .scene
        .lod
        .as_ref()
        .unwrap_or_else(|| panic!("no levels: {}", st.status));
    assert_eq!(levels.iter().map(|l| l.faces).collect::<Vec<_>>(), want);
    assert!(st.view.lod_scene && st.scene.lod_source.contains("lods"));
    h.step();
    let hist = h.state().lod_histogram();
    assert_eq!(hist.iter().sum::<usize>(), 21 * 21);
    assert!(
        hist.iter().all(|&n| n > 0),
        "from the first view, every level has its instances: {hist:?}"
    );

    h.state_mut()
        .open(dir.path().join("front/ball.pareto.json"));
    finish_job(&mut h);
    let manifest = json("front/ball.pareto.json");
    let members = manifest["front"].as_array().unwrap();
    {
        let st = h.state();
        assert!(
            st.scene.lod.is_none(),
            "the levels were of the model before"
        );
        let front = st
            .scene
            .front
            .as_ref()
            .unwrap_or_else(|| panic!("no front: {}", st.status));
        assert!(members.len() >= 2, "{members:?}");
        assert_eq!(front.members.len(), members.len());
        for (m, e) in front.members.iter().zip(members) {
            assert_eq!(m.vertices as u64, e["vertices"].as_u64().unwrap());
        }
        assert_eq!(
            front.baseline.len(),
            members.len(),
            "the greedy chain, dashed"
        );
    }
    h.step();
    let last = members.len() - 1;
    let at = front_point(&h, 1);
    click_at(&mut h, at, egui::Modifiers::NONE);
    finish_job(&mut h);
    let st = h.state();
    let shown = st
        .scene
        .simplified
        .as_ref()
        .unwrap_or_else(|| panic!("nothing shown: {}", st.status));
    assert_eq!(
        shown.mesh.triangles.len() as u64,
        members[1]["faces"].as_u64().unwrap()
    );
    assert_eq!(st.scene.front.as_ref().unwrap().selected, Some(1));
    assert!(shown.error.is_some_and(|(mean, _)| mean > 0.0));
    h.state_mut().view.side_by_side = true;
    h.step();
    assert!(drawn_share(&h.render().unwrap()) > 0.05);

    let ctrl = egui::Modifiers {
        ctrl: true,
        command: true,
        ..Default::default()
    };
    for k in [0, last] {
        let at = front_point(&h, k);
        click_at(&mut h, at, ctrl);
    }
    assert_eq!(
        h.state().scene.front.as_ref().unwrap().chosen,
        [0, last].into_iter().collect()
    );
    assert!(
        h.state().jobs.running().is_none(),
        "Ctrl+click only chooses"
    );
    h.get_by_label("LOD scene from 2 chosen").click();
    h.step();
    finish_job(&mut h);
    let faces = level_faces(&h);
    let member_faces = |k: usize| members[k]["faces"].as_u64().unwrap() as usize;
    assert_eq!(
        faces,
        [ball.triangles.len(), member_faces(last), member_faces(0)]
    );

    // The panel's Search runs the same NSGA-II on the open mesh, here and now.
    h.state_mut().panel.pareto.population = 10;
    h.state_mut().panel.pareto.generations = 2;
    h.get_by_label("Search").click();
    h.step();
    finish_job(&mut h);
    let st = h.state();
    let front = st
        .scene
        .front
        .as_ref()
        .unwrap_or_else(|| panic!("no front: {}", st.status));
    assert!(front.source.contains("searched here"), "{}", front.source);
    assert!(!front.members.is_empty() && front.members.len() <= 10);
    assert!(
        front.baseline.is_empty(),
        "the window does not measure the chain"
    );
    if let Ok(p) = std::env::var("MESHSLIM_FRONT_PNG") {
        h.render().unwrap().save(p).unwrap();
    }

    h.state_mut()
        .open(dir.path().join("made/builtin-sphere.lods.json"));
    finish_job(&mut h);
    let status = &h.state().status;
    assert!(
        status.contains("builtin:sphere:500") && status.contains("meshslim view"),
        "{status}"
    );
}
