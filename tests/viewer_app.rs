//! The interactive viewer's real eframe app, driven headless by egui_kittest on the machine's
//! adapter (lavapipe in CI): the simplifier runs on the window's own device and the window draws
//! the rounds' buffers; the UI keeps drawing frames while a simplification runs and can cancel
//! it; modes, side by side and the LOD scene change what is drawn; shortcuts are ignored while a
//! text field has the keyboard. With CI=true a missing adapter fails.

mod common;

use common::*;
use eframe::egui;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use meshslim::simplify::Backend;
use meshslim::viewer::{Mode, Model, Start, ViewerApp};
use std::time::{Duration, Instant};

fn harness(model: Model) -> Harness<'static, ViewerApp> {
    Harness::builder()
        .with_size(egui::vec2(900.0, 600.0))
        .wgpu_setup(meshslim::viewer::app::wgpu_setup())
        .build_eframe(|cc| ViewerApp::new(cc, Start::Model(model)).expect("the viewer starts"))
}

/// Steps until the running job is done; returns how many frames were drawn meanwhile.
fn finish_job(h: &mut Harness<'static, ViewerApp>) -> u64 {
    let (t, f0) = (Instant::now(), h.state().frames);
    while h.state().job.is_some() {
        assert!(
            t.elapsed() < Duration::from_secs(300),
            "the job did not finish: {}",
            h.state().status
        );
        h.step();
    }
    h.state().frames - f0
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
    h.state_mut().backend = Backend::Gpu;
    h.state_mut().set_target_faces(3000);
    h.step();
    let before = h.render().expect("render");
    assert!(drawn_share(&before) > 0.05, "the original is drawn");

    h.get_by_label("Simplify").click();
    h.step();
    assert!(h.state().job.is_some(), "a job runs: {}", h.state().status);
    let frames = finish_job(&mut h);
    assert!(
        frames >= 2,
        "only {frames} frames drawn while simplifying: the UI was blocked"
    );
    assert!(h.state().clock.smoothed > 0.0, "frame time measured");
    let s = h
        .state()
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

    // Side by side: the original and the result, two panes of half the width.
    let (_, full) = h.state().pane_rgba(0).unwrap();
    h.state_mut().side_by_side = true;
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
        h.state_mut().style.mode = mode;
        h.step();
        frames.push(h.state().pane_rgba(0).unwrap().0);
    }
    h.state_mut().style.mode = Mode::Shaded;
    h.state_mut().style.wireframe = true;
    h.step();
    frames.push(h.state().pane_rgba(0).unwrap().0);
    h.state_mut().style.wireframe = false;
    h.step();
    assert_eq!(
        h.state().pane_rgba(0).unwrap().0,
        frames[0],
        "the same view twice"
    );
    assert_ne!(frames[0], frames[1], "normals look shaded");
    assert_ne!(frames[0], frames[2], "no wireframe drawn");
    // No texture on this mesh: the texture mode stays off.
    assert!(!h.state().mode_available(Mode::Texture));

    // Keys act on the view…
    assert!(!h.state().side_by_side);
    h.key_press(egui::Key::B);
    h.step();
    assert!(h.state().side_by_side, "B toggles side by side");
    let cam = h.state().camera;
    h.key_press(egui::Key::G);
    h.step();
    assert!(h.state().fly);
    h.key_down(egui::Key::W);
    h.step();
    h.step();
    h.key_up(egui::Key::W);
    h.step();
    assert_ne!(h.state().camera.target, cam.target, "W flies forward");
    // …but not while a text field has the keyboard.
    h.get_all_by_value("simplified.ply")
        .next()
        .expect("the save path field")
        .focus();
    h.step();
    h.key_press(egui::Key::B);
    h.step();
    assert!(
        h.state().side_by_side,
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
        h.state_mut().backend = backend;
        h.state_mut().set_target_faces(100);
        h.step();
        h.state_mut().simplify();
        h.step();
        h.get_by_label("Cancel").click();
        finish_job(&mut h);
        assert!(h.state().simplified.is_none(), "{backend:?}");
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
    let faces: Vec<usize> = h
        .state()
        .lod
        .as_ref()
        .unwrap_or_else(|| panic!("{}", h.state().status))
        .iter()
        .map(|l| l.faces)
        .collect();
    assert_eq!(faces.len(), 1 + meshslim::viewer::app::LOD_RATIOS.len());
    assert_eq!(faces[0], input);
    for (f, r) in faces[1..].iter().zip(meshslim::viewer::app::LOD_RATIOS) {
        let target = (input as f64 * r).round() as usize;
        assert!((target - 1..=target).contains(f), "{f} faces for ratio {r}");
    }
    assert!(h.state().lod_scene);
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
    h.state_mut().lod_on = false;
    h.step();
    assert_eq!(h.state().lod_histogram()[0], 21 * 21, "LOD off: all full");
    let pixels_off = h.state().pane_rgba(0).unwrap().0;
    assert_ne!(pixels_on, pixels_off, "LOD off draws the same meshes");
    let st = h.state();
    assert!(st.lod_frame[0].is_some() && st.lod_frame[1].is_some());
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
    assert!(h.state().model.is_none());
    h.input_mut()
        .dropped_files
        .push(std::sync::Arc::new(Dropped(input.clone())));
    h.step();
    finish_job(&mut h);
    let faces = h
        .state()
        .model
        .as_ref()
        .unwrap_or_else(|| panic!("{}", h.state().status))
        .faces();
    assert_eq!(faces, 5120);

    h.state_mut().set_target_faces(500);
    h.state_mut().backend = Backend::CpuParallel;
    h.state_mut().simplify();
    finish_job(&mut h);
    // Saving over the input is refused; elsewhere it writes the result.
    h.state_mut().save_path = input.display().to_string();
    h.state_mut().save();
    assert!(h.state().status.contains("input"), "{}", h.state().status);
    assert_eq!(meshslim::io::read(&input).unwrap().triangles.len(), 5120);
    let out = dir.path().join("ball-500.obj");
    h.state_mut().save_path = out.display().to_string();
    h.state_mut().save();
    let saved = meshslim::io::read(&out).unwrap_or_else(|_| panic!("{}", h.state().status));
    assert!((499..=500).contains(&saved.triangles.len()));

    let png = dir.path().join("shot.png");
    h.state_mut().shot_path = png.display().to_string();
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
    h.state_mut().backend = Backend::Gpu;
    h.state_mut().set_method(meshslim::Method::Hybrid);
    assert_eq!(h.state().backend, Backend::CpuParallel);
    for method in [meshslim::Method::Cluster, meshslim::Method::FloatingCell] {
        h.state_mut().backend = Backend::Gpu;
        h.state_mut().set_method(method);
        assert_eq!(h.state().backend, Backend::Gpu);
        h.state_mut().set_target_faces(2000);
        h.step();
        h.get_by_label("Simplify").click();
        h.step();
        finish_job(&mut h);
        let s = h
            .state()
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
