//! Hand-built cases for each step of the remesher.

use glam::DVec3;

use super::halfedge::{HalfEdges, NONE};
use super::steps::Remesher;
use super::{RemeshOptions, features};
use crate::Mesh;
use crate::metrics::TriangleBvh;

fn flat(positions: &[[f32; 2]], triangles: Vec<[u32; 3]>) -> Mesh {
    Mesh::new(
        positions.iter().map(|p| [p[0], p[1], 0.0]).collect(),
        triangles,
    )
}

/// Runs `f` on a remesher of `m` with the flags of the default options at `length`.
fn with_remesher<T>(m: &Mesh, length: f64, f: impl FnOnce(&mut Remesher) -> T) -> T {
    let he = HalfEdges::from_mesh(m).unwrap();
    let (ef, vf) = features(&he, &RemeshOptions::default(), length, &[]);
    let surface = TriangleBvh::new(m);
    let lines = TriangleBvh::new(&super::feature_lines(&he, &ef, m));
    let mut r = Remesher::new(he, ef, vf, &surface, &lines, length, None);
    f(&mut r)
}

/// The half-edge structure's own invariants: twins, loops of three around faces, closed
/// border loops, and every live vertex's one-ring reaching back to it.
fn check(he: &HalfEdges) {
    for (f, &h) in he.fhe.iter().enumerate() {
        if h == NONE {
            continue;
        }
        let (n, p) = (he.next[h as usize], he.prev[h as usize]);
        assert_eq!(he.next[n as usize], p, "face {f} is not a triangle");
        for g in [h, n, p] {
            assert_eq!(he.face[g as usize], f as u32);
            assert!(!he.dead_edge[(g / 2) as usize]);
        }
    }
    for h in 0..he.to.len() as u32 {
        if he.dead_edge[(h / 2) as usize] {
            continue;
        }
        assert_eq!(he.prev[he.next[h as usize] as usize], h);
        assert_eq!(he.to[he.prev[h as usize] as usize], he.from(h));
        assert!(
            he.live_vertex(he.to[h as usize]),
            "half-edge {h} ends at a dead vertex"
        );
    }
    for v in 0..he.pos.len() as u32 {
        he.for_out(v, |g| assert_eq!(he.from(g), v));
    }
}

fn valence_deviation(he: &HalfEdges) -> i32 {
    (0..he.pos.len() as u32)
        .filter(|&v| he.live_vertex(v))
        .map(|v| {
            let target = if he.is_border_vertex(v) { 4 } else { 6 };
            (he.valence(v) as i32 - target).abs()
        })
        .sum()
}

#[test]
fn a_long_edge_is_split_in_two() {
    // A unit square cut by its diagonal (length 1.41): with 4/3 L = 1.33 only the diagonal is
    // too long, and splitting it at its midpoint leaves four faces round the centre.
    let m = flat(
        &[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
        vec![[0, 1, 2], [0, 2, 3]],
    );
    with_remesher(&m, 1.0, |r| {
        assert_eq!(r.split_long(4.0 / 3.0), 1);
        check(&r.he);
        let out = r.he.to_mesh();
        assert_eq!((out.vertex_count(), out.face_count()), (5, 4));
        assert_eq!(out.positions[4], [0.5, 0.5, 0.0]);
        assert!(out.triangles.iter().all(|t| t.contains(&4)));
        let t = crate::mesh::topology(&out);
        assert_eq!((t.euler_characteristic, t.boundary_loops), (1, 1));
        assert_eq!(t.inconsistently_oriented_edges, 0);
    });
}

#[test]
fn a_short_edge_is_collapsed() {
    // A hexagon fan round the origin whose centre is pulled next to one rim vertex: the
    // spoke between them (0.1) is the one edge under 4/5 L; the centre goes, the rim stays.
    // (The longest edge it makes, to the far rim vertex, is 2: the upper bound is 2.5 here.)
    let mut pos: Vec<[f32; 2]> = (0..6)
        .map(|k| {
            let a = k as f32 * std::f32::consts::PI / 3.0;
            [a.cos(), a.sin()]
        })
        .collect();
    pos.push([0.9, 0.0]);
    let tris = (0..6).map(|k| [6, k, (k + 1) % 6]).collect();
    let m = flat(&pos, tris);
    with_remesher(&m, 1.0, |r| {
        assert_eq!(r.collapse_short(0.8, 2.5), 1);
        check(&r.he);
        assert!(!r.he.live_vertex(6));
        let out = r.he.to_mesh();
        assert_eq!((out.vertex_count(), out.face_count()), (6, 4));
        let t = crate::mesh::topology(&out);
        assert_eq!((t.euler_characteristic, t.boundary_loops), (1, 1));
        assert_eq!(t.inconsistently_oriented_edges, 0);
        assert_eq!(t.degenerate_faces, 0);
    });
}

#[test]
fn a_collapse_that_would_pinch_the_surface_is_refused() {
    // Two triangles sharing one edge whose ends are both on the border: removing it would
    // join two border vertices through the inside.
    let m = flat(
        &[[0.0, 0.0], [0.1, 0.0], [0.05, 1.0], [0.05, -1.0]],
        vec![[0, 1, 2], [1, 0, 3]],
    );
    with_remesher(&m, 1.0, |r| {
        let mut mark = Vec::new();
        // Edge (0, 1) is inside; both its ends are on the border.
        let e = (0..r.he.edge_count() as u32)
            .find(|&e| {
                let (a, b) = (r.he.from(2 * e), r.he.to[2 * e as usize]);
                (a.min(b), a.max(b)) == (0, 1)
            })
            .unwrap();
        assert!(!r.he.can_collapse(2 * e, &mut mark, 1));
        assert!(!r.he.can_collapse(2 * e + 1, &mut mark, 2));
    });
}

#[test]
fn flips_raise_valence_regularity() {
    // The generated grid alternates its diagonals: inner vertices of valence 4 and 8. Flips
    // towards 6 (4 on the border) must lower the total deviation and keep the mesh valid.
    let m = crate::mesh::grid(8);
    with_remesher(&m, 1.0 / 8.0, |r| {
        let before = valence_deviation(&r.he);
        let flips = r.flip_towards_regular();
        check(&r.he);
        let after = valence_deviation(&r.he);
        assert!(
            flips > 0 && after < before,
            "{flips} flips: {before} -> {after}"
        );
        let out = r.he.to_mesh();
        let t = crate::mesh::topology(&out);
        assert_eq!((t.faces, t.euler_characteristic), (m.face_count(), 1));
        assert_eq!(
            (t.inconsistently_oriented_edges, t.degenerate_faces),
            (0, 0)
        );
        // A flat grid: every face still faces +z.
        for tri in &out.triangles {
            let [a, b, c] =
                tri.map(|v| DVec3::from_array(out.positions[v as usize].map(f64::from)));
            assert!((b - a).cross(c - a).z > 0.0);
        }
    });
}

#[test]
fn building_refuses_what_is_not_a_manifold() {
    // Three faces on one edge.
    let fin = Mesh::new(
        vec![
            [0.0; 3],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
        ],
        vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]],
    );
    let e = HalfEdges::from_mesh(&fin).unwrap_err().to_string();
    assert!(e.contains("(0, 1) has 3 faces"), "{e}");
    // Two faces traversing their shared edge the same way.
    let flipped = Mesh::new(
        vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0]],
        vec![[0, 1, 2], [0, 1, 3]],
    );
    let e = HalfEdges::from_mesh(&flipped).unwrap_err().to_string();
    assert!(e.contains("not consistently oriented"), "{e}");
    // Two fans meeting at vertex 0 (a bow tie).
    let bowtie = Mesh::new(
        vec![
            [0.0; 3],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [-1.0, 0.0, 0.0],
            [-1.0, -1.0, 0.0],
        ],
        vec![[0, 1, 2], [0, 3, 4]],
    );
    let e = HalfEdges::from_mesh(&bowtie).unwrap_err().to_string();
    assert!(e.contains("vertex 0 joins several fans"), "{e}");
}
