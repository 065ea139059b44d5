//! The headless viewer on the machine's adapter (lavapipe in CI): frames drawn from the
//! simplifier's own buffers cover the mesh's part of the image, each mode gives a different
//! image, and the screenshot command writes a PNG. With CI=true a missing adapter fails.

mod common;

use common::*;
use meshslim::viewer::{Mode, screenshot};
use resvg::tiny_skia::Pixmap;

const BACKGROUND: [u8; 3] = [28, 31, 36]; // the clear colour (0.11, 0.12, 0.14) in 8 bits

fn is_background(px: &[u8]) -> bool {
    px[..3]
        .iter()
        .zip(BACKGROUND)
        .all(|(&a, b)| a.abs_diff(b) <= 2)
}

#[test]
fn frames_cover_the_mesh_and_modes_differ() {
    if gpu_context().is_none() {
        return;
    }
    let m = meshslim::mesh::noisy_sphere(4, 0.01, 5);
    let size = (160, 120);
    let mut images = Vec::new();
    for mode in [Mode::Shaded, Mode::Normals, Mode::Heatmap] {
        let frame = screenshot(&m, 0.2, mode, size).unwrap();
        // The target (a fifth of 5120) or one above: the rounds land on it ±1.
        assert!(
            (1024..=1025).contains(&frame.faces),
            "{mode:?}: {} faces drawn",
            frame.faces
        );
        let img = Pixmap::decode_png(&frame.png).expect("a valid PNG");
        assert_eq!((img.width(), img.height()), size);
        let px = |x: u32, y: u32| {
            let i = 4 * (y * size.0 + x) as usize;
            img.data()[i..i + 4].to_vec()
        };
        // The sphere fills the middle; the corners are background.
        assert!(
            !is_background(&px(80, 60)),
            "{mode:?}: centre is background"
        );
        for (x, y) in [(0, 0), (159, 0), (0, 119), (159, 119)] {
            assert!(
                is_background(&px(x, y)),
                "{mode:?}: corner ({x},{y}) is drawn"
            );
        }
        // A sphere of diameter 1 framed by its bounding sphere: it covers a disc of about a
        // quarter to half of the height's square.
        let covered = img.data().chunks(4).filter(|p| !is_background(p)).count();
        let share = covered as f64 / (size.0 * size.1) as f64;
        assert!(
            (0.1..0.6).contains(&share),
            "{mode:?}: {share:.2} of the image drawn"
        );
        if mode == Mode::Heatmap {
            assert!(
                frame.max_error > 0.0 && frame.max_error < 0.05,
                "{}",
                frame.max_error
            );
        }
        images.push(img.data().to_vec());
    }
    assert_ne!(images[0], images[1], "shaded and normals look the same");
    assert_ne!(images[0], images[2], "shaded and heatmap look the same");
    assert_ne!(images[1], images[2], "normals and heatmap look the same");
}

#[test]
fn screenshot_command_writes_a_png() {
    if gpu_context().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let o = meshslim(
        &[
            "view",
            "builtin:torus",
            "--screenshot",
            "torus.png",
            "--ratio",
            "0.1",
            "--size",
            "96x64",
        ],
        dir.path(),
    );
    expect_code(&o, 0);
    let png = std::fs::read(dir.path().join("torus.png")).unwrap();
    let img = Pixmap::decode_png(&png).unwrap();
    assert_eq!((img.width(), img.height()), (96, 64));
    assert!(
        img.data().chunks(4).any(|p| !is_background(p)),
        "the torus is drawn"
    );
    // Without --screenshot it says what exists today; a bad size is a usage error.
    expect_code(&meshslim(&["view", "builtin:torus"], dir.path()), 2);
    expect_code(
        &meshslim(
            &[
                "view",
                "builtin:torus",
                "--screenshot",
                "a.png",
                "--size",
                "9",
            ],
            dir.path(),
        ),
        2,
    );
}
