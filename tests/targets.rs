//! Every backend lands on its face target or one below it (an interior collapse removes two
//! faces), never above, unless no valid collapse is left — and then the report says why. The
//! rounds reach every target the greedy reference reaches.

use crate::common;
use common::{generated_meshes, gpu_context, shared_models};
use meshslim::{Backend, Mesh, SimplifyOptions, StopReason, simplify};

const RATIOS: [f64; 4] = [0.5, 0.1, 0.01, 0.001];

/// The backends this machine can run (gpu needs an adapter; with CI=true a missing one fails).
fn backends() -> Vec<Backend> {
    let mut b = vec![Backend::Cpu, Backend::CpuParallel];
    if gpu_context().is_some() {
        b.push(Backend::Gpu);
    }
    b
}

/// Runs every backend at every ratio on `mesh` and checks where each landed; returns the rows
/// (ratio, backend, target, faces) for a failure message.
fn sweep(name: &str, mesh: &Mesh) {
    for ratio in RATIOS {
        let mut greedy_reached = None;
        for backend in backends() {
            let mut opts = SimplifyOptions::with_ratio(mesh.triangles.len(), ratio).unwrap();
            opts.backend = backend;
            let target = opts.target_faces;
            let (out, report) = simplify(mesh, &opts)
                .unwrap_or_else(|e| panic!("{name} at {ratio} on {backend:?}: {e}"));
            let faces = out.triangles.len();
            let at = format!("{name} at {ratio} on {backend:?}: {faces} faces for {target}");
            assert_eq!(faces, report.output_faces, "{at}");
            if faces <= target {
                assert!(faces + 1 >= target, "{at}: more than one below");
                assert_eq!(report.stop_reason, StopReason::TargetReached, "{at}");
                assert!(report.blocked.is_none(), "{at}");
            } else {
                assert_ne!(report.stop_reason, StopReason::TargetReached, "{at}");
                let b = report
                    .blocked
                    .unwrap_or_else(|| panic!("{at}: stopped above the target without a reason"));
                assert!(
                    b.edges > 0 && b.topology + b.geometry + b.over_max_error > 0,
                    "{at}: {b:?}"
                );
            }
            match backend {
                Backend::Cpu => greedy_reached = Some(faces <= target),
                _ => assert!(
                    greedy_reached == Some(false) || faces <= target,
                    "{at}: the greedy reached the target, the rounds did not"
                ),
            }
        }
    }
}

#[test]
fn every_backend_lands_on_the_target_or_one_below_or_says_why_not_on_generated_meshes() {
    for (name, mesh) in generated_meshes() {
        sweep(name, &mesh);
    }
}

#[test]
fn every_backend_lands_on_the_target_or_one_below_or_says_why_not_on_the_shared_models() {
    let Some(dir) = shared_models() else {
        eprintln!("note: ../shared/models absent, the shared models' sweep is skipped");
        return;
    };
    for file in [
        "suzanne.obj",
        "teapot.obj",
        "spot/spot_triangulated.obj",
        "fandisk.obj",
        "stanford-bunny.obj",
        "horse.ply",
    ] {
        let mesh = meshslim::io::read(&dir.join(file)).unwrap();
        sweep(file, &mesh);
    }
}

/// An octagon fanned from its centre: 8 faces, an open disk. Every target down to one face is
/// reachable (border collapses remove one face each).
///
/// ```text
///    7---6
///   / \ / \
///  0---c---5 ...  eight triangles around c
/// ```
#[test]
fn an_octagon_reaches_an_odd_target_exactly() {
    let mut m = Mesh::default();
    m.positions.push([0.0, 0.0, 0.0]);
    for i in 0..8 {
        let a = i as f32 * std::f32::consts::TAU / 8.0;
        m.positions.push([a.cos(), a.sin(), 0.0]);
    }
    m.triangles = (0..8u32).map(|i| [0, 1 + i, 1 + (i + 1) % 8]).collect();
    for backend in backends() {
        let mut opts = SimplifyOptions::with_faces(3);
        opts.backend = backend;
        let (out, report) = simplify(&m, &opts).unwrap();
        assert!(
            (2..=3).contains(&out.triangles.len()),
            "{backend:?}: {} faces",
            out.triangles.len()
        );
        assert_eq!(report.stop_reason, StopReason::TargetReached, "{backend:?}");
    }
}

/// A target at or above the input's faces (or a single triangle) runs no round: every backend
/// returns the input as it is, and nothing panics reading back a mesh no round has touched.
#[test]
fn a_target_at_or_above_the_input_returns_it_on_every_backend() {
    let single = Mesh {
        positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        triangles: vec![[0, 1, 2]],
        ..Default::default()
    };
    let sphere = meshslim::mesh::icosphere(2);
    let n = sphere.triangles.len();
    for backend in backends() {
        for (mesh, target) in [(&single, 1), (&single, 5), (&sphere, n), (&sphere, 2 * n)] {
            let mut opts = SimplifyOptions::with_faces(target);
            opts.backend = backend;
            let (out, report) = simplify(mesh, &opts).unwrap();
            assert_eq!(
                out.triangles.len(),
                mesh.triangles.len(),
                "{backend:?} to {target}"
            );
            assert_eq!(report.stop_reason, StopReason::TargetReached);
            assert_eq!(report.collapses, 0);
        }
        let mut opts = SimplifyOptions::with_ratio(1, 0.5).unwrap();
        opts.backend = backend;
        let (out, _) = simplify(&single, &opts).unwrap();
        assert_eq!(out.triangles.len(), 1, "{backend:?}: a lone triangle stays");
    }
}

/// A point cloud (vertices, no faces) is refused with a reason, not written out as an empty
/// mesh that "reached the face target".
#[test]
fn a_mesh_without_faces_is_an_error() {
    let cloud = Mesh {
        positions: vec![[0.0; 3], [1.0, 0.0, 0.0]],
        ..Default::default()
    };
    for backend in [Backend::Cpu, Backend::CpuParallel, Backend::Gpu] {
        let mut opts = SimplifyOptions::with_faces(0);
        opts.backend = backend;
        let e = simplify(&cloud, &opts).unwrap_err().to_string();
        assert!(e.contains("no faces"), "{backend:?}: {e}");
    }
}
