//! The per-vertex passes of the set-up ([`Prepared::build`](super::prepare::Prepared::build)),
//! each over the welded faces and the faces around each vertex: the reference normals and
//! planes, the quadrics with their border and seam constraints and each vertex's mobility,
//! then the appearance attributes' terms.

use super::vec::{cross, dot, norm, sub};
use crate::mesh::Mesh;
use crate::options::SimplifyOptions;
use crate::quadric::Quadric;
use crate::quadric::attributes::{Attributes, FaceTerms, Layout, MAX_STRIDE};
use rayon::prelude::*;

/// The welded faces over the normalized positions, which every pass of the set-up reads.
#[derive(Clone, Copy)]
pub(super) struct Geometry<'a> {
    pub(super) topo: &'a [u32],
    pub(super) faces: &'a [[u32; 3]],
    pub(super) pos: &'a [[f64; 3]],
}

impl Geometry<'_> {
    /// The topological vertices of a face given by its attribute vertices.
    #[inline]
    fn topo_face(&self, f: &[u32; 3]) -> [u32; 3] {
        f.map(|v| self.topo[v as usize])
    }

    /// The positions of face `f`'s corners.
    #[inline]
    fn corners(&self, f: usize) -> [[f64; 3]; 3] {
        self.topo_face(&self.faces[f]).map(|v| self.pos[v as usize])
    }

    /// Face `f`'s plane: its unit normal, offset and twice its area, no area for a face
    /// without a normal.
    fn plane(&self, f: usize) -> [f64; 5] {
        let [p0, p1, p2] = self.corners(f);
        let c = cross(sub(p1, p0), sub(p2, p0));
        let len = norm(c);
        if len > 0.0 {
            let n = c.map(|x| x / len);
            [n[0], n[1], n[2], -dot(n, p0), len]
        } else {
            [0.0; 5]
        }
    }

    /// Face `f`'s unit normal, or its zero cross product for a face without area.
    fn unit_normal(&self, f: usize) -> [f64; 3] {
        let [p0, p1, p2] = self.corners(f);
        let c = cross(sub(p1, p0), sub(p2, p0));
        let l = norm(c);
        if l > 0.0 { c.map(|x| x / l) } else { c }
    }

    /// Every face's reference normal (its own, or the original face's under a carried one) and
    /// plane, in parallel.
    pub(super) fn planes_and_normals(
        &self,
        face_origin: &[u32],
        carried: Option<&Carried>,
    ) -> (Vec<[f32; 3]>, Vec<[f64; 5]>) {
        (0..self.faces.len())
            .into_par_iter()
            .map(|f| {
                let plane = self.plane(f);
                let own = (plane[4] > 0.0).then(|| [0, 1, 2].map(|k| plane[k] as f32));
                // The original face under a carried one, as the rounds' upload takes it.
                let under = carried.and_then(|c| c.normals.get(face_origin[f] as usize));
                let normal = match (own, under) {
                    (Some(_), Some(&n)) if n != [0.0; 3] => n,
                    (own, _) => own.unwrap_or([0.0; 3]),
                };
                (normal, plane)
            })
            .unzip()
    }
}

/// The set-up's geometry with the faces around each topological vertex: `corners` (face
/// corners `3 f + k`) grouped by vertex, vertex `v`'s from `corner_start[v]`.
#[derive(Clone, Copy)]
pub(super) struct Around<'a> {
    pub(super) geo: Geometry<'a>,
    pub(super) corners: &'a [u32],
    pub(super) corner_start: &'a [u32],
}

impl Around<'_> {
    /// The faces around vertex `v`, in face order.
    #[inline]
    fn faces_of(&self, v: usize) -> impl ExactSizeIterator<Item = u32> + '_ {
        self.corners[self.corner_start[v] as usize..self.corner_start[v + 1] as usize]
            .iter()
            .map(|&c| c / 3)
    }

    /// The face at place `i` (the low half of a packed edge) among `v`'s faces.
    #[inline]
    fn face_at(&self, v: usize, i: u64) -> u32 {
        self.corners[self.corner_start[v] as usize + i as u32 as usize] / 3
    }

    /// The appearance attributes' part of the set-up: per vertex, in parallel and in face
    /// order like the geometric part, each face's attribute functions folded into the
    /// vertex's quadric and added to the sums of the attribute vertex the face uses there (a
    /// seam vertex has one per side).
    pub(super) fn fold_attributes(
        &self,
        mesh: &Mesh,
        layout: Layout,
        quadrics: &mut [Quadric],
    ) -> Attributes {
        let mut at = Attributes::new(mesh, layout);
        let stride = at.layout.stride();
        let nt = quadrics.len();
        // In place, per vertex: the folded terms straight into its quadric, the first side's
        // sums into a row of its own (scattered to the attribute vertices after), further
        // sides (seams only) in a list, so most vertices allocate and copy nothing; collecting
        // 400-byte tuples per vertex was mostly memcpy.
        let mut first_sums = vec![0.0f64; nt * stride];
        let mut first_id = vec![u32::MAX; nt];
        let extra: Vec<Vec<(u32, [f64; MAX_STRIDE])>> = quadrics
            .par_iter_mut()
            .zip(first_sums.par_chunks_mut(stride))
            .zip(first_id.par_iter_mut())
            .enumerate()
            .map(|(v, ((q, first), first_av))| self.attribute_sides(&at, v, q, first, first_av))
            .collect();
        for (v, sides) in extra.into_iter().enumerate() {
            let av = first_id[v];
            if av != u32::MAX {
                at.sums[av as usize * stride..(av as usize + 1) * stride]
                    .copy_from_slice(&first_sums[v * stride..(v + 1) * stride]);
            }
            for (av, s) in sides {
                let at_v = av as usize * stride;
                at.sums[at_v..at_v + stride].copy_from_slice(&s[..stride]);
            }
        }
        at
    }

    /// Vertex `v`'s attribute terms: folded into `q`, the first attribute vertex's sums into
    /// `first` (its id into `first_av`); returns the sums of its further sides (seams only).
    fn attribute_sides(
        &self,
        at: &Attributes,
        v: usize,
        q: &mut Quadric,
        first: &mut [f64],
        first_av: &mut u32,
    ) -> Vec<(u32, [f64; MAX_STRIDE])> {
        let (faces, stride) = (self.geo.faces, at.layout.stride());
        let mut sides: Vec<(u32, [f64; MAX_STRIDE])> = Vec::new();
        let mut ft = FaceTerms::default();
        for f in self.faces_of(v) {
            let f = f as usize;
            let t = self.geo.topo_face(&faces[f]);
            let p = t.map(|u| self.geo.pos[u as usize]);
            let area = 0.5 * norm(cross(sub(p[1], p[0]), sub(p[2], p[0])));
            if !ft.set(&at.layout, p, faces[f].map(|a| at.values(a))) {
                continue;
            }
            ft.fold_into(q, area);
            let av = faces[f][t.iter().position(|&u| u == v as u32).unwrap_or(0)];
            if *first_av == u32::MAX {
                *first_av = av;
            }
            if *first_av == av {
                ft.add_to(first, area);
            } else {
                let i = match sides.iter().position(|s| s.0 == av) {
                    Some(i) => i,
                    None => {
                        sides.push((av, [0.0; MAX_STRIDE]));
                        sides.len() - 1
                    }
                };
                ft.add_to(&mut sides[i].1[..stride], area);
            }
        }
        sides
    }
}

/// The per-vertex pass of the set-up: each vertex's quadric (its faces' planes, then the
/// constraint planes of its border and seam edges) and how it may move.
pub(super) struct VertexPass<'a> {
    pub(super) around: Around<'a>,
    /// Each face's plane (see [`Geometry::plane`]).
    pub(super) planes: &'a [[f64; 5]],
    /// Attribute vertices per topological vertex.
    pub(super) attr_count: &'a [u32],
    pub(super) opts: &'a SimplifyOptions,
}

impl VertexPass<'_> {
    /// Every vertex's quadric, mobility and border flag, in parallel.
    ///
    /// Per vertex: the sum of its faces' plane quadrics in face order, then the constraint
    /// planes of its border and seam edges in ascending order of the other end, which is the
    /// order one pass over all edges sorted by (low, high) end gives each vertex; so the sums
    /// do not depend on the thread count. Each face's plane is read from the reference
    /// normals' pass (40 bytes a face) and its quadric made per vertex: cheaper than one
    /// 88-byte quadric per face written out and read back, and than the plane worked out
    /// again at each corner. Each constraint is computed once per vertex that needs it.
    /// Straight into the three arrays, without collecting tuples and copying them out.
    pub(super) fn quadrics_and_mobility(
        &self,
        nt: usize,
    ) -> (Vec<Quadric>, (Vec<Mobility>, Vec<bool>)) {
        let seamless = !self.attr_count.par_iter().any(|&c| c > 1);
        (0..nt)
            .into_par_iter()
            .map_init(
                || (Vec::new(), Vec::new()),
                |(edges, fan): &mut (Vec<u64>, Vec<u32>), v| self.vertex(v, seamless, edges, fan),
            )
            .unzip()
    }

    /// Vertex `v`'s quadric, mobility and border flag; `edges` and `fan` are scratch space.
    fn vertex(
        &self,
        v: usize,
        seamless: bool,
        edges: &mut Vec<u64>,
        fan: &mut Vec<u32>,
    ) -> (Quadric, (Mobility, bool)) {
        let mut q = self.face_quadric(v);
        // Most vertices are inside a surface without seams: their edges need no sorting,
        // since they add no constraint plane.
        if seamless {
            let geo = self.around.geo;
            let around = self
                .around
                .faces_of(v)
                .map(|f| geo.topo_face(&geo.faces[f as usize]));
            if let Some(fans) = interior_fans(around, v as u32, fan) {
                let mobility = if fans > 1 {
                    Mobility::Pinned
                } else {
                    Mobility::Free
                };
                return (q, (mobility, false));
            }
        }
        let mut mobility = if self.attr_count[v] > 1 {
            Mobility::Seam
        } else {
            Mobility::Free
        };
        self.sorted_edges(v, edges);
        let border = self.edge_constraints(v, edges, fan, &mut q, &mut mobility);
        // A vertex whose faces form more than one fan (a bow-tie) is pinned: collapsing
        // around it cannot keep the surface's topology well defined.
        if fan_count(fan) > 1 {
            mobility = Mobility::Pinned;
        }
        if self.opts.lock_border && border {
            mobility = match mobility {
                Mobility::Free => Mobility::LockedBorder,
                _ => Mobility::Pinned,
            };
        }
        (q, (mobility, border))
    }

    /// The sum of the plane quadrics of `v`'s faces, in face order.
    fn face_quadric(&self, v: usize) -> Quadric {
        let mut q = Quadric::default();
        for f in self.around.faces_of(v) {
            let [n0, n1, n2, d, len] = self.planes[f as usize];
            if len > 0.0 {
                q.add(&Quadric::from_plane([n0, n1, n2], d, 0.5 * len));
            }
        }
        q
    }

    /// Into `edges`, sorted: the edges at `v`, each with the place of its face among `v`'s
    /// faces (so in face order within an edge): 1 face for a border, 2 for a manifold edge,
    /// more for a non-manifold one. Packed `other end << 32 | place` and sorted as one
    /// integer: the order of (other end, face, place) triples, since the places follow the
    /// faces.
    fn sorted_edges(&self, v: usize, edges: &mut Vec<u64>) {
        let geo = self.around.geo;
        let vt = v as u32;
        edges.clear();
        for (i, f) in self.around.faces_of(v).enumerate() {
            let t = geo.topo_face(&geo.faces[f as usize]);
            edges.extend(
                t.into_iter()
                    .filter(|&u| u != vt)
                    .map(|u| (u as u64) << 32 | i as u64),
            );
        }
        edges.sort_unstable();
    }

    /// Walks `v`'s sorted `edges`: adds the constraint planes of its border and seam edges to
    /// `q`, pins it at a non-manifold edge, and joins its faces across its manifold edges into
    /// the fans around it (`fan`). Returns whether `v` is on a border.
    fn edge_constraints(
        &self,
        v: usize,
        edges: &[u64],
        fan: &mut Vec<u32>,
        q: &mut Quadric,
        mobility: &mut Mobility,
    ) -> bool {
        let (vt, pos) = (v as u32, self.around.geo.pos);
        let mut border = false;
        fan.clear();
        fan.extend(0..self.around.faces_of(v).len() as u32);
        let mut i = 0;
        while i < edges.len() {
            let mut j = i + 1;
            while j < edges.len() && edges[j] >> 32 == edges[i] >> 32 {
                j += 1;
            }
            let u = (edges[i] >> 32) as u32;
            let (a, b) = (vt.min(u), vt.max(u));
            let (pa, pb) = (pos[a as usize], pos[b as usize]);
            match j - i {
                1 => {
                    border = true;
                    if let Some(c) =
                        self.border_constraint(self.around.face_at(v, edges[i]), pa, pb)
                    {
                        q.add(&c);
                    }
                }
                2 => {
                    let f1 = self.around.face_at(v, edges[i]);
                    let f2 = self.around.face_at(v, edges[i + 1]);
                    join(fan, edges[i] as u32, edges[i + 1] as u32);
                    if let Some(c) = self.seam_constraint(f1, f2, a, b) {
                        q.add(&c);
                    }
                }
                _ => *mobility = Mobility::Pinned,
            }
            i = j;
        }
        border
    }

    /// Hoppe's boundary constraint for border edge (pa, pb) of face `f`: a plane through the
    /// edge, perpendicular to its face, weighted by the squared edge length so it scales like
    /// an area.
    fn border_constraint(&self, f: u32, pa: [f64; 3], pb: [f64; 3]) -> Option<Quadric> {
        let [p0, p1, p2] = self.around.geo.corners(f as usize);
        let fnrm = cross(sub(p1, p0), sub(p2, p0));
        edge_constraint(pa, pb, fnrm, self.opts.border_weight)
    }

    /// A seam edge (a, b) between faces `f1` and `f2` (the faces disagree on an endpoint's
    /// attribute vertex) gets a constraint plane like a border, so the seam keeps its course;
    /// `None` for an edge that is no seam.
    fn seam_constraint(&self, f1: u32, f2: u32, a: u32, b: u32) -> Option<Quadric> {
        let geo = self.around.geo;
        let attr = |fi: u32, x: u32| {
            let t = geo.topo_face(&geo.faces[fi as usize]);
            geo.faces[fi as usize][t.iter().position(|&y| y == x).unwrap_or(0)]
        };
        // Only a seam vertex (more than one attribute vertex) can disagree, so the four
        // lookups are skipped for the others.
        let seam_end = self.attr_count[a as usize] > 1 || self.attr_count[b as usize] > 1;
        if seam_end
            && (attr(f1, a) != attr(f2, a) || attr(f1, b) != attr(f2, b))
            && self.opts.border_weight > 0.0
        {
            let (n1, n2) = (geo.unit_normal(f1 as usize), geo.unit_normal(f2 as usize));
            let avg = [0, 1, 2].map(|k| n1[k] + n2[k]);
            let (pa, pb) = (geo.pos[a as usize], geo.pos[b as usize]);
            edge_constraint(pa, pb, avg, self.opts.border_weight)
        } else {
            None
        }
    }
}

/// How a vertex may take part in collapses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Mobility {
    /// May move and may be removed.
    Free,
    /// Keeps its position; may survive a collapse, never be removed: attribute seams and
    /// non-manifold spots.
    Pinned,
    /// A border vertex under `lock_border`: keeps its position, and may be removed only by sliding
    /// along a straight stretch of border onto a border neighbour.
    LockedBorder,
    /// On an attribute seam (a UV, normal or colour discontinuity): keeps its position, and may be
    /// removed only by sliding along the seam onto a seam neighbour, each side of the seam
    /// taking that neighbour's attributes on its side. Seams thin out without tearing.
    Seam,
}

/// What an earlier phase hands the greedy with its mesh (the hybrid's clusters): the frame to
/// normalize in (the original's, so errors keep its units), and per input face the normal of
/// the original face under it, for the flip test (a clustered face can already lean).
///
/// The clusters' quadrics are not carried: the queue ranks collapses by the clustered
/// surface's own planes. Measured on the four shared scans and both 1M meshes at 10% and 1%,
/// that gave a mean error 4–19% below the rounds' from the carried quadrics (docs/PERFORMANCE.md,
/// "`hybrid`"), and 3–17% below this queue's from them. Summed over a whole cell, the members'
/// planes charge every collapse for the cell's spread of orientations, where the clustered
/// surface keeps only what is left of it.
pub(crate) struct Carried<'a> {
    pub frame: ([f64; 3], f64),
    pub normals: &'a [[f32; 3]],
}

/// Neighbour entries (two per face) up to which [`interior_fans`] works on a fixed-width row:
/// eight faces around a vertex.
pub(super) const FAN_ROW: usize = 16;

/// The number of fans `v`'s faces `around` (topological, each holding `v` once) make when
/// every neighbour is on exactly two of them: no border, seam or non-manifold edge at `v`, so
/// its set-up adds no constraint plane. `None` otherwise, or beyond [`FAN_ROW`] entries.
/// Counted against a fixed-width row (which the compiler vectorizes) instead of sorting the
/// entries; the fans are the same sets whatever order their faces are joined in.
pub(super) fn interior_fans(
    around: impl Iterator<Item = [u32; 3]>,
    v: u32,
    fan: &mut Vec<u32>,
) -> Option<usize> {
    // Padded with no vertex: ids are below the vertex count.
    let mut row = [u32::MAX; FAN_ROW];
    let mut n = 0;
    for t in around {
        for u in t {
            if u != v {
                *row.get_mut(n)? = u;
                n += 1;
            }
        }
    }
    if !row[..n]
        .iter()
        .all(|&u| row.iter().filter(|&&w| w == u).count() == 2)
    {
        return None;
    }
    // Entries 2i and 2i + 1 are face i's.
    fan.clear();
    fan.extend(0..(n / 2) as u32);
    for j in 0..n {
        if let Some(k) = (j + 1..n).find(|&k| row[k] == row[j]) {
            join(fan, j as u32 / 2, k as u32 / 2);
        }
    }
    Some(fan_count(fan))
}

/// The root of `x` in the union-find `fan` (halving the path on the way).
fn fan_root(fan: &mut [u32], mut x: u32) -> u32 {
    while fan[x as usize] != x {
        fan[x as usize] = fan[fan[x as usize] as usize];
        x = fan[x as usize];
    }
    x
}

/// Joins the sets of faces `a` and `b` in `fan` (the lower root stays).
pub(super) fn join(fan: &mut [u32], a: u32, b: u32) {
    let (a, b) = (fan_root(fan, a), fan_root(fan, b));
    fan[a.max(b) as usize] = a.min(b);
}

/// The number of sets (fans) in `fan`.
pub(super) fn fan_count(fan: &mut [u32]) -> usize {
    (0..fan.len() as u32)
        .filter(|&x| fan_root(fan, x) == x)
        .count()
}

/// Hoppe's edge constraint: the plane through edge (pa, pb) perpendicular to the surface
/// (normal `surface`), weighted by the squared edge length so it scales like a face area.
pub(super) fn edge_constraint(
    pa: [f64; 3],
    pb: [f64; 3],
    surface: [f64; 3],
    weight: f64,
) -> Option<Quadric> {
    let e = sub(pb, pa);
    let n = cross(e, surface);
    let l = norm(n);
    (l > 0.0 && weight > 0.0).then(|| {
        let n = n.map(|x| x / l);
        Quadric::from_plane(n, -dot(n, pa), weight * dot(e, e))
    })
}
