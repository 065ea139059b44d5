//! Isotropic remeshing on generated meshes: what it must keep (manifoldness, Euler
//! characteristic, borders, sharp edges, orientation) and where its vertices end up.

use crate::common;

use meshslim::Mesh;
use meshslim::mesh::{self, topology};
use meshslim::metrics::{TriangleBvh, triangle_quality};
use meshslim::remesh::{Adaptive, EdgeTarget, RemeshOptions, remesh};

fn opts(target: EdgeTarget) -> RemeshOptions {
    RemeshOptions {
        target,
        ..Default::default()
    }
}

/// The largest distance from a vertex of `b` to the surface of `a`.
fn farthest_vertex(a: &Mesh, b: &Mesh) -> f64 {
    let bvh = TriangleBvh::new(a);
    b.positions
        .iter()
        .map(|p| bvh.closest(p.map(f64::from), None).unwrap().dist2.sqrt())
        .fold(0.0, f64::max)
}

/// Manifold, as many borders, the same Euler characteristic and orientation, no degenerate
/// faces, better triangles than the input's.
fn assert_kept(input: &Mesh, out: &Mesh) {
    let (a, b) = (topology(input), topology(out));
    assert!(b.is_manifold(), "{b:?}");
    assert_eq!(b.euler_characteristic, a.euler_characteristic);
    assert_eq!(b.boundary_loops, a.boundary_loops);
    assert_eq!(b.connected_components, a.connected_components);
    assert_eq!(b.inconsistently_oriented_edges, 0);
    assert_eq!((b.degenerate_faces, b.duplicate_faces), (0, 0));
    assert_eq!(b.signed_volume > 0.0, a.signed_volume > 0.0);
}

#[test]
fn closed_surfaces_keep_their_topology_and_stay_on_the_input() {
    // The noisy sphere's noise is half an edge long: at 45 degrees it makes a net of creases
    // that the remesher would keep; there it is no feature (180).
    let cases = [
        ("torus", mesh::torus(1.0, 0.35, 90, 30), 45.0),
        ("noisy sphere", mesh::noisy_sphere(4, 0.01, 3), 180.0),
        ("double torus", mesh::double_torus(2), 45.0),
    ];
    for (name, input, feature_angle_deg) in cases {
        for factor in [0.5, 2.0] {
            let o = RemeshOptions {
                feature_angle_deg,
                ..opts(EdgeTarget::MeanEdgeTimes(factor))
            };
            let (out, report) = remesh(&input, &o).unwrap();
            assert_kept(&input, &out);
            // Vertices are projected onto the input after every relaxation; a split's
            // midpoint that a fold check put back may sit off it by a chord's sagitta.
            let far = farthest_vertex(&input, &out);
            assert!(
                far <= 0.05 * report.edge_length,
                "{name} x{factor}: a vertex {far} from the input (L = {})",
                report.edge_length
            );
            let q = triangle_quality(&out);
            assert_eq!(q.share_under_10_deg, 0.0, "{name} x{factor}: {q:?}");
            assert!(q.share_under_30_deg < 0.01, "{name} x{factor}: {q:?}");
            // The double torus is voxels: its feature lines, one voxel apart, leave room
            // for right isosceles triangles (45 degrees) only.
            let mean = if name == "double torus" { 44.9 } else { 50.0 };
            assert!(q.mean_min_angle_deg > mean, "{name} x{factor}: {q:?}");
        }
    }
}

#[test]
fn a_cubes_edges_stay_sharp_and_its_corners_stay_put() {
    let cube = mesh::cube(8);
    let (out, report) = remesh(&cube, &opts(EdgeTarget::Length(0.2))).unwrap();
    assert_kept(&cube, &out);
    assert_eq!((report.feature_edges, report.corners), (12 * 8, 8));
    let on = |c: f32| c.abs() < 1e-5 || (c - 1.0).abs() < 1e-5;
    for corner in 0..8 {
        let want = [corner & 1, (corner >> 1) & 1, corner >> 2].map(|b| b as f32);
        assert!(out.positions.contains(&want), "corner {want:?} is gone");
    }
    // Sharp: no face bends round an edge — the three corners of each share a side of the cube.
    for t in &out.triangles {
        let [a, b, c] = t.map(|v| out.positions[v as usize]);
        let shared = (0..3).any(|k| on(a[k]) && a[k] == b[k] && b[k] == c[k]);
        assert!(shared, "face {a:?} {b:?} {c:?} cuts a corner of the cube");
    }
    // And the remesher did its work: edges near 0.2, not the input's 0.125.
    let q = triangle_quality(&out);
    assert!(
        out.face_count() < cube.face_count() && q.mean_min_angle_deg > 45.0,
        "{} faces: {q:?}",
        out.face_count()
    );
}

#[test]
fn a_border_is_kept_and_a_locked_one_is_not_touched() {
    // A bumpy square patch: its border is a square outline with four corners.
    let mut patch = mesh::grid(24);
    for p in &mut patch.positions {
        p[2] = 0.05 * (p[0] * 9.0).sin() * (p[1] * 7.0).cos();
    }
    let on_outline = |p: &[f32; 3]| {
        let edge = |c: f32| c.abs() < 1e-6 || (c - 1.0).abs() < 1e-6;
        edge(p[0]) || edge(p[1])
    };
    let border_vertices = |m: &Mesh| {
        let mut count = std::collections::HashMap::new();
        for t in &m.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *count.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
        let mut vs: Vec<[f32; 3]> = count
            .into_iter()
            .filter(|(_, n)| *n == 1)
            .flat_map(|((a, b), _)| [a, b])
            .map(|v| m.positions[v as usize])
            .collect();
        vs.sort_by(|x, y| x.partial_cmp(y).unwrap());
        vs.dedup();
        vs
    };
    let (out, _) = remesh(&patch, &opts(EdgeTarget::MeanEdgeTimes(2.0))).unwrap();
    assert_kept(&patch, &out);
    let border = border_vertices(&out);
    assert!(
        border.iter().all(on_outline),
        "a border vertex left the outline"
    );
    for corner in [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]] {
        assert!(
            border
                .iter()
                .any(|p| p[0] == corner[0] && p[1] == corner[1]),
            "corner {corner:?} is gone"
        );
    }
    assert!(
        border.len() < border_vertices(&patch).len(),
        "the border was not coarsened"
    );

    let locked = RemeshOptions {
        lock_border: true,
        ..opts(EdgeTarget::MeanEdgeTimes(2.0))
    };
    let (out, _) = remesh(&patch, &locked).unwrap();
    assert_kept(&patch, &out);
    assert_eq!(border_vertices(&out), border_vertices(&patch));
}

#[test]
fn a_face_count_sets_the_length_and_threads_do_not_change_the_result() {
    let sphere = mesh::icosphere(5);
    let run = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| remesh(&sphere, &opts(EdgeTarget::Faces(3000))).unwrap())
    };
    let (one, _) = run(1);
    let (two, _) = run(2);
    assert_eq!(one.positions, two.positions);
    assert_eq!(one.triangles, two.triangles);
    let n = one.face_count() as f64;
    assert!((n / 3000.0 - 1.0).abs() < 0.1, "{n} faces for 3000");
}

#[test]
fn bad_input_and_options_are_refused_with_a_reason() {
    let e = remesh(&Mesh::new(vec![], vec![]), &RemeshOptions::default()).unwrap_err();
    assert!(e.to_string().contains("no faces"), "{e}");
    let bad_angle = RemeshOptions {
        feature_angle_deg: 200.0,
        ..Default::default()
    };
    let e = remesh(&mesh::icosphere(1), &bad_angle).unwrap_err();
    assert!(e.to_string().contains("feature angle"), "{e}");
    let e = remesh(&mesh::icosphere(1), &opts(EdgeTarget::Length(-1.0))).unwrap_err();
    assert!(e.to_string().contains("positive"), "{e}");
    // A length that would need billions of faces is refused before any work.
    let e = remesh(&mesh::icosphere(1), &opts(EdgeTarget::Length(1e-5))).unwrap_err();
    assert!(e.to_string().contains("remeshing allows"), "{e}");
    let broken = Mesh::new(vec![[0.0; 3]; 3], vec![[0, 1, 7]]);
    let e = remesh(&broken, &RemeshOptions::default()).unwrap_err();
    assert!(e.to_string().contains('7'), "{e}");
}

#[test]
fn a_triangle_soup_is_welded_first() {
    // Every face with its own three vertices: without welding, every edge would be a border.
    let torus = mesh::torus(1.0, 0.35, 48, 16);
    let soup = common::triangle_soup(&torus);
    let (out, _) = remesh(&soup, &opts(EdgeTarget::MeanEdge)).unwrap();
    assert_kept(&torus, &out);
    assert_eq!(topology(&out).boundary_loops, 0);
}

#[test]
fn normals_colours_and_seamless_uvs_are_interpolated_on_the_input() {
    // A flat patch whose normal is +z, colour red and UV its own (x, y): a new vertex at
    // (x, y) must get exactly those.
    let mut patch = mesh::grid(16);
    let n = patch.positions.len();
    patch.normals = Some(vec![[0.0, 0.0, 1.0]; n]);
    patch.colors = Some(vec![[1.0, 0.0, 0.0, 1.0]; n]);
    patch.uvs = Some(patch.positions.iter().map(|p| [p[0], p[1]]).collect());
    let (out, report) = remesh(&patch, &opts(EdgeTarget::MeanEdgeTimes(1.5))).unwrap();
    assert!(report.not_carried.is_empty(), "{:?}", report.not_carried);
    let (normals, colors, uvs) = (
        out.normals.as_ref().unwrap(),
        out.colors.as_ref().unwrap(),
        out.uvs.as_ref().unwrap(),
    );
    for (v, p) in out.positions.iter().enumerate() {
        assert_eq!(normals[v], [0.0, 0.0, 1.0]);
        assert_eq!(colors[v], [1.0, 0.0, 0.0, 1.0]);
        assert!((uvs[v][0] - p[0]).abs() < 1e-5 && (uvs[v][1] - p[1]).abs() < 1e-5);
    }
    // With a seam (the torus's chart cut open along a meridian, u = 0 on one side and 1 on
    // the other): the seam stays a line, its vertices are stored once per side, and no face
    // spreads across the atlas. The torus's u is its angle round the z axis over 2π.
    let seamed = common::seamed_torus();
    let (out, report) = remesh(&seamed, &RemeshOptions::default()).unwrap();
    assert!(report.not_carried.is_empty(), "{report:?}");
    let uv = out.uvs.as_ref().expect("UVs carried");
    let t = topology(&out);
    assert_eq!((t.euler_characteristic, t.boundary_loops), (0, 0), "{t:?}");
    assert!(
        out.vertex_count() > t.welded_vertices,
        "the seam's vertices are not split"
    );
    for tri in &out.triangles {
        let us = tri.map(|v| uv[v as usize][0]);
        let spread = common::u_spread(us);
        assert!(
            spread < 0.1,
            "a face spreads over {spread} of the atlas: {us:?}"
        );
        for v in *tri {
            let p = out.positions[v as usize];
            let angle = (p[1].atan2(p[0]) / std::f32::consts::TAU).rem_euclid(1.0);
            let u = uv[v as usize][0];
            let off = (u - angle)
                .abs()
                .min((u - angle - 1.0).abs())
                .min((u - angle + 1.0).abs());
            assert!(off < 0.01, "u {u} at angle {angle}");
        }
    }
}

#[test]
fn adaptive_sizing_makes_short_edges_where_the_surface_bends() {
    // A flat square with a narrow bump in its middle.
    let mut patch = mesh::grid(60);
    for p in &mut patch.positions {
        let r2 = (p[0] - 0.5).powi(2) + (p[1] - 0.5).powi(2);
        p[2] = 0.15 * (-r2 / (2.0 * 0.06f32.powi(2))).exp();
    }
    let o = RemeshOptions {
        adaptive: Some(Adaptive::default()),
        feature_angle_deg: 180.0,
        ..opts(EdgeTarget::Length(0.08))
    };
    let (out, _) = remesh(&patch, &o).unwrap();
    assert_kept(&patch, &out);
    // Mean edge length near the bump's top and far out on the flat part.
    let (mut near, mut far) = ((0.0, 0), (0.0, 0));
    for t in &out.triangles {
        for k in 0..3 {
            let [a, b] = [t[k], t[(k + 1) % 3]].map(|v| out.positions[v as usize]);
            let len = (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f32>().sqrt() as f64;
            let r =
                (((a[0] + b[0]) / 2.0 - 0.5).powi(2) + ((a[1] + b[1]) / 2.0 - 0.5).powi(2)).sqrt();
            if r < 0.06 {
                near = (near.0 + len, near.1 + 1);
            } else if r > 0.3 {
                far = (far.0 + len, far.1 + 1);
            }
        }
    }
    let (near, far) = (near.0 / near.1 as f64, far.0 / far.1 as f64);
    assert!(near < 0.6 * far, "near the bump {near}, on the flat {far}");
    assert!(
        (far / 0.08 - 1.0).abs() < 0.25,
        "flat edges {far} for L = 0.08"
    );
    // Without it the same length everywhere (within the 4/5..4/3 band).
    let (out, _) = remesh(
        &patch,
        &RemeshOptions {
            adaptive: None,
            ..o
        },
    )
    .unwrap();
    assert!(farthest_vertex(&patch, &out) < 0.08);
}
