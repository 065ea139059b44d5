//! The Metro distance and the other comparison figures on cases with known answers.

use meshslim::Mesh;
use meshslim::mesh::{self, icosphere};
use meshslim::metrics::{CompareOptions, Comparison, ValenceBin, compare};

fn translated(m: &Mesh, d: [f32; 3]) -> Mesh {
    let mut t = m.clone();
    for p in &mut t.positions {
        for k in 0..3 {
            p[k] += d[k];
        }
    }
    t
}

fn close(x: f64, want: f64, tol: f64) -> bool {
    (x - want).abs() <= tol
}

#[test]
fn a_mesh_against_itself_is_zero() {
    let m = mesh::torus(1.0, 0.3, 32, 16);
    let c = compare(&m, &m, &CompareOptions::default()).unwrap();
    let d = &c.distance;
    // Zero up to the rounding of a sample projected back onto its own face (~1e-16).
    for s in [&d.a_to_b, &d.b_to_a] {
        assert!(s.distances.max_rel < 1e-12, "{s:?}");
        assert!(s.distances.mean_rel < 1e-12, "{s:?}");
        assert!(s.distances.rms_rel < 1e-12, "{s:?}");
        assert_eq!(
            s.face_samples,
            (10 * m.face_count()).max(meshslim::metrics::MIN_FACE_SAMPLES)
        );
        assert_eq!(s.vertex_samples, m.vertex_count());
        // At least the midpoint of each of the 3F/2 edges.
        assert!(s.edge_samples >= 3 * m.face_count() / 2, "{s:?}");
    }
    assert!(d.two_sided.max_rel < 1e-12);
    assert_eq!(c.area.relative, Some(0.0));
    assert_eq!(c.volume.relative, Some(0.0));
    assert!(c.topology.unchanged());
    assert_eq!(c.topology.difference.euler_characteristic, 0);
    assert_eq!(c.topology.genus_a, Some(1));
}

#[test]
fn a_flat_grid_lifted_along_its_normal_is_exactly_that_far() {
    // Every point of the open unit square lifted by d lies right above a point of the square,
    // so every distance is d, in both directions.
    let d = 0.0625f32; // a power of two: the lifted positions are exact
    let a = mesh::grid(20);
    let b = translated(&a, [0.0, 0.0, d]);
    let c = compare(&a, &b, &CompareOptions::default()).unwrap();
    let diag = a.bounds().unwrap().diagonal();
    for s in [&c.distance.a_to_b, &c.distance.b_to_a] {
        assert!(close(s.distances.max, d as f64, 1e-12), "{s:?}");
        assert!(close(s.distances.mean, d as f64, 1e-12), "{s:?}");
        assert!(close(s.distances.rms, d as f64, 1e-12), "{s:?}");
        assert!(close(s.distances.max_rel, d as f64 / diag, 1e-12), "{s:?}");
    }
    assert!(close(c.distance.two_sided.mean, d as f64, 1e-12));
    assert!(close(c.area.relative.unwrap(), 0.0, 1e-12));
}

#[test]
fn sphere_against_inscribed_icosphere_has_the_known_gap() {
    // A: a fine icosphere standing in for the unit sphere; B: a coarse one inscribed in it.
    // Every point of the sphere is within 1 − r_min of B, r_min being the smallest distance
    // from the centre to a face plane of B (its vertices are on the sphere, so the gap is
    // largest above the face centres, and the fine sphere lies inside the unit ball): the max
    // is at most 1 − r_min and reaches it up to how close A's samples come to those points.
    let fine = icosphere(6);
    let coarse = icosphere(1);
    let r_min = (0..coarse.face_count())
        .map(|f| {
            let n = coarse.face_normal(f).unwrap();
            let p = coarse.positions[coarse.triangles[f][0] as usize].map(|c| c as f64);
            (n[0] * p[0] + n[1] * p[1] + n[2] * p[2]).abs()
        })
        .fold(f64::INFINITY, f64::min);
    let gap = 1.0 - r_min;
    let c = compare(&fine, &coarse, &CompareOptions::default()).unwrap();
    let ab = &c.distance.a_to_b;
    assert!(
        ab.distances.max <= gap + 1e-6,
        "{} > {gap}",
        ab.distances.max
    );
    // The fine sphere has a vertex within ~0.02 rad of each coarse face centre's direction:
    // its distance falls short of the gap by ~θ²/2 ≈ 2e-4, 0.1% of the gap.
    assert!(
        ab.distances.max >= 0.99 * gap,
        "{} vs {gap}",
        ab.distances.max
    );
    assert!(
        ab.distances.mean > 0.2 * gap && ab.distances.mean < gap,
        "{} vs {gap}",
        ab.distances.mean
    );
    // Every point of B is inside the unit sphere and outside the fine sphere's inscribed ball.
    assert!(c.distance.b_to_a.distances.max <= gap + 1e-6);
    assert!(c.volume.relative.unwrap() < 0.0, "B is inside A");
}

#[test]
fn a_small_patch_is_close_to_a_big_grid_but_not_the_other_way() {
    // A: the unit square. B: its corner [0, 0.25]², same plane. B → A is zero; A → B is as
    // far as the opposite corner (1, 1) from (0.25, 0.25).
    let a = mesh::grid(16);
    let mut b = mesh::grid(4);
    for p in &mut b.positions {
        p[0] *= 0.25;
        p[1] *= 0.25;
    }
    let c = compare(&a, &b, &CompareOptions::default()).unwrap();
    let far = (2.0f64 * 0.75 * 0.75).sqrt();
    assert!(close(c.distance.a_to_b.distances.max, far, 1e-6), "{c:?}");
    assert!(
        c.distance.a_to_b.distances.mean > 0.3,
        "{:?}",
        c.distance.a_to_b
    );
    assert!(
        c.distance.b_to_a.distances.max < 1e-12,
        "{:?}",
        c.distance.b_to_a
    );
    assert!(
        c.distance.b_to_a.distances.mean < 1e-12,
        "{:?}",
        c.distance.b_to_a
    );
    assert_eq!(c.distance.two_sided.max, c.distance.a_to_b.distances.max);
    assert!(close(c.area.relative.unwrap(), 0.0625 - 1.0, 1e-9));
}

/// Two triangles (a square) spanning `[-5, 5]²` in the plane `axis = at`.
fn wall(axis: usize, at: f32, m: &mut Mesh) {
    let base = m.positions.len() as u32;
    for (u, v) in [(-5.0, -5.0), (5.0, -5.0), (5.0, 5.0), (-5.0, 5.0)] {
        let mut p = [0.0f32; 3];
        p[axis] = at;
        p[(axis + 1) % 3] = u;
        p[(axis + 2) % 3] = v;
        m.positions.push(p);
    }
    m.triangles.push([base, base + 1, base + 2]);
    m.triangles.push([base, base + 2, base + 3]);
}

#[test]
fn a_maximum_inside_an_edge_is_found() {
    // B: one triangle (0,0,0), (1,0,0), (0.5,-1,0). A: the walls x = -0.1, x = 1.33 and
    // y = -0.715. The distance from (x, y, 0) in B to A is min(x + 0.1, |1.33 - x|, |y + 0.715|),
    // largest (0.715) at (0.615, 0, 0) only: inside the edge y = 0, 61.5% along it, neither at a
    // vertex (0.1 and 0.33 there) nor at its midpoint (0.6), nor at one of the evenly spaced
    // points the face-sample spacing asks for (t = 0.2, 0.4, ...; 0.7 at t = 0.6).
    let b = Mesh::new(
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, -1.0, 0.0]],
        vec![[0, 1, 2]],
    );
    let mut a = Mesh::default();
    wall(0, -0.1, &mut a);
    wall(0, 1.33, &mut a);
    wall(1, -0.715, &mut a);
    let want = 0.715f64;
    for seed in [1, 2, 3] {
        // Ten face samples: 0.22 apart, so the edge gets evenly spaced points at t = 0.2, 0.4,
        // ... (0.7 at t = 0.6), and the refinement has to find the rest.
        let opts = CompareOptions {
            samples: Some(10),
            seed,
            ..Default::default()
        };
        let c = compare(&a, &b, &opts).unwrap();
        let ba = &c.distance.b_to_a;
        assert!(
            ba.distances.max <= want + 1e-6,
            "above the true maximum: {ba:?}"
        );
        assert!(
            ba.distances.max >= want * (1.0 - 2e-3),
            "{} vs {want}: {ba:?}",
            ba.distances.max
        );
        // Without the edges the maximum is missed by far.
        let faces_only = CompareOptions {
            vertices_and_edges: false,
            ..opts
        };
        let f = compare(&a, &b, &faces_only).unwrap();
        assert!(
            f.distance.b_to_a.distances.max < 0.71,
            "{:?}",
            f.distance.b_to_a
        );
    }
}

fn noisy_pair() -> (Mesh, Mesh) {
    (
        mesh::noisy_sphere(4, 0.01, 3),
        mesh::noisy_sphere(2, 0.02, 4),
    )
}

#[test]
fn the_same_seed_gives_the_same_figures_and_another_seed_other_samples() {
    let (a, b) = noisy_pair();
    let opts = CompareOptions {
        samples: Some(20_000),
        seed: 9,
        ..Default::default()
    };
    let c1 = compare(&a, &b, &opts).unwrap();
    let c2 = compare(&a, &b, &opts).unwrap();
    assert_eq!(c1, c2);
    assert_eq!(c1.distance.a_to_b.face_samples, 20_000);
    let c3 = compare(&a, &b, &CompareOptions { seed: 10, ..opts }).unwrap();
    assert_ne!(
        c1.distance.a_to_b.distances.mean,
        c3.distance.a_to_b.distances.mean
    );
    // ... but estimates of the same mean.
    let (m1, m3) = (
        c1.distance.a_to_b.distances.mean,
        c3.distance.a_to_b.distances.mean,
    );
    assert!((m1 - m3).abs() < 0.02 * m1, "{m1} vs {m3}");
}

#[test]
fn the_figures_do_not_depend_on_the_thread_count() {
    let (a, b) = noisy_pair();
    // Enough samples for several parallel chunks.
    let opts = CompareOptions {
        samples: Some(50_000),
        ..Default::default()
    };
    let run = |threads: usize| -> Comparison {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| compare(&a, &b, &opts).unwrap())
    };
    let one = run(1);
    let four = run(4);
    assert_eq!(one, four);
    assert_eq!(
        one.distance.a_to_b.distances.mean.to_bits(),
        four.distance.a_to_b.distances.mean.to_bits()
    );
}

#[test]
fn triangle_quality_and_topology_of_a_simplified_mesh() {
    let a = mesh::grid(10);
    // Drop two faces: a hole, so one more boundary loop and two fewer faces in Euler.
    let mut b = a.clone();
    b.triangles.drain(90..92);
    let c = compare(&a, &b, &CompareOptions::default()).unwrap();
    let q = &c.quality_b;
    // Grid triangles are right isosceles: 45 degrees, aspect (1 + sqrt 2) / 2 ≈ 1.21.
    assert!(close(q.min_angle_deg, 45.0, 1e-4), "{q:?}");
    assert_eq!(q.aspect_ratio_histogram[0].count, b.face_count());
    assert_eq!(q.aspect_ratio_histogram.last().unwrap().upper, None);
    assert_eq!(q.degenerate_faces, 0);
    assert_eq!((q.share_under_30_deg, q.share_under_10_deg), (0.0, 0.0));
    // The grid alternates its diagonals, so an inner vertex with i + j even meets eight edges
    // and one with i + j odd meets four (41 and 40 of the 9 × 9). The hole (cell i = 5, j = 4)
    // drops only its diagonal, between two even corners: they become border vertices of
    // valence 7, its two odd corners border vertices of valence 4. The four corners have
    // valence 3 and the 36 side vertices alternate 3 and 5. Only those two valence-4 border
    // vertices are regular.
    let bin = |valence, interior, border| ValenceBin {
        valence,
        interior,
        border,
    };
    assert_eq!(
        q.valence_histogram,
        [
            bin(3, 0, 24),
            bin(4, 38, 2),
            bin(5, 0, 16),
            bin(7, 0, 2),
            bin(8, 39, 0)
        ]
    );
    assert!(close(q.regular_valence_share, 2.0 / 121.0, 1e-12), "{q:?}");
    let t = &c.topology;
    assert_eq!(t.a.boundary_loops, 1);
    assert_eq!(t.difference.boundary_loops, 1, "{t:?}");
    assert_eq!(t.difference.euler_characteristic, -1, "{t:?}");
    assert!(!t.unchanged());
}

#[test]
fn empty_meshes_are_refused() {
    let a = mesh::grid(2);
    let err = compare(&a, &Mesh::default(), &CompareOptions::default()).unwrap_err();
    assert!(err.to_string().contains("mesh B has no faces"), "{err}");
    let zero = CompareOptions {
        samples: Some(0),
        ..Default::default()
    };
    assert!(compare(&a, &a, &zero).is_err());
}

/// An icosphere painted by height (red rising with z) with its unit normals.
fn painted_sphere(level: u32) -> Mesh {
    let mut m = icosphere(level);
    m.colors = Some(
        m.positions
            .iter()
            .map(|p| [0.5 + 0.4 * p[2], 0.2, 0.7, 1.0])
            .collect(),
    );
    m.normals = Some(
        m.positions
            .iter()
            .map(|p| {
                let l = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
                p.map(|c| c / l)
            })
            .collect(),
    );
    m
}

/// The colour and normal differences, at the distance's samples: none against itself; a
/// colour shifted by 0.1 in one channel is 0.1 off everywhere; normals turned around are 180
/// degrees off; a mesh without colours has no colour figure, and one with no attribute the
/// other has, no appearance at all (nor an `appearance` key in the JSON).
#[test]
fn appearance_measures_colour_and_normal_differences() {
    let a = painted_sphere(3);
    let same = compare(&a, &a, &CompareOptions::default()).unwrap();
    let look = same
        .appearance
        .as_ref()
        .expect("both have colours and normals");
    let (c, n) = (
        look.color.as_ref().unwrap(),
        look.normal_deg.as_ref().unwrap(),
    );
    assert!(c.max < 1e-6 && n.max < 1e-3, "{look:?}");

    let mut shifted = a.clone();
    for c in shifted.colors.as_mut().unwrap() {
        c[1] += 0.1;
    }
    for n in shifted.normals.as_mut().unwrap() {
        *n = n.map(|x| -x);
    }
    let diff = compare(&a, &shifted, &CompareOptions::default()).unwrap();
    let look = diff.appearance.unwrap();
    let c = look.color.unwrap();
    assert!(close(c.mean, 0.1, 1e-5) && close(c.max, 0.1, 1e-5), "{c:?}");
    assert!(close(c.a_to_b_mean, c.b_to_a_mean, 1e-6), "{c:?}");
    let n = look.normal_deg.unwrap();
    assert!(n.mean > 179.9, "{n:?}");

    // A coarser painted sphere: colour error grows with the gradient lost between vertices.
    let coarse = compare(&a, &painted_sphere(1), &CompareOptions::default()).unwrap();
    let c = coarse.appearance.unwrap().color.unwrap();
    assert!(c.mean > 1e-4 && c.mean < 0.05, "{c:?}");

    let mut plain = a.clone();
    plain.colors = None;
    let look = compare(&a, &plain, &CompareOptions::default())
        .unwrap()
        .appearance
        .unwrap();
    assert!(look.color.is_none() && look.normal_deg.is_some());
    plain.normals = None;
    let none = compare(&a, &plain, &CompareOptions::default()).unwrap();
    assert!(none.appearance.is_none());
    let json = serde_json::to_value(&none).unwrap();
    assert!(json.get("appearance").is_none(), "{json}");
}
