//! `meshslim bench` end to end on small built-in meshes: every requested backend × ratio has a
//! row with every field, each of ours is held against its meshoptimizer peer under the table,
//! the plot has one series per backend, bad usage exits 2.

use crate::common;
use common::{expect_code, meshslim};

/// 1280 faces, one repeat, few samples: the whole run takes a fraction of a second.
const SMALL: [&str; 6] = [
    "bench",
    "builtin:sphere:1000",
    "--repeat",
    "1",
    "--samples",
    "500",
];

const ROW_FIELDS: [&str; 17] = [
    "mesh",
    "input_faces",
    "ratio",
    "target_faces",
    "backend",
    "device",
    "output_faces",
    "median_s",
    "times_s",
    "mtri_per_s",
    "peak_bytes",
    "peak_mib",
    "diagonal",
    "mean_err",
    "max_err",
    "mean_err_rel",
    "max_err_rel",
];

#[test]
fn json_and_plot_have_every_backend_at_every_ratio() {
    let dir = tempfile::tempdir().unwrap();
    let mut args = SMALL.to_vec();
    args.extend([
        "--ratios",
        "0.5,0.1",
        "--json",
        "bench.json",
        "--plot",
        "bench.svg",
    ]);
    let o = meshslim(&args, dir.path());
    expect_code(&o, 0);
    let table = String::from_utf8_lossy(&o.stdout);
    assert!(table.contains("Mtri/s"), "the table is printed:\n{table}");
    // Under it, each of our rows against its meshoptimizer peer, at both ratios.
    for (ours, peer) in [("cpu", "meshopt"), ("cluster", "meshopt-sloppy")] {
        let against = table
            .lines()
            .skip_while(|l| !l.starts_with("against meshoptimizer"))
            .filter(|l| l.split_whitespace().nth(2) == Some(ours))
            .filter(|l| l.split_whitespace().nth(3) == Some(peer))
            .count();
        assert_eq!(against, 2, "{ours} against {peer} at both ratios:\n{table}");
    }

    let text = std::fs::read_to_string(dir.path().join("bench.json")).unwrap();
    let json: serde_json::Value = serde_json::from_str(&text).unwrap();
    let cpu = json["machine"]["cpu"].as_str().unwrap();
    assert!(!cpu.is_empty());
    assert!(json["machine"]["cores"].as_u64().unwrap() >= 1);
    let rows = json["rows"].as_array().unwrap();
    // Every backend this machine can run: gpu only where there is an adapter.
    let backends: Vec<&str> = meshslim::bench::available_backends()
        .iter()
        .map(|b| b.name)
        .collect();
    assert!(backends.len() >= 4, "{backends:?}");
    assert_eq!(rows.len(), 2 * backends.len(), "{text}");
    for &backend in &backends {
        for ratio in [0.5, 0.1] {
            let row = rows
                .iter()
                .find(|r| r["backend"] == backend && r["ratio"].as_f64() == Some(ratio))
                .unwrap_or_else(|| panic!("no row for {backend} at {ratio}:\n{text}"));
            for field in ROW_FIELDS {
                assert!(
                    row.get(field).is_some_and(|v| !v.is_null()),
                    "{backend} at {ratio}: {field} missing or null:\n{row:#}"
                );
            }
            // The device that ran it: the CPU, or the GPU adapter for the GPU backends.
            if backend.ends_with("gpu") {
                assert_ne!(row["device"], cpu, "{row:#}");
            } else {
                assert_eq!(row["device"], cpu);
            }
            assert_eq!(row["mesh"], "builtin:sphere:1000");
            assert_eq!(row["input_faces"], 1280);
            let out = row["output_faces"].as_u64().unwrap();
            assert!(out > 0 && out <= 1280, "{row:#}");
            assert!(row["median_s"].as_f64().unwrap() > 0.0);
            assert!(row["peak_bytes"].as_u64().unwrap() > 0, "{row:#}");
            let (mean, max) = (
                row["mean_err_rel"].as_f64().unwrap(),
                row["max_err_rel"].as_f64().unwrap(),
            );
            assert!(0.0 < mean && mean <= max && max < 0.1, "{row:#}");
        }
    }

    let svg = std::fs::read_to_string(dir.path().join("bench.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    for backend in &backends {
        let series = format!(r#"<g class="series" data-backend="{backend}">"#);
        assert_eq!(svg.matches(&series).count(), 1, "one series for {backend}");
    }
    assert_eq!(svg.matches(r#"class="series""#).count(), backends.len());
    for label in ["ratio 0.5", "ratio 0.1", "median simplify time (s)"] {
        assert!(svg.contains(label), "{label} missing from the plot");
    }
}

#[test]
fn json_to_stdout_replaces_the_table() {
    let dir = tempfile::tempdir().unwrap();
    let mut args = SMALL.to_vec();
    args.extend(["--ratios", "0.5", "--backends", "meshopt", "--json", "-"]);
    let o = meshslim(&args, dir.path());
    expect_code(&o, 0);
    let json: serde_json::Value = serde_json::from_slice(&o.stdout).expect("stdout is JSON");
    let rows = json["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 1);
    assert_eq!(rows[0]["backend"], "meshopt");
}

#[test]
fn bad_usage_exits_2() {
    let dir = tempfile::tempdir().unwrap();
    for extra in [
        &["--backends", "cpu,nope"][..],
        &["--ratios", "0.5,0"],
        &["--ratios", "1.5"],
        &["--repeat", "0"],
        &["--plot", "bench.pdf"],
    ] {
        let mut args = SMALL.to_vec();
        args.extend(extra);
        let o = meshslim(&args, dir.path());
        expect_code(&o, 2);
    }
    let o = meshslim(&["bench", "--backends", "nope"], dir.path());
    expect_code(&o, 2);
    assert!(
        String::from_utf8_lossy(&o.stderr)
            .contains("cpu, cpu-parallel, gpu, cluster, cluster-gpu, floating-cell, floating-cell-gpu, decimate, hybrid, hybrid-parallel, hybrid-gpu, meshopt, meshopt-attr-0.1, meshopt-attr-0.3, meshopt-attr-1, meshopt-sloppy"),
        "the error lists the backends"
    );
}

#[test]
fn missing_mesh_exits_1_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let o = meshslim(&["bench", "no-such-mesh.ply", "--repeat", "1"], dir.path());
    expect_code(&o, 1);
    assert!(String::from_utf8_lossy(&o.stderr).contains("no-such-mesh.ply"));
}

/// `--plot FILE.png` renders the same plot to a PNG image.
#[test]
fn the_plot_can_be_a_png() {
    let dir = tempfile::tempdir().unwrap();
    let mut args = SMALL.to_vec();
    args.extend(["--ratios", "0.1", "--plot", "bench.png"]);
    let o = meshslim(&args, dir.path());
    expect_code(&o, 0);
    let png = std::fs::read(dir.path().join("bench.png")).unwrap();
    assert!(png.starts_with(b"\x89PNG\r\n\x1a\n"), "not a PNG");
    // The width and height in the IHDR chunk: the plot's own size, not an empty image.
    let (w, h) = (
        u32::from_be_bytes(png[16..20].try_into().unwrap()),
        u32::from_be_bytes(png[20..24].try_into().unwrap()),
    );
    assert!(w >= 400 && h >= 200, "{w}x{h}");
    assert!(png.len() > 5_000, "{} bytes: nothing drawn?", png.len());
}
