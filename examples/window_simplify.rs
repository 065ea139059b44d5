//! Simplifies a mesh in the real window app, driven headless by egui_kittest on this machine's
//! adapter (lavapipe here), as a user would: open, *Simplify* at a ratio with the backend the
//! window starts on (or the one given); prints the backend and why, and the status line (time
//! and error).
//!
//! cargo run --release --example window_simplify -- MESH [RATIO] [BACKEND]
use eframe::egui;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use meshslim::viewer::{Start, ViewerApp};
use std::time::Instant;

fn main() {
    let mut args = std::env::args().skip(1);
    let path = std::path::PathBuf::from(args.next().expect("a mesh"));
    let ratio: f64 = args.next().map_or(0.01, |r| r.parse().expect("RATIO"));
    let backend = args.next().map(|b| match b.as_str() {
        "gpu" => meshslim::Backend::Gpu,
        "cpu" => meshslim::Backend::Cpu,
        _ => meshslim::Backend::CpuParallel,
    });
    let mut h = Harness::builder()
        .with_size(egui::vec2(1280.0, 800.0))
        .wgpu_setup(meshslim::viewer::app::wgpu_setup())
        .build_eframe(|cc| ViewerApp::new(cc, Start::Nothing).expect("the viewer starts"));
    h.state_mut().open(path.clone());
    wait(&mut h);
    h.state_mut().set_ratio(ratio);
    if let Some(b) = backend {
        h.state_mut().panel.backend = b;
    }
    println!("{}", h.state().status);
    println!(
        "backend {} (the window started on {})",
        h.state().backend().name(),
        h.state().panel.backend_why
    );
    h.step();
    let t = Instant::now();
    h.get_by_label("Simplify").click();
    wait(&mut h);
    println!("{}", h.state().status);
    println!("{:.2} s from the click", t.elapsed().as_secs_f64());
}

/// Steps frames until the window's job is done.
fn wait(h: &mut Harness<'static, ViewerApp>) {
    h.step();
    while h.state().jobs.busy() {
        std::thread::sleep(std::time::Duration::from_millis(50));
        h.step();
    }
    h.step();
}
