//! The round-based backend on the CPU (`cpu-parallel`): the greedy reference's invariants on
//! generated meshes, determinism, tiny exact cases, and the shared scans when present.

use crate::common;

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

#[test]
fn max_error_stops_before_the_target() {
    let m = meshslim::mesh::noisy_sphere(4, 0.02, 1);
    let mut o = SimplifyOptions::with_faces(20);
    o.backend = Backend::CpuParallel;
    o.max_error = Some(1e-3);
    let (out, report) = simplify(&m, &o).unwrap();
    assert_eq!(report.stop_reason, StopReason::MaxError, "{report:?}");
    assert!(out.triangles.len() > 20);
    assert!(
        report.max_collapse_error <= 1e-3,
        "{}",
        report.max_collapse_error
    );
}

/// A UV seam (the same position with two UVs) is kept whole: no face mixes the two sides'
/// UVs, and the grid simplifies up to and along it.
#[test]
fn seams_are_kept_and_attributes_follow() {
    let mut m = meshslim::mesh::grid(20);
    // UV = (x, y), except vertices right of the middle column take u + 1: a seam at x = 0.5.
    let n = m.positions.len();
    let mut uvs: Vec<[f32; 2]> = m.positions.iter().map(|p| [p[0], p[1]]).collect();
    for t in m.triangles.iter_mut() {
        if t.iter().all(|&v| m.positions[v as usize][0] >= 0.5) {
            for v in t.iter_mut() {
                let p = m.positions[*v as usize];
                m.positions.push(p);
                uvs.push([p[0] + 1.0, p[1]]);
                *v = (m.positions.len() - 1) as u32;
            }
        }
    }
    assert!(m.positions.len() > n);
    m.uvs = Some(uvs);
    let (out, report) = simplify(&m, &opts(m.triangles.len(), 0.2)).unwrap();
    assert!(out.triangles.len() < m.triangles.len() / 2, "{report:?}");
    let uvs = out.uvs.as_ref().expect("UVs kept");
    // Faces right of the seam keep u >= 1.5 - so no face mixes the two sides' UVs.
    for t in &out.triangles {
        let right = t.iter().filter(|&&v| uvs[v as usize][0] >= 1.5).count();
        let left = t
            .iter()
            .filter(|&&v| uvs[v as usize][0] < 0.5 + 1e-6)
            .count();
        assert!(right == 0 || left == 0, "a face straddles the seam: {t:?}");
    }
}

/// Before any collapse, every corner's attribute vertex as the rounds see it (what the output
/// and the viewer's per-corner UVs are made from) is the input corner's own, on both sides of a
/// seam.
#[test]
fn corner_attributes_of_the_upload_are_the_input_corners() {
    use meshslim::rounds::{Upload, corner_attributes};
    let m = seamed_torus();
    let up = Upload::new(&m);
    let attrs = corner_attributes(&up.flags, &up.vertex_attr, &up.indices, &up.face_extra);
    assert_eq!(attrs.len(), up.indices.len());
    let uv = up.welded.uvs.as_ref().unwrap();
    let mut seam_corners = 0;
    for (f, x) in up.face_extra.iter().enumerate() {
        let input = up.welded.triangles[x.origin as usize];
        for k in 0..3 {
            let got = attrs[3 * f + k];
            // The same position and the same UV as the input corner: its own attribute vertex.
            assert_eq!(got, input[k], "face {f} corner {k}");
            let v = up.indices[3 * f + k] as usize;
            seam_corners += (up.flags[v] & meshslim::compute::types::flag::SEAM != 0) as usize;
            assert_eq!(uv[got as usize], uv[input[k] as usize]);
        }
    }
    // 24 seam vertices with six corners each.
    assert_eq!(seam_corners, 24 * 6);
}

/// The rounds' quadrics carry the greedy reference's seam constraint planes: on a flat grid
/// with an L-shaped UV seam, sliding the corner of the L along one arm costs something, sliding
/// a vertex along a straight stretch of the seam nothing (the face planes alone cost nothing on
/// a flat grid).
#[test]
fn seam_bends_cost_to_slide_away() {
    use meshslim::compute::common::quadric_eval;
    use meshslim::rounds::cpu::CpuRounds;
    use meshslim::rounds::{SELECTION_PASSES, Upload};
    let mut m = meshslim::mesh::grid(8);
    let mut uvs: Vec<[f32; 2]> = m.positions.iter().map(|p| [p[0], p[1]]).collect();
    // The lower-left quarter's faces take vertices of their own with shifted UVs: a seam along
    // x = 0.5 below y = 0.5 and along y = 0.5 left of x = 0.5, bending at (0.5, 0.5).
    for t in m.triangles.iter_mut() {
        let c = t.iter().fold([0.0f32; 2], |c, &v| {
            let p = m.positions[v as usize];
            [c[0] + p[0] / 3.0, c[1] + p[1] / 3.0]
        });
        if c[0] < 0.5 && c[1] < 0.5 {
            for v in t.iter_mut() {
                let p = m.positions[*v as usize];
                m.positions.push(p);
                uvs.push([p[0] + 2.0, p[1]]);
                *v = (m.positions.len() - 1) as u32;
            }
        }
    }
    m.uvs = Some(uvs);
    let up = Upload::new(&m);
    let opts = SimplifyOptions::with_ratio(m.triangles.len(), 0.5).unwrap();
    let p = up.base_params(&opts);
    let mut cpu = CpuRounds::new(&up, SELECTION_PASSES);
    cpu.build_adjacency(&p).unwrap();
    cpu.setup(&p).unwrap();
    // Vertices by their grid position, through the upload's normalized frame.
    let id = |x: f32, y: f32| {
        let q = [0, 1].map(|i| (([x, y][i] as f64 - up.center[i]) * up.scale) as f32);
        up.positions
            .iter()
            .position(|w| (w[0] - q[0]).abs() < 1e-6 && (w[1] - q[1]).abs() < 1e-6)
            .expect("a grid vertex")
    };
    let cost = |v: usize, onto: usize| {
        let (a, b) = (cpu.positions[v], cpu.positions[onto]);
        quadric_eval(&cpu.quadrics[v], [b[0] - a[0], b[1] - a[1], b[2] - a[2]])
    };
    let corner = id(0.5, 0.5);
    let straight = id(0.5, 0.25);
    assert!(
        up.flags[corner] != 0 && up.flags[straight] != 0,
        "both on the seam"
    );
    // Along the seam from a straight stretch: free. Off the bend: the other arm's plane costs.
    assert!(
        cost(straight, id(0.5, 0.125)) < 1e-12,
        "{}",
        cost(straight, id(0.5, 0.125))
    );
    assert!(
        // The arm's plane at distance e from the point, weighted |e|², e = 1/8 of the grid.
        cost(corner, id(0.5, 0.375)) > 1e-6,
        "{}",
        cost(corner, id(0.5, 0.375))
    );
}

/// The rounds thin a seam out like the greedy reference: seam vertices slide along it and free
/// ones collapse onto it, so the seam does not pin the target away.
#[test]
fn uv_seams_slide_without_tearing() {
    let m = seamed_torus();
    for ratio in [0.1, 0.02] {
        let (out, report) = simplify(&m, &opts(m.triangles.len(), ratio)).unwrap();
        check_seamed_torus(
            &format!("cpu-parallel seamed torus at {ratio}"),
            &m,
            &out,
            &report,
        );
    }
}

#[test]
fn shared_models_keep_their_invariants() {
    let Some(dir) = shared_models() else {
        println!("note: ../shared/models not found; skipping the real-scan checks");
        return;
    };
    for name in [
        "fandisk.obj",
        "suzanne.obj",
        "teapot.obj",
        "spot/spot_triangulated.obj",
        "stanford-bunny.obj",
        "horse.ply",
        "igea.ply",
    ] {
        let m = meshslim::io::read(&dir.join(name)).unwrap();
        for ratio in [0.1, 0.01] {
            let (out, report) = simplify(&m, &opts(m.triangles.len(), ratio)).unwrap();
            check_invariants(
                &format!("cpu-parallel {name} at {ratio}"),
                &m,
                &out,
                &report,
            );
        }
    }
}

/// The LOD scene's way of running: one set of rounds driven to falling targets in turn, the
/// quadrics kept between them. Each stop lands on its target and keeps the invariants.
#[test]
fn a_resumed_run_lands_each_target_and_keeps_the_invariants() {
    use meshslim::rounds::cpu::CpuRounds;
    use meshslim::rounds::{Driver, RoundRunner, SELECTION_PASSES, Upload};
    let m = meshslim::mesh::noisy_sphere(5, 0.01, 3);
    let up = Upload::new(&m);
    let n = up.face_count();
    let mut rounds = CpuRounds::new(&up, SELECTION_PASSES);
    let mut o = SimplifyOptions::with_faces(n);
    o.backend = Backend::CpuParallel;
    let mut driver = Driver::new(&up, &o);
    for ratio in [0.5, 0.1, 0.02] {
        let target = (n as f64 * ratio).round() as usize;
        let reason = driver.run_to(&mut rounds, target, &mut |_| {}).unwrap();
        assert_eq!(reason, StopReason::TargetReached, "at {ratio}");
        assert!(
            (target - 1..=target).contains(&driver.faces),
            "{}",
            driver.faces
        );
        let out = up.build_output(&rounds.download().unwrap(), false);
        let report = meshslim::SimplifyReport {
            input_faces: n,
            target_faces: target,
            collapses: 0,
            ..meshslim::SimplifyReport::counts(Backend::CpuParallel, &m, &out, reason)
        };
        check_invariants(&format!("resumed to {ratio}"), &m, &out, &report);
    }
    // Going on keeps the quality of one run: within 10% of a run straight to 2%.
    let resumed = up.build_output(&rounds.download().unwrap(), false);
    let (direct, _) = simplify(&m, &opts(n, 0.02)).unwrap();
    let dist = |b: &Mesh| {
        meshslim::metrics::compare(&m, b, &Default::default())
            .unwrap()
            .distance
            .two_sided
            .mean_rel
    };
    let (r, d) = (dist(&resumed), dist(&direct));
    assert!(r <= d * 1.1, "resumed {r:e} vs direct {d:e}");
}

#[test]
fn cancelled_options_stop_every_backend() {
    let m = meshslim::mesh::noisy_sphere(4, 0.01, 1);
    for backend in [Backend::Cpu, Backend::CpuParallel] {
        let mut o = opts(m.triangles.len(), 0.1);
        o.backend = backend;
        o.cancel.cancel();
        let r = simplify(&m, &o);
        assert!(
            matches!(r, Err(meshslim::Error::Cancelled)),
            "{backend:?}: {:?}",
            r.map(|(_, rep)| rep)
        );
    }
}

/// `Backend::Auto` resolves in the library: it runs a real backend (`gpu` on a hardware adapter,
/// `cpu-parallel` otherwise, lavapipe included), reports which, says why, and writes what that
/// backend writes when asked for by name.
#[test]
fn auto_backend_runs_a_real_backend_and_says_why() {
    let m = meshslim::mesh::icosphere(3);
    let mut opts = SimplifyOptions::with_ratio(m.face_count(), 0.1).unwrap();
    opts.backend = Backend::Auto;
    let (out, report) = simplify(&m, &opts).unwrap();
    assert!(
        matches!(report.backend, Backend::Gpu | Backend::CpuParallel),
        "{:?}",
        report.backend
    );
    let why = report.auto.clone().expect("auto says what it picked");
    assert!(why.starts_with(report.backend.name()), "{why}");
    let named = SimplifyOptions {
        backend: report.backend,
        ..opts.clone()
    };
    let (again, _) = simplify(&m, &named).unwrap();
    assert_eq!(out, again);
    // A named backend reports no auto choice.
    assert_eq!(simplify(&m, &named).unwrap().1.auto, None);
}
