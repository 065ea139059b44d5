//! `--method cluster --stream` (src/cluster/stream.rs): the faces read from the file in blocks at
//! every pass give the clustering the whole-mesh path gives; options it cannot honour are
//! refused with a clear message; the command line streams on request or when the budget says so.

use crate::common;

use common::{expect_code, meshslim};
use meshslim::cluster::stream::{Target, simplify_file_in_blocks};
use meshslim::{Backend, Error, Mesh, Method, SimplifyOptions, simplify};
use std::path::Path;

fn opts(faces: usize) -> SimplifyOptions {
    let mut o = SimplifyOptions::with_faces(faces);
    o.method = Method::Cluster;
    o.backend = Backend::CpuParallel;
    o
}

fn noisy_torus() -> Mesh {
    let mut m = meshslim::mesh::torus(1.0, 0.3, 120, 60);
    meshslim::mesh::add_noise(&mut m, 0.002, 9);
    m
}

fn write(m: &Mesh, path: &Path, ascii: bool) {
    let o = meshslim::io::WriteOptions {
        ply_ascii: ascii,
        ..Default::default()
    };
    meshslim::io::write_with(path, m, &o).unwrap();
}

#[test]
fn streamed_clustering_is_the_whole_mesh_clustering() {
    let dir = tempfile::tempdir().unwrap();
    let m = noisy_torus();
    for (ascii, block) in [(false, 1000), (false, 7), (true, 4096)] {
        let path = dir.path().join(format!("torus-{ascii}.ply"));
        write(&m, &path, ascii);
        // The file as the whole-mesh path reads it (f32 positions round trip exactly).
        let whole = meshslim::io::read(&path).unwrap();
        for target in [2000, 300] {
            let label = format!("ascii {ascii}, block {block}, target {target}");
            let (a, ra) = simplify(&whole, &opts(target)).unwrap();
            let (b, rb) =
                simplify_file_in_blocks(&path, Target::Faces(target), &opts(0), block, &mut |_| {})
                    .unwrap();
            assert_eq!(rb.input_faces, whole.triangles.len(), "{label}");
            assert_eq!(rb.input_vertices, whole.positions.len(), "{label}");
            assert_eq!(rb.target_faces, target, "{label}");
            let (ca, cb) = (ra.clustering.unwrap(), rb.clustering.unwrap());
            assert_eq!(ca.cell_size, cb.cell_size, "{label}: the same size search");
            assert_eq!(
                a.triangles, b.triangles,
                "{label}: the same faces, numbered alike"
            );
            // The quadrics are summed block after block (another order of the same sums), so a
            // vertex agrees to rounding, within a hundredth of a cell.
            let cell = cb.cell_size * whole.bounds().unwrap().diagonal();
            let mut worst = 0f64;
            for (p, q) in a.positions.iter().zip(&b.positions) {
                let d = (0..3)
                    .map(|i| (p[i] - q[i]) as f64)
                    .fold(0f64, |m, x| m.max(x.abs()));
                worst = worst.max(d / cell);
            }
            eprintln!("{label}: worst move {worst:e} cells");
            assert!(
                worst <= 0.01,
                "{label}: a vertex {worst} cells from the whole-mesh one"
            );
            assert!(b.normals.is_none() && b.uvs.is_none() && b.colors.is_none());
        }
    }
}

/// The streamed hybrid: the same clusters (cells split by a union-find fed block by block), its
/// quadrics scattered instead of gathered, then the rounds in memory: the exact target, no
/// non-manifold edge on a manifold input, the whole-mesh hybrid's error within a few percent.
#[test]
fn streamed_hybrid_is_the_whole_mesh_hybrid() {
    let dir = tempfile::tempdir().unwrap();
    // 57,600 faces: clustering to 2 x 1500 + 20,000 saves rounds (under half the input).
    let mut m = meshslim::mesh::torus(1.0, 0.3, 240, 120);
    meshslim::mesh::add_noise(&mut m, 0.001, 9);
    let path = dir.path().join("torus.ply");
    write(&m, &path, false);
    let whole = meshslim::io::read(&path).unwrap();
    let mut o = opts(1500);
    o.method = Method::Hybrid;
    let (a, ra) = simplify(&whole, &o).unwrap();
    let (b, rb) =
        simplify_file_in_blocks(&path, Target::Faces(1500), &o, 999, &mut |_| {}).unwrap();
    let (ca, cb) = (ra.clustering.unwrap(), rb.clustering.unwrap());
    assert_eq!(
        (ca.clusters, ca.split_clusters, ca.intermediate_faces),
        (cb.clusters, cb.split_clusters, cb.intermediate_faces)
    );
    assert!(
        ca.intermediate_faces.is_some(),
        "the hybrid clustered first"
    );
    assert!(
        b.triangles.len().abs_diff(1500) <= 2,
        "{}",
        b.triangles.len()
    );
    assert_eq!(rb.input_faces, whole.triangles.len());
    let t = meshslim::mesh::topology(&b);
    assert_eq!(t.non_manifold_edges, 0);
    let err = |x: &Mesh| {
        meshslim::metrics::compare(&whole, x, &Default::default())
            .unwrap()
            .distance
            .two_sided
            .mean_rel
    };
    let (ea, eb) = (err(&a), err(&b));
    assert!(eb <= 1.05 * ea, "streamed {eb} against whole {ea}");
}

/// An OBJ streams by its positions: the faces and the clustering of the whole-mesh path (the
/// file has no attributes, so no seam vertices either way).
#[test]
fn an_obj_streams_like_a_ply() {
    let dir = tempfile::tempdir().unwrap();
    let m = noisy_torus();
    let path = dir.path().join("torus.obj");
    meshslim::io::write(&path, &m).unwrap();
    let whole = meshslim::io::read(&path).unwrap();
    let (a, _) = simplify(&whole, &opts(2000)).unwrap();
    let (b, rb) =
        simplify_file_in_blocks(&path, Target::Faces(2000), &opts(0), 1000, &mut |_| {}).unwrap();
    assert_eq!(rb.input_faces, whole.triangles.len());
    assert_eq!(a.triangles, b.triangles);
    // An error in the file names its line, as the whole-mesh reader's does.
    let bad = dir.path().join("bad.obj");
    std::fs::write(&bad, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n").unwrap();
    let e = simplify_file_in_blocks(&bad, Target::Faces(1), &opts(0), 10, &mut |_| {})
        .unwrap_err()
        .to_string();
    assert!(e.contains("bad.obj") && e.contains("line 4"), "{e}");
}

#[test]
fn a_ratio_is_taken_of_the_files_faces() {
    let dir = tempfile::tempdir().unwrap();
    let m = noisy_torus();
    let path = dir.path().join("torus.ply");
    write(&m, &path, false);
    let (_, r) =
        simplify_file_in_blocks(&path, Target::Ratio(0.1), &opts(0), 5000, &mut |_| {}).unwrap();
    assert_eq!(
        r.target_faces,
        (m.triangles.len() as f64 * 0.1).round() as usize
    );
    let band = 0.05 * r.target_faces as f64;
    assert!(
        (r.output_faces as f64 - r.target_faces as f64).abs() <= band,
        "{r:?}"
    );
}

#[test]
fn what_streaming_cannot_do_is_refused_with_a_reason() {
    let dir = tempfile::tempdir().unwrap();
    let m = noisy_torus();
    let ply = dir.path().join("torus.ply");
    let stl = dir.path().join("torus.stl");
    write(&m, &ply, false);
    meshslim::io::write(&stl, &m).unwrap();
    let run = |path: &Path, o: SimplifyOptions| {
        simplify_file_in_blocks(path, Target::Faces(500), &o, 1000, &mut |_| {})
    };
    let expect = |r: meshslim::Result<(Mesh, meshslim::SimplifyReport)>, needle: &str| match r {
        Err(Error::InvalidOption(msg)) => assert!(msg.contains(needle), "{msg}"),
        other => panic!("expected a refusal naming {needle:?}, got {other:?}"),
    };
    expect(run(&stl, opts(0)), "PLY (ascii or binary) and OBJ");
    let mut qem = opts(0);
    qem.method = Method::Qem;
    expect(run(&ply, qem), "--method cluster");
    let mut locked = opts(0);
    locked.lock_border = true;
    expect(run(&ply, locked), "--lock-border");
    // A file that is not there: the path in the error.
    let missing = dir.path().join("missing.ply");
    let e = run(&missing, opts(0)).unwrap_err().to_string();
    assert!(e.contains("missing.ply"), "{e}");
}

/// The library decides streaming as the command line does (`stream_reason`): a cluster or hybrid
/// input over the memory budget streams, with the sizes in the reason; under the budget, the
/// QEM method, a locked border or `cluster` on the GPU (which holds the mesh on the device) read
/// it whole.
#[test]
fn the_library_streams_what_does_not_fit() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("torus.ply");
    write(&noisy_torus(), &path, false);
    let reason = |o: &SimplifyOptions, memory: u64| {
        meshslim::simplify::stream_reason(&path, o, Some(memory))
    };
    // 14,400 faces at 64 bytes (cluster) and 128 (hybrid) a face: 900 KiB and 1.8 MiB.
    let why = reason(&opts(100), 100 << 10).expect("over 100 KiB: streamed");
    assert!(why.contains("1 MiB") && why.contains("0 MiB"), "{why}");
    assert_eq!(reason(&opts(100), 1 << 30), None, "under 1 GiB: read whole");
    let mut hybrid = opts(100);
    hybrid.method = Method::Hybrid;
    assert!(reason(&hybrid, 1 << 20).is_some(), "hybrid needs 1.8 MiB");
    let mut qem = opts(100);
    qem.method = Method::Qem;
    assert_eq!(reason(&qem, 1), None, "qem does not stream");
    let mut locked = opts(100);
    locked.lock_border = true;
    assert_eq!(
        reason(&locked, 1),
        None,
        "a locked border needs the whole mesh"
    );
    let mut gpu = opts(100);
    gpu.backend = Backend::Gpu;
    assert_eq!(
        reason(&gpu, 1),
        None,
        "cluster on the GPU holds the mesh there"
    );
    gpu.method = Method::Hybrid;
    assert!(
        reason(&gpu, 1).is_some(),
        "hybrid's clustering streams on any backend"
    );
}

#[test]
fn the_command_line_streams_on_request_or_over_the_budget() {
    let dir = tempfile::tempdir().unwrap();
    write(&noisy_torus(), &dir.path().join("torus.ply"), false);
    for extra in [&["--stream"][..], &["--memory", "100k"][..]] {
        let mut args = vec![
            "simplify",
            "torus.ply",
            "out.ply",
            "--method",
            "cluster",
            "--ratio",
            "0.1",
            "--json",
        ];
        args.extend(extra);
        let o = meshslim(&args, dir.path());
        expect_code(&o, 0);
        let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let why = j["streamed"].as_str().unwrap_or_else(|| panic!("{j:#}"));
        assert!(why.contains(extra[0]), "{extra:?}: {why}");
        assert!(j["peak_resident_bytes"].as_u64().unwrap() > 0, "{j:#}");
        assert!(j["topology"].is_null(), "the input is not held to compare");
        let out = meshslim::io::read(&dir.path().join("out.ply")).unwrap();
        assert_eq!(
            out.triangles.len() as u64,
            j["output_faces"].as_u64().unwrap()
        );
    }
    // The default budget (half the machine) holds this mesh: read whole, topology reported.
    let o = meshslim(
        &[
            "simplify",
            "torus.ply",
            "out2.ply",
            "--method",
            "cluster",
            "--json",
        ],
        dir.path(),
    );
    expect_code(&o, 0);
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(j["streamed"].is_null() && !j["topology"].is_null(), "{j:#}");
    // Bad uses: a builtin mesh, a bad size.
    let o = meshslim(
        &["simplify", "builtin:sphere", "o.ply", "--stream"],
        dir.path(),
    );
    expect_code(&o, 2);
    assert!(String::from_utf8_lossy(&o.stderr).contains("--stream reads a file"));
    let o = meshslim(
        &["simplify", "torus.ply", "o.ply", "--memory", "lots"],
        dir.path(),
    );
    expect_code(&o, 2);
    assert!(String::from_utf8_lossy(&o.stderr).contains("not a size"));
}

/// A painted scan streams with its colours: each cluster takes its nearest member's colour,
/// exactly what the whole-mesh clustering gives without a colour weight; a colour out of range
/// in the file is an error naming it.
#[test]
fn streamed_clustering_carries_colours() {
    let dir = tempfile::tempdir().unwrap();
    let mut m = noisy_torus();
    meshslim::mesh::paint(&mut m);
    let path = dir.path().join("painted.ply");
    write(&m, &path, false);
    let whole = meshslim::io::read(&path).unwrap();
    let mut o = opts(1000);
    o.attributes = meshslim::options::AttributeWeights::OFF;
    let (a, _) = simplify(&whole, &o).unwrap();
    let (b, _) =
        simplify_file_in_blocks(&path, Target::Faces(1000), &opts(0), 4096, &mut |_| {}).unwrap();
    assert_eq!(a.triangles, b.triangles);
    assert!(a.colors.is_some());
    assert_eq!(a.colors, b.colors, "the nearest members' colours");

    // Written by hand: the writers refuse such a mesh.
    let bad_path = dir.path().join("bad.ply");
    std::fs::write(
        &bad_path,
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
         property float z\nproperty float red\nproperty float green\nproperty float blue\n\
         element face 1\nproperty list uchar int vertex_indices\nend_header\n\
         0 0 0 nan 0 0\n1 0 0 0 0 0\n0 1 0 0 0 0\n3 0 1 2\n",
    )
    .unwrap();
    match simplify_file_in_blocks(&bad_path, Target::Faces(1000), &opts(0), 4096, &mut |_| {}) {
        Err(e) => assert!(
            e.to_string().contains("bad.ply") && e.to_string().contains("colour"),
            "{e}"
        ),
        Ok(_) => panic!("a NaN colour was streamed"),
    }
}
