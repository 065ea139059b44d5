//! Measures the viewer's LOD scene: the real window app, driven headless by egui_kittest on this
//! machine's adapter (lavapipe here), draws the 21×21 grid as first framed with LOD on and off,
//! and prints the milliseconds per frame of each (each frame waited for on the GPU).
//!
//! cargo run --release --example lod_scene_frames -- MESH|X.lods.json|X.pareto.json [FRAMES]
//!
//! A mesh gets the window's *Make levels* (one GPU run, snapshots at 25%, 6%, 1.5%); a lods
//! manifest brings its own levels; a Pareto manifest has its members at about a half, a quarter,
//! a tenth and a twentieth of the vertices chosen, as a Ctrl+click would.
use eframe::egui;
use egui_kittest::Harness;
use meshslim::viewer::{Start, ViewerApp};
use std::time::Instant;

fn main() {
    let mut args = std::env::args().skip(1);
    let path = std::path::PathBuf::from(args.next().expect("a mesh or a manifest"));
    let frames: usize = args.next().map_or(20, |f| f.parse().expect("FRAMES"));
    let mut h = Harness::builder()
        .with_size(egui::vec2(1280.0, 800.0))
        .wgpu_setup(meshslim::viewer::app::wgpu_setup())
        .build_eframe(|cc| ViewerApp::new(cc, Start::Nothing).expect("the viewer starts"));
    let finish = |h: &mut Harness<'static, ViewerApp>| {
        while h.state().jobs.busy() {
            h.step();
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
    };
    h.state_mut().open(path.clone());
    finish(&mut h);
    let is_pareto = path.to_string_lossy().ends_with(".pareto.json");
    if h.state().scene.lod.is_none() && !is_pareto {
        h.step();
        let t = Instant::now();
        h.state_mut().make_lod();
        finish(&mut h);
        println!("levels made in {:.2} s", t.elapsed().as_secs_f64());
    }
    if is_pareto {
        let front = h.state().scene.front.clone().expect("a front");
        for share in [0.5, 0.25, 0.1, 0.05] {
            let want = share * front.input_vertices as f64;
            let k = (0..front.members.len())
                .min_by(|&a, &b| {
                    let d = |k: usize| (front.members[k].vertices as f64 - want).abs();
                    d(a).total_cmp(&d(b))
                })
                .expect("members");
            h.state_mut().choose_member(k);
        }
        h.state_mut().lod_from_front();
        finish(&mut h);
    }
    let st = h.state();
    let levels = st
        .scene
        .lod
        .as_ref()
        .unwrap_or_else(|| panic!("no levels: {}", st.status));
    let faces: Vec<String> = levels.iter().map(|l| l.faces.to_string()).collect();
    println!(
        "{}: levels {} faces, from {}",
        path.display(),
        faces.join(" / "),
        st.scene.lod_source
    );
    for on in [true, false] {
        h.state_mut().view.lod_on = on;
        // Two frames to settle (the view's textures, the first pipelines).
        h.step();
        h.step();
        let t = Instant::now();
        for _ in 0..frames {
            h.step();
            let (device, _) = h.state().device();
            device
                .poll(wgpu::PollType::wait_indefinitely())
                .expect("poll");
        }
        let ms = t.elapsed().as_secs_f64() * 1e3 / frames as f64;
        println!(
            "LOD {}: {ms:.1} ms per frame ({:.1} FPS), instances per level {:?}",
            if on { "on " } else { "off" },
            1e3 / ms,
            h.state().lod_histogram()
        );
    }
}
