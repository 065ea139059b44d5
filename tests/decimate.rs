//! Vertex decimation (`--method decimate`): hand-built fans with known outcomes, the loop
//! splitting of a polygon with a known best diagonal, and the invariants on generated meshes.

use crate::common;

use common::{check_invariants, generated_meshes};
use glam::DVec3;
use meshslim::decimate::{Decimator, Outcome, Refusal, Removal, VertexClass, split_loop};
use meshslim::{Mesh, Method, SimplifyOptions, StopReason, simplify};

const REMOVALS: [Removal; 2] = [Removal::LoopSplit, Removal::HalfEdge];

fn options(removal: Removal) -> SimplifyOptions {
    let mut o = SimplifyOptions::with_faces(0);
    o.method = Method::Decimate;
    o.removal = removal;
    o
}

/// The engine's id of the input vertex at `p`.
fn id_at(d: &Decimator, p: [f32; 3]) -> u32 {
    (0..d.vertex_count() as u32)
        .find(|&v| d.position(v) == p)
        .expect("a vertex at that position")
}

/// A fan: centre vertex 0 at `centre`, ring vertices 1..=n, faces (0, i, i + 1) counter-clockwise.
fn fan(centre: [f32; 3], ring: &[[f32; 3]]) -> Mesh {
    let n = ring.len() as u32;
    let mut pos = vec![centre];
    pos.extend_from_slice(ring);
    let tris = (0..n).map(|i| [0, 1 + i, 1 + (i + 1) % n]).collect();
    Mesh::new(pos, tris)
}

/// Closes a fan's ring with a cap of faces below, so that the ring vertices are not border
/// vertices: the ring joined to an apex under the centre.
fn closed_fan(centre: [f32; 3], ring: &[[f32; 3]]) -> Mesh {
    let mut m = fan(centre, ring);
    let n = ring.len() as u32;
    let apex = m.positions.len() as u32;
    m.positions.push([0.0, 0.0, -2.0]);
    for i in 0..n {
        m.triangles.push([apex, 1 + (i + 1) % n, 1 + i]);
    }
    m
}

fn hexagon() -> Vec<[f32; 3]> {
    (0..6)
        .map(|i| {
            let a = i as f32 * std::f32::consts::TAU / 6.0;
            [a.cos(), a.sin(), 0.0]
        })
        .collect()
}

/// ```text
///     2 ---- 1
///    / \    / \
///   3 -- 0 ---- 6      flat: the centre 0 goes, at no error, and its six faces become four
///    \ /    \ /        over the same six ring vertices
///     4 ---- 5
/// ```
#[test]
fn the_centre_of_a_flat_hexagon_goes() {
    for removal in REMOVALS {
        let m = closed_fan([0.0; 3], &hexagon());
        let mut d = Decimator::new(&m, &options(removal));
        let c = id_at(&d, [0.0; 3]);
        assert_eq!(d.classify(c), VertexClass::Simple);
        let faces = d.face_count();
        match d.remove(c) {
            Outcome::Removed { error } => assert!(error < 1e-9, "{removal:?}: error {error}"),
            o => panic!("{removal:?}: {o:?}"),
        }
        assert_eq!(d.face_count(), faces - 2);
        let out = d.mesh();
        assert_eq!(out.positions.len(), 7, "six ring vertices and the apex");
        assert!(!out.positions.contains(&[0.0; 3]));
        assert_eq!(d.remove(c), Outcome::Refused(Refusal::Gone));
    }
}

/// ```text
///              1
///             /|
///    9 ----- 0 +----- 2        a sharp five-pointed star around the centre 0 (tips at radius
///     `.     / |    .'         1, inner corners at 0.15): no tip or inner corner sees the
///        `. /  |  .'           whole star, so every half-edge collapse of 0 folds a face over
///           ...                (refused), and loop splitting must split between the spikes
/// ```
#[test]
fn a_removal_that_would_fold_is_refused() {
    let ring: Vec<[f32; 3]> = (0..10)
        .map(|i| {
            let a = i as f32 * std::f32::consts::TAU / 10.0;
            let r = if i % 2 == 0 { 1.0 } else { 0.15 };
            [r * a.cos(), r * a.sin(), 0.0]
        })
        .collect();
    let m = closed_fan([0.0; 3], &ring);
    let mut d = Decimator::new(&m, &options(Removal::HalfEdge));
    let c = id_at(&d, [0.0; 3]);
    assert_eq!(d.classify(c), VertexClass::Simple);
    assert_eq!(d.remove(c), Outcome::Refused(Refusal::NoValidFill));
    // Loop splitting: whatever it does, no face of the result may wind against the fan.
    let mut d = Decimator::new(&m, &options(Removal::LoopSplit));
    let c = id_at(&d, [0.0; 3]);
    if let Outcome::Removed { .. } = d.remove(c) {
        let out = d.mesh();
        for t in &out.triangles {
            let [a, b, c] = t.map(|v| DVec3::from_array(out.positions[v as usize].map(f64::from)));
            if a.z == 0.0 && b.z == 0.0 && c.z == 0.0 {
                assert!((b - a).cross(c - a).z > 0.0, "a folded face {t:?}");
            }
        }
    }
}

/// A cube's corner meets three feature edges (90 degrees): a corner, kept by both operators.
#[test]
fn a_cube_corner_stays() {
    for removal in REMOVALS {
        let m = meshslim::mesh::cube(2);
        let mut d = Decimator::new(&m, &options(removal));
        let b = m.bounds().unwrap();
        let corner = id_at(&d, b.min);
        assert_eq!(d.classify(corner), VertexClass::Corner);
        assert_eq!(
            d.remove(corner),
            Outcome::Refused(Refusal::Kept(VertexClass::Corner))
        );
        // A vertex in the middle of an edge of the cube is on exactly two feature edges.
        let mid = (0..d.vertex_count() as u32)
            .find(|&v| {
                let p = d.position(v);
                let on = |i: usize| p[i] == b.min[i] || p[i] == b.max[i];
                (0..3).filter(|&i| on(i)).count() == 2
            })
            .unwrap();
        assert_eq!(d.classify(mid), VertexClass::InteriorEdge);
    }
}

/// An open strip of two rows; vertex 1 on the lower border.
///
/// ```text
///   3 ---- 4 ---- 5
///   | \    | \    |
///   |  \   |  \   |
///   0 ---- 1 ---- 2      straight: 1 goes, under --lock-border too;
///                        bent (1 pushed down in the plane): 1 stays under --lock-border
/// ```
fn strip(dip: f32) -> Mesh {
    let pos = vec![
        [0.0, 0.0, 0.0],
        [1.0, -dip, 0.0],
        [2.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
        [2.0, 1.0, 0.0],
    ];
    let tris = vec![[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4]];
    Mesh::new(pos, tris)
}

#[test]
fn border_vertices_go_on_a_straight_border_and_stay_on_a_bent_one_when_locked() {
    for removal in REMOVALS {
        for lock in [false, true] {
            let mut o = options(removal);
            o.lock_border = lock;
            let mut d = Decimator::new(&strip(0.0), &o);
            let v = id_at(&d, [1.0, 0.0, 0.0]);
            assert_eq!(d.classify(v), VertexClass::Boundary);
            assert!(
                matches!(d.remove(v), Outcome::Removed { error } if error < 1e-9),
                "{removal:?} lock {lock}"
            );
            assert_eq!(d.face_count(), 3, "a border removal takes one face");

            let mut d = Decimator::new(&strip(0.3), &o);
            let v = id_at(&d, [1.0, -0.3, 0.0]);
            let got = d.remove(v);
            if lock {
                assert_eq!(got, Outcome::Refused(Refusal::LockedBorder), "{removal:?}");
            } else {
                assert!(
                    matches!(got, Outcome::Removed { error } if error > 0.0),
                    "{removal:?}: {got:?}"
                );
            }
        }
    }
}

/// A rhombus, long across x: the short diagonal (1, 3) leaves its other corners at distance 2
/// for a length of 2 (aspect 1), the long one (0, 2) at 1 for 4 (aspect 0.25): loop splitting
/// takes (1, 3), and a diagonal already in the mesh is never taken.
///
/// ```text
///            1 (0, 1)
///          /   \
///  (-2, 0) 2     0 (2, 0)
///          \   /
///            3 (0, -1)
/// ```
#[test]
fn loop_splitting_takes_the_best_diagonal() {
    let pts = [
        DVec3::new(2.0, 0.0, 0.0),
        DVec3::new(0.0, 1.0, 0.0),
        DVec3::new(-2.0, 0.0, 0.0),
        DVec3::new(0.0, -1.0, 0.0),
    ];
    let (mut out, mut work) = (Vec::new(), Vec::new());
    assert!(split_loop(
        &pts,
        DVec3::Z,
        &mut |_, _| false,
        &mut out,
        &mut work
    ));
    let mut tris: Vec<[usize; 3]> = out.clone();
    tris.sort();
    assert_eq!(tris, vec![[1, 2, 3], [3, 0, 1]]);
    // With (1, 3) already an edge, the long diagonal it is.
    assert!(split_loop(
        &pts,
        DVec3::Z,
        &mut |a, b| (a.min(b), a.max(b)) == (1, 3),
        &mut out,
        &mut work
    ));
    out.sort();
    assert_eq!(out, vec![[0, 1, 2], [2, 3, 0]]);
    // Every diagonal taken: no split.
    assert!(!split_loop(
        &pts,
        DVec3::Z,
        &mut |_, _| true,
        &mut out,
        &mut work
    ));
}

/// On the generated meshes, both operators: the invariants every method keeps (Euler
/// characteristic, borders, components, manifoldness, no flipped or degenerate face), the
/// target reached within one face, and every output vertex one of the input's, unmoved, with
/// its attributes.
#[test]
fn generated_meshes_keep_topology_and_a_subset_of_the_vertices() {
    for (name, m) in generated_meshes() {
        for removal in REMOVALS {
            let mut o = options(removal);
            o.target_faces = m.triangles.len() / 10;
            let label = format!("{name} {removal:?}");
            let (out, report) = simplify(&m, &o).unwrap();
            check_invariants(&label, &m, &out, &report);
            if name != "sharp_cube" {
                assert_eq!(report.stop_reason, StopReason::TargetReached, "{label}");
            }
            let input: std::collections::HashSet<[u32; 3]> =
                m.positions.iter().map(|p| p.map(f32::to_bits)).collect();
            for p in &out.positions {
                assert!(
                    input.contains(&p.map(f32::to_bits)),
                    "{label}: new position {p:?}"
                );
            }
            let d = report.decimation.as_ref().unwrap();
            assert_eq!(d.removed, report.collapses);
        }
    }
}

/// UVs and normals are the input's, per kept vertex: every output (position, UV, normal) is an
/// input vertex's; and the UV seam stays a seam.
#[test]
fn attributes_are_carried_not_invented() {
    let mut m = common::seamed_torus();
    m.recompute_normals();
    for removal in REMOVALS {
        let mut o = options(removal);
        o.target_faces = m.triangles.len() / 10;
        let (out, report) = simplify(&m, &o).unwrap();
        common::check_seamed_torus(&format!("{removal:?}"), &m, &out, &report);
        let (uv, n) = (out.uvs.as_ref().unwrap(), out.normals.as_ref().unwrap());
        let (iuv, inn) = (m.uvs.as_ref().unwrap(), m.normals.as_ref().unwrap());
        for v in 0..out.positions.len() {
            assert!(
                (0..m.positions.len()).any(|w| m.positions[w] == out.positions[v]
                    && iuv[w] == uv[v]
                    && inn[w] == n[v]),
                "{removal:?}: vertex {v} has attributes no input vertex had"
            );
        }
    }
}

/// A run stops on --max-error: every removal's error within the bound, and fewer removals.
#[test]
fn max_error_stops_the_run() {
    let m = meshslim::mesh::noisy_sphere(4, 0.01, 7);
    let mut o = options(Removal::HalfEdge);
    o.target_faces = 100;
    let (_, free) = simplify(&m, &o).unwrap();
    o.max_error = Some(free.max_collapse_error / 4.0);
    let (out, bound) = simplify(&m, &o).unwrap();
    assert_eq!(bound.stop_reason, StopReason::MaxError);
    assert!(bound.max_collapse_error <= free.max_collapse_error / 4.0);
    assert!(out.triangles.len() > 100);
}

/// The engine refuses the backends it does not run on, with a message naming the fix.
#[test]
fn decimate_runs_on_the_cpu_only() {
    let mut o = options(Removal::HalfEdge);
    o.target_faces = 100;
    o.backend = meshslim::Backend::Gpu;
    let e = simplify(&meshslim::mesh::icosphere(3), &o).unwrap_err();
    assert!(e.to_string().contains("--backend cpu"), "{e}");
}
