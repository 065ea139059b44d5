//! The round-based backend on the CPU (`cpu-parallel`): the greedy reference's invariants on
//! generated meshes, determinism, tiny exact cases, and the shared scans when present.

mod common;

use common::*;
use meshslim::{Backend, Mesh, SimplifyOptions, StopReason, simplify};

fn opts(faces: usize, ratio: f64) -> SimplifyOptions {
    let mut o = SimplifyOptions::with_ratio(faces, ratio).unwrap();
    o.backend = Backend::CpuParallel;
    o
}

#[test]
fn generated_meshes_keep_their_invariants() {
    for (name, m) in generated_meshes() {
        for ratio in [0.5, 0.1, 0.01] {
            let (out, report) = simplify(&m, &opts(m.triangles.len(), ratio)).unwrap();
            let label = format!("cpu-parallel {name} at {ratio}");
            check_invariants(&label, &m, &out, &report);
            let rounds = report.rounds.as_ref().expect("round report");
            assert_eq!(rounds.rounds, rounds.faces_removed_per_round.len());
            if ratio >= 0.1 && name != "sharp_cube" {
                assert_eq!(
                    report.stop_reason,
                    StopReason::TargetReached,
                    "{label}: {report:?}"
                );
            }
        }
    }
}

#[test]
fn runs_are_deterministic() {
    let m = meshslim::mesh::noisy_sphere(4, 0.01, 7);
    let o = opts(m.triangles.len(), 0.05);
    let (a, _) = simplify(&m, &o).unwrap();
    let (b, _) = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(|| simplify(&m, &o).unwrap());
    assert_eq!(a, b);
}

/// The tetrahedron of tests/greedy.rs: every collapse would glue two faces together.
#[test]
fn tetrahedron_is_stuck() {
    let m = Mesh::new(
        vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
        vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
    );
    let mut o = SimplifyOptions::with_faces(2);
    o.backend = Backend::CpuParallel;
    let (out, report) = simplify(&m, &o).unwrap();
    assert_eq!(out.triangles.len(), 4);
    assert_eq!(report.stop_reason, StopReason::NoValidCollapse);
    assert_eq!(report.collapses, 0);
}
