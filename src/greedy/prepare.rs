//! The set-up every run starts from: the mesh welded, its positions grouped into topological
//! vertices in Morton order, normalized, with per-vertex quadrics (faces, borders, seams) and
//! how each vertex may move.

use super::vec::{cross, dot, norm, sub};
use crate::mesh::Mesh;
use crate::mesh::prepare::{Surface, counting_sort, denormalize, normalize};
use crate::options::SimplifyOptions;
use crate::quadric::Quadric;
use crate::quadric::attributes::{Attributes, FaceTerms, Layout, MAX_STRIDE};
use rayon::prelude::*;

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

/// The prepared surface: welded topology, normalized positions, per-vertex quadrics and flags.
/// Shared by the greedy backend and (later) the parallel ones, which start from the same state.
#[derive(Clone)]
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
    /// Pinned by the caller (`SimplifyOptions::pin`, a tile's border): no collapse may join two
    /// of these by a new edge, since the neighbouring tile may hold that edge already.
    pub held: Vec<bool>,
    pub border: Vec<bool>,
    /// More than one attribute vertex at this position.
    pub seam: Vec<bool>,
    pub center: [f64; 3],
    pub scale: f64,
    pub dropped_degenerate: usize,
    /// Appearance attributes in the cost (`opts.attributes`), per attribute vertex; their
    /// geometric part is folded into `quadrics`. `None`: the attributes ride along.
    pub attrs: Option<Attributes>,
    /// A sub-problem's attribute vertex → the whole mesh's, when it has `attrs` (see
    /// [`Prepared::subset`]); empty otherwise: the ids are the whole's.
    pub attr_global: Vec<u32>,
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

impl Prepared {
    /// The set-up, with the attributes `opts.attributes` weighs in the quadrics.
    pub fn new(input: &Mesh, opts: &SimplifyOptions) -> Prepared {
        Prepared::build(input, opts, None)
    }

    /// As [`Prepared::new`]; with `carried`, in its frame and with its reference normals.
    pub fn build(input: &Mesh, opts: &SimplifyOptions, carried: Option<&Carried>) -> Prepared {
        let surface = Surface::in_frame(input, carried.map(|c| c.frame));
        let layout = Layout::new(&surface.welded, &opts.attributes);
        let Surface {
            welded: mesh,
            class: topo,
            representative: firsts,
            attr_count,
            faces,
            face_origin,
            dropped_degenerate,
            weld_remap,
            center,
            scale,
        } = surface;
        let nt = firsts.len();
        let pos: Vec<[f64; 3]> = firsts
            .par_iter()
            .map(|&v| normalize(mesh.positions[v as usize], center, scale))
            .collect();

        let tf = |f: &[u32; 3]| f.map(|v| topo[v as usize]);
        // A face's plane: its unit normal, offset and twice its area, no area for a face
        // without a normal.
        let plane = |f: usize| -> [f64; 5] {
            let [p0, p1, p2] = tf(&faces[f]).map(|v| pos[v as usize]);
            let c = cross(sub(p1, p0), sub(p2, p0));
            let len = norm(c);
            if len > 0.0 {
                let n = c.map(|x| x / len);
                [n[0], n[1], n[2], -dot(n, p0), len]
            } else {
                [0.0; 5]
            }
        };
        // The faces around each vertex, in face order (a counting sort, mostly on one core),
        // and beside it each face's plane and reference normal: on the 1M scan 0.045-0.054 s
        // one after the other, 0.030-0.037 s side by side.
        let ((corners, corner_start), (ref_normal, planes)) = rayon::join(
            || counting_sort(nt, faces.len() * 3, |c| topo[faces[c / 3][c % 3] as usize]),
            || -> (Vec<[f32; 3]>, Vec<[f64; 5]>) {
                (0..faces.len())
                    .into_par_iter()
                    .map(|f| {
                        let plane = plane(f);
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
            },
        );
        let faces_of = |v: usize| {
            corners[corner_start[v] as usize..corner_start[v + 1] as usize]
                .iter()
                .map(|&c| c / 3)
        };
        // Per vertex, in parallel: the sum of its faces' plane quadrics in face order, then the
        // constraint planes of its border and seam edges in ascending order of the other end,
        // which is the order one pass over all edges sorted by (low, high) end gives each
        // vertex; so the sums do not depend on the thread count. Each face's plane is read
        // from the reference normals' pass (40 bytes a face) and its quadric made per vertex:
        // cheaper than one 88-byte quadric per face written out and read back, and than the
        // plane worked out again at each corner (`hybrid` on the 1M scan at 10%: this set-up
        // 0.0390 -> 0.0348 s, medians of 21 calls; `cpu` 0.191 -> 0.184 s, of 9). Each
        // constraint is computed once per vertex that needs it. Measured on the 1M scan, the
        // sequential pass over all edges with a union-find over all corners took 0.12 s.
        // Straight into the three arrays: collecting tuples and copying them out took 0.027 s,
        // on one core, of the 0.25 s set-up of the 1M scan.
        let seamless = !attr_count.par_iter().any(|&c| c > 1);
        let (mut quadrics, (mut mobility, border)): (Vec<Quadric>, (Vec<Mobility>, Vec<bool>)) = (0
            ..nt)
            .into_par_iter()
            .map_init(
                || (Vec::new(), Vec::new()),
                |(edges, fan): &mut (Vec<u64>, Vec<u32>), v| {
                    let mut q = Quadric::default();
                    for f in faces_of(v) {
                        let [n0, n1, n2, d, len] = planes[f as usize];
                        if len > 0.0 {
                            q.add(&Quadric::from_plane([n0, n1, n2], d, 0.5 * len));
                        }
                    }
                    // Most vertices are inside a surface without seams: their edges need no
                    // sorting, since they add no constraint plane. The 1M scan at 10% (`cpu`,
                    // two cores, 8 calls each way, turn about): this pass 0.073 -> 0.064 s.
                    if seamless {
                        let around = faces_of(v).map(|f| tf(&faces[f as usize]));
                        if let Some(fans) = interior_fans(around, v as u32, fan) {
                            let mobility = if fans > 1 {
                                Mobility::Pinned
                            } else {
                                Mobility::Free
                            };
                            return (q, (mobility, false));
                        }
                    }
                    let mut mobility = if attr_count[v] > 1 {
                        Mobility::Seam
                    } else {
                        Mobility::Free
                    };
                    let mut border = false;
                    // The edges at v, each with the place of its face among v's faces (so in
                    // face order within an edge): 1 face for a border, 2 for a manifold edge,
                    // more for a non-manifold one. Packed `other end << 32 | place` and sorted
                    // as one integer: the order of (other end, face, place) triples, since the
                    // places follow the faces. This per-vertex pass on the 1M scan at 10%
                    // (two cores, median of 15): 0.0996 s sorting triples, 0.0965 s this.
                    let vt = v as u32;
                    let face_at =
                        |i: u64| corners[corner_start[v] as usize + i as u32 as usize] / 3;
                    edges.clear();
                    for (i, f) in faces_of(v).enumerate() {
                        let t = tf(&faces[f as usize]);
                        edges.extend(
                            t.into_iter()
                                .filter(|&u| u != vt)
                                .map(|u| (u as u64) << 32 | i as u64),
                        );
                    }
                    edges.sort_unstable();
                    // v's faces joined across its manifold edges: the fans around v.
                    fan.clear();
                    fan.extend(0..faces_of(v).len() as u32);
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
                                // Hoppe's boundary constraint: a plane through the edge,
                                // perpendicular to its face, weighted by the squared edge length
                                // so it scales like an area.
                                let t = tf(&faces[face_at(edges[i]) as usize]);
                                let [p0, p1, p2] = t.map(|v| pos[v as usize]);
                                let fnrm = cross(sub(p1, p0), sub(p2, p0));
                                if let Some(c) = edge_constraint(pa, pb, fnrm, opts.border_weight) {
                                    q.add(&c);
                                }
                            }
                            2 => {
                                let (f1, f2) = (face_at(edges[i]), face_at(edges[i + 1]));
                                join(fan, edges[i] as u32, edges[i + 1] as u32);
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
                    if fan_count(fan) > 1 {
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
        drop(planes);
        let attrs = layout.map(|layout| {
            let mut at = Attributes::new(&mesh, layout);
            let stride = at.layout.stride();
            // Per vertex, in parallel and in face order like the geometric part: each face's
            // attribute functions folded into the vertex's quadric and added to the sums of the
            // attribute vertex the face uses there (a seam vertex has one per side).
            // In place, per vertex: the folded terms straight into its quadric, the first
            // side's sums into a row of its own (scattered to the attribute vertices after),
            // further sides (seams only) in a list, so most vertices allocate and copy nothing.
            // Collecting 400-byte tuples per vertex was most of the 70M instructions of memcpy
            // simplifying the painted horse.
            let mut first_sums = vec![0.0f64; nt * stride];
            let mut first_id = vec![u32::MAX; nt];
            let extra: Vec<Vec<(u32, [f64; MAX_STRIDE])>> = quadrics
                .par_iter_mut()
                .zip(first_sums.par_chunks_mut(stride))
                .zip(first_id.par_iter_mut())
                .enumerate()
                .map(|(v, ((q, first), first_av))| {
                    let mut sides: Vec<(u32, [f64; MAX_STRIDE])> = Vec::new();
                    let mut ft = FaceTerms::default();
                    for f in faces_of(v) {
                        let f = f as usize;
                        let t = tf(&faces[f]);
                        let p = t.map(|u| pos[u as usize]);
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
                })
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
        });
        // The caller's pins (a tile's border) override whatever the vertex would be.
        let mut held = vec![false; nt];
        // Pins name the original's vertices, which a carried mesh does not have; `simplify`
        // refuses pins for every method but qem.
        debug_assert!(carried.is_none() || opts.pin.is_empty());
        for &v in opts.pin.iter().filter(|_| carried.is_none()) {
            let t = topo[weld_remap[v as usize] as usize] as usize;
            mobility[t] = Mobility::Pinned;
            held[t] = true;
        }
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
            held,
            border,
            seam: attr_count.iter().map(|&c| c > 1).collect(),
            center,
            scale,
            dropped_degenerate,
            attrs,
            attr_global: Vec::new(),
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
        // The vertices used, in ascending order, through a bitmap over the span of their ids
        // with each word's count of used ids before it; a vertex's local id is its rank.
        // Measured on the 1M scan: sorting the 400k corners of each of 8 regions and
        // binary-searching them took 0.05 s per region, twice the region's whole queue set-up.
        // A table of one u32 per id in the span came next; but a region's faces that cross
        // into regions far along the Morton order stretch its span to much of the mesh, and
        // filling and scanning those tables cost 47M of `qem`'s 11.4G instructions on the 1M
        // scan at 10% (callgrind, one thread, the read included).
        let corner_topo = |f: u32| self.faces[f as usize].map(|v| self.topo[v as usize]);
        let (lo, hi) = faces
            .iter()
            .flat_map(|&f| corner_topo(f))
            .fold((u32::MAX, 0), |(lo, hi), t| (lo.min(t), hi.max(t)));
        let span = (hi + 1).saturating_sub(lo) as usize;
        let mut used = vec![0u64; span.div_ceil(64)];
        for &f in faces {
            for t in corner_topo(f) {
                let i = (t - lo) as usize;
                used[i / 64] |= 1 << (i % 64);
            }
        }
        let mut before = Vec::with_capacity(used.len());
        let mut topo_global = Vec::new();
        for (w, &bits) in used.iter().enumerate() {
            before.push(topo_global.len() as u32);
            let mut rest = bits;
            while rest != 0 {
                topo_global.push(lo + (w * 64) as u32 + rest.trailing_zeros());
                rest &= rest - 1;
            }
        }
        let local = |t: u32| {
            let i = (t - lo) as usize;
            before[i / 64] + (used[i / 64] & ((1u64 << (i % 64)) - 1)).count_ones()
        };
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
        let mut sub_faces: Vec<[u32; 3]> = faces.iter().map(|&f| self.faces[f as usize]).collect();
        // With attributes, the sub-problem numbers its attribute vertices densely (ascending
        // ids of the whole) and carries their values and sums, so regions run apart;
        // `attr_global` maps them back.
        let (attrs, attr_global) = match &self.attrs {
            None => (None, Vec::new()),
            Some(at) => {
                let mut ids: Vec<u32> = sub_faces.iter().flatten().copied().collect();
                ids.sort_unstable();
                ids.dedup();
                let local = |a: u32| ids.binary_search(&a).expect("a corner of the subset") as u32;
                for t in &mut sub_faces {
                    *t = t.map(local);
                }
                for a in &mut first_attr {
                    *a = local(*a);
                }
                let (m, s) = (at.layout.m, at.layout.stride());
                let local_at = Attributes {
                    layout: at.layout.clone(),
                    value: ids.iter().flat_map(|&a| at.values(a)).copied().collect(),
                    sums: ids.iter().flat_map(|&a| at.sums_of(a)).copied().collect(),
                };
                debug_assert_eq!(local_at.value.len(), ids.len() * m);
                debug_assert_eq!(local_at.sums.len(), ids.len() * s);
                (Some(local_at), ids)
            }
        };
        let sub = Prepared {
            mesh: Mesh::default(),
            topo: Vec::new(),
            first_attr,
            faces: sub_faces,
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
            held: (0..n).map(|l| self.held[pick(l)]).collect(),
            border: (0..n).map(|l| self.border[pick(l)]).collect(),
            seam: (0..n).map(|l| self.seam[pick(l)]).collect(),
            center: self.center,
            scale: self.scale,
            dropped_degenerate: 0,
            attrs,
            attr_global,
        };
        (sub, topo_faces, topo_global)
    }

    /// Into the normalized frame; the same arithmetic as the set-up, so a vertex that never
    /// moved compares equal.
    pub fn normalize(&self, p: [f32; 3]) -> [f64; 3] {
        normalize(p, self.center, self.scale)
    }

    pub fn denormalize(&self, p: [f64; 3]) -> [f32; 3] {
        denormalize(p, self.center, self.scale)
    }
}

/// Neighbour entries (two per face) up to which [`interior_fans`] works on a fixed-width row:
/// eight faces around a vertex.
const FAN_ROW: usize = 16;

/// The number of fans `v`'s faces `around` (topological, each holding `v` once) make when
/// every neighbour is on exactly two of them: no border, seam or non-manifold edge at `v`, so
/// its set-up adds no constraint plane. `None` otherwise, or beyond [`FAN_ROW`] entries.
/// Counted against a fixed-width row (which the compiler vectorizes) instead of sorting the
/// entries; the fans are the same sets whatever order their faces are joined in.
fn interior_fans(
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
fn join(fan: &mut [u32], a: u32, b: u32) {
    let (a, b) = (fan_root(fan, a), fan_root(fan, b));
    fan[a.max(b) as usize] = a.min(b);
}

/// The number of sets (fans) in `fan`.
fn fan_count(fan: &mut [u32]) -> usize {
    (0..fan.len() as u32)
        .filter(|&x| fan_root(fan, x) == x)
        .count()
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Faces around vertex 0: each fan a ring of `ring` new neighbours, closed (the last face
    /// back to the first neighbour) or open (a border at both ends).
    fn fans(spec: &[(usize, bool)]) -> Vec<[u32; 3]> {
        let mut next = 1u32;
        let mut out = Vec::new();
        for &(ring, closed) in spec {
            let first = next;
            let faces = if closed { ring } else { ring - 1 };
            for i in 0..faces as u32 {
                let a = first + i;
                let b = if i + 1 == ring as u32 { first } else { a + 1 };
                out.push([0, a, b]);
            }
            next += ring as u32;
        }
        out
    }

    /// The fans of vertex 0 counted with a sorted edge list: each neighbour's faces, `None`
    /// unless every neighbour is on exactly two, else the components of faces joined across
    /// their shared neighbours.
    fn sorted_fans(around: &[[u32; 3]]) -> Option<usize> {
        let mut edges: Vec<(u32, usize)> = Vec::new();
        for (i, t) in around.iter().enumerate() {
            edges.extend(t.iter().filter(|&&u| u != 0).map(|&u| (u, i)));
        }
        edges.sort_unstable();
        let mut set: Vec<usize> = (0..around.len()).collect();
        for run in edges.chunk_by(|a, b| a.0 == b.0) {
            if run.len() != 2 {
                return None;
            }
            let (a, b) = (set[run[0].1], set[run[1].1]);
            set.iter_mut().filter(|s| **s == b).for_each(|s| *s = a);
        }
        set.sort_unstable();
        set.dedup();
        Some(set.len())
    }

    /// The row's count equals the sorted list's: closed fans (one, two or three at a vertex),
    /// open fans and a mix (borders), an edge on three faces. Past eight faces the row gives
    /// way (`None`) and the sorted count stands.
    #[test]
    fn interior_fans_equal_the_sorted_count() {
        let mut nonmanifold = fans(&[(4, true)]);
        nonmanifold.push([0, 1, 9]);
        let two_reversed: Vec<[u32; 3]> = fans(&[(3, true), (3, true)]).into_iter().rev().collect();
        // (faces around vertex 0, the row's answer, the sorted count)
        let cases = [
            (fans(&[(6, true)]), Some(1), Some(1)),
            (fans(&[(8, true)]), Some(1), Some(1)),
            (fans(&[(3, true), (3, true)]), Some(2), Some(2)),
            (fans(&[(3, true), (5, true)]), Some(2), Some(2)),
            (two_reversed, Some(2), Some(2)),
            (fans(&[(6, false)]), None, None),
            (fans(&[(3, true), (4, false)]), None, None),
            (nonmanifold, None, None),
            (fans(&[(9, true)]), None, Some(1)),
            (fans(&[(3, true), (3, true), (3, true)]), None, Some(3)),
        ];
        let mut fan = Vec::new();
        for (around, row, sorted) in cases {
            assert_eq!(sorted_fans(&around), sorted, "{around:?}");
            let got = interior_fans(around.iter().copied(), 0, &mut fan);
            assert_eq!(got, row, "{around:?}");
            if around.len() <= FAN_ROW / 2 {
                assert_eq!(got, sorted, "{around:?}");
            }
        }
    }

    /// A vertex where closed fans meet is pinned and one with a single closed fan is free,
    /// with few faces (the row) and with many (the sorted path); no vertex of a closed
    /// surface is a border.
    #[test]
    fn fans_meeting_at_a_vertex_pin_it() {
        for ring in [3, 6] {
            // Two closed cones with apex 0, each capped by a fan around a centre vertex.
            let mut triangles = fans(&[(ring, true), (ring, true)]);
            for cone in 0..2u32 {
                let first = 1 + cone * ring as u32;
                let centre = 1 + 2 * ring as u32 + cone;
                for i in 0..ring as u32 {
                    let a = first + i;
                    let b = first + (i + 1) % ring as u32;
                    triangles.push([centre, b, a]);
                }
            }
            let mut positions = vec![[0.0f32; 3]];
            for cone in 0..2 {
                let z = if cone == 0 { 1.0 } else { -1.0 };
                for i in 0..ring {
                    let a = i as f32 * std::f32::consts::TAU / ring as f32;
                    positions.push([a.cos(), a.sin(), z]);
                }
            }
            positions.extend([[0.0, 0.0, 1.5], [0.0, 0.0, -1.5]]);
            let m = Mesh::new(positions, triangles);
            let p = Prepared::new(&m, &SimplifyOptions::with_faces(4));
            let apex = p.topo[0] as usize;
            assert_eq!(p.mobility[apex], Mobility::Pinned, "ring {ring}");
            let mut others = (0..p.pos.len()).filter(|&v| v != apex);
            assert!(others.all(|v| p.mobility[v] == Mobility::Free));
            assert!(!p.border.contains(&true));
        }
    }
}
