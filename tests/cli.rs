//! The `meshslim` binary end to end: arguments, exit codes, messages, files written.

use crate::common;
use common::{expect_code, meshslim};
use std::path::{Path, PathBuf};
use std::process::Output;

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn json(o: &Output) -> serde_json::Value {
    serde_json::from_str(&stdout(o))
        .unwrap_or_else(|e| panic!("stdout is not one JSON value ({e}):\n{}", stdout(o)))
}

fn info_faces(path: &Path, dir: &Path) -> u64 {
    let o = meshslim(&["info", path.to_str().unwrap(), "--json"], dir);
    expect_code(&o, 0);
    json(&o)["faces"].as_u64().expect("info --json has faces")
}

/// 1280 faces: small enough that every test stays fast in any profile.
const SMALL_SPHERE: &str = "builtin:sphere:1000";

#[test]
fn simplify_builtin_sphere_to_obj_and_ply_by_ratio_and_faces() {
    let dir = tempfile::tempdir().unwrap();
    for (file, flag, value, want) in [
        ("half.obj", "--ratio", "0.5", 640),
        ("half.ply", "--ratio", "0.5", 640),
        ("n300.obj", "--faces", "300", 300),
        ("n300.ply", "--faces", "300", 300),
    ] {
        let o = meshslim(&["simplify", SMALL_SPHERE, file, flag, value], dir.path());
        expect_code(&o, 0);
        assert!(
            stdout(&o).contains("1280 faces"),
            "the summary names the input faces:\n{}",
            stdout(&o)
        );
        let faces = info_faces(&dir.path().join(file), dir.path());
        assert!(
            faces == want || faces + 1 == want,
            "{file}: {faces} faces, wanted {want} (or one below)"
        );
    }
}

#[test]
fn default_ratio_is_a_tenth() {
    let dir = tempfile::tempdir().unwrap();
    let o = meshslim(&["simplify", SMALL_SPHERE, "out.ply", "--json"], dir.path());
    expect_code(&o, 0);
    assert_eq!(json(&o)["target_faces"], 128);
}

#[test]
fn json_report_is_the_only_stdout_and_has_every_field() {
    let dir = tempfile::tempdir().unwrap();
    let o = meshslim(
        &[
            "simplify",
            SMALL_SPHERE,
            "out.ply",
            "--faces",
            "400",
            "--json",
            "--stats",
        ],
        dir.path(),
    );
    expect_code(&o, 0);
    let v = json(&o);
    for key in [
        "input_faces",
        "output_faces",
        "input_vertices",
        "output_vertices",
        "target_faces",
        "backend",
        "stop_reason",
        "collapses",
        "max_collapse_error",
        "seconds",
        "input",
        "output",
    ] {
        assert!(v.get(key).is_some(), "missing {key} in {v}");
    }
    for key in ["load", "simplify", "save"] {
        assert!(v["seconds"][key].is_f64(), "seconds.{key} in {v}");
    }
    assert_eq!(v["input"], SMALL_SPHERE);
    assert_eq!(v["output"], "out.ply");
    assert_eq!(v["backend"], "cpu");
    assert_eq!(v["input_faces"], 1280);
    assert_eq!(v["target_faces"], 400);
    assert_eq!(v["stop_reason"], "target-reached");
    assert_eq!(
        info_faces(&dir.path().join("out.ply"), dir.path()),
        v["output_faces"]
    );
}

#[test]
fn stats_prints_the_report_details() {
    let dir = tempfile::tempdir().unwrap();
    let o = meshslim(
        &["simplify", SMALL_SPHERE, "out.obj", "--stats"],
        dir.path(),
    );
    expect_code(&o, 0);
    let out = stdout(&o);
    for word in [
        "collapses",
        "pinned vertices",
        "degenerate",
        "max collapse error",
        "time",
    ] {
        assert!(out.contains(word), "{word} missing from:\n{out}");
    }
}

#[test]
fn refuses_to_overwrite_the_input() {
    let dir = tempfile::tempdir().unwrap();
    let o = meshslim(&["simplify", SMALL_SPHERE, "in.ply"], dir.path());
    expect_code(&o, 0);
    let input = dir.path().join("in.ply");
    let before = std::fs::read(&input).unwrap();
    // The same file, also written another way.
    for out in ["in.ply", "./in.ply"] {
        let o = meshslim(&["simplify", "in.ply", out, "--ratio", "0.5"], dir.path());
        expect_code(&o, 1);
        assert!(stderr(&o).contains("in.ply"), "{}", stderr(&o));
        assert!(stderr(&o).contains("overwrite"), "{}", stderr(&o));
    }
    assert_eq!(std::fs::read(&input).unwrap(), before, "the input changed");
}

#[test]
fn no_input_prints_getting_started_and_exits_2() {
    let dir = tempfile::tempdir().unwrap();
    for args in [&["simplify"][..], &[][..]] {
        let o = meshslim(args, dir.path());
        expect_code(&o, 2);
        let err = stderr(&o);
        assert!(
            err.contains("meshslim simplify builtin:bumpy-sphere bumpy-10.ply --ratio 0.1"),
            "{err}"
        );
        assert!(err.contains("meshslim info"), "{err}");
        assert!(err.contains("--help"), "{err}");
        assert!(stdout(&o).is_empty());
    }
}

#[test]
fn input_without_output_is_a_usage_error() {
    let dir = tempfile::tempdir().unwrap();
    let o = meshslim(&["simplify", SMALL_SPHERE], dir.path());
    expect_code(&o, 2);
    assert!(stderr(&o).starts_with("error: "), "{}", stderr(&o));
    assert!(stderr(&o).contains("output"), "{}", stderr(&o));
}

#[test]
fn unsupported_output_extension_fails_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let o = meshslim(&["simplify", SMALL_SPHERE, "out.xyz"], dir.path());
    expect_code(&o, 1);
    assert!(stderr(&o).contains("xyz"), "{}", stderr(&o));
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        0,
        "nothing may be written"
    );
}

#[test]
fn missing_input_names_the_path() {
    let dir = tempfile::tempdir().unwrap();
    let o = meshslim(&["simplify", "no-such-mesh.ply", "out.ply"], dir.path());
    expect_code(&o, 1);
    assert!(stderr(&o).contains("no-such-mesh.ply"), "{}", stderr(&o));
    assert!(!dir.path().join("out.ply").exists());
    let o = meshslim(&["info", "no-such-mesh.obj"], dir.path());
    expect_code(&o, 1);
    assert!(stderr(&o).contains("no-such-mesh.obj"), "{}", stderr(&o));
}

#[test]
fn corrupt_input_names_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("huge-claim.ply");
    std::fs::write(
        &bad,
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
         property float z\nelement face 4000000000\nproperty list uchar int vertex_indices\n\
         end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
    )
    .unwrap();
    let o = meshslim(&["simplify", "huge-claim.ply", "out.ply"], dir.path());
    expect_code(&o, 1);
    let err = stderr(&o);
    assert!(err.contains("huge-claim.ply"), "{err}");
    assert_eq!(err.matches("error:").count(), 1, "printed once: {err}");
    assert!(!dir.path().join("out.ply").exists());
}

#[test]
fn out_of_range_ratio_is_a_usage_error() {
    let dir = tempfile::tempdir().unwrap();
    for r in ["0", "1.5", "-0.1", "nan"] {
        let o = meshslim(
            &["simplify", SMALL_SPHERE, "out.ply", &format!("--ratio={r}")],
            dir.path(),
        );
        expect_code(&o, 2);
        assert!(stderr(&o).contains("ratio"), "{}", stderr(&o));
    }
    let o = meshslim(
        &[
            "simplify",
            SMALL_SPHERE,
            "out.ply",
            "--ratio",
            "0.5",
            "--faces",
            "10",
        ],
        dir.path(),
    );
    expect_code(&o, 2);
    assert!(!dir.path().join("out.ply").exists());
}

#[test]
fn unknown_builtin_is_a_usage_error_listing_the_names() {
    let dir = tempfile::tempdir().unwrap();
    let o = meshslim(&["simplify", "builtin:teapot", "out.ply"], dir.path());
    expect_code(&o, 2);
    for name in ["sphere", "bumpy-sphere", "double-torus"] {
        assert!(stderr(&o).contains(name), "{}", stderr(&o));
    }
}

#[test]
fn info_reports_topology_of_a_builtin() {
    let dir = tempfile::tempdir().unwrap();
    let o = meshslim(&["info", "builtin:torus:1000", "--json"], dir.path());
    expect_code(&o, 0);
    let v = json(&o);
    assert_eq!(v["genus"], 1);
    assert_eq!(v["boundary_loops"], 0);
    assert_eq!(v["normals"], false);
    // The triangle quality, as compare reports it for B. The valences count every vertex
    // once, and on a closed torus (Euler 0, so 3 edges per vertex) they average 6.
    let q = &v["quality"];
    let bins = q["valence_histogram"].as_array().unwrap();
    let count =
        |b: &serde_json::Value| b["interior"].as_u64().unwrap() + b["border"].as_u64().unwrap();
    let counted: u64 = bins.iter().map(count).sum();
    let ends: u64 = bins
        .iter()
        .map(|b| b["valence"].as_u64().unwrap() * count(b))
        .sum();
    assert_eq!(counted, v["vertices"].as_u64().unwrap(), "{q}");
    assert_eq!(ends, 6 * counted, "{q}");
    assert!(q["share_under_30_deg"].is_f64() && q["mean_min_angle_deg"].is_f64());
    let o = meshslim(&["info", "builtin:grid:200"], dir.path());
    expect_code(&o, 0);
    let out = stdout(&o);
    for word in [
        "faces",
        "boundary",
        "genus",
        "orientation",
        "area",
        "volume",
        "diagonal",
        "smallest angle",
        "under 30 deg",
        "valence",
    ] {
        assert!(out.contains(word), "{word} missing from:\n{out}");
    }
}

#[test]
fn help_teaches() {
    let dir = tempfile::tempdir().unwrap();
    let o = meshslim(&["simplify", "--help"], dir.path());
    expect_code(&o, 0);
    let help = stdout(&o);
    for word in [
        "Examples:",
        "bumpy-sphere",
        "double-torus",
        "bounding-box diagonal",
        "QualityThr",
        "[default: 0.3]",
        "--lock-border",
    ] {
        assert!(help.contains(word), "{word} missing from:\n{help}");
    }
    let o = meshslim(&["info", "--help"], dir.path());
    expect_code(&o, 0);
    assert!(stdout(&o).contains("Examples:"));
}

#[test]
fn shared_horse_to_ten_percent() {
    let horse = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/models/horse.ply");
    if !horse.exists() {
        eprintln!("note: {} not found; skipping", horse.display());
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let o = meshslim(
        &[
            "simplify",
            horse.to_str().unwrap(),
            "horse-10.ply",
            "--ratio",
            "0.1",
            "--json",
        ],
        dir.path(),
    );
    expect_code(&o, 0);
    let v = json(&o);
    let input = v["input_faces"].as_u64().unwrap();
    let target = (input as f64 * 0.1).round() as u64;
    assert_eq!(v["target_faces"], target);
    let faces = info_faces(&dir.path().join("horse-10.ply"), dir.path());
    assert_eq!(v["output_faces"], faces);
    assert!(
        faces == target || faces + 1 == target,
        "{faces} vs {target}"
    );
}

#[test]
fn compare_json_has_every_field() {
    let dir = tempfile::tempdir().unwrap();
    let o = meshslim(
        &[
            "compare",
            SMALL_SPHERE,
            "builtin:sphere:300",
            "--samples",
            "5000",
            "--seed",
            "3",
            "--json",
        ],
        dir.path(),
    );
    expect_code(&o, 0);
    let v = json(&o);
    for key in [
        "a",
        "b",
        "faces_a",
        "faces_b",
        "vertices_a",
        "vertices_b",
        "seed",
        "distance",
        "area",
        "volume",
        "quality_b",
        "topology",
        "seconds",
    ] {
        assert!(v.get(key).is_some(), "missing {key} in {v}");
    }
    for dir_key in ["a_to_b", "b_to_a"] {
        let d = &v["distance"][dir_key];
        for key in [
            "max",
            "mean",
            "rms",
            "max_rel",
            "mean_rel",
            "rms_rel",
            "face_samples",
            "vertex_samples",
            "edge_samples",
            "vertex_distance_sum_rel",
        ] {
            assert!(d[key].is_number(), "distance.{dir_key}.{key} in {v}");
        }
        assert_eq!(d["face_samples"], 5000);
    }
    for key in ["max", "mean", "rms", "max_rel", "mean_rel", "rms_rel"] {
        assert!(v["distance"]["two_sided"][key].is_f64(), "two_sided.{key}");
    }
    assert!(v["distance"]["diagonal"].is_f64());
    for key in ["a", "b", "relative"] {
        assert!(
            v["area"][key].is_f64() && v["volume"][key].is_f64(),
            "{key}"
        );
    }
    let q = &v["quality_b"];
    for key in [
        "min_angle_deg",
        "mean_min_angle_deg",
        "max_aspect_ratio",
        "share_under_30_deg",
        "share_under_10_deg",
        "regular_valence_share",
    ] {
        assert!(q[key].is_f64(), "quality_b.{key} in {q}");
    }
    assert_eq!(q["degenerate_faces"], 0);
    let bins = q["aspect_ratio_histogram"].as_array().unwrap();
    let total: u64 = bins.iter().map(|b| b["count"].as_u64().unwrap()).sum();
    assert_eq!(total, v["faces_b"].as_u64().unwrap());
    for side in ["a", "b", "difference"] {
        for key in [
            "euler_characteristic",
            "boundary_loops",
            "non_manifold_edges",
            "non_manifold_vertices",
            "connected_components",
        ] {
            assert!(v["topology"][side][key].is_i64(), "topology.{side}.{key}");
        }
    }
    assert_eq!(v["topology"]["difference"]["euler_characteristic"], 0);
    assert_eq!(v["a"], SMALL_SPHERE);
    assert_eq!(v["seed"], 3);
}

#[test]
fn compare_prints_a_table_and_names_a_missing_file() {
    let dir = tempfile::tempdir().unwrap();
    let o = meshslim(&["compare", SMALL_SPHERE, "builtin:sphere:300"], dir.path());
    expect_code(&o, 0);
    let out = stdout(&o);
    for word in [
        "A -> B",
        "B -> A",
        "Hausdorff",
        "mean",
        "RMS",
        "area",
        "volume",
        "smallest angle",
        "under 30 deg",
        "aspect ratio",
        "valence",
        "euler",
        "boundary loops",
    ] {
        assert!(out.contains(word), "{word} missing from:\n{out}");
    }
    let o = meshslim(&["compare", SMALL_SPHERE, "no-such-mesh.ply"], dir.path());
    expect_code(&o, 1);
    assert!(stderr(&o).contains("no-such-mesh.ply"), "{}", stderr(&o));
    assert_eq!(stderr(&o).matches("error:").count(), 1, "{}", stderr(&o));
    let o = meshslim(
        &["compare", SMALL_SPHERE, SMALL_SPHERE, "--samples", "0"],
        dir.path(),
    );
    expect_code(&o, 2);
}

#[test]
fn round_backends_report_rounds_and_stages() {
    let dir = tempfile::tempdir().unwrap();
    let o = meshslim(
        &[
            "simplify",
            SMALL_SPHERE,
            "out.ply",
            "--backend",
            "cpu-parallel",
            "--json",
        ],
        dir.path(),
    );
    expect_code(&o, 0);
    let v = json(&o);
    assert_eq!(v["backend"], "cpu-parallel");
    assert!(v["rounds"]["rounds"].as_u64().unwrap() >= 1);
    assert!(v["rounds"]["stage_seconds"].as_array().unwrap().len() > 5);
    // auto says which backend it took, on stderr.
    let o = meshslim(
        &[
            "simplify",
            SMALL_SPHERE,
            "out2.ply",
            "--backend",
            "auto",
            "--stats",
        ],
        dir.path(),
    );
    expect_code(&o, 0);
    assert!(stderr(&o).contains("backend auto:"), "{}", stderr(&o));
    assert!(stdout(&o).contains("rounds"), "{}", stdout(&o));
    // A software rasterizer (lavapipe here and in CI) is passed over for the CPU's cores; a
    // hardware adapter is taken.
    let took = if stderr(&o).contains("is a software rasterizer") {
        "cpu-parallel"
    } else if stderr(&o).contains("backend auto: gpu on") {
        "gpu"
    } else {
        "cpu-parallel"
    };
    assert!(
        stdout(&o).contains(&format!("(backend {took})")),
        "auto said {:?} but ran {}",
        stderr(&o),
        stdout(&o)
    );
}

/// Writing a format that cannot hold part of the mesh says what is left behind (on stderr,
/// not with -q), and writing one that keeps everything says nothing.
#[test]
fn writing_a_poorer_format_says_what_it_drops() {
    let dir = tempfile::tempdir().unwrap();
    let mut m = meshslim::mesh::noisy_sphere(3, 0.001, 2);
    m.uvs = Some(m.positions.iter().map(|p| [p[0], p[1]]).collect());
    m.materials = vec![meshslim::Material {
        name: "skin".into(),
        gltf: Some(serde_json::json!({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}})),
    }];
    m.face_materials = Some(vec![0; m.triangles.len()]);
    m.textures.textures = vec![serde_json::json!({"source": 0})];
    m.textures.images = vec![meshslim::mesh::TextureImage {
        data: Some(b"\x89PNG not really".to_vec().into()),
        ..Default::default()
    }];
    meshslim::io::write(&dir.path().join("scan.glb"), &m).unwrap();
    let o = meshslim(&["info", "scan.glb", "--json"], dir.path());
    expect_code(&o, 0);
    let info = json(&o);
    assert_eq!(info["texture_images"], 1, "{info}");
    assert_eq!(info["uv_origin"], "top-left", "{info}");
    let o = meshslim(&["info", "scan.glb"], dir.path());
    assert!(
        stdout(&o).contains("texture images     1"),
        "{}",
        stdout(&o)
    );
    for (out, dropped) in [
        (
            "small.obj",
            Some("the glTF material definitions and 1 texture image(s)"),
        ),
        ("small.ply", Some("the glTF material definitions")),
        ("small.stl", Some("the UVs, materials")),
        ("small.glb", None),
    ] {
        let o = meshslim(&["simplify", "scan.glb", out, "--ratio", "0.5"], dir.path());
        expect_code(&o, 0);
        let err = stderr(&o);
        match dropped {
            Some(what) => assert!(
                err.contains(&format!("note: {out} (")) && err.contains(what),
                "{out}: {err}"
            ),
            None => assert!(!err.contains("does not keep"), "{out}: {err}"),
        }
        let o = meshslim(
            &["simplify", "scan.glb", out, "--ratio", "0.5", "-q"],
            dir.path(),
        );
        expect_code(&o, 0);
        assert!(!stderr(&o).contains("note:"), "-q: {}", stderr(&o));
    }
}

#[test]
fn an_obj_written_to_another_folder_still_finds_its_material_library() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("scan")).unwrap();
    std::fs::create_dir_all(dir.path().join("out")).unwrap();
    let mut m = meshslim::mesh::noisy_sphere(3, 0.001, 2);
    m.material_libs = vec!["scan.mtl".into()];
    m.materials = vec![meshslim::Material::named("skin")];
    m.face_materials = Some(vec![0; m.triangles.len()]);
    meshslim::io::write(&dir.path().join("scan/scan.obj"), &m).unwrap();
    std::fs::write(dir.path().join("scan/scan.mtl"), "newmtl skin\nKd 1 0 0\n").unwrap();
    let o = meshslim(
        &[
            "simplify",
            "scan/scan.obj",
            "out/small.obj",
            "--ratio",
            "0.5",
        ],
        dir.path(),
    );
    expect_code(&o, 0);
    let text = std::fs::read_to_string(dir.path().join("out/small.obj")).unwrap();
    assert!(text.contains("\nmtllib ../scan/scan.mtl\n"), "{text:.200}");
    assert!(!stderr(&o).contains("does not keep"), "{}", stderr(&o));
}

/// The new user's panic cases: a target at or above the input, a lone triangle, a bench at
/// ratio 1, a screenshot of a lone triangle — every backend exits 0 (gpu where an adapter is;
/// with CI=true a missing adapter fails the run).
#[test]
fn targets_at_or_above_the_input_exit_cleanly_on_every_backend() {
    let dir = tempfile::tempdir().unwrap();
    let single = dir.path().join("single.obj");
    std::fs::write(&single, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let mut backends = vec!["cpu", "cpu-parallel"];
    if common::gpu_context().is_some() {
        backends.push("gpu");
    }
    for backend in &backends {
        for args in [
            vec!["simplify", SMALL_SPHERE, "a.obj", "--ratio", "1"],
            vec!["simplify", SMALL_SPHERE, "b.obj", "--faces", "5000"],
            vec!["simplify", "single.obj", "c.obj", "--ratio", "0.5"],
        ] {
            let mut args = args.clone();
            args.extend(["--backend", backend]);
            let o = meshslim(&args, dir.path());
            expect_code(&o, 0);
            assert!(stdout(&o).contains("reached the face target"), "{args:?}");
        }
        let o = meshslim(
            &[
                "bench",
                SMALL_SPHERE,
                "--ratios",
                "1",
                "--backends",
                backend,
                "--repeat",
                "1",
            ],
            dir.path(),
        );
        expect_code(&o, 0);
    }
    if backends.contains(&"gpu") {
        let o = meshslim(
            &[
                "view",
                "single.obj",
                "--screenshot",
                "s.png",
                "--ratio",
                "0.5",
                "--size",
                "64x48",
            ],
            dir.path(),
        );
        expect_code(&o, 0);
        assert!(dir.path().join("s.png").is_file());
    }
}

/// Misleading or late messages a new user met, each now early and to the point.
#[test]
fn bad_inputs_get_early_messages_that_say_what_is_wrong() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(
        d.join("cloud.ply"),
        "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n\
         property float z\nend_header\n0 0 0\n1 0 0\n",
    )
    .unwrap();
    std::fs::create_dir(d.join("folder.obj")).unwrap();
    std::fs::write(d.join("single.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    // (arguments, exit code, what stderr says)
    let cases: &[(&[&str], i32, &str)] = &[
        (&["simplify", "cloud.ply", "out.ply"], 1, "no faces"),
        (
            &["simplify", "folder.obj", "out.ply"],
            1,
            "a directory, not a mesh file",
        ),
        (
            &["simplify", "single.obj", "o.ply", "--ratio", "-1"],
            2,
            "the ratio must be in (0, 1]",
        ),
        (
            &["simplify", "single.obj", "o.ply", "--faces", "-3"],
            2,
            "whole number",
        ),
        (
            &[
                "view",
                "single.obj",
                "--screenshot",
                "s.png",
                "--size",
                "0x0",
            ],
            2,
            "1 to 16384 pixels",
        ),
        (
            &["view", "single.obj", "--screenshot", "nowhere/s.png"],
            1,
            "does not exist",
        ),
    ];
    for (args, code, says) in cases {
        let o = meshslim(args, d);
        expect_code(&o, *code);
        assert!(stderr(&o).contains(says), "{args:?}:\n{}", stderr(&o));
        assert!(
            !stderr(&o).contains("-- -1"),
            "{args:?}: clap's tip for negative numbers"
        );
    }
    assert!(
        !d.join("out.ply").exists(),
        "nothing is written for a point cloud"
    );
    if common::gpu_context().is_some() {
        // Refused before simplifying: no spinner or GPU work comes first.
        let o = meshslim(
            &[
                "view",
                "single.obj",
                "--screenshot",
                "t.png",
                "--mode",
                "texture",
                "--ratio",
                "0.5",
            ],
            d,
        );
        expect_code(&o, 1);
        assert!(
            stderr(&o).contains("no UVs or no texture"),
            "{}",
            stderr(&o)
        );
        assert!(!d.join("t.png").exists());
    }
}

/// Mesa's device-select layer makes libwayland print "XDG_RUNTIME_DIR is invalid or not set"
/// on a headless machine; the binary gives the probe an empty runtime directory of its own.
#[test]
fn gpu_commands_print_no_wayland_noise_without_a_runtime_dir() {
    if common::gpu_context().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_meshslim"))
        .args(["simplify", SMALL_SPHERE, "o.ply", "--backend", "gpu"])
        .current_dir(dir.path())
        .env_remove("XDG_RUNTIME_DIR")
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("WAYLAND_SOCKET")
        .output()
        .unwrap();
    expect_code(&o, 0);
    assert!(
        !stderr(&o).contains("XDG_RUNTIME_DIR"),
        "stderr:\n{}",
        stderr(&o)
    );
}
