//! `meshslim remesh` and `simplify --remesh` end to end: files written, reports, usage errors.

use crate::common;

#[test]
fn the_commands_remesh_and_simplify_then_remesh() {
    let dir = tempfile::tempdir().unwrap();
    let o = common::meshslim(
        &[
            "remesh",
            "builtin:torus",
            "even.ply",
            "--edge-factor",
            "2",
            "--json",
        ],
        dir.path(),
    );
    common::expect_code(&o, 0);
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let faces = j["report"]["output_faces"].as_u64().unwrap() as usize;
    let written = meshslim::io::read(&dir.path().join("even.ply")).unwrap();
    assert_eq!(written.face_count(), faces);
    // The generated torus has long thin faces (28% under 30 degrees, mean smallest angle
    // 35.6); its tube is narrow for this length, which holds the mean near 50.
    let q = &j["quality"];
    assert!(q["mean_min_angle_deg"].as_f64().unwrap() > 45.0, "{q}");
    assert_eq!(q["share_under_30_deg"].as_f64().unwrap(), 0.0, "{q}");

    // Simplify to 2,000 faces, then one remeshing iteration: about as many faces.
    let o = common::meshslim(
        &[
            "simplify",
            "builtin:torus",
            "s.ply",
            "--faces",
            "2000",
            "--remesh",
            "1",
            "--json",
        ],
        dir.path(),
    );
    common::expect_code(&o, 0);
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let written = meshslim::io::read(&dir.path().join("s.ply")).unwrap();
    assert_eq!(
        j["output_faces"].as_u64().unwrap() as usize,
        written.face_count()
    );
    assert_eq!(j["remesh"]["input_faces"], 2000);
    let off = written.face_count() as f64 / 2000.0 - 1.0;
    assert!(off.abs() < 0.05, "{} faces", written.face_count());

    // Usage mistakes exit with 2 and say what is wrong.
    let o = common::meshslim(
        &["remesh", "builtin:torus", "x.ply", "--edge-length", "-1"],
        dir.path(),
    );
    common::expect_code(&o, 2);
    let o = common::meshslim(
        &[
            "remesh",
            "builtin:torus",
            "x.ply",
            "--edge-length",
            "1",
            "--faces",
            "10",
        ],
        dir.path(),
    );
    common::expect_code(&o, 2);
}
