//! Helpers of the window app's tests (tests/viewer_app.rs and tests/viewer_panel.rs): the app
//! on a generated model, a job waited for, a click at a point.
#![allow(dead_code)]

use eframe::egui;
use egui_kittest::Harness;
use meshslim::viewer::{Model, Start, ViewerApp};
use std::time::{Duration, Instant};

pub fn harness(model: Model) -> Harness<'static, ViewerApp> {
    Harness::builder()
        .with_size(egui::vec2(900.0, 600.0))
        .wgpu_setup(meshslim::viewer::app::wgpu_setup())
        .build_eframe(|cc| ViewerApp::new(cc, Start::Model(model)).expect("the viewer starts"))
}

/// Steps until the running job is done; returns how many frames were drawn meanwhile.
pub fn finish_job(h: &mut Harness<'static, ViewerApp>) -> u64 {
    let (t, f0) = (Instant::now(), h.state().view.frames);
    while h.state().jobs.running().is_some() {
        assert!(
            t.elapsed() < Duration::from_secs(300),
            "the job did not finish: {}",
            h.state().status
        );
        h.step();
    }
    h.state().view.frames - f0
}

/// A click of the primary button at `at` with `modifiers` held, as winit hands it to egui.
pub fn click_at(h: &mut Harness<'static, ViewerApp>, at: egui::Pos2, modifiers: egui::Modifiers) {
    h.input_mut().events.push(egui::Event::PointerMoved(at));
    h.step();
    h.input_mut()
        .events
        .push(egui::Event::ModifiersChanged(modifiers));
    for pressed in [true, false] {
        h.input_mut().events.push(egui::Event::PointerButton {
            pos: at,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers,
        });
        h.step();
    }
    h.input_mut()
        .events
        .push(egui::Event::ModifiersChanged(egui::Modifiers::NONE));
    h.step();
}
