//! The headless viewer on the machine's adapter (lavapipe in CI): frames drawn from the
//! simplifier's own buffers cover the mesh's part of the image, each mode gives a different
//! image, and the screenshot command writes a PNG. With CI=true a missing adapter fails.

use crate::common;

use common::*;
use meshslim::UvOrigin;
use meshslim::viewer::{Mode, Model, Style, screenshot};
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
    let mut m = meshslim::mesh::noisy_sphere(4, 0.01, 5);
    m.uvs = Some(spherical_uvs(&m.positions));
    meshslim::mesh::paint(&mut m);
    let mut model = Model::from_mesh("noisy sphere".into(), m).unwrap();
    model.texture = Some(checker(64));
    let size = (160, 120);
    let mut images = Vec::new();
    for mode in Mode::ALL {
        let style = Style {
            mode,
            ..Style::default()
        };
        let frame = screenshot(&model, 0.2, style, size).unwrap();
        // The target (a fifth of 5120) or one below: an interior collapse removes two faces.
        assert!(
            (1023..=1024).contains(&frame.faces),
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
    for i in 0..images.len() {
        for j in i + 1..images.len() {
            assert_ne!(
                images[i],
                images[j],
                "{:?} and {:?} look the same",
                Mode::ALL[i],
                Mode::ALL[j]
            );
        }
    }
    // Smooth shading and the wireframe overlay change the shaded image too.
    let shaded = |smooth, wireframe| {
        let style = Style {
            smooth,
            wireframe,
            ..Style::default()
        };
        let f = screenshot(&model, 0.2, style, size).unwrap();
        Pixmap::decode_png(&f.png).unwrap().data().to_vec()
    };
    assert_eq!(shaded(false, false), images[0], "the same frame twice");
    assert_ne!(shaded(true, false), images[0], "smooth looks flat");
    assert_ne!(shaded(false, true), images[0], "no wireframe drawn");
}

/// Longitude and latitude as UVs.
fn spherical_uvs(p: &[[f32; 3]]) -> Vec<[f32; 2]> {
    p.iter()
        .map(|v| {
            let r = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt().max(1e-9);
            [
                0.5 + v[2].atan2(v[0]) / std::f32::consts::TAU,
                0.5 + (v[1] / r).asin() / std::f32::consts::PI,
            ]
        })
        .collect()
}

/// glTF counts UVs from the texture's top-left corner, OBJ from its bottom-left: the same
/// surface with its UVs stored either way draws the same picture, and the picture shows a flip.
#[test]
fn uv_origin_keeps_the_texture_upright() {
    if gpu_context().is_none() {
        return;
    }
    let sphere = meshslim::mesh::noisy_sphere(3, 0.0, 1);
    // On a 1/64 grid, so that 1 - v is exact and both ways give the same bits.
    let uvs: Vec<[f32; 2]> = spherical_uvs(&sphere.positions)
        .into_iter()
        .map(|t| t.map(|x| (x * 64.0).round() / 64.0))
        .collect();
    let flipped: Vec<[f32; 2]> = uvs.iter().map(|&[u, v]| [u, 1.0 - v]).collect();
    // Red above, white below: upside down is another picture.
    let n = 32u32;
    let rgba = (0..n * n)
        .flat_map(|i| {
            if i / n < n / 2 {
                [220, 40, 40, 255]
            } else {
                [250; 4]
            }
        })
        .collect();
    let texture = meshslim::viewer::scene::Image { rgba, size: (n, n) };
    let draw = |uvs: &[[f32; 2]], origin| {
        let mut m = sphere.clone();
        m.uvs = Some(uvs.to_vec());
        m.uv_origin = origin;
        let mut model = Model::from_mesh("sphere".into(), m).unwrap();
        model.texture = Some(texture.clone());
        let style = Style {
            mode: Mode::Texture,
            ..Style::default()
        };
        screenshot(&model, 1.0, style, (96, 72)).unwrap().png
    };
    let upright = draw(&uvs, UvOrigin::BottomLeft);
    // The sphere's UVs put v = 1 at its top (+y), the image's first rows are red, and
    // bottom-left UVs sample row 0 at v = 1: the top of the drawn sphere is red, the bottom not.
    let img = Pixmap::decode_png(&upright).unwrap();
    let (w, h) = (img.width() as usize, img.height() as usize);
    let red_share = |rows: std::ops::Range<usize>| {
        let px: Vec<&[u8]> = rows
            .flat_map(|y| (0..w).map(move |x| (y * w + x) * 4))
            .map(|i| &img.data()[i..i + 4])
            .filter(|p| !is_background(p))
            .collect();
        px.iter().filter(|p| p[0] > 150 && p[1] < 120).count() as f64 / px.len().max(1) as f64
    };
    let (top, bottom) = (red_share(0..h / 2), red_share(h / 2..h));
    assert!(
        top > 0.5 && bottom < 0.5,
        "red should be on top: {top:.2} of the upper half's pixels red, {bottom:.2} of the lower's"
    );
    assert!(
        draw(&flipped, UvOrigin::TopLeft) == upright,
        "top-left UVs drew another picture"
    );
    assert!(
        draw(&flipped, UvOrigin::BottomLeft) != upright,
        "a flipped texture drew the same picture: the test cannot see a flip"
    );
}

/// A glTF scan's material names its base colour texture, embedded in the file: the viewer
/// shows that image (no GPU needed to find and decode it).
#[test]
fn gltf_base_color_texture_is_found() {
    use serde_json::json;
    let dir = tempfile::tempdir().unwrap();
    let mut m = meshslim::mesh::noisy_sphere(2, 0.0, 1);
    m.uvs = Some(spherical_uvs(&m.positions));
    m.uv_origin = UvOrigin::TopLeft;
    let mut png = Vec::new();
    image::RgbaImage::from_pixel(4, 2, image::Rgba([1, 2, 3, 255]))
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    m.materials = vec![meshslim::Material {
        name: "skin".into(),
        gltf: Some(json!({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}})),
    }];
    m.face_materials = Some(vec![0; m.triangles.len()]);
    m.textures.textures = vec![json!({"source": 0})];
    m.textures.images = vec![meshslim::mesh::TextureImage {
        data: Some(png.into()),
        mime_type: Some("image/png".into()),
        ..Default::default()
    }];
    let path = dir.path().join("scan.glb");
    meshslim::io::write(&path, &m).unwrap();
    let model = Model::open(&path, None).unwrap();
    assert_eq!(model.texture_note, None);
    let t = model
        .texture
        .expect("the base colour texture was not found");
    assert_eq!(t.size, (4, 2));
    assert_eq!(&t.rgba[..4], &[1, 2, 3, 255]);
}

/// A red and white checkerboard.
fn checker(n: u32) -> meshslim::viewer::scene::Image {
    let mut rgba = Vec::new();
    for y in 0..n {
        for x in 0..n {
            let on = (x / 8 + y / 8) % 2 == 0;
            rgba.extend_from_slice(&if on { [220, 40, 40, 255] } else { [250; 4] });
        }
    }
    meshslim::viewer::scene::Image { rgba, size: (n, n) }
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
    // Without a display the window cannot open: an error that points at --screenshot (the
    // window itself is tested in tests/viewer_app.rs).
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_meshslim"))
        .args(["view", "builtin:torus"])
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .current_dir(dir.path())
        .output()
        .unwrap();
    expect_code(&o, 1);
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("--screenshot"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    // A missing file fails before any window opens.
    let o = meshslim(&["view", "missing.ply"], dir.path());
    expect_code(&o, 1);
    assert!(String::from_utf8_lossy(&o.stderr).contains("missing.ply"));
    // --mode texture on a mesh without UVs says why; a bad size is a usage error.
    let o = meshslim(
        &[
            "view",
            "builtin:torus",
            "--screenshot",
            "t.png",
            "--mode",
            "texture",
        ],
        dir.path(),
    );
    expect_code(&o, 1);
    assert!(String::from_utf8_lossy(&o.stderr).contains("texture"));
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

/// `view X.mslod --screenshot --frames N --json`: the DAG's cut drawn and timed, with fewer
/// triangles than the mesh it was built from draws the same way; the options that make no
/// sense for it are usage errors.
#[test]
fn a_dag_screenshot_draws_its_cut_and_times_its_frames() {
    if gpu_context().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let build = meshslim(
        &["dag", "build", "builtin:bumpy-sphere", "s.mslod"],
        dir.path(),
    );
    expect_code(&build, 0);
    let json = |args: &[&str]| -> serde_json::Value {
        let o = meshslim(args, dir.path());
        expect_code(&o, 0);
        serde_json::from_slice(&o.stdout).unwrap()
    };
    let size = ["--size", "160x120", "--frames", "3", "--json"];
    let dag = json(&[&["view", "s.mslod", "--screenshot", "dag.png"][..], &size].concat());
    let mesh = json(
        &[
            &["view", "builtin:bumpy-sphere", "--screenshot", "m.png"][..],
            &size,
        ]
        .concat(),
    );
    assert_eq!(dag["frames"], 3);
    assert_eq!(dag["frame_seconds_each"].as_array().unwrap().len(), 3);
    assert!(dag["frame_seconds"].as_f64().unwrap() > 0.0, "{dag}");
    assert!(mesh["frame_seconds"].as_f64().unwrap() > 0.0, "{mesh}");
    let (d, m) = (
        dag["triangles_drawn"].as_u64().unwrap(),
        mesh["triangles_drawn"].as_u64().unwrap(),
    );
    assert!(d > 0 && d < m, "the cut draws {d} triangles, the mesh {m}");
    assert!(dag["clusters_drawn"].as_u64().unwrap() <= dag["clusters_in_cut"].as_u64().unwrap());
    assert_eq!(dag["pixels"], 1.0);
    assert!(mesh["clusters_drawn"].is_null());
    let img = Pixmap::decode_png(&std::fs::read(dir.path().join("dag.png")).unwrap()).unwrap();
    assert!(
        img.data().chunks(4).any(|p| !is_background(p)),
        "the cut is drawn"
    );
    for bad in [
        &["view", "s.mslod", "--screenshot", "x.png", "--ratio", "0.5"][..],
        &[
            "view",
            "builtin:torus",
            "--screenshot",
            "x.png",
            "--pixels",
            "1",
        ],
        &["view", "s.mslod", "--screenshot", "x.png", "--pixels", "0"],
        &["view", "builtin:torus", "--frames", "2"],
        &["view", "s.mslod", "--pixels", "2"],
    ] {
        let o = meshslim(bad, dir.path());
        assert_ne!(o.status.code(), Some(0), "{bad:?}");
        assert!(!o.stderr.is_empty(), "{bad:?}: says why");
    }
}

/// The size of the box of non-background pixels.
/// `--side-by-side` saves what the window's B shows: the original in the left half and the
/// result in the right, each with its label in its top left corner.
#[test]
fn a_side_by_side_screenshot_holds_both_panes_and_their_labels() {
    if gpu_context().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let shot = |name: &str, extra: &[&str]| {
        let mut args = vec![
            "view",
            "builtin:torus",
            "--screenshot",
            name,
            "--size",
            "320x160",
        ];
        args.extend(extra);
        expect_code(&meshslim(&args, dir.path()), 0);
        Pixmap::decode_png(&std::fs::read(dir.path().join(name)).unwrap()).unwrap()
    };
    let both = shot("both.png", &["--ratio", "0.02", "--side-by-side"]);
    assert_eq!((both.width(), both.height()), (320, 160));
    let half = |img: &Pixmap, x0: u32| -> Vec<u8> {
        (40..160)
            .flat_map(|y| {
                let at = 4 * (y * img.width() + x0) as usize;
                img.data()[at..at + 4 * 160].to_vec()
            })
            .collect()
    };
    // Below the labels, each half is a drawn torus, and the 2% result differs from the original.
    for x0 in [0, 160] {
        let h = half(&both, x0);
        assert!(
            h.chunks(4).any(|p| !is_background(p)),
            "half at {x0} is empty"
        );
    }
    assert_ne!(
        half(&both, 0),
        half(&both, 160),
        "the result looks like the original"
    );
    // The labels: light text in each half's top left corner, where the torus does not reach.
    for x0 in [0, 160] {
        let light = (6..22)
            .flat_map(|y| (x0 + 8..x0 + 60).map(move |x| (x, y)))
            .filter(|&(x, y)| {
                let at = 4 * (y * both.width() + x) as usize;
                both.data()[at..at + 3].iter().all(|&c| c > 150)
            })
            .count();
        assert!(
            light > 10,
            "no label in the half at {x0}: {light} light pixels"
        );
    }
}

fn drawn_extent(png: &[u8]) -> (u32, u32) {
    let img = Pixmap::decode_png(png).expect("a valid PNG");
    let (mut lo, mut hi) = ((u32::MAX, u32::MAX), (0, 0));
    for (i, px) in img.data().chunks_exact(4).enumerate() {
        if !is_background(px) {
            let (x, y) = (i as u32 % img.width(), i as u32 / img.width());
            lo = (lo.0.min(x), lo.1.min(y));
            hi = (hi.0.max(x), hi.1.max(y));
        }
    }
    assert!(hi.0 >= lo.0, "nothing drawn");
    (hi.0 - lo.0 + 1, hi.1 - lo.1 + 1)
}

/// A standing figure — a Y-up box three times taller than wide — stands in the first view,
/// as OBJ, PLY and glTF files mean it; the largest-silhouette choice would lay it down, and
/// STL's convention is +Z up.
#[test]
fn standing_figures_are_drawn_upright_in_their_files_up_axis() {
    use meshslim::viewer::camera::Up;
    if gpu_context().is_none() {
        return;
    }
    let mut m = meshslim::mesh::cube(4);
    for p in &mut m.positions {
        p[1] *= 3.0;
    }
    let mut model = Model::from_mesh("tall box".into(), m.clone()).unwrap();
    assert_eq!(model.up_axis, Up::Y);
    let (w, h) = drawn_extent(
        &screenshot(&model, 1.0, Style::default(), (160, 160))
            .unwrap()
            .png,
    );
    assert!(h > 2 * w, "Y up: {w}x{h} pixels, not standing");
    model.up_axis = Up::Auto;
    let (w, h) = drawn_extent(
        &screenshot(&model, 1.0, Style::default(), (160, 160))
            .unwrap()
            .png,
    );
    assert!(w > 2 * h, "auto: {w}x{h} pixels, the longest axis across");
    // The same figure stood up along Z in an STL file.
    let dir = tempfile::tempdir().unwrap();
    let stl = dir.path().join("tall.stl");
    for p in &mut m.positions {
        *p = [p[0], -p[2], p[1]];
    }
    meshslim::io::write(&stl, &m).unwrap();
    let model = Model::open(&stl, None).unwrap();
    assert_eq!(model.up_axis, Up::Z);
    let (w, h) = drawn_extent(
        &screenshot(&model, 1.0, Style::default(), (160, 160))
            .unwrap()
            .png,
    );
    assert!(h > 2 * w, "STL, Z up: {w}x{h} pixels, not standing");
}

#[test]
fn clustering_results_are_drawn_too() {
    if gpu_context().is_none() {
        return;
    }
    let model = Model::from_mesh(
        "noisy sphere".into(),
        meshslim::mesh::noisy_sphere(4, 0.01, 5),
    )
    .unwrap();
    let size = (160, 120);
    for method in [
        meshslim::Method::Cluster,
        meshslim::Method::FloatingCell,
        meshslim::Method::Hybrid,
    ] {
        let frame =
            meshslim::viewer::screenshot_with(&model, 0.2, method, Style::default(), size).unwrap();
        // 1024 faces: hybrid exactly (or one below), the clusterings within 5%.
        assert!(
            (972..=1076).contains(&frame.faces),
            "{method:?}: {} faces drawn",
            frame.faces
        );
        let img = Pixmap::decode_png(&frame.png).expect("a valid PNG");
        let covered = img
            .data()
            .chunks_exact(4)
            .filter(|px| !is_background(px))
            .count();
        assert!(covered > 160 * 120 / 10, "{method:?}: the sphere is drawn");
    }
}

#[test]
fn the_quality_mode_shows_slivers_red_and_even_faces_blue() {
    if gpu_context().is_none() {
        return;
    }
    // The share of drawn pixels whose red channel beats the blue one.
    let reddish = |m: meshslim::Mesh| {
        let model = Model::from_mesh("m".into(), m).unwrap();
        let style = Style {
            mode: Mode::Quality,
            ..Style::default()
        };
        let frame = screenshot(&model, 1.0, style, (160, 120)).unwrap();
        let img = Pixmap::decode_png(&frame.png).unwrap();
        let drawn: Vec<&[u8]> = img.data().chunks(4).filter(|p| !is_background(p)).collect();
        drawn.iter().filter(|p| p[0] > p[2]).count() as f64 / drawn.len() as f64
    };
    // An icosphere's faces are near equilateral (smallest angles 54-60 degrees): blue.
    assert!(reddish(meshslim::mesh::icosphere(3)) < 0.05);
    // The same sphere stretched ten times along x: thin faces, red.
    let mut flat = meshslim::mesh::icosphere(3);
    for p in &mut flat.positions {
        p[0] *= 10.0;
    }
    assert!(reddish(flat) > 0.5);
}

/// The vertex-colour mode draws the colours the simplification solved: a sphere red above and
/// blue below shows red in the upper half of the picture and blue in the lower, at 20% of its
/// faces; `--mode color` on a mesh without colours is an error, not a grey picture.
#[test]
fn colour_mode_draws_the_vertex_colours() {
    if gpu_context().is_none() {
        return;
    }
    let mut m = meshslim::mesh::icosphere(4);
    m.colors = Some(
        m.positions
            .iter()
            .map(|p| {
                if p[1] > 0.0 {
                    [0.9, 0.1, 0.1, 1.0]
                } else {
                    [0.1, 0.1, 0.9, 1.0]
                }
            })
            .collect(),
    );
    let model = Model::from_mesh("two-tone sphere".into(), m.clone()).unwrap();
    let style = Style {
        mode: Mode::Color,
        ..Style::default()
    };
    let img = Pixmap::decode_png(&screenshot(&model, 0.2, style, (96, 72)).unwrap().png).unwrap();
    let (w, h) = (img.width() as usize, img.height() as usize);
    let share = |rows: std::ops::Range<usize>, red: bool| {
        let px: Vec<&[u8]> = rows
            .flat_map(|y| (0..w).map(move |x| (y * w + x) * 4))
            .map(|i| &img.data()[i..i + 4])
            .filter(|p| !is_background(p))
            .collect();
        let hit = |p: &&&[u8]| {
            if red {
                p[0] > 2 * p[2]
            } else {
                p[2] > 2 * p[0]
            }
        };
        px.iter().filter(hit).count() as f64 / px.len().max(1) as f64
    };
    // The camera looks a little down on the sphere, so the red cap reaches into the lower
    // half of the picture; every drawn pixel is one colour or the other, never grey.
    let (top_red, bottom_blue) = (share(0..h / 2, true), share(h / 2..h, false));
    let (all_red, all_blue) = (share(0..h, true), share(0..h, false));
    assert!(
        top_red > 0.9 && bottom_blue > 0.6 && all_red + all_blue > 0.99,
        "{top_red:.2} of the upper half red, {bottom_blue:.2} of the lower half blue, \
         {:.2} of all pixels red or blue",
        all_red + all_blue
    );
    m.colors = None;
    let plain = Model::from_mesh("sphere".into(), m).unwrap();
    let err = screenshot(&plain, 0.2, style, (96, 72)).unwrap_err();
    assert!(err.to_string().contains("no vertex colours"), "{err}");
}
