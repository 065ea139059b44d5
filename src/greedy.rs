//! Backend `cpu`: greedy quadric edge collapse with a priority queue, in f64 — the quality
//! reference every other backend is held against.
//!
//! The queue is lazy: an edge enters keyed by its quadric error alone, which is a lower bound of
//! its full priority (error scaled up for poor triangle quality, MeshLab-style). When it comes out
//! on top, the full priority is computed (flips, needles, quality); if it grew, the edge goes
//! back in, else the link condition and the other topological checks decide. So the expensive
//! checks run once for the edge that really is cheapest, and the many edges a collapse touches
//! are only re-keyed cheaply.
//! Entries are stamped with their endpoints' versions; a collapse bumps the survivor's version,
//! which retires every older entry of its edges.

use crate::error::Result;
use crate::mesh::{Mesh, weld, weld::position_classes};
use crate::quadric::Quadric;
use crate::simplify::{SimplifyOptions, SimplifyReport, StopReason};
use rayon::prelude::*;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

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

/// Quality of a triangle as |cross| / longest edge²: 0 for a needle or sliver, √3/2 ≈ 0.866 for
/// an equilateral triangle (the measure vcglib's quadric collapse uses, so its threshold of 0.3
/// means the same here).
pub(crate) fn triangle_quality(p0: [f64; 3], p1: [f64; 3], p2: [f64; 3]) -> f64 {
    let d10 = sub(p1, p0);
    let d20 = sub(p2, p0);
    let d12 = sub(p1, p2);
    let area2 = norm(cross(d10, d20));
    let longest = dot(d10, d10).max(dot(d20, d20)).max(dot(d12, d12));
    if longest > 0.0 { area2 / longest } else { 0.0 }
}

#[inline]
fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
#[inline]
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
#[inline]
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
#[inline]
fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// The prepared surface: welded topology, normalized positions, per-vertex quadrics and flags.
/// Shared by the greedy backend and (later) the parallel ones, which start from the same state.
pub(crate) struct Prepared {
    /// Mesh after exact welding; its vertices are the "attribute vertices" written out.
    pub mesh: Mesh,
    /// Attribute vertex → topological vertex (position class).
    pub topo: Vec<u32>,
    /// Per topological vertex: one attribute vertex (the only one unless the vertex is a seam).
    pub first_attr: Vec<u32>,
    /// Faces with three distinct topological vertices, as attribute-vertex ids.
    pub faces: Vec<[u32; 3]>,
    /// Index of each kept face in `mesh.triangles` (for materials and groups).
    pub face_origin: Vec<u32>,
    /// Unit normal of each face as it was in the input (zero for a face without area). A face
    /// keeps its identity through collapses, so checking new normals against it bounds the
    /// drift that many small turns could add up to.
    pub ref_normal: Vec<[f32; 3]>,
    /// Normalized positions per topological vertex: centred on the bounding box, divided by its
    /// diagonal, so errors are relative to the diagonal and f32 GPU twins keep precision.
    pub pos: Vec<[f64; 3]>,
    pub quadrics: Vec<Quadric>,
    pub mobility: Vec<Mobility>,
    pub border: Vec<bool>,
    /// More than one attribute vertex at this position.
    pub seam: Vec<bool>,
    pub center: [f64; 3],
    pub scale: f64,
    pub dropped_degenerate: usize,
}

impl Prepared {
    pub fn new(input: &Mesh, opts: &SimplifyOptions) -> Prepared {
        let mesh = weld(input).mesh;
        // Without attributes `weld` merged by position already: every position is its own class,
        // and hashing them all again cost 0.03 s of 0.4 s here on the 1M scan.
        let (topo, firsts) =
            if input.normals.is_none() && input.uvs.is_none() && input.colors.is_none() {
                let id: Vec<u32> = (0..mesh.positions.len() as u32).collect();
                (id.clone(), id)
            } else {
                position_classes(&mesh.positions)
            };
        let (topo, firsts) = spatial_order(&mesh.positions, topo, firsts);
        let nt = firsts.len();
        let mut faces = Vec::with_capacity(mesh.triangles.len());
        let mut face_origin = Vec::with_capacity(mesh.triangles.len());
        for (f, t) in mesh.triangles.iter().enumerate() {
            let [a, b, c] = t.map(|v| topo[v as usize]);
            if a != b && b != c && a != c {
                faces.push(*t);
                face_origin.push(f as u32);
            }
        }
        let dropped_degenerate = mesh.triangles.len() - faces.len();
        // Attribute vertices per position, counting only those the kept faces use: an unused
        // vertex with other attributes at the same point must not make a seam.
        let mut used = vec![false; mesh.positions.len()];
        for f in &faces {
            for &v in f {
                used[v as usize] = true;
            }
        }
        let mut attr_count = vec![0u32; nt];
        let mut firsts = firsts;
        for (v, &t) in topo.iter().enumerate() {
            attr_count[t as usize] += used[v] as u32;
            // A position's representative attribute vertex must be one the faces use: a
            // collapse maps the removed vertex's corners from it.
            if used[v] && !used[firsts[t as usize] as usize] {
                firsts[t as usize] = v as u32;
            }
        }
        // Faces in the order of their first vertex, so a vertex's faces sit close in memory; a
        // counting sort, stable, so faces with the same first vertex keep their input order.
        let (order, _) = counting_sort(nt, faces.len(), |f| {
            faces[f]
                .map(|v| topo[v as usize])
                .into_iter()
                .min()
                .unwrap_or(0)
        });
        let faces: Vec<[u32; 3]> = order.par_iter().map(|&f| faces[f as usize]).collect();
        let face_origin: Vec<u32> = order.par_iter().map(|&f| face_origin[f as usize]).collect();

        let (center, scale) = match mesh.bounds() {
            Some(b) if b.diagonal() > 0.0 => (b.center(), 1.0 / b.diagonal()),
            Some(b) => (b.center(), 1.0),
            None => ([0.0; 3], 1.0),
        };
        let pos: Vec<[f64; 3]> = firsts
            .par_iter()
            .map(|&v| {
                let p = mesh.positions[v as usize];
                // Keep in step with `Prepared::normalize`.
                [0, 1, 2].map(|i| (p[i] as f64 - center[i]) * scale)
            })
            .collect();

        let tf = |f: &[u32; 3]| f.map(|v| topo[v as usize]);
        // The faces around each vertex, in face order.
        let (corners, corner_start) =
            counting_sort(nt, faces.len() * 3, |c| topo[faces[c / 3][c % 3] as usize]);
        let faces_of = |v: usize| {
            corners[corner_start[v] as usize..corner_start[v + 1] as usize]
                .iter()
                .map(|&c| c / 3)
        };
        // A face's unit normal and its plane quadric (area-weighted).
        let plane = |f: usize| {
            let [p0, p1, p2] = tf(&faces[f]).map(|v| pos[v as usize]);
            let c = cross(sub(p1, p0), sub(p2, p0));
            let len = norm(c);
            (len > 0.0).then(|| {
                let n = c.map(|x| x / len);
                (n, Quadric::from_plane(n, -dot(n, p0), 0.5 * len))
            })
        };
        let ref_normal: Vec<[f32; 3]> = (0..faces.len())
            .into_par_iter()
            .map(|f| plane(f).map_or([0.0; 3], |(n, _)| n.map(|x| x as f32)))
            .collect();
        // Per vertex, in parallel: the sum of its faces' plane quadrics in face order, then the
        // constraint planes of its border and seam edges in ascending order of the other end,
        // which is the order one pass over all edges sorted by (low, high) end gives each
        // vertex; so the sums do not depend on the thread count. Each face's plane and each
        // constraint is computed once per vertex that needs it: cheaper than one 88-byte
        // quadric per face written out and read back, and, measured on the 1M scan, the
        // sequential pass over all edges with a union-find over all corners took 0.12 s.
        // Straight into the three arrays: collecting tuples and copying them out took 0.027 s,
        // on one core, of the 0.25 s set-up of the 1M scan.
        let (quadrics, (mobility, border)): (Vec<Quadric>, (Vec<Mobility>, Vec<bool>)) = (0..nt)
            .into_par_iter()
            .map_init(
                || (Vec::new(), Vec::new()),
                |(edges, fan): &mut (Vec<(u32, u32, u32)>, Vec<u32>), v| {
                    let mut q = Quadric::default();
                    for f in faces_of(v) {
                        if let Some((_, fq)) = plane(f as usize) {
                            q.add(&fq);
                        }
                    }
                    let mut mobility = if attr_count[v] > 1 {
                        Mobility::Seam
                    } else {
                        Mobility::Free
                    };
                    let mut border = false;
                    // The edges at v with their faces (and each face's place among v's faces),
                    // in face order within an edge: 1 face for a border, 2 for a manifold edge,
                    // more for a non-manifold one.
                    let vt = v as u32;
                    edges.clear();
                    for (i, f) in faces_of(v).enumerate() {
                        let t = tf(&faces[f as usize]);
                        edges.extend(t.into_iter().filter(|&u| u != vt).map(|u| (u, f, i as u32)));
                    }
                    edges.sort_unstable();
                    // v's faces joined across its manifold edges: the fans around v.
                    fan.clear();
                    fan.extend(0..faces_of(v).len() as u32);
                    let root = |fan: &mut Vec<u32>, mut x: u32| {
                        while fan[x as usize] != x {
                            fan[x as usize] = fan[fan[x as usize] as usize];
                            x = fan[x as usize];
                        }
                        x
                    };
                    let mut i = 0;
                    while i < edges.len() {
                        let mut j = i + 1;
                        while j < edges.len() && edges[j].0 == edges[i].0 {
                            j += 1;
                        }
                        let u = edges[i].0;
                        let (a, b) = (vt.min(u), vt.max(u));
                        let (pa, pb) = (pos[a as usize], pos[b as usize]);
                        match j - i {
                            1 => {
                                border = true;
                                // Hoppe's boundary constraint: a plane through the edge,
                                // perpendicular to its face, weighted by the squared edge length
                                // so it scales like an area.
                                let t = tf(&faces[edges[i].1 as usize]);
                                let [p0, p1, p2] = t.map(|v| pos[v as usize]);
                                let fnrm = cross(sub(p1, p0), sub(p2, p0));
                                if let Some(c) = edge_constraint(pa, pb, fnrm, opts.border_weight) {
                                    q.add(&c);
                                }
                            }
                            2 => {
                                let (f1, f2) = (edges[i].1, edges[i + 1].1);
                                let (r1, r2) = (root(fan, edges[i].2), root(fan, edges[i + 1].2));
                                fan[r1.max(r2) as usize] = r1.min(r2);
                                // A seam edge (the faces disagree on an endpoint's attribute
                                // vertex) gets a constraint plane like a border, so the seam
                                // keeps its course.
                                let attr = |fi: u32, x: u32| {
                                    let t = tf(&faces[fi as usize]);
                                    faces[fi as usize][t.iter().position(|&y| y == x).unwrap_or(0)]
                                };
                                // Only a seam vertex (more than one attribute vertex) can
                                // disagree; skipping the four lookups for the others saved 60M
                                // of 3.8G instructions simplifying builtin:bumpy-sphere to 1%.
                                let seam_end =
                                    attr_count[a as usize] > 1 || attr_count[b as usize] > 1;
                                if seam_end
                                    && (attr(f1, a) != attr(f2, a) || attr(f1, b) != attr(f2, b))
                                    && opts.border_weight > 0.0
                                {
                                    let normal = |fi: u32| {
                                        let [p0, p1, p2] =
                                            tf(&faces[fi as usize]).map(|v| pos[v as usize]);
                                        let c = cross(sub(p1, p0), sub(p2, p0));
                                        let l = norm(c);
                                        if l > 0.0 { c.map(|x| x / l) } else { c }
                                    };
                                    let (n1, n2) = (normal(f1), normal(f2));
                                    let avg = [0, 1, 2].map(|k| n1[k] + n2[k]);
                                    if let Some(c) =
                                        edge_constraint(pa, pb, avg, opts.border_weight)
                                    {
                                        q.add(&c);
                                    }
                                }
                            }
                            _ => mobility = Mobility::Pinned,
                        }
                        i = j;
                    }
                    // A vertex whose faces form more than one fan (a bow-tie) is pinned:
                    // collapsing around it cannot keep the surface's topology well defined.
                    if (0..fan.len() as u32).filter(|&x| root(fan, x) == x).count() > 1 {
                        mobility = Mobility::Pinned;
                    }
                    if opts.lock_border && border {
                        mobility = match mobility {
                            Mobility::Free => Mobility::LockedBorder,
                            _ => Mobility::Pinned,
                        };
                    }
                    (q, (mobility, border))
                },
            )
            .unzip();
        Prepared {
            mesh,
            topo,
            first_attr: firsts,
            faces,
            face_origin,
            ref_normal,
            pos,
            quadrics,
            mobility,
            border,
            seam: attr_count.iter().map(|&c| c > 1).collect(),
            center,
            scale,
            dropped_degenerate,
        }
    }

    /// The sub-problem made of `faces` (indices into `self.faces`): its own dense topological
    /// ids in the same (Morton) order, everything else copied, `pin` (per topological vertex of
    /// the whole) added to the pinned vertices. Attribute vertex ids stay those of the whole
    /// mesh, and `face_origin` holds each face's index in `self.faces`, so results map straight
    /// back. The sub-problem's `topo` is left empty: it would have to cover every attribute
    /// vertex of the whole mesh (measured on the 1M scan, zeroing that for each of 32 regions
    /// was 68 MB of fresh pages); its faces come as topological faces instead.
    /// Returns the sub-problem, its topological faces and its local → whole topological vertex
    /// map.
    pub(crate) fn subset(
        &self,
        faces: &[u32],
        pin: &[bool],
    ) -> (Prepared, Vec<[u32; 3]>, Vec<u32>) {
        // The vertices used, in ascending order, through a table over the span of their ids
        // (a region is one or two runs of the Morton order): measured on the 1M scan, sorting
        // the 400k corners of each of 8 regions and binary-searching them took 0.05 s per
        // region, twice the region's whole queue set-up.
        let corner_topo = |f: u32| self.faces[f as usize].map(|v| self.topo[v as usize]);
        let (lo, hi) = faces
            .iter()
            .flat_map(|&f| corner_topo(f))
            .fold((u32::MAX, 0), |(lo, hi), t| (lo.min(t), hi.max(t)));
        let mut local_of = vec![u32::MAX; (hi + 1).saturating_sub(lo) as usize];
        for &f in faces {
            for t in corner_topo(f) {
                local_of[(t - lo) as usize] = 0;
            }
        }
        let mut topo_global = Vec::new();
        for (i, l) in local_of.iter_mut().enumerate() {
            if *l == 0 {
                *l = topo_global.len() as u32;
                topo_global.push(lo + i as u32);
            }
        }
        let local = |t: u32| local_of[(t - lo) as usize];
        let topo_faces: Vec<[u32; 3]> = faces.iter().map(|&f| corner_topo(f).map(local)).collect();
        let mut first_attr = vec![u32::MAX; topo_global.len()];
        for (&f, t) in faces.iter().zip(&topo_faces) {
            for (&v, &lt) in self.faces[f as usize].iter().zip(t) {
                if first_attr[lt as usize] == u32::MAX
                    || v == self.first_attr[topo_global[lt as usize] as usize]
                {
                    first_attr[lt as usize] = v;
                }
            }
        }
        let pick = |lt: usize| topo_global[lt] as usize;
        let n = topo_global.len();
        let sub = Prepared {
            mesh: Mesh::default(),
            topo: Vec::new(),
            first_attr,
            faces: faces.iter().map(|&f| self.faces[f as usize]).collect(),
            face_origin: faces.to_vec(),
            ref_normal: faces.iter().map(|&f| self.ref_normal[f as usize]).collect(),
            pos: (0..n).map(|l| self.pos[pick(l)]).collect(),
            quadrics: (0..n).map(|l| self.quadrics[pick(l)]).collect(),
            mobility: (0..n)
                .map(|l| {
                    if pin[pick(l)] {
                        Mobility::Pinned
                    } else {
                        self.mobility[pick(l)]
                    }
                })
                .collect(),
            border: (0..n).map(|l| self.border[pick(l)]).collect(),
            seam: (0..n).map(|l| self.seam[pick(l)]).collect(),
            center: self.center,
            scale: self.scale,
            dropped_degenerate: 0,
        };
        (sub, topo_faces, topo_global)
    }

    /// Into the normalized frame; the same arithmetic as the set-up, so a vertex that never
    /// moved compares equal.
    pub fn normalize(&self, p: [f32; 3]) -> [f64; 3] {
        [0, 1, 2].map(|i| (p[i] as f64 - self.center[i]) * self.scale)
    }

    pub fn denormalize(&self, p: [f64; 3]) -> [f32; 3] {
        [0, 1, 2].map(|i| (p[i] / self.scale + self.center[i]) as f32)
    }
}

/// Indices `0..n` ordered by `key(i) < buckets`, stable (a counting sort), and where each
/// bucket starts in that order (`buckets + 1` entries).
fn counting_sort(
    buckets: usize,
    n: usize,
    key: impl Fn(usize) -> u32 + Sync,
) -> (Vec<u32>, Vec<u32>) {
    let keys: Vec<u32> = (0..n).into_par_iter().map(&key).collect();
    let mut start = vec![0u32; buckets + 1];
    for &k in &keys {
        start[k as usize + 1] += 1;
    }
    for b in 0..buckets {
        start[b + 1] += start[b];
    }
    let begin = start.clone();
    let mut out = vec![0u32; n];
    for (i, &k) in keys.iter().enumerate() {
        out[start[k as usize] as usize] = i as u32;
        start[k as usize] += 1;
    }
    (out, begin)
}

/// Hoppe's edge constraint: the plane through edge (pa, pb) perpendicular to the surface
/// (normal `surface`), weighted by the squared edge length so it scales like a face area.
fn edge_constraint(pa: [f64; 3], pb: [f64; 3], surface: [f64; 3], weight: f64) -> Option<Quadric> {
    let e = sub(pb, pa);
    let n = cross(e, surface);
    let l = norm(n);
    (l > 0.0 && weight > 0.0).then(|| {
        let n = n.map(|x| x / l);
        Quadric::from_plane(n, -dot(n, pa), weight * dot(e, e))
    })
}

/// Renumbers position classes along a Morton (Z-order) curve. The queue visits the mesh in cost
/// order, effectively at random; with neighbours close in memory, the dozen vertices and faces
/// one collapse touches share cache lines and pages instead of each being a miss.
pub(crate) fn spatial_order(
    positions: &[[f32; 3]],
    topo: Vec<u32>,
    firsts: Vec<u32>,
) -> (Vec<u32>, Vec<u32>) {
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for &v in &firsts {
        let p = positions[v as usize];
        lo = [0, 1, 2].map(|i| lo[i].min(p[i]));
        hi = [0, 1, 2].map(|i| hi[i].max(p[i]));
    }
    let spread = (0..3)
        .map(|i| hi[i] - lo[i])
        .fold(0.0f32, f32::max)
        .max(f32::MIN_POSITIVE);
    // Spread the low 10 bits of x to every third bit.
    let part = |x: u32| {
        let mut x = x & 0x3ff;
        x = (x | (x << 16)) & 0x030000ff;
        x = (x | (x << 8)) & 0x0300f00f;
        x = (x | (x << 4)) & 0x030c30c3;
        (x | (x << 2)) & 0x09249249
    };
    let code = |v: u32| {
        let p = positions[v as usize];
        let q = |i: usize| (((p[i] - lo[i]) / spread) * 1023.0) as u32;
        part(q(0)) | (part(q(1)) << 1) | (part(q(2)) << 2)
    };
    let mut keyed: Vec<(u32, u32)> = (0..firsts.len() as u32)
        .into_par_iter()
        .map(|c| (code(firsts[c as usize]), c))
        .collect();
    keyed.par_sort_unstable();
    let order: Vec<u32> = keyed.into_iter().map(|(_, c)| c).collect();
    let mut rank = vec![0u32; firsts.len()];
    for (new, &old) in order.iter().enumerate() {
        rank[old as usize] = new as u32;
    }
    let firsts = order.par_iter().map(|&old| firsts[old as usize]).collect();
    (topo.par_iter().map(|&t| rank[t as usize]).collect(), firsts)
}

/// What [`State::evaluate_below`] found for an edge.
enum Evaluation {
    /// Not allowed now (a flip, a needle, the link condition, a seam).
    Refused,
    /// Its priority (the key given) grew above the bound: back into the queue.
    Later(u32),
    Collapse(Collapse),
}

/// A collapse that passed every check: `remove` goes into `keep`, which moves to `pos`.
#[derive(Debug, Clone, Copy)]
struct Collapse {
    keep: u32,
    remove: u32,
    pos: [f64; 3],
    error: f64,
    /// (attribute vertex of `remove`, attribute vertex of `keep` its corners take); the second
    /// pair is used only when a seam vertex slides along its seam (one pair per side).
    attr_map: [(u32, u32); 2],
}

/// The faces around each vertex, all in one arena: a vertex's list is `data[start..start + len]`
/// with room up to `cap`. Built in vertex (Morton) order, so the lists of neighbours sit side by
/// side; a list that outgrows its room moves into the removed vertex's (a neighbour's, so still
/// nearby) or else to the end. Measured on the 1M scan at 10%: one `Vec` per vertex spent
/// 0.45 G of 15 G instructions in malloc/realloc/free, and each list was a cache miss of its own.
struct VertFaces {
    /// Per vertex: start, len, cap.
    span: Vec<[u32; 3]>,
    data: Vec<u32>,
}

impl VertFaces {
    /// Lists in face order, from each face's vertices.
    fn new(nt: usize, topo_faces: &[[u32; 3]]) -> VertFaces {
        let mut span = vec![[0u32; 3]; nt];
        for t in topo_faces {
            for &v in t {
                span[v as usize][2] += 1;
            }
        }
        let mut at = 0u32;
        for s in &mut span {
            s[0] = at;
            at += s[2];
        }
        let mut data = vec![0u32; at as usize];
        // Room for the lists that will move: a collapse grows one list by a few faces.
        data.reserve(at as usize / 8);
        for (f, t) in topo_faces.iter().enumerate() {
            for &v in t {
                let s = &mut span[v as usize];
                data[(s[0] + s[1]) as usize] = f as u32;
                s[1] += 1;
            }
        }
        VertFaces { span, data }
    }

    #[inline]
    fn get(&self, v: usize) -> &[u32] {
        let [start, len, _] = self.span[v];
        &self.data[start as usize..(start + len) as usize]
    }

    /// Replaces `keep`'s list by its own entries that pass `live`, then `extra`; `remove`'s list
    /// is emptied and its room may be reused.
    fn merge_into(
        &mut self,
        keep: usize,
        remove: usize,
        live: impl Fn(u32) -> bool,
        extra: &[u32],
    ) {
        let [start, len, cap] = self.span[keep];
        let (start, cap) = (start as usize, cap as usize);
        let mut n = start;
        for i in start..start + len as usize {
            let f = self.data[i];
            if live(f) {
                self.data[n] = f;
                n += 1;
            }
        }
        let kept = n - start;
        let need = kept + extra.len();
        let [rs, _, rc] = self.span[remove];
        self.span[remove] = [rs, 0, 0];
        let (start, cap) = if need <= cap {
            (start, cap)
        } else if need <= rc as usize {
            self.data.copy_within(start..start + kept, rs as usize);
            (rs as usize, rc as usize)
        } else {
            let at = self.data.len();
            let cap = need + need / 2;
            self.data.resize(at + cap, 0);
            self.data.copy_within(start..start + kept, at);
            (at, cap)
        };
        self.data[start + kept..start + need].copy_from_slice(extra);
        self.span[keep] = [start as u32, need as u32, cap as u32];
    }
}

/// `topo_faces` entry of a removed face. The hot loops test this instead of `face_alive`: the
/// face's vertices are read next anyway, so liveness costs no extra cache line.
const DEAD: u32 = u32::MAX;

struct State<'a> {
    opts: &'a SimplifyOptions,
    p: Prepared,
    topo_faces: Vec<[u32; 3]>,
    face_alive: Vec<bool>,
    /// Live (and some dead, pruned lazily) faces around each vertex.
    vert_faces: VertFaces,
    alive: Vec<bool>,
    version: Vec<u32>,
    mark: Vec<u32>,
    mark_gen: u32,
    cos_max_angle: f64,
    scratch: Vec<u32>,
    /// Live faces.
    faces: usize,
    collapses: usize,
    /// `collapses` when every live edge was last queued: the queue is filled again when it runs
    /// dry only if something collapsed since. Kept across `run` calls, so a run cut into
    /// epochs by cost ceilings refills exactly where an uninterrupted one would.
    seeded_at: usize,
    /// Times the queue was filled again.
    refills: usize,
    max_collapse_err2: f64,
    hit_max_error: bool,
}

/// The queue of (key, a, b, stamp) entries: a bucket queue on the key's top bits (f32
/// exponent and three mantissa bits, so a bucket spans 6-12.5% of cost) in front of a binary heap
/// that orders the one bucket being taken. An entry is appended to its bucket, moved once into
/// the heap when its bucket comes up, and popped; an edge re-keyed below the bucket being taken
/// (a collapse can make a neighbouring edge cheaper than the edge just taken) goes straight into
/// the heap. Ties come out in (a, b) order, so the order never depends on anything but the
/// entries. When a bucket comes up its stale entries (most are: an edge is re-keyed each time a
/// collapse touches it; 4.2M of 5.3M pops on the 1M scan at 10%) are dropped in one linear
/// pass instead of each costing a heap pop. Measured on the 1M scan at 1%: the radix heap this
/// replaced spent 1.9 G of 13.1 G instructions moving entries between its 33 buckets; std's
/// BinaryHeap over every entry had spent 3.1 s of 6.5 s in `pop` before that.
struct Queue {
    /// The bucket being taken, and anything pushed below its end.
    active: BinaryHeap<Reverse<(u32, u32, u32, u32)>>,
    /// Keys below this go to `active`; the buckets below it are empty.
    active_end: u64,
    buckets: Vec<Vec<(u32, u32, u32, u32)>>,
    /// One bit per non-empty bucket.
    occupied: Vec<u64>,
    /// Entries in `buckets`.
    waiting: usize,
}

/// Key bits below the bucket index. Measured on the 1M scan (1% / 10%): 16 bits 1.58 / 1.48 s,
/// 18 bits 1.47 / 1.38 s, 20 bits 1.41 / 1.32 s, 22 bits 1.49 / 1.38 s.
const BUCKET_SHIFT: u32 = 20;
const BUCKETS: usize = 1 << (32 - BUCKET_SHIFT);

impl Queue {
    fn new() -> Queue {
        Queue {
            active: BinaryHeap::new(),
            active_end: 0,
            buckets: vec![Vec::new(); BUCKETS],
            occupied: vec![0; BUCKETS / 64],
            waiting: 0,
        }
    }

    fn push(&mut self, key: u32, a: u32, b: u32, stamp: u32) {
        if u64::from(key) < self.active_end {
            self.active.push(Reverse((key, a, b, stamp)));
        } else {
            let i = (key >> BUCKET_SHIFT) as usize;
            self.buckets[i].push((key, a, b, stamp));
            self.occupied[i / 64] |= 1 << (i % 64);
            self.waiting += 1;
        }
    }

    /// The entry with the smallest key; when a new bucket comes up, only its entries that are
    /// still `current` are kept.
    fn pop(&mut self, current: impl Fn(u32, u32, u32) -> bool) -> Option<(u32, u32, u32, u32)> {
        loop {
            if let Some(Reverse(e)) = self.active.pop() {
                return Some(e);
            }
            let from = (self.active_end >> BUCKET_SHIFT) as usize;
            let Some(i) = (from / 64..self.occupied.len()).find_map(|w| {
                let bits = self.occupied[w] & (!0u64 << (from.max(w * 64) - w * 64));
                (bits != 0).then(|| w * 64 + bits.trailing_zeros() as usize)
            }) else {
                // Empty: start again from the bottom, so a queue filled anew (the run re-queues
                // every edge before giving up) fills buckets rather than all go to the heap.
                self.active_end = 0;
                return None;
            };
            self.occupied[i / 64] &= !(1 << (i % 64));
            let list = std::mem::take(&mut self.buckets[i]);
            self.waiting -= list.len();
            self.active_end = ((i as u64) + 1) << BUCKET_SHIFT;
            // The heap is empty here: its allocation takes the bucket's live entries.
            let mut live = std::mem::take(&mut self.active).into_vec();
            live.clear();
            live.extend(
                list.into_iter()
                    .filter(|&(_, a, b, stamp)| current(a, b, stamp))
                    .map(Reverse),
            );
            self.active = BinaryHeap::from(live);
        }
    }

    fn is_empty(&self) -> bool {
        self.active.is_empty() && self.waiting == 0
    }
}

/// Non-negative f64 priorities as f32 bits keep the heap entries 16 bytes; ordering of
/// non-negative IEEE floats equals ordering of their bit patterns.
fn key(priority: f64) -> u32 {
    (priority as f32).to_bits()
}

impl<'a> State<'a> {
    fn next_mark(&mut self) -> u32 {
        self.next_marks(1)
    }

    /// `n` fresh mark values `m..m + n`; returns `m`.
    fn next_marks(&mut self, n: u32) -> u32 {
        if self.mark_gen > u32::MAX - n {
            self.mark.iter_mut().for_each(|m| *m = 0);
            self.mark_gen = 0;
        }
        let m = self.mark_gen + 1;
        self.mark_gen += n;
        m
    }

    fn stamp(&self, a: u32, b: u32) -> u32 {
        self.version[a as usize].wrapping_add(self.version[b as usize])
    }

    /// Position and quadric error of collapsing edge (a, b), ignoring validity: the queue key.
    /// Inlined (with `Quadric::optimum`) into its callers, which call it for every edge
    /// around a vertex: 1.263 → 1.206 s on the 1M scan at 1% (min of 5, output identical).
    #[inline]
    fn placement(&self, a: u32, b: u32) -> Option<(u32, u32, [f64; 3], f64)> {
        let (ma, mb) = (self.p.mobility[a as usize], self.p.mobility[b as usize]);
        let q = self.p.quadrics[a as usize].sum(&self.p.quadrics[b as usize]);
        let (pa, pb) = (self.p.pos[a as usize], self.p.pos[b as usize]);
        use Mobility::{Free, LockedBorder, Pinned, Seam};
        match (ma, mb) {
            (Free, Free) => {
                let (pos, err) = match q.optimum() {
                    Some(p) => (p, q.eval(p)),
                    None => {
                        let mid = [0, 1, 2].map(|i| 0.5 * (pa[i] + pb[i]));
                        [pa, pb, mid].into_iter().map(|p| (p, q.eval(p))).fold(
                            (mid, f64::INFINITY),
                            |best, c| if c.1 < best.1 { c } else { best },
                        )
                    }
                };
                // The survivor is the endpoint nearer the new position: its attributes fit best.
                let (keep, remove) =
                    if dot(sub(pos, pa), sub(pos, pa)) <= dot(sub(pos, pb), sub(pos, pb)) {
                        (a, b)
                    } else {
                        (b, a)
                    };
                Some((keep, remove, pos, err))
            }
            (Pinned | LockedBorder | Seam, Free) => Some((a, b, pa, q.eval(pa))),
            (Free, Pinned | LockedBorder | Seam) => Some((b, a, pb, q.eval(pb))),
            (Pinned, Pinned) => None,
            (Seam, Seam | Pinned) | (Pinned, Seam) => {
                for (keep, remove) in [(a, b), (b, a)] {
                    if self.p.mobility[remove as usize] == Seam
                        && self.seam_slide(remove, keep).is_some()
                    {
                        let pk = self.p.pos[keep as usize];
                        return Some((keep, remove, pk, q.eval(pk)));
                    }
                }
                None
            }
            (Seam, LockedBorder) | (LockedBorder, Seam) => None,
            (Pinned | LockedBorder, LockedBorder) | (LockedBorder, Pinned) => {
                // A locked border may shed a vertex that lies on the straight line between its
                // border neighbours: the outline does not change.
                for (keep, remove) in [(a, b), (b, a)] {
                    if self.p.mobility[remove as usize] == LockedBorder
                        && self.on_straight_border(remove, keep)
                    {
                        let pk = self.p.pos[keep as usize];
                        return Some((keep, remove, pk, q.eval(pk)));
                    }
                }
                None
            }
        }
    }

    /// When seam vertex `v` can slide along edge `(v, toward)`: `v` is interior, has exactly two
    /// attribute vertices, and the two faces on the edge use different attribute vertices at both
    /// ends — the edge is the seam. Returns `[(v's attribute, toward's attribute); 2]`, one pair
    /// per side of the seam.
    fn seam_slide(&self, v: u32, toward: u32) -> Option<[(u32, u32); 2]> {
        if self.p.border[v as usize] {
            return None;
        }
        let mut sides = [(u32::MAX, u32::MAX); 2];
        let mut n = 0;
        let mut attrs = [u32::MAX; 2];
        for &f in self.vert_faces.get(v as usize) {
            if self.topo_faces[f as usize][0] == DEAD {
                continue;
            }
            let t = self.topo_faces[f as usize];
            let av = self.p.faces[f as usize][t.iter().position(|&u| u == v)?];
            if attrs[0] == u32::MAX || attrs[0] == av {
                attrs[0] = av;
            } else if attrs[1] == u32::MAX || attrs[1] == av {
                attrs[1] = av;
            } else {
                return None; // three or more attribute vertices: a seam junction stays
            }
            if let Some(i) = t.iter().position(|&u| u == toward) {
                if n == 2 {
                    return None;
                }
                sides[n] = (av, self.p.faces[f as usize][i]);
                n += 1;
            }
        }
        (n == 2 && sides[0].0 != sides[1].0 && sides[0].1 != sides[1].1).then_some(sides)
    }

    /// True when `v` is a border vertex, `(v, toward)` a border edge, and `v` lies on the segment
    /// between its two border neighbours (relative tolerance 1e-9 of the segment length²).
    fn on_straight_border(&self, v: u32, toward: u32) -> bool {
        let nbrs = self.border_neighbours(v);
        if nbrs.len() != 2 || !nbrs.contains(&toward) {
            return false;
        }
        let (p0, p1, pv) = (
            self.p.pos[nbrs[0] as usize],
            self.p.pos[nbrs[1] as usize],
            self.p.pos[v as usize],
        );
        let d = sub(p1, p0);
        let c = cross(d, sub(pv, p0));
        let l2 = dot(d, d);
        l2 > 0.0
            && dot(c, c) <= 1e-18 * l2 * l2
            && dot(sub(pv, p0), d) > 0.0
            && dot(sub(pv, p1), d) < 0.0
    }

    /// Neighbours of `v` across border edges (edges with one live face).
    fn border_neighbours(&self, v: u32) -> Vec<u32> {
        let mut count: Vec<(u32, u32)> = Vec::new();
        for &f in self.vert_faces.get(v as usize) {
            if self.topo_faces[f as usize][0] == DEAD {
                continue;
            }
            for &u in &self.topo_faces[f as usize] {
                if u != v {
                    match count.iter_mut().find(|e| e.0 == u) {
                        Some(e) => e.1 += 1,
                        None => count.push((u, 1)),
                    }
                }
            }
        }
        count
            .into_iter()
            .filter(|e| e.1 == 1)
            .map(|e| e.0)
            .collect()
    }

    /// Full evaluation of edge (a, b) with no bound: the collapse, or `None` when it is not
    /// allowed now.
    #[cfg(test)]
    fn evaluate(&mut self, a: u32, b: u32) -> Option<Collapse> {
        match self.evaluate_below(a, b, u32::MAX) {
            Evaluation::Collapse(c) => Some(c),
            Evaluation::Refused | Evaluation::Later(_) => None,
        }
    }

    /// Evaluation of edge (a, b) popped at key `bound`: placement, the moved faces (flips,
    /// needles and the quality-weighted priority), and, only when the priority is still within
    /// `bound`, the topological checks that keep the mesh valid. An edge whose priority grew
    /// goes back into the queue; its link is checked when it comes out again. Measured on the
    /// 1M scan at 1%: 642k of 1.13M evaluations ended that way, each paying for the link
    /// condition before.
    fn evaluate_below(&mut self, a: u32, b: u32, bound: u32) -> Evaluation {
        let Some((keep, remove, pos, error)) = self.placement(a, b) else {
            return Evaluation::Refused;
        };
        let (k, r) = (keep as usize, remove as usize);

        // Faces that move: the normal may not turn more than the limit, no needle may appear,
        // and the worst resulting quality scales the priority.
        let mut min_quality = f64::INFINITY;
        for (moved, other) in [(k, r), (r, k)] {
            for &f in self.vert_faces.get(moved) {
                let t = self.topo_faces[f as usize];
                if t[0] == DEAD || t.contains(&(other as u32)) {
                    continue;
                }
                let old = t.map(|u| self.p.pos[u as usize]);
                let new = t.map(|u| {
                    if u as usize == moved {
                        pos
                    } else {
                        self.p.pos[u as usize]
                    }
                });
                let n_old = cross(sub(old[1], old[0]), sub(old[2], old[0]));
                let e = [
                    sub(new[1], new[0]),
                    sub(new[2], new[0]),
                    sub(new[1], new[2]),
                ];
                let n_new = cross(e[0], e[1]);
                let (l_old, l_new) = (norm(n_old), norm(n_new));
                if l_new <= 0.0 {
                    return Evaluation::Refused;
                }
                if l_old > 0.0 && dot(n_old, n_new) < self.cos_max_angle * l_old * l_new {
                    return Evaluation::Refused;
                }
                let n_ref = self.p.ref_normal[f as usize].map(f64::from);
                if dot(n_ref, n_new) < self.cos_max_angle * l_new && n_ref != [0.0; 3] {
                    return Evaluation::Refused;
                }
                // `triangle_quality(new)`, reusing |n_new|: the same bits, one cross product and
                // square root fewer.
                let longest = dot(e[0], e[0]).max(dot(e[1], e[1])).max(dot(e[2], e[2]));
                let q_new = if longest > 0.0 { l_new / longest } else { 0.0 };
                if q_new < self.opts.min_quality && q_new < triangle_quality(old[0], old[1], old[2])
                {
                    return Evaluation::Refused;
                }
                min_quality = min_quality.min(q_new);
            }
        }
        let qt = self.opts.quality_threshold;
        let priority = if qt > 0.0 && min_quality < qt {
            error * qt / min_quality.max(1e-12)
        } else {
            error
        };
        if key(priority) > bound {
            return Evaluation::Later(key(priority));
        }

        // Link condition: the common neighbours of the endpoints are exactly the vertices
        // opposite the edge in its faces (Dey et al. 1999), which keeps a manifold manifold.
        // m marks keep's neighbours, m + 1 those of them already counted as common.
        let m = self.next_marks(2);
        for &f in self.vert_faces.get(k) {
            if self.topo_faces[f as usize][0] != DEAD {
                for &u in &self.topo_faces[f as usize] {
                    self.mark[u as usize] = m;
                }
            }
        }
        let mut edge_faces = 0u32;
        let mut opposite = [u32::MAX; 2];
        let mut common = 0u32;
        for &f in self.vert_faces.get(r) {
            if self.topo_faces[f as usize][0] == DEAD {
                continue;
            }
            let t = self.topo_faces[f as usize];
            if t.contains(&keep) {
                if edge_faces >= 2 {
                    return Evaluation::Refused;
                }
                let Some(c) = t.into_iter().find(|&u| u != keep && u != remove) else {
                    return Evaluation::Refused;
                };
                opposite[edge_faces as usize] = c;
                edge_faces += 1;
            }
            for u in t {
                if u != keep && u != remove && self.mark[u as usize] == m {
                    // Counted once however many of remove's faces it is on: re-marking
                    // replaced collecting them all and sorting out the duplicates.
                    self.mark[u as usize] = m + 1;
                    common += 1;
                }
            }
        }
        if edge_faces == 0 || common != edge_faces {
            return Evaluation::Refused;
        }
        // Joining two border vertices through the interior would pinch the surface.
        if edge_faces == 2 && self.p.border[k] && self.p.border[r] {
            return Evaluation::Refused;
        }
        // A border edge whose face has its other two edges on the border too is a lone
        // triangle: collapsing it would delete a whole component (the link condition with the
        // border closed by a dummy vertex forbids it).
        if edge_faces == 1 {
            let c = opposite[0];
            let border_edge = |s: &Self, v: usize| {
                s.vert_faces
                    .get(v)
                    .iter()
                    .filter(|&&f| s.topo_faces[f as usize].contains(&c)) // dead faces hold no vertex
                    .count()
                    == 1
            };
            if border_edge(self, k) && border_edge(self, r) {
                return Evaluation::Refused;
            }
        }
        // A tetrahedral fan: faces (keep, c, d) and (remove, c, d) off the edge would become
        // one face twice.
        if edge_faces == 2 {
            let [c, d] = opposite;
            let on_cd = |s: &Self, v: usize, other: u32| {
                s.vert_faces.get(v).iter().any(|&f| {
                    let t = s.topo_faces[f as usize];
                    !t.contains(&other) && t.contains(&c) && t.contains(&d)
                })
            };
            if on_cd(self, k, remove) && on_cd(self, r, keep) {
                return Evaluation::Refused;
            }
        }

        // Attribute vertices of `keep` that the removed vertex's corners take: its only one, or
        // for a seam vertex the one it uses in the faces on the edge, which must agree — unless
        // the removed vertex slides along the seam, when each side maps to its own.
        let mut attr_map = [
            (self.p.first_attr[r], self.p.first_attr[k]),
            (u32::MAX, u32::MAX),
        ];
        if self.p.mobility[r] == Mobility::Seam {
            let Some(sides) = self.seam_slide(remove, keep) else {
                return Evaluation::Refused;
            };
            attr_map = sides;
        } else if self.p.seam[k] {
            let mut keep_attr = u32::MAX;
            for &f in self.vert_faces.get(r) {
                if self.topo_faces[f as usize][0] == DEAD {
                    continue;
                }
                let t = self.topo_faces[f as usize];
                if let Some(i) = t.iter().position(|&u| u == keep) {
                    let av = self.p.faces[f as usize][i];
                    if keep_attr != u32::MAX && keep_attr != av {
                        return Evaluation::Refused;
                    }
                    keep_attr = av;
                }
            }
            attr_map[0].1 = keep_attr;
        }
        Evaluation::Collapse(Collapse {
            keep,
            remove,
            pos,
            error,
            attr_map,
        })
    }

    /// Applies a checked collapse; returns how many faces it removed.
    fn apply(&mut self, c: &Collapse) -> usize {
        let (k, r) = (c.keep as usize, c.remove as usize);
        self.p.pos[k] = c.pos;
        let qr = self.p.quadrics[r];
        self.p.quadrics[k].add(&qr);
        self.p.border[k] |= self.p.border[r];
        self.alive[r] = false;
        let mut removed = 0;
        // `remove`'s faces that stay go to the end of `keep`'s list, in order.
        let mut moved = std::mem::take(&mut self.scratch);
        moved.clear();
        for &f in self.vert_faces.get(r) {
            let fu = f as usize;
            if self.topo_faces[fu][0] == DEAD {
                continue;
            }
            if self.topo_faces[fu].contains(&c.keep) {
                self.face_alive[fu] = false;
                self.topo_faces[fu] = [DEAD; 3];
                removed += 1;
                continue;
            }
            for i in 0..3 {
                if self.topo_faces[fu][i] == c.remove {
                    self.topo_faces[fu][i] = c.keep;
                    let old = self.p.faces[fu][i];
                    let (_, new) = c
                        .attr_map
                        .iter()
                        .copied()
                        .find(|&(from, _)| from == old)
                        .expect("every attribute vertex of the removed vertex is mapped");
                    self.p.faces[fu][i] = new;
                }
            }
            moved.push(f);
        }
        let topo_faces = &self.topo_faces;
        self.vert_faces
            .merge_into(k, r, |f| topo_faces[f as usize][0] != DEAD, &moved);
        self.scratch = moved;
        self.version[k] = self.version[k].wrapping_add(1);
        self.version[r] = self.version[r].wrapping_add(1);
        removed
    }

    /// Queues every edge around `v` with its cheap lower-bound key.
    fn push_edges_of(&mut self, v: u32, heap: &mut Queue) {
        let m = self.next_mark();
        self.mark[v as usize] = m;
        for i in 0..self.vert_faces.get(v as usize).len() {
            let f = self.vert_faces.get(v as usize)[i] as usize;
            for u in self.topo_faces[f] {
                if self.mark[u as usize] != m {
                    self.mark[u as usize] = m;
                    if let Some((_, _, _, err)) = self.placement(v, u) {
                        let (lo, hi) = if v < u { (v, u) } else { (u, v) };
                        heap.push(key(err), lo, hi, self.stamp(lo, hi));
                    }
                }
            }
        }
    }
}

impl<'a> State<'a> {
    /// Sets up the collapse state and queues every unique edge once, keyed by its quadric error.
    fn new(p: Prepared, opts: &'a SimplifyOptions) -> (State<'a>, Queue) {
        let topo_faces: Vec<[u32; 3]> = p
            .faces
            .iter()
            .map(|f| f.map(|v| p.topo[v as usize]))
            .collect();
        State::with_topo_faces(p, topo_faces, opts)
    }

    /// [`State::new`] with the faces' topological vertices given (`p.topo` is not read).
    fn with_topo_faces(
        p: Prepared,
        topo_faces: Vec<[u32; 3]>,
        opts: &'a SimplifyOptions,
    ) -> (State<'a>, Queue) {
        let nt = p.pos.len();
        let nf = p.faces.len();
        assert_eq!(topo_faces.len(), nf, "one topological face per face");
        let vert_faces = VertFaces::new(nt, &topo_faces);
        let s = State {
            opts,
            p,
            topo_faces,
            face_alive: vec![true; nf],
            vert_faces,
            alive: vec![true; nt],
            version: vec![0; nt],
            mark: vec![0; nt],
            mark_gen: 0,
            cos_max_angle: opts.max_normal_angle_deg.to_radians().cos(),
            scratch: Vec::new(),
            faces: nf,
            collapses: 0,
            max_collapse_err2: 0.0,
            seeded_at: 0,
            refills: 0,
            hit_max_error: false,
        };
        let mut heap = Queue::new();
        s.queue_all_edges(&mut heap);
        (s, heap)
    }

    /// Queues every unique edge of the live faces once, keyed by its quadric error, in
    /// ascending (lower, higher) vertex order. Gathered per vertex from its face list instead of
    /// sorting all edge keys: measured on the 1M scan at 10%, the global sort was 0.55 G of the
    /// run's 15 G instructions.
    fn queue_all_edges(&self, heap: &mut Queue) {
        let mut nbrs: Vec<u32> = Vec::new();
        for a in 0..self.p.pos.len() as u32 {
            nbrs.clear();
            for &f in self.vert_faces.get(a as usize) {
                let t = self.topo_faces[f as usize];
                if t[0] != DEAD {
                    nbrs.extend(t.into_iter().filter(|&u| u > a));
                }
            }
            nbrs.sort_unstable();
            nbrs.dedup();
            for &b in &nbrs {
                if let Some((_, _, _, err)) = self.placement(a, b) {
                    heap.push(key(err), a, b, self.stamp(a, b));
                }
            }
        }
    }

    /// Collapses the cheapest valid edges until `target` faces remain, the queue runs dry, or
    /// the cheapest key exceeds `key_limit` (that entry stays queued). Returns true when it
    /// stopped at the key limit.
    fn run(
        &mut self,
        heap: &mut Queue,
        target: usize,
        key_limit: u32,
        progress: &mut dyn FnMut(usize),
    ) -> bool {
        let max_err2 = self.opts.max_error.map(|e| e * e);
        let mut next_report = self.collapses;

        while self.faces > target {
            let Some((k, a, b, stamp)) = heap.pop(|a, b, stamp| self.stamp(a, b) == stamp) else {
                // An edge refused earlier (a flip, the link condition) can have become valid
                // through collapses around it that did not touch its endpoints: before giving
                // up, queue every live edge once more if anything changed since the last time.
                if self.collapses > self.seeded_at {
                    self.seeded_at = self.collapses;
                    self.refills += 1;
                    self.queue_all_edges(heap);
                    if heap.is_empty() {
                        return false;
                    }
                    continue;
                }
                return false;
            };
            if k > key_limit {
                heap.push(k, a, b, stamp);
                return true;
            }
            // A removed vertex's version was bumped too, so one comparison retires every entry
            // whose edge changed or vanished.
            if self.stamp(a, b) != stamp {
                continue;
            }
            let c = match self.evaluate_below(a, b, k) {
                Evaluation::Collapse(c) => c,
                Evaluation::Later(full) => {
                    heap.push(full, a, b, stamp);
                    continue;
                }
                Evaluation::Refused => continue,
            };
            let q = self.p.quadrics[c.keep as usize].sum(&self.p.quadrics[c.remove as usize]);
            let err2 = if q.weight > 0.0 {
                c.error / q.weight
            } else {
                0.0
            };
            if max_err2.is_some_and(|m| err2 > m) {
                // Quadrics only grow, so this edge will not become acceptable again.
                self.hit_max_error = true;
                continue;
            }
            // At most two faces go per collapse and faces > target, so the result is at worst one
            // below the target.
            self.faces -= self.apply(&c);
            self.collapses += 1;
            self.max_collapse_err2 = self.max_collapse_err2.max(err2);
            self.push_edges_of(c.keep, heap);
            if self.collapses >= next_report {
                progress(self.faces);
                next_report = self.collapses + 4096;
                if self.opts.cancel.is_cancelled() {
                    // The caller turns this into Error::Cancelled.
                    return false;
                }
            }
        }
        false
    }
}

/// Meshes at least this large are simplified in parts at once (see [`simplify_greedy`]);
/// smaller ones in one sequential run.
const PARTITION_MIN_FACES: usize = 100_000;
/// Faces per region of the first level, between 8 and 32 regions: a function of the face
/// count, not of the thread count, so the result is the same on every machine. Smaller regions
/// are faster per collapse (their data stays in cache): measured on the 1M scan at 1%, 32
/// regions then 4 took 1.52 s against 1.76 s for 8 regions then the sequential phase.
const REGION_FACES: usize = 32_768;
/// Regions of the second level.
const SECOND_LEVEL_REGIONS: usize = 4;
/// Cost ceiling step between the epochs of a level whose floors keep it from reaching its
/// stop (see [`partitioned_level`]); a few epochs still report progress.
const UNSTOPPABLE_LEVEL_STEP: f32 = 64.0;

/// The partitioned levels stop once the mesh is within 20% of the target.
fn partitioned_stop(target: usize) -> usize {
    (target as f64 * 1.2) as usize
}

/// Greedy simplification; `progress` receives the fraction of the needed collapses done.
///
/// Large meshes are simplified in levels, so that both cores (or more) work. The first level
/// cuts the vertices into runs of the Morton order (compact patches); each region runs its own
/// greedy queue on its faces, with the vertices on faces that cross regions pinned, so regions
/// never touch each other's data. The regions advance together through rising cost ceilings
/// (doubling each epoch): within a ceiling each region takes its cheapest collapses in order,
/// which is what one global queue would take across the mesh, up to the order between
/// independent regions, which does not change the result. A second level does the same with
/// fewer regions cut elsewhere, freeing the vertices the first pinned. The levels stop once
/// the mesh is within 20% of the target; then one sequential queue runs over the whole reduced
/// mesh, region borders included, with the quadrics accumulated so far, down to the exact
/// target.
pub fn simplify_greedy(
    input: &Mesh,
    opts: &SimplifyOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<(Mesh, SimplifyReport)> {
    let p = Prepared::new(input, opts);
    let pinned_vertices = p
        .mobility
        .iter()
        .filter(|&&m| m == Mobility::Pinned)
        .count();
    let nf = p.faces.len();
    let target = opts.target_faces;
    let need = nf.saturating_sub(target).max(1) as f32;
    let regions = opts.partitions.unwrap_or(if nf >= PARTITION_MIN_FACES {
        (nf / REGION_FACES).clamp(8, 32)
    } else {
        1
    });
    let mut levels = LevelStats::default();
    let p = if regions > 1 && target < nf {
        let mut report = |faces: usize| progress((nf - faces) as f32 / need);
        let first = Cuts::first(p.pos.len(), regions);
        let p = partitioned_level(p, opts, first, None, &mut levels, &mut report);
        if p.faces.len() > partitioned_stop(target) && !opts.cancel.is_cancelled() {
            // The second level: fewer, larger regions, each cut half a first-level region
            // along the Morton order from a first-level cut, so the vertices the first level
            // had to pin are interior now and thin out with the rest.
            let second = first.second(SECOND_LEVEL_REGIONS);
            partitioned_level(p, opts, second, None, &mut levels, &mut report)
        } else {
            p
        }
    } else {
        p
    };
    opts.cancel.check()?;
    let (mut s, mut heap) = State::new(p, opts);
    s.run(&mut heap, target, u32::MAX, &mut |faces| {
        progress((nf - faces) as f32 / need)
    });
    opts.cancel.check()?;
    progress(1.0);

    let stop_reason = if s.faces <= target {
        StopReason::TargetReached
    } else if s.hit_max_error || levels.hit_max_error {
        StopReason::MaxError
    } else {
        StopReason::NoValidCollapse
    };
    let out = build_output(&s.p, &s.face_alive, &s.alive, input.normals.is_some());
    let report = SimplifyReport {
        backend: opts.backend,
        input_faces: input.triangles.len(),
        target_faces: target,
        output_faces: out.triangles.len(),
        input_vertices: input.positions.len(),
        output_vertices: out.positions.len(),
        collapses: s.collapses + levels.collapses,
        max_collapse_error: s.max_collapse_err2.max(levels.max_collapse_err2).sqrt(),
        stop_reason,
        dropped_degenerate_faces: s.p.dropped_degenerate,
        pinned_vertices,
        rounds: None,
        blocked: None,
    };
    Ok((out, report))
}

#[derive(Default)]
struct LevelStats {
    collapses: usize,
    /// Times a region's queue was filled again (see `State::seeded_at`).
    refills: usize,
    max_collapse_err2: f64,
    hit_max_error: bool,
}

/// Where a partitioned level cuts the topological vertices (Morton ranks `0..nt`): into `base`
/// equal runs of the Morton order, the first starting `shift` ranks along (so run 0 wraps
/// around the end of the order), grouped `base / regions` at a time into `regions` regions.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Cuts {
    nt: usize,
    base: usize,
    regions: usize,
    shift: usize,
}

impl Cuts {
    /// The first level: `regions` runs from rank 0.
    fn first(nt: usize, regions: usize) -> Cuts {
        Cuts {
            nt,
            base: regions,
            regions,
            shift: 0,
        }
    }

    /// A second level of at most `regions` regions made of this level's runs moved half a run
    /// along, so each of its cuts is half a run from every cut of this level. (Cutting the
    /// shifted order into `regions` equal parts instead put cuts right on first-level cuts
    /// whenever the first level's count was not a multiple of it.)
    fn second(self, regions: usize) -> Cuts {
        Cuts {
            nt: self.nt,
            base: self.base,
            regions: regions.min(self.base),
            shift: self.nt / (2 * self.base),
        }
    }

    fn region_of(&self, t: u32) -> u32 {
        let nt = self.nt.max(1);
        let run = (t as usize + self.shift) % nt * self.base / nt;
        (run * self.regions / self.base) as u32
    }
}

/// One partitioned level of [`simplify_greedy`], its regions as `cuts` says: returns the whole
/// mesh, reduced, prepared for the next level or the final queue; adds to `stats`. `step`
/// overrides the factor between the epochs' cost ceilings (tests).
fn partitioned_level(
    mut p: Prepared,
    opts: &SimplifyOptions,
    cuts: Cuts,
    step: Option<f32>,
    stats: &mut LevelStats,
    progress: &mut dyn FnMut(usize),
) -> Prepared {
    use rayon::prelude::*;
    let nt = p.pos.len();
    assert_eq!(cuts.nt, nt, "cuts made for another mesh");
    let regions = cuts.regions;
    let nf = p.faces.len();
    let region_of = |t: u32| cuts.region_of(t);
    let face_topo = |f: usize| p.faces[f].map(|v| p.topo[v as usize]);
    let face_region: Vec<u32> = (0..nf)
        .map(|f| {
            let r = face_topo(f).map(region_of);
            if r[0] == r[1] && r[1] == r[2] {
                r[0]
            } else {
                u32::MAX
            }
        })
        .collect();
    // Vertices of faces that cross regions stay put in this level.
    let mut frontier = vec![false; nt];
    for (f, &r) in face_region.iter().enumerate() {
        if r == u32::MAX {
            for t in face_topo(f) {
                frontier[t as usize] = true;
            }
        }
    }
    let cut_faces = face_region.iter().filter(|&&r| r == u32::MAX).count();
    let ratio = opts.target_faces as f64 / nf as f64;

    struct Region<'a> {
        state: State<'a>,
        heap: Queue,
        /// Local topological vertex → topological vertex of the whole mesh.
        topo_global: Vec<u32>,
        floor: usize,
        own_cut: usize,
    }
    let p_ref = &p;
    // Each region's own faces and the crossing faces that touch it, in face order, from one
    // pass over the faces (filtering all faces once per region cost R times as much).
    let mut region_faces: Vec<Vec<u32>> = vec![Vec::new(); regions];
    for (f, &fr) in face_region.iter().enumerate() {
        if fr != u32::MAX {
            region_faces[fr as usize].push(f as u32);
        } else {
            let [a, b, c] = face_topo(f).map(region_of);
            region_faces[a as usize].push(f as u32);
            if b != a {
                region_faces[b as usize].push(f as u32);
            }
            if c != a && c != b {
                region_faces[c as usize].push(f as u32);
            }
        }
    }
    let mut subs: Vec<Region> = region_faces
        .into_par_iter()
        .enumerate()
        .map(|(r, faces)| {
            let r = r as u32;
            let own = faces
                .iter()
                .filter(|&&f| face_region[f as usize] == r)
                .count();
            let own_cut = faces.len() - own;
            let (sub, topo_faces, topo_global) = p_ref.subset(&faces, &frontier);
            // Pinned frontier vertices cannot thin out; if the interior were simplified far
            // below their density, its faces would fan out from them into long slivers. So a
            // region stops where its frontier would be a quarter of its vertices (a closed
            // triangle mesh has about two faces per vertex) and the next level or the final
            // queue takes it from there.
            let own_frontier = topo_global
                .iter()
                .filter(|&&t| frontier[t as usize] && region_of(t) == r)
                .count();
            let floor = own_cut + ((own as f64 * ratio).ceil() as usize).max(8 * own_frontier);
            let (state, heap) = State::with_topo_faces(sub, topo_faces, opts);
            Region {
                state,
                heap,
                topo_global,
                floor,
                own_cut,
            }
        })
        .collect();

    // Epochs of rising cost ceilings, from far below the cheapest edge.
    let stop_at = partitioned_stop(opts.target_faces);
    let total = |subs: &[Region]| {
        subs.iter()
            .map(|s| s.state.faces - s.own_cut)
            .sum::<usize>()
            + cut_faces
    };
    // The ceilings matter only for where the level stops: a region's collapses come in its own
    // cost order whatever the ceilings, so a region that runs down to its floor ends the same.
    // When the floors keep the level above `stop_at` (every level at 1%, the first at 10%),
    // large steps give the same result in fewer epochs; each epoch walks through every
    // region's data again from a cold cache. Measured on the 1M scan at 1%, same output: 1.35 s
    // with doubling, 1.17 s with steps of 64.
    // A region ends one face below its floor at the lowest (a collapse removes at most two),
    // or where it starts if that is lower already.
    let lowest = subs
        .iter()
        .map(|s| {
            s.state
                .faces
                .min(s.floor.saturating_sub(1))
                .saturating_sub(s.own_cut)
        })
        .sum::<usize>()
        + cut_faces;
    let step = step.unwrap_or(if lowest > stop_at {
        UNSTOPPABLE_LEVEL_STEP
    } else {
        2.0
    });
    let mut ceiling = 1e-30f32;
    loop {
        let limit = ceiling.to_bits();
        let more: Vec<bool> = subs
            .par_iter_mut()
            .map(|s| s.state.run(&mut s.heap, s.floor, limit, &mut |_| {}))
            .collect();
        let faces = total(&subs);
        progress(faces);
        if faces <= stop_at
            || !more.iter().any(|&m| m)
            || !ceiling.is_finite()
            || opts.cancel.is_cancelled()
        {
            break;
        }
        ceiling *= step;
    }
    debug_assert!(total(&subs) >= lowest, "a region went below its floor");

    // Write the regions back into the whole mesh: moved vertices, merged quadrics, live faces.
    let mut faces: Vec<[u32; 3]> = Vec::new();
    let mut origin: Vec<u32> = Vec::new();
    let mut ref_normal: Vec<[f32; 3]> = Vec::new();
    for (f, &r) in face_region.iter().enumerate() {
        if r == u32::MAX {
            faces.push(p.faces[f]);
            origin.push(p.face_origin[f]);
            ref_normal.push(p.ref_normal[f]);
        }
    }
    for (r, sub) in subs.iter().enumerate() {
        let st = &sub.state;
        stats.collapses += st.collapses;
        stats.refills += st.refills;
        stats.max_collapse_err2 = stats.max_collapse_err2.max(st.max_collapse_err2);
        stats.hit_max_error |= st.hit_max_error;
        for (lt, &gt) in sub.topo_global.iter().enumerate() {
            if region_of(gt) == r as u32 && st.alive[lt] {
                let g = gt as usize;
                p.pos[g] = st.p.pos[lt];
                p.quadrics[g] = st.p.quadrics[lt];
                p.border[g] = st.p.border[lt];
            }
        }
        for (sf, &alive) in st.face_alive.iter().enumerate() {
            // A sub-problem's faces carry their attribute vertices of the whole mesh and, as
            // origin, their index in the whole mesh's face list.
            let gf = st.p.face_origin[sf] as usize;
            if alive && face_region[gf] == r as u32 {
                faces.push(st.p.faces[sf]);
                origin.push(p.face_origin[gf]);
                ref_normal.push(p.ref_normal[gf]);
            }
        }
    }
    p.faces = faces;
    p.face_origin = origin;
    p.ref_normal = ref_normal;
    p
}

/// The output mesh: live faces with their materials and groups, positions moved back out of the
/// normalized frame, unused vertices dropped, normals recomputed when the input had normals.
pub(crate) fn build_output(
    p: &Prepared,
    face_alive: &[bool],
    vertex_alive: &[bool],
    normals: bool,
) -> Mesh {
    let mut out = p.mesh.clone_without_geometry();
    out.positions = p.mesh.positions.clone();
    out.uvs = p.mesh.uvs.clone();
    out.colors = p.mesh.colors.clone();
    for (v, pos) in out.positions.iter_mut().enumerate() {
        let t = p.topo[v] as usize;
        // Only moved vertices go back through the frame: a round trip through f64 could shift
        // a vertex that stayed (a locked border, a seam) by one float step.
        if vertex_alive[t] && p.pos[t] != p.normalize(*pos) {
            *pos = p.denormalize(p.pos[t]);
        }
    }
    let live: Vec<usize> = (0..p.faces.len()).filter(|&f| face_alive[f]).collect();
    out.triangles = live.iter().map(|&f| p.faces[f]).collect();
    let origin = |f: usize| p.face_origin[f] as usize;
    out.face_materials = p
        .mesh
        .face_materials
        .as_ref()
        .map(|m| live.iter().map(|&f| m[origin(f)]).collect());
    out.face_groups = p
        .mesh
        .face_groups
        .as_ref()
        .map(|g| live.iter().map(|&f| g[origin(f)]).collect());
    out.remove_unused_vertices();
    if normals {
        out.recompute_normals();
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ```text
    ///           C
    ///           |\
    ///           | \        the centre c of a flat fan; B sits just above the segment c–A.
    ///   D ----- c  B-A     Moving c onto A drags face (c, B, C) across the line B–C: it
    ///           |  /       folds over. Moving c onto D folds nothing.
    ///           E
    /// ```
    #[test]
    fn collapse_refuses_flip() {
        let ring = [
            [1.0, 0.0],
            [0.2, 0.05],
            [0.0, 1.0],
            [-1.0, 0.0],
            [0.0, -1.0],
        ];
        let mut pos = vec![[0.0f32, 0.0, 0.0]];
        pos.extend(ring.iter().map(|p| [p[0] as f32, p[1] as f32, 0.0]));
        let n = ring.len() as u32;
        let m = Mesh::new(
            pos.clone(),
            (0..n).map(|i| [0, 1 + i, 1 + (i + 1) % n]).collect(),
        );
        let mut opts = SimplifyOptions::with_faces(4);
        opts.lock_border = true;
        let p = Prepared::new(&m, &opts);
        // Topological ids are in Morton order: find them by position.
        let id = |q: [f32; 3]| p.pos.iter().position(|&x| x == p.normalize(q)).unwrap() as u32;
        let (centre, folding, harmless) = (id(pos[0]), id(pos[1]), id(pos[4]));
        let (mut s, _) = State::new(p, &opts);
        assert!(
            s.evaluate(centre, folding).is_none(),
            "the folding collapse was allowed"
        );
        let c = s
            .evaluate(centre, harmless)
            .expect("the harmless collapse was refused");
        assert_eq!((c.keep, c.remove), (harmless, centre));
        // With the normal limit lifted, the folding collapse goes through: it is the flip
        // check, not some other rule, that refuses it.
        let mut lax = opts.clone();
        lax.max_normal_angle_deg = 180.0;
        lax.min_quality = 0.0;
        let (mut s, _) = State::new(Prepared::new(&m, &lax), &lax);
        assert!(s.evaluate(centre, folding).is_some());
    }

    /// A level that its floors keep above its stop ends the same whatever the steps between
    /// its cost ceilings: each region takes its collapses in its own cost order down to its
    /// floor, and fills its queue again when it runs dry exactly where an uninterrupted run
    /// would. (This is what lets such a level take steps of 64 instead of doubling.)
    #[test]
    fn unstoppable_level_ignores_ceiling_steps() {
        let m = crate::mesh::noisy_sphere(5, 0.002, 3);
        let mut opts = SimplifyOptions::with_ratio(m.triangles.len(), 0.01).unwrap();
        // Without an error bound the regions run down to their floors; with a tight one their
        // queues run dry above them and are filled again (edges refused earlier may have
        // become valid), the path a cut-up run used to skip.
        for max_error in [None, Some(1e-4)] {
            opts.max_error = max_error;
            let level = |step| {
                let p = Prepared::new(&m, &opts);
                let cuts = Cuts::first(p.pos.len(), 8);
                let mut stats = LevelStats::default();
                let p = partitioned_level(p, &opts, cuts, Some(step), &mut stats, &mut |_| {});
                let state = (p.faces, p.pos, p.quadrics, p.border);
                (state, stats.collapses, stats.refills)
            };
            let doubling = level(2.0);
            let what = format!("max error {max_error:?}");
            assert!(
                doubling.0.0.len() > partitioned_stop(opts.target_faces),
                "{what}: the floors should keep this level above its stop: {} faces",
                doubling.0.0.len()
            );
            assert!(doubling.1 > 0, "{what}: the level collapsed nothing");
            if max_error.is_some() {
                assert!(doubling.2 > 0, "{what}: no region filled its queue again");
            }
            // 1e30: ceilings 1e-30, 1, 1e30 and infinity, so nearly one uninterrupted run.
            for step in [64.0, 1e30] {
                assert!(
                    level(step) == doubling,
                    "{what}: steps of {step} changed the level"
                );
            }
        }
    }

    /// The queue gives entries back in (key, a, b, stamp) order across buckets and within one,
    /// gives an entry pushed below the last key taken next, sorts entries pushed while it is
    /// being drained among the rest, and drops the entries of a bucket that are no longer
    /// current when that bucket comes up.
    #[test]
    fn queue_pops_in_key_order_and_drops_stale_entries() {
        // A deterministic spread of keys over many buckets and exponents, with ties.
        let keys: Vec<u32> = (0..5000u32)
            .map(|i| {
                (0.5 + (i.wrapping_mul(2_654_435_761) % 977) as f32 * 1e-3).to_bits() >> (i % 3)
            })
            .collect();
        let mut q = Queue::new();
        for (i, &k) in keys.iter().enumerate() {
            q.push(k, i as u32 % 7, i as u32, 0);
        }
        let mut expected: Vec<(u32, u32, u32, u32)> = keys
            .iter()
            .enumerate()
            .map(|(i, &k)| (k, i as u32 % 7, i as u32, 0))
            .collect();
        expected.sort_unstable();
        // Pushed while draining, as a run re-keys edges: above everything (the top bucket,
        // whose end is 2^32) and in the middle.
        let late = [
            (u32::MAX, 3, 4, 0),
            (0x8000_0000, 1, 2, 0),
            (keys[17], 8, 9, 0),
        ];
        expected.extend(late);
        expected.sort_unstable();
        let mut got = Vec::new();
        while let Some(e) = q.pop(|_, _, _| true) {
            got.push(e);
            if got.len() == 100 {
                // Below everything still queued (and below the last key taken): it must come
                // out next.
                let below = got[99].0 - 1;
                q.push(below, 0, u32::MAX, 9);
                assert_eq!(q.pop(|_, _, _| true), Some((below, 0, u32::MAX, 9)));
                for (k, a, b, stamp) in late {
                    q.push(k, a, b, stamp);
                }
            }
        }
        assert_eq!(got, expected);
        assert!(q.is_empty());
        // Filled again after running dry, it starts from the bottom.
        q.push(5, 0, 1, 0);
        q.push(3, 0, 2, 0);
        assert_eq!(q.pop(|_, _, _| true), Some((3, 0, 2, 0)));
        assert_eq!(q.pop(|_, _, _| true), Some((5, 0, 1, 0)));
        assert!(q.is_empty());

        // Odd stamps are stale: none of them comes out, every even one does.
        let mut q = Queue::new();
        for (i, &k) in keys.iter().enumerate() {
            q.push(k, 1, i as u32, i as u32 % 2);
        }
        let mut n = 0;
        while let Some((_, _, _, stamp)) = q.pop(|_, _, stamp| stamp == 0) {
            assert_eq!(stamp, 0);
            n += 1;
        }
        assert_eq!(n, keys.len().div_ceil(2));
        assert!(q.is_empty());
    }

    /// Every cut of the second level is half a first-level run from the nearest first-level
    /// cut, whatever the first level's region count, and the second level has all its regions.
    #[test]
    fn second_level_cuts_fall_between_first_level_cuts() {
        let nt = 100_003;
        let cut_ranks = |c: Cuts| -> Vec<usize> {
            (1..nt)
                .filter(|&t| c.region_of(t as u32) != c.region_of(t as u32 - 1))
                .collect()
        };
        for base in 2..=40 {
            let first = Cuts::first(nt, base);
            let second = first.second(SECOND_LEVEL_REGIONS);
            let (a, b) = (cut_ranks(first), cut_ranks(second));
            assert_eq!(a.len(), base - 1);
            let regions: std::collections::BTreeSet<u32> =
                (0..nt as u32).map(|t| second.region_of(t)).collect();
            assert_eq!(regions.len(), SECOND_LEVEL_REGIONS.min(base), "{base} runs");
            let run = nt / base;
            for &c in &b {
                let nearest = a.iter().map(|&x| x.abs_diff(c)).min().unwrap_or(nt);
                assert!(
                    nearest + 2 >= run / 2,
                    "{base} runs: a second-level cut at {c} is {nearest} from a first-level cut"
                );
            }
        }
    }
}
