//! The set-up every run starts from: the mesh welded, its positions grouped into topological
//! vertices in Morton order, normalized, with per-vertex quadrics (faces, borders, seams) and
//! how each vertex may move.

use super::vertex_pass::{Around, Geometry, VertexPass};
pub(crate) use super::vertex_pass::{Carried, Mobility};
use crate::mesh::Mesh;
use crate::mesh::prepare::{Surface, counting_sort, denormalize, normalize};
use crate::options::SimplifyOptions;
use crate::quadric::Quadric;
use crate::quadric::attributes::{Attributes, Layout};
use rayon::prelude::*;

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
        let geo = Geometry {
            topo: &topo,
            faces: &faces,
            pos: &pos,
        };
        // The faces around each vertex, in face order (a counting sort, mostly on one core),
        // and beside it each face's plane and reference normal.
        let ((corners, corner_start), (ref_normal, planes)) = rayon::join(
            || counting_sort(nt, faces.len() * 3, |c| topo[faces[c / 3][c % 3] as usize]),
            || geo.planes_and_normals(&face_origin, carried),
        );
        let around = Around {
            geo,
            corners: &corners,
            corner_start: &corner_start,
        };
        let pass = VertexPass {
            around,
            planes: &planes,
            attr_count: &attr_count,
            opts,
        };
        let (mut quadrics, (mut mobility, border)) = pass.quadrics_and_mobility(nt);
        drop(planes);
        let attrs = layout.map(|layout| around.fold_attributes(&mesh, layout, &mut quadrics));
        let held = hold_pins(opts, carried, &topo, &weld_remap, &mut mobility);
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

/// The caller's pins (a tile's border), which override whatever the vertex would be: pins
/// `mobility` there and returns which vertices they hold.
fn hold_pins(
    opts: &SimplifyOptions,
    carried: Option<&Carried>,
    topo: &[u32],
    weld_remap: &[u32],
    mobility: &mut [Mobility],
) -> Vec<bool> {
    let mut held = vec![false; mobility.len()];
    // Pins name the original's vertices, which a carried mesh does not have; `simplify`
    // refuses pins for every method but qem.
    debug_assert!(carried.is_none() || opts.pin.is_empty());
    for &v in opts.pin.iter().filter(|_| carried.is_none()) {
        let t = topo[weld_remap[v as usize] as usize] as usize;
        mobility[t] = Mobility::Pinned;
        held[t] = true;
    }
    held
}

#[cfg(test)]
mod tests {
    use super::super::vertex_pass::{FAN_ROW, interior_fans};
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
