//! The topology report: what kind of surface a mesh is.
//!
//! Computed on the position-welded surface (vertices at the same point are one vertex), so that
//! attribute seams do not show up as false borders.

use super::{Aabb, Mesh, weld::position_classes};
use serde::Serialize;

/// Counts and measures describing a mesh's surface.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Topology {
    /// Vertices as stored (attribute seams split a point into several vertices).
    pub vertices: usize,
    /// Distinct positions used by at least one face.
    pub welded_vertices: usize,
    pub faces: usize,
    pub edges: usize,
    pub boundary_edges: usize,
    pub boundary_loops: usize,
    /// Edges shared by more than two faces.
    pub non_manifold_edges: usize,
    /// Vertices whose incident faces form more than one fan.
    pub non_manifold_vertices: usize,
    pub connected_components: usize,
    /// V - E + F over the welded surface.
    pub euler_characteristic: i64,
    /// Genus from Euler, components and boundary loops; `None` when the surface is not manifold.
    pub genus: Option<i64>,
    /// Manifold edges whose two faces traverse them in the same direction.
    pub inconsistently_oriented_edges: usize,
    /// Faces with a repeated vertex or zero area.
    pub degenerate_faces: usize,
    /// Faces using the same three vertices as an earlier face (in any order).
    pub duplicate_faces: usize,
    pub surface_area: f64,
    pub signed_volume: f64,
    pub bounds_min: [f32; 3],
    pub bounds_max: [f32; 3],
}

impl Topology {
    pub fn is_manifold(&self) -> bool {
        self.non_manifold_edges == 0 && self.non_manifold_vertices == 0
    }
    pub fn is_closed(&self) -> bool {
        self.boundary_edges == 0
    }
    pub fn is_consistently_oriented(&self) -> bool {
        self.inconsistently_oriented_edges == 0
    }
}

/// Union-find with path halving; small and local, so no crate for it.
pub(crate) struct Dsu(Vec<u32>);

impl Dsu {
    pub(crate) fn new(n: usize) -> Self {
        Dsu((0..n as u32).collect())
    }
    pub(crate) fn find(&mut self, mut x: u32) -> u32 {
        while self.0[x as usize] != x {
            let p = self.0[self.0[x as usize] as usize];
            self.0[x as usize] = p;
            x = p;
        }
        x
    }
    pub(crate) fn union(&mut self, a: u32, b: u32) {
        let (a, b) = (self.find(a), self.find(b));
        if a != b {
            // Lower id becomes the root, so results do not depend on the order of unions.
            let (lo, hi) = if a < b { (a, b) } else { (b, a) };
            self.0[hi as usize] = lo;
        }
    }
}

/// An undirected edge key with the lower vertex in the high bits, so sorting groups edges.
pub(crate) fn edge_key(a: u32, b: u32) -> u64 {
    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
    ((lo as u64) << 32) | hi as u64
}

/// Builds the topology report of `mesh`.
pub fn topology(mesh: &Mesh) -> Topology {
    let (class, _) = position_classes(&mesh.positions);
    let tris: Vec<[u32; 3]> = mesh
        .triangles
        .iter()
        .map(|t| t.map(|v| class[v as usize]))
        .collect();
    let nv = class.iter().copied().max().map_or(0, |m| m as usize + 1);
    let nf = tris.len();

    let mut used = vec![false; nv];
    let mut degenerate = 0;
    for (f, t) in tris.iter().enumerate() {
        for &v in t {
            used[v as usize] = true;
        }
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || mesh.face_area(f) == 0.0 {
            degenerate += 1;
        }
    }
    let welded_vertices = used.iter().filter(|&&u| u).count();

    let mut sorted: Vec<[u32; 3]> = tris
        .iter()
        .map(|t| {
            let mut s = *t;
            s.sort_unstable();
            s
        })
        .collect();
    sorted.sort_unstable();
    let duplicate_faces = sorted.windows(2).filter(|w| w[0] == w[1]).count();

    // Directed half-edges of non-degenerate corners, sorted by undirected key.
    let mut half: Vec<(u64, u32, bool)> = Vec::with_capacity(nf * 3);
    for (f, t) in tris.iter().enumerate() {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            if a != b {
                half.push((edge_key(a, b), f as u32, a < b));
            }
        }
    }
    half.sort_unstable();

    let mut edges = 0;
    let mut boundary_edges = 0;
    let mut non_manifold_edges = 0;
    let mut inconsistent = 0;
    let mut boundary_dsu = Dsu::new(nv);
    let mut on_boundary = vec![false; nv];
    // Corner union-find: corners of a vertex joined across manifold edges form its fans.
    let mut corner_dsu = Dsu::new(nf * 3);
    let corner = |f: u32, v: u32| -> u32 {
        let t = tris[f as usize];
        f * 3 + t.iter().position(|&x| x == v).unwrap_or(0) as u32
    };
    let mut i = 0;
    while i < half.len() {
        let mut j = i;
        while j < half.len() && half[j].0 == half[i].0 {
            j += 1;
        }
        edges += 1;
        let (a, b) = ((half[i].0 >> 32) as u32, half[i].0 as u32);
        match j - i {
            1 => {
                boundary_edges += 1;
                boundary_dsu.union(a, b);
                on_boundary[a as usize] = true;
                on_boundary[b as usize] = true;
            }
            2 => {
                let (f1, f2) = (half[i].1, half[i + 1].1);
                if half[i].2 == half[i + 1].2 {
                    inconsistent += 1;
                }
                corner_dsu.union(corner(f1, a), corner(f2, a));
                corner_dsu.union(corner(f1, b), corner(f2, b));
            }
            _ => non_manifold_edges += 1,
        }
        i = j;
    }

    let boundary_loops = (0..nv as u32)
        .filter(|&v| on_boundary[v as usize] && boundary_dsu.find(v) == v)
        .count();

    let mut fan_root = vec![u32::MAX; nv];
    let mut nm_vertex = vec![false; nv];
    for (f, t) in tris.iter().enumerate() {
        for (k, &v) in t.iter().enumerate() {
            let r = corner_dsu.find(f as u32 * 3 + k as u32);
            let slot = &mut fan_root[v as usize];
            if *slot == u32::MAX {
                *slot = r;
            } else if *slot != r {
                nm_vertex[v as usize] = true;
            }
        }
    }
    let non_manifold_vertices = nm_vertex.iter().filter(|&&x| x).count();

    let mut comp = Dsu::new(nv);
    for t in &tris {
        comp.union(t[0], t[1]);
        comp.union(t[1], t[2]);
    }
    let connected_components = (0..nv as u32)
        .filter(|&v| used[v as usize] && comp.find(v) == v)
        .count();

    let euler = welded_vertices as i64 - edges as i64 + nf as i64;
    let manifold = non_manifold_edges == 0 && non_manifold_vertices == 0;
    let genus =
        manifold.then(|| (2 * connected_components as i64 - euler - boundary_loops as i64) / 2);
    let b = mesh.bounds().unwrap_or(Aabb {
        min: [0.0; 3],
        max: [0.0; 3],
    });
    Topology {
        vertices: mesh.positions.len(),
        welded_vertices,
        faces: nf,
        edges,
        boundary_edges,
        boundary_loops,
        non_manifold_edges,
        non_manifold_vertices,
        connected_components,
        euler_characteristic: euler,
        genus,
        inconsistently_oriented_edges: inconsistent,
        degenerate_faces: degenerate,
        duplicate_faces,
        surface_area: mesh.surface_area(),
        signed_volume: mesh.signed_volume(),
        bounds_min: b.min,
        bounds_max: b.max,
    }
}
