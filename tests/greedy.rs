//! The greedy reference backend (`cpu`): invariants on generated meshes at 50%, 10% and 1%, tiny
//! hand-built cases with exact results, and the shared scans when they are present.

use crate::common;

use common::*;
use meshslim::mesh::{self, topology};
use meshslim::{Mesh, SimplifyOptions, StopReason, simplify};

#[test]
fn generated_meshes_keep_their_invariants() {
    for (name, m) in generated_meshes() {
        for ratio in [0.5, 0.1, 0.01] {
            let opts = SimplifyOptions::with_ratio(m.triangles.len(), ratio).unwrap();
            let (out, report) = simplify(&m, &opts).unwrap();
            let label = format!("{name} at {ratio}");
            check_invariants(&label, &m, &out, &report);
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
fn lock_border_keeps_invariants_and_outline() {
    let m = mesh::grid(30);
    let mut opts = SimplifyOptions::with_ratio(m.triangles.len(), 0.1).unwrap();
    opts.lock_border = true;
    let (out, report) = simplify(&m, &opts).unwrap();
    check_invariants("grid locked", &m, &out, &report);
}

/// ```text
///      3
///     /|\
///    / | \      a tetrahedron: every edge collapse would glue two faces
///   0--|--2     onto each other, so nothing can be removed
///    \ | /
///     \|/
///      1
/// ```
#[test]
fn tetrahedron_is_stuck() {
    let m = Mesh::new(
        vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
        vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
    );
    assert_eq!(topology(&m).euler_characteristic, 2);
    let (out, report) = simplify(&m, &SimplifyOptions::with_faces(2)).unwrap();
    assert_eq!(out.triangles.len(), 4);
    assert_eq!(report.stop_reason, StopReason::NoValidCollapse);
    assert_eq!(report.collapses, 0);
}

/// ```text
///  +--+--+--+--+      a flat 4 × 4 grid with its border locked: the outline is a square, so
///  |  |  |  |  |      every straight border vertex may slide onto a neighbour and the
///  +--+--+--+--+      interior is free; the end is the square as two triangles on its
///  ...                four corners
/// ```
#[test]
fn flat_grid_with_locked_border_collapses_to_two_triangles() {
    let m = mesh::grid(4);
    let mut opts = SimplifyOptions::with_faces(2);
    opts.lock_border = true;
    let (out, report) = simplify(&m, &opts).unwrap();
    assert_eq!(report.stop_reason, StopReason::TargetReached, "{report:?}");
    assert_eq!(out.triangles.len(), 2);
    let mut corners: Vec<[f32; 3]> = out.positions.clone();
    corners.sort_by(|a, b| a.partial_cmp(b).unwrap());
    assert_eq!(
        corners,
        vec![[0., 0., 0.], [0., 1., 0.], [1., 0., 0.], [1., 1., 0.]]
    );
    assert!((out.surface_area() - 1.0).abs() < 1e-6);
}

/// With a locked border, a curved outline keeps every border vertex exactly where it was.
#[test]
fn locked_border_never_moves() {
    let mut m = mesh::grid(10);
    for p in &mut m.positions {
        p[2] = (p[0] * 3.0).sin() * 0.1; // curved, so no border vertex lies on a straight line
    }
    let mut opts = SimplifyOptions::with_faces(20);
    opts.lock_border = true;
    let (out, _) = simplify(&m, &opts).unwrap();
    let border_in: Vec<[f32; 3]> = m
        .positions
        .iter()
        .copied()
        .filter(|p| p[1] == 0.0 || p[1] == 1.0) // the curved sides
        .collect();
    for p in border_in {
        assert!(
            out.positions.contains(&p),
            "border vertex {p:?} moved or vanished"
        );
    }
}

/// ```text
///        2
///       /|\
///   3--/ | \--1      vertex 0 in the middle of a concave star: sliding it onto the
///    \ 4 0   /       reflex corner 4 is cheap (all flat) but would fold the faces
///     \  |  /        on the far side over; the collapse is refused, others are taken
///       \|/
///        5
/// ```
#[test]
fn collapse_refuses_flip() {
    // A flat star around the origin whose ring has a reflex vertex at index 4.
    let ring = [
        [1.0, 0.0],
        [0.0, 1.0],
        [-1.0, 0.2],
        [-0.15, 0.0],
        [-1.0, -0.2],
        [0.0, -1.0],
    ];
    let mut pos = vec![[0.0f32, 0.0, 0.0]];
    pos.extend(ring.iter().map(|p| [p[0] as f32, p[1] as f32, 0.0]));
    let n = ring.len() as u32;
    let tris: Vec<[u32; 3]> = (0..n).map(|i| [0, 1 + i, 1 + (i + 1) % n]).collect();
    let m = Mesh::new(pos, tris);
    let mut opts = SimplifyOptions::with_faces(5);
    opts.lock_border = true; // the centre is the only free vertex: it must go somewhere
    let (out, report) = simplify(&m, &opts).unwrap();
    // Every collapse here costs nothing (all flat), so the order alone would happily pick the
    // reflex corner (-0.15, 0), which folds the faces beyond it over: the centre must go to a
    // corner that folds nothing, and one collapse must happen.
    assert_eq!(out.triangles.len(), 4, "{report:?}"); // an interior collapse removes two
    assert_eq!(out.positions.len(), 6);
    assert!(
        !out.positions.contains(&[0.0, 0.0, 0.0]),
        "the centre did not collapse"
    );
    for f in 0..out.triangles.len() {
        let n = out.face_normal(f).unwrap();
        assert!(
            n[2] > 0.0,
            "face {f} flipped: {:?} ({report:?})",
            out.triangles[f]
        );
    }
}

#[test]
fn max_error_stops_before_the_target() {
    let m = mesh::noisy_sphere(4, 0.02, 1);
    let mut opts = SimplifyOptions::with_faces(20);
    opts.max_error = Some(1e-3);
    let (out, report) = simplify(&m, &opts).unwrap();
    assert_eq!(report.stop_reason, StopReason::MaxError);
    assert!(out.triangles.len() > 20);
    assert!(report.max_collapse_error <= 1e-3);
}

#[test]
fn shared_models_keep_their_invariants() {
    let Some(dir) = shared_models() else {
        println!("note: ../shared/models not found; skipping the real-scan checks");
        return;
    };
    let models = [
        "fandisk.obj",
        "suzanne.obj",
        "teapot.obj",
        "spot/spot_triangulated.obj",
        "stanford-bunny.obj",
        "horse.ply",
        "nefertiti.obj",
        "igea.ply",
    ];
    for name in models {
        let m = meshslim::io::read(&dir.join(name)).unwrap();
        for ratio in [0.1, 0.01] {
            let opts = SimplifyOptions::with_ratio(m.triangles.len(), ratio).unwrap();
            let (out, report) = simplify(&m, &opts).unwrap();
            let label = format!("{name} at {ratio}");
            check_invariants(&label, &m, &out, &report);
            println!(
                "{label}: {} -> {} faces ({:?})",
                m.triangles.len(),
                out.triangles.len(),
                report.stop_reason
            );
        }
    }
}

/// The parallel levels (regions of the Morton order simplified at once, region borders pinned;
/// then fewer regions cut elsewhere) must keep every invariant the sequential run keeps.
#[test]
fn partitioned_run_keeps_invariants() {
    let mut meshes = generated_meshes();
    // Regions big enough that the parallel levels do most of the work, as on real scans.
    meshes.push(("big_noisy_sphere", mesh::noisy_sphere(6, 0.002, 3)));
    for (name, m) in meshes {
        // 10: a count the second level's 4 regions do not divide.
        for (ratio, regions) in [(0.1, 8), (0.01, 8), (0.01, 10)] {
            let mut opts = SimplifyOptions::with_ratio(m.triangles.len(), ratio).unwrap();
            opts.partitions = Some(regions);
            let (out, report) = simplify(&m, &opts).unwrap();
            let what = format!("{name} at {ratio}, {regions} regions");
            check_invariants(&what, &m, &out, &report);
        }
    }
}

/// Mean distance of the output's vertices from the unit sphere the input samples.
fn radial_error(m: &Mesh) -> f64 {
    m.positions
        .iter()
        .map(|p| {
            ((p[0] as f64).powi(2) + (p[1] as f64).powi(2) + (p[2] as f64).powi(2)).sqrt() - 1.0
        })
        .map(f64::abs)
        .sum::<f64>()
        / m.positions.len() as f64
}

#[test]
fn partitioned_run_is_as_good_as_sequential_and_deterministic() {
    let m = mesh::icosphere(6);
    let run = |partitions| {
        let mut opts = SimplifyOptions::with_ratio(m.triangles.len(), 0.02).unwrap();
        opts.partitions = Some(partitions);
        simplify(&m, &opts).unwrap().0
    };
    let (seq, par) = (run(1), run(8));
    // The same mesh whatever the number of threads.
    let pool = |n| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap()
    };
    assert_eq!(
        pool(1).install(|| run(8)),
        pool(4).install(|| run(8)),
        "depends on the thread count"
    );
    assert!(seq.triangles.len().abs_diff(par.triangles.len()) <= 1);
    let (es, ep) = (radial_error(&seq), radial_error(&par));
    assert!(
        ep <= es * 1.25,
        "8 regions: mean radial error {ep:.3e}, sequential {es:.3e}"
    );
    assert_eq!(
        par,
        run(8),
        "the same input and options must give the same mesh"
    );
}

/// A torus whose UV chart is cut open along one meridian: the vertices there are stored twice
/// (same position, u = 0 and u = 1). The seam must thin out (it may not pin the target away)
/// without tearing: the welded surface stays a closed torus and every output vertex keeps UVs.
#[test]
fn uv_seams_slide_without_tearing() {
    let m = seamed_torus();
    assert_eq!(topology(&m).euler_characteristic, 0);
    for ratio in [0.1, 0.02] {
        let opts = SimplifyOptions::with_ratio(m.triangles.len(), ratio).unwrap();
        let (out, report) = simplify(&m, &opts).unwrap();
        check_seamed_torus(&format!("seamed torus at {ratio}"), &m, &out, &report);
    }
}

/// ```text
///   +---+       a lone triangle beside a closed sphere: collapsing any of its edges would
///   | /         delete a component, so it stays, and the sphere stops at a tetrahedron
///   +
/// ```
#[test]
fn lone_triangle_and_small_components_survive() {
    let mut m = mesh::icosphere(2);
    let base = m.positions.len() as u32;
    m.positions
        .extend([[3.0, 0.0, 0.0], [4.0, 0.0, 0.0], [3.0, 1.0, 0.0]]);
    m.triangles.push([base, base + 1, base + 2]);
    let (out, report) = simplify(&m, &SimplifyOptions::with_faces(0)).unwrap();
    check_invariants("sphere and triangle at 0 faces", &m, &out, &report);
    assert_eq!(report.stop_reason, StopReason::NoValidCollapse);
    assert_eq!(out.triangles.len(), 4 + 1);
}

/// An unused vertex listed first at the same position as a used one, with other UVs: it is no
/// seam, and the used vertex stays the one its corners map from (found by a randomized run
/// that panicked in `apply`).
#[test]
fn unused_vertex_at_a_used_position_is_ignored() {
    let g = mesh::grid(6);
    let mut m = Mesh::new(
        std::iter::once(g.positions[8])
            .chain(g.positions.iter().copied())
            .collect(),
        g.triangles.iter().map(|t| t.map(|v| v + 1)).collect(),
    );
    let mut uvs = vec![[9.0, 9.0]];
    uvs.extend(g.positions.iter().map(|p| [p[0], p[1]]));
    m.uvs = Some(uvs);
    for lock_border in [false, true] {
        let mut opts = SimplifyOptions::with_faces(2);
        opts.lock_border = lock_border;
        let (out, report) = simplify(&m, &opts).unwrap();
        check_invariants("grid with an unused twin vertex", &m, &out, &report);
        assert_eq!(out.triangles.len(), 2, "{report:?}");
    }
}
