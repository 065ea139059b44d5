//! Evaluating one edge: where its collapse puts the survivor and at what error, then the checks
//! that the collapse keeps the mesh valid (no flip, no needle, the link condition, borders and
//! seams) and the quality-weighted priority.

use super::prepare::Mobility;
use super::queue::key;
use super::state::{DEAD, State};
use super::vec::{cross, dot, norm, sub};
use crate::quadric::Quadric;
use crate::quadric::attributes::{Attributes, hold, reduce_pair};

/// Attribute vertices of a survivor counted in its collapse cost: a seam vertex has two sides,
/// a junction of seams three or four.
const GROUPS: usize = 4;

/// A survivor's attribute vertices (the first `.1` of `.0`) and the removed vertex's
/// `(from, to)` pairs onto them.
type SurvivorSides = ([u32; GROUPS], usize, [(u32, u32); 2]);

/// Where two free vertices `a` and `b` meet under `q`: its minimum, or where it is ill
/// conditioned the cheapest of the two ends and the midpoint. The survivor is the endpoint
/// nearer the new position (with attributes riding along, its values fit best). Returns
/// (survivor, removed, position, error).
#[inline(always)]
fn meet(
    q: &Quadric,
    (a, pa): (u32, [f64; 3]),
    (b, pb): (u32, [f64; 3]),
) -> (u32, u32, [f64; 3], f64) {
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
    if dot(sub(pos, pa), sub(pos, pa)) <= dot(sub(pos, pb), sub(pos, pb)) {
        (a, b, pos, err)
    } else {
        (b, a, pos, err)
    }
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

/// What [`State::evaluate_below`] found for an edge.
pub(super) enum Evaluation {
    /// Not allowed now (a flip, a needle, the link condition, a seam).
    Refused,
    /// Its priority (the key given) grew above the bound: back into the queue.
    Later(u32),
    Collapse(Collapse),
}

/// A collapse that passed every check: `remove` goes into `keep`, which moves to `pos`.
#[derive(Debug, Clone, Copy)]
pub(super) struct Collapse {
    pub(super) keep: u32,
    pub(super) remove: u32,
    pub(super) pos: [f64; 3],
    pub(super) error: f64,
    /// (attribute vertex of `remove`, attribute vertex of `keep` its corners take); the second
    /// pair is used only when a seam vertex slides along its seam (one pair per side).
    pub(super) attr_map: [(u32, u32); 2],
}

impl<'a> State<'a> {
    /// Position and quadric error of collapsing edge (a, b), ignoring validity: the queue key.
    /// Inlined (with `Quadric::optimum`) into its callers, which call it for every edge
    /// around a vertex: 1.263 → 1.206 s on the 1M scan at 1% (min of 5, output identical).
    #[inline]
    pub(super) fn placement(&self, a: u32, b: u32) -> Option<(u32, u32, [f64; 3], f64)> {
        match &self.p.attrs {
            None => self.placement_geometric(a, b),
            // Two free vertices: the attribute solve alone places them.
            Some(at)
                if self.p.mobility[a as usize] == Mobility::Free
                    && self.p.mobility[b as usize] == Mobility::Free =>
            {
                self.placement_with_attributes(at, (a, b, [0.0; 3], 0.0))
            }
            Some(at) => {
                let found = self.placement_geometric(a, b)?;
                self.placement_with_attributes(at, found)
            }
        }
    }

    /// [`State::placement`] with the attribute quadrics: two free vertices meet where the
    /// quadric reduced by their merged attribute sums is least (position and values from one
    /// solve); a survivor that stays put is charged, at its place, with each of its attribute
    /// vertices taking its best values, the removed vertex's sums joining the side they map to.
    fn placement_with_attributes(
        &self,
        at: &Attributes,
        (keep, remove, pos, _): (u32, u32, [f64; 3], f64),
    ) -> Option<(u32, u32, [f64; 3], f64)> {
        let (k, r) = (keep as usize, remove as usize);
        let q = self.p.quadrics[k].sum(&self.p.quadrics[r]);
        let m = at.layout.m;
        if self.p.mobility[k] == Mobility::Free && self.p.mobility[r] == Mobility::Free {
            let rq = reduce_pair(
                &q,
                m,
                at.sums_of(self.p.first_attr[k]),
                at.sums_of(self.p.first_attr[r]),
            );
            return Some(meet(&rq, (keep, self.p.pos[k]), (remove, self.p.pos[r])));
        }
        // A survivor that stays put (a border, a seam, a pin) keeps its values too: a seam's
        // UVs sit on its chart's boundary, and moving them would open the seam in the texture.
        // Held values make the error linear in the sums, so each attribute vertex of the
        // survivor is held against its own sums and those of the removed vertex's side that
        // joins it, one after the other: forming each merged group first (and a 1.2 KB array of
        // them) was 90M of 1.43G instructions simplifying the painted horse to 1%.
        let (keeps, n, map) = self.attribute_groups(keep, remove)?;
        let mut hq = q;
        for &kv in &keeps[..n] {
            let values = at.values(kv);
            hq = hold(&hq, &at.layout, at.sums_of(kv), values);
            if let Some(&(from, _)) = map.iter().find(|&&(_, to)| to == kv) {
                hq = hold(&hq, &at.layout, at.sums_of(from), values);
            }
        }
        Some((keep, remove, pos, hq.eval(pos)))
    }

    /// `keep`'s attribute vertices (at most [`GROUPS`]; a seam junction with more leaves the
    /// rest out) and which of `remove`'s joins which (`(from, to)` pairs), or `None` when
    /// `remove`'s sides cannot be matched.
    fn attribute_groups(&self, keep: u32, remove: u32) -> Option<SurvivorSides> {
        let (k, r) = (keep as usize, remove as usize);
        let map = if self.p.mobility[r] == Mobility::Seam {
            self.seam_slide(remove, keep)?
        } else {
            let to = if self.p.seam[k] {
                self.keep_attr_on_edge(keep, remove)?
            } else {
                self.p.first_attr[k]
            };
            [(self.p.first_attr[r], to), (u32::MAX, u32::MAX)]
        };
        let mut keeps = [u32::MAX; GROUPS];
        let mut n = 0;
        if self.p.seam[k] {
            for &f in self.vert_faces.get(k) {
                let t = self.topo_faces[f as usize];
                if t[0] == DEAD {
                    continue;
                }
                let i = t.iter().position(|&u| u == keep)?;
                let av = self.p.faces[f as usize][i];
                if !keeps[..n].contains(&av) && n < GROUPS {
                    keeps[n] = av;
                    n += 1;
                }
            }
        } else {
            keeps[0] = self.p.first_attr[k];
            n = 1;
        }
        Some((keeps, n, map))
    }

    /// The attribute vertex `keep` uses in the first live face it shares with `remove`.
    fn keep_attr_on_edge(&self, keep: u32, remove: u32) -> Option<u32> {
        self.vert_faces.get(remove as usize).iter().find_map(|&f| {
            let t = self.topo_faces[f as usize];
            let i = t.iter().position(|&u| u == keep)?;
            (t[0] != DEAD).then(|| self.p.faces[f as usize][i])
        })
    }

    /// Position and geometric quadric error of collapsing edge (a, b): the survivor, the
    /// removed vertex, where the survivor goes.
    #[inline]
    fn placement_geometric(&self, a: u32, b: u32) -> Option<(u32, u32, [f64; 3], f64)> {
        let (ma, mb) = (self.p.mobility[a as usize], self.p.mobility[b as usize]);
        let q = self.p.quadrics[a as usize].sum(&self.p.quadrics[b as usize]);
        let (pa, pb) = (self.p.pos[a as usize], self.p.pos[b as usize]);
        use Mobility::{Free, LockedBorder, Pinned, Seam};
        match (ma, mb) {
            (Free, Free) => Some(meet(&q, (a, pa), (b, pb))),
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
    pub(super) fn evaluate_below(&mut self, a: u32, b: u32, bound: u32) -> Evaluation {
        let Some((keep, remove, pos, error)) = self.placement(a, b) else {
            return Evaluation::Refused;
        };
        let (k, r) = (keep as usize, remove as usize);
        let Some(min_quality) = self.moved_faces_quality(k, r, pos) else {
            return Evaluation::Refused;
        };
        // The worst resulting quality scales the priority.
        let qt = self.opts.quality_threshold;
        let priority = if qt > 0.0 && min_quality < qt {
            error * qt / min_quality.max(1e-12)
        } else {
            error
        };
        if key(priority) > bound {
            return Evaluation::Later(key(priority));
        }
        let Some((edge_faces, opposite)) = self.link_condition(keep, remove) else {
            return Evaluation::Refused;
        };
        if self.pinches(keep, remove, edge_faces, opposite) {
            return Evaluation::Refused;
        }
        let Some(attr_map) = self.attribute_map(keep, remove) else {
            return Evaluation::Refused;
        };
        Evaluation::Collapse(Collapse {
            keep,
            remove,
            pos,
            error,
            attr_map,
        })
    }

    /// The worst quality of the faces that move when `k` and `r` meet at `pos`, or `None` when
    /// one of them refuses the collapse: its normal may not turn more than the limit (from its
    /// current and its reference normal) and no needle may appear.
    #[inline]
    fn moved_faces_quality(&self, k: usize, r: usize, pos: [f64; 3]) -> Option<f64> {
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
                    return None;
                }
                if l_old > 0.0 && dot(n_old, n_new) < self.cos_max_angle * l_old * l_new {
                    return None;
                }
                let n_ref = self.p.ref_normal[f as usize].map(f64::from);
                if dot(n_ref, n_new) < self.cos_max_angle * l_new && n_ref != [0.0; 3] {
                    return None;
                }
                // `triangle_quality(new)`, reusing |n_new|: the same bits, one cross product and
                // square root fewer.
                let longest = dot(e[0], e[0]).max(dot(e[1], e[1])).max(dot(e[2], e[2]));
                let q_new = if longest > 0.0 { l_new / longest } else { 0.0 };
                if q_new < self.opts.min_quality && q_new < triangle_quality(old[0], old[1], old[2])
                {
                    return None;
                }
                min_quality = min_quality.min(q_new);
            }
        }
        Some(min_quality)
    }

    /// Link condition: the common neighbours of the endpoints are exactly the vertices
    /// opposite the edge in its faces (Dey et al. 1999), which keeps a manifold manifold; no
    /// new edge may join two caller-pinned vertices either. Returns the edge's live faces (1
    /// or 2) and their opposite vertices, or `None` when the collapse is refused.
    #[inline]
    fn link_condition(&mut self, keep: u32, remove: u32) -> Option<(u32, [u32; 2])> {
        let (k, r) = (keep as usize, remove as usize);
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
        let held_k = self.p.held[k];
        for &f in self.vert_faces.get(r) {
            if self.topo_faces[f as usize][0] == DEAD {
                continue;
            }
            let t = self.topo_faces[f as usize];
            if t.contains(&keep) {
                if edge_faces >= 2 {
                    return None;
                }
                let c = t.into_iter().find(|&u| u != keep && u != remove)?;
                opposite[edge_faces as usize] = c;
                edge_faces += 1;
            }
            for u in t {
                if u != keep && u != remove {
                    if self.mark[u as usize] == m {
                        // Counted once however many of remove's faces it is on: re-marking
                        // replaced collecting them all and sorting out the duplicates.
                        self.mark[u as usize] = m + 1;
                        common += 1;
                    } else if held_k && self.mark[u as usize] != m + 1 && self.p.held[u as usize] {
                        // A new edge between two caller-pinned vertices (a tile's border):
                        // the tile next door may have that edge, and the weld would give it
                        // three faces.
                        return None;
                    }
                }
            }
        }
        if edge_faces == 0 || common != edge_faces {
            return None;
        }
        Some((edge_faces, opposite))
    }

    /// True when collapsing edge (keep, remove), on `edge_faces` faces with `opposite`
    /// vertices, would pinch the surface, delete a lone triangle or make a face twice.
    #[inline]
    fn pinches(&self, keep: u32, remove: u32, edge_faces: u32, opposite: [u32; 2]) -> bool {
        let (k, r) = (keep as usize, remove as usize);
        // Joining two border vertices through the interior would pinch the surface.
        if edge_faces == 2 && self.p.border[k] && self.p.border[r] {
            return true;
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
                return true;
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
                return true;
            }
        }
        false
    }

    /// Attribute vertices of `keep` that the removed vertex's corners take: its only one, or
    /// for a seam vertex the one it uses in the faces on the edge, which must agree (`None`
    /// when they do not) — unless the removed vertex slides along the seam, when each side
    /// maps to its own.
    #[inline]
    fn attribute_map(&self, keep: u32, remove: u32) -> Option<[(u32, u32); 2]> {
        let (k, r) = (keep as usize, remove as usize);
        let mut attr_map = [
            (self.p.first_attr[r], self.p.first_attr[k]),
            (u32::MAX, u32::MAX),
        ];
        if self.p.mobility[r] == Mobility::Seam {
            attr_map = self.seam_slide(remove, keep)?;
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
                        return None;
                    }
                    keep_attr = av;
                }
            }
            attr_map[0].1 = keep_attr;
        }
        Some(attr_map)
    }
}

#[cfg(test)]
mod tests {
    use super::super::prepare::Prepared;
    use super::*;
    use crate::mesh::Mesh;
    use crate::options::SimplifyOptions;

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
}
