//! The decimation state and its one operation: evaluate a vertex (class, hole filling, checks,
//! error) and remove it. The run to a target and the removal of a given order both call these.

use super::fan::{DEAD, Fan, FanInput, VertexClass};
use super::triangulate::{fan_from, split_loop};
use crate::greedy::prepare::Prepared;
use crate::greedy::state::VertFaces;
use crate::greedy::triangle_quality;
use crate::metrics::closest_on_triangle;
use crate::options::Removal;
use crate::quadric::Quadric;
use crate::quadric::attributes::{MAX_CHANNELS, hold};
use glam::DVec3;

/// Why a vertex was not removed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Refusal {
    /// Already removed.
    Gone,
    /// A corner or a complex vertex, which always stays.
    Kept(VertexClass),
    /// A border vertex off a straight stretch under `lock_border`.
    LockedBorder,
    /// No hole filling keeps the faces unflipped, non-degenerate and the edges manifold.
    NoValidFill,
    /// Its error is over `max_error`.
    OverMaxError,
}

impl Refusal {
    pub fn explain(self) -> String {
        match self {
            Refusal::Gone => "already removed".into(),
            Refusal::Kept(c) => format!("a {} vertex, which always stays", c.name()),
            Refusal::LockedBorder => {
                "a border vertex off a straight stretch (locked border)".into()
            }
            Refusal::NoValidFill => {
                "every filling of its hole would flip, crush or duplicate a face".into()
            }
            Refusal::OverMaxError => "its error is over the maximum error".into(),
        }
    }
}

/// The settings the engine reads.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Params {
    pub removal: Removal,
    pub feature_cos: f64,
    pub lock_border: bool,
    pub min_quality: f64,
    /// Cosine of the largest angle a new face's normal may make with its side's average normal.
    pub normal_cos: f64,
    pub max_error: Option<f64>,
}

/// One side of the hole: the fan's faces `start..start + count` (cyclically) and the polygon of
/// their `verts` loop vertices (`count + 1`, or `count` for a whole closed fan), whose closing
/// edge (last to first) is new unless `closing_exists`.
#[derive(Clone, Copy)]
struct Side {
    start: usize,
    count: usize,
    verts: usize,
    closing_exists: bool,
}

/// A removal found valid: its error and where its quadric goes. The new faces wait in
/// `Engine::new_faces`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Plan {
    /// `Q_v(foot)`: the area-weighted squared distance of the planes the vertex carries from
    /// the surface that replaces it, the queue's key.
    pub cost: f64,
    /// `sqrt(cost / weight)`: as a distance relative to the bounding-box diagonal.
    pub error: f64,
    /// Loop vertices that take the removed vertex's quadric, with their shares.
    transfer: [(u32, f64); 3],
    /// Whether the hole was filled and checked (the new faces wait in `new_faces`).
    pub filled: bool,
}

/// A face a filling makes: topological and attribute corners, the input face whose material
/// and group it takes, its reference normal.
type NewFace = ([u32; 3], [u32; 3], u32, [f32; 3]);

/// The queue's key of a cost: non-negative f64 as f32 bits, which order as the costs do.
pub(crate) fn key(cost: f64) -> u32 {
    (cost as f32).to_bits()
}

#[derive(Clone)]
pub(crate) struct Engine {
    pub p: Prepared,
    pub params: Params,
    pub topo: Vec<[u32; 3]>,
    pub face_alive: Vec<bool>,
    pub alive: Vec<bool>,
    /// Bumped whenever a vertex's fan changes, retiring its older queue entries.
    pub version: Vec<u32>,
    vf: VertFaces,
    /// Live faces.
    pub faces: usize,
    fan: Fan,
    pts: Vec<DVec3>,
    poly: Vec<(u32, u32)>,
    tris: Vec<[usize; 3]>,
    work: Vec<usize>,
    extra: Vec<u32>,
    /// The new faces of the plan last evaluated: topological and attribute corners, the input
    /// face whose material and group they take, and their reference normal.
    new_faces: Vec<NewFace>,
    /// Per face: a stamp marking the faces of the fan being evaluated.
    face_mark: Vec<u32>,
    mark: u32,
}

impl Engine {
    pub fn new(p: Prepared, params: Params) -> Engine {
        let topo: Vec<[u32; 3]> = p
            .faces
            .iter()
            .map(|f| f.map(|v| p.topo[v as usize]))
            .collect();
        let nv = p.pos.len();
        let nf = topo.len();
        let vf = VertFaces::new(nv, &topo);
        let mut alive = vec![false; nv];
        for t in &topo {
            for &v in t {
                alive[v as usize] = true;
            }
        }
        Engine {
            params,
            face_alive: vec![true; nf],
            alive,
            version: vec![0; nv],
            vf,
            faces: nf,
            fan: Fan::default(),
            pts: Vec::new(),
            poly: Vec::new(),
            tris: Vec::new(),
            work: Vec::new(),
            extra: Vec::new(),
            new_faces: Vec::new(),
            face_mark: vec![0; nf],
            mark: 0,
            topo,
            p,
        }
    }

    /// The class of `v` as the mesh is now.
    pub fn classify(&mut self, v: u32) -> VertexClass {
        if !self.alive[v as usize] {
            return VertexClass::Complex;
        }
        self.gather(v);
        self.fan.class()
    }

    fn gather(&mut self, v: u32) {
        let p = &self.p;
        let material = |f: u32| {
            let o = p.face_origin[f as usize] as usize;
            (
                p.mesh.face_materials.as_ref().map_or(u32::MAX, |m| m[o]),
                p.mesh.face_groups.as_ref().map_or(u32::MAX, |g| g[o]),
            )
        };
        let has_material = p.mesh.face_materials.is_some() || p.mesh.face_groups.is_some();
        let input = FanInput {
            pos: &p.pos,
            topo: &self.topo,
            attr: &p.faces,
            material: has_material.then_some(&material as &dyn Fn(u32) -> (u32, u32)),
            feature_cos: self.params.feature_cos,
        };
        self.fan
            .gather(v, self.vf.get(v as usize), p.held[v as usize], &input);
    }

    /// Evaluates the removal of `v`: its class and its cost (for a half-edge collapse, into the
    /// cheapest allowed neighbour). When the cost's key is at most `fill_up_to`, the hole is
    /// also filled and checked, and a valid filling is left in `new_faces` (`Plan::filled`);
    /// a cost over it comes back unfilled, for the queue to take again at that cost.
    pub fn evaluate(&mut self, v: u32, fill_up_to: Option<u32>) -> Result<Plan, Refusal> {
        if !self.alive[v as usize] {
            return Err(Refusal::Gone);
        }
        self.gather(v);
        let class = self.fan.class();
        if !class.removable() {
            return Err(Refusal::Kept(class));
        }
        let n = self.fan.len();
        let pv = self.at(v);
        let (sides, nsides, line) = self.hole_sides(class);
        let (foot_plane, line_t) = self.replacement_foot(line, pv);
        if class == VertexClass::Boundary && self.params.lock_border {
            // The outline stays exactly: only a vertex on the straight line between its border
            // neighbours may go.
            let (a, b) = (self.at(self.fan.x[0]), self.at(self.fan.x[n]));
            let off = (pv - a).cross(b - a).length();
            if off > 1e-12 * (b - a).length() {
                return Err(Refusal::LockedBorder);
            }
        }
        let q = self.p.quadrics[v as usize];
        let (cands, ncand) = self.candidates(line, &q, fill_up_to);
        for &cand in &cands[..ncand] {
            let (foot, transfer) = self.candidate_target(cand, line_t, foot_plane, pv);
            let cost = self.held(&q, &transfer).eval(foot.to_array());
            let plan = Plan {
                cost,
                error: rms(cost, &q),
                transfer,
                filled: false,
            };
            if fill_up_to.is_none_or(|k| key(cost) > k) {
                return Ok(plan);
            }
            if self.fill(v, &sides[..nsides], self.fan.x[cand]) {
                return self.filled_plan(plan, pv, &q);
            }
        }
        Err(Refusal::NoValidFill)
    }

    /// The sides of the hole `v`'s removal leaves (one, or two for an edge vertex), and the
    /// line of an edge or border vertex: the fan places of its two feature or border
    /// neighbours.
    fn hole_sides(&self, class: VertexClass) -> ([Side; 2], usize, Option<(usize, usize)>) {
        let n = self.fan.len();
        let mut sides = [Side {
            start: 0,
            count: n,
            verts: n,
            closing_exists: true,
        }; 2];
        let (nsides, line) = match class {
            VertexClass::Simple => (1, None),
            VertexClass::Boundary => {
                sides[0].verts = n + 1;
                sides[0].closing_exists = false;
                (1, Some((0, n)))
            }
            _ => {
                let (ia, ib) = (self.fan.features[0], self.fan.features[1]);
                let (c1, c2) = (ib - ia, n - (ib - ia));
                sides[0] = Side {
                    start: ia,
                    count: c1,
                    verts: c1 + 1,
                    closing_exists: c2 == 1,
                };
                sides[1] = Side {
                    start: ib,
                    count: c2,
                    verts: c2 + 1,
                    closing_exists: c1 == 1,
                };
                (2, Some((ia, ib)))
            }
        };
        (sides, nsides, line)
    }

    /// Where the surface that replaces the vertex at `pv` passes: the average plane's foot
    /// (simple), the line through the two feature or border neighbours (Schroeder 1992's
    /// criteria), with the foot's parameter along that line.
    fn replacement_foot(
        &self,
        line: Option<(usize, usize)>,
        pv: DVec3,
    ) -> (DVec3, Option<(usize, usize, f64)>) {
        match line {
            None => {
                let (nrm, c) = self.fan.average_plane(&self.p.pos, 0..self.fan.len());
                (pv - nrm * nrm.dot(pv - c), None)
            }
            Some((ia, ib)) => {
                let (a, b) = (self.at(self.fan.x[ia]), self.at(self.fan.x[ib]));
                let d = b - a;
                let t = if d.length_squared() > 0.0 {
                    ((pv - a).dot(d) / d.length_squared()).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                (a + d * t, Some((ia, ib, t)))
            }
        }
    }

    /// The candidates, as fan places, and their count: one filling for loop splitting; for a
    /// half-edge collapse, the allowed neighbours, the cheapest under `q` first (all sorted by
    /// cost when the hole is to be filled, `fill_up_to`).
    fn candidates(
        &self,
        line: Option<(usize, usize)>,
        q: &Quadric,
        fill_up_to: Option<u32>,
    ) -> ([usize; super::fan::MAX_FAN + 1], usize) {
        let n = self.fan.len();
        let mut cands = [0usize; super::fan::MAX_FAN + 1];
        let ncand = match (self.params.removal, line) {
            (Removal::LoopSplit, _) => 1,
            (Removal::HalfEdge, None) => {
                for (k, c) in cands.iter_mut().enumerate().take(n) {
                    *c = k;
                }
                n
            }
            (Removal::HalfEdge, Some((ia, ib))) => {
                cands[0] = ia;
                cands[1] = ib;
                2
            }
        };
        if self.params.removal == Removal::HalfEdge {
            // The cheapest allowed neighbour first, not the nearest as in Schroeder 1997:
            // measured on horse at 10%, the nearest gave a mean two-sided distance of 2.05e-4
            // of the diagonal, the cheapest 1.57e-4 (greedy QEM: 1.04e-4).
            let mut cost = [0.0f64; super::fan::MAX_FAN + 1];
            for &i in &cands[..ncand] {
                let to = [(self.fan.x[i], 1.0), (u32::MAX, 0.0), (u32::MAX, 0.0)];
                cost[i] = self.held(q, &to).eval(self.at(self.fan.x[i]).to_array());
            }
            if fill_up_to.is_some() {
                cands[..ncand].sort_by(|&i, &j| cost[i].total_cmp(&cost[j]).then(i.cmp(&j)));
            } else {
                // The key needs only the cheapest.
                let best = (0..ncand)
                    .min_by(|&a, &b| cost[cands[a]].total_cmp(&cost[cands[b]]))
                    .unwrap_or(0);
                cands.swap(0, best);
            }
        }
        (cands, ncand)
    }

    /// Where candidate `cand` puts the removed vertex at `pv` and who takes its quadric: the
    /// neighbour itself for a half-edge collapse; for loop splitting `foot_plane`, the
    /// quadric shared by the line's two ends (`line_t`) or the two nearest loop vertices.
    fn candidate_target(
        &self,
        cand: usize,
        line_t: Option<(usize, usize, f64)>,
        foot_plane: DVec3,
        pv: DVec3,
    ) -> (DVec3, [(u32, f64); 3]) {
        match (self.params.removal, line_t) {
            (Removal::HalfEdge, _) => (
                self.at(self.fan.x[cand]),
                [(self.fan.x[cand], 1.0), (u32::MAX, 0.0), (u32::MAX, 0.0)],
            ),
            (Removal::LoopSplit, Some((ia, ib, t))) => (
                foot_plane,
                [
                    (self.fan.x[ia], 1.0 - t),
                    (self.fan.x[ib], t),
                    (u32::MAX, 0.0),
                ],
            ),
            (Removal::LoopSplit, None) => {
                let [a, b] = self.nearest_two(pv);
                (foot_plane, [a, b, (u32::MAX, 0.0)])
            }
        }
    }

    /// The plan of a removal whose hole was filled: for loop splitting costed again on the
    /// new faces; refused over `max_error`.
    fn filled_plan(&self, mut plan: Plan, pv: DVec3, q: &Quadric) -> Result<Plan, Refusal> {
        if self.params.removal == Removal::LoopSplit {
            // The surface that really replaces v, not its average plane: measured on horse at
            // 10%, charging the average plane's foot gave a mean two-sided distance of 2.62e-4
            // of the diagonal, the new faces' nearest point 1.96e-4. The queue's key stays the
            // average plane's (no filling needed); a removal that costs more than its key goes
            // back in the queue.
            let (foot, transfer) = self.nearest_on_new(pv);
            let cost = self.held(q, &transfer).eval(foot.to_array());
            plan = Plan {
                cost,
                error: rms(cost, q),
                transfer,
                filled: true,
            };
        }
        plan.filled = true;
        if self.params.max_error.is_some_and(|m| plan.error > m) {
            return Err(Refusal::OverMaxError);
        }
        Ok(plan)
    }

    fn at(&self, x: u32) -> DVec3 {
        DVec3::from_array(self.p.pos[x as usize])
    }

    /// The point of the new faces nearest `p`, and its face's corners with their barycentric
    /// weights there.
    fn nearest_on_new(&self, p: DVec3) -> (DVec3, [(u32, f64); 3]) {
        let mut best = (f64::INFINITY, p, [(u32::MAX, 0.0); 3]);
        for &(t, ..) in &self.new_faces {
            let [a, b, c] = t.map(|x| self.at(x));
            // A degenerate triangle the region tests let through counts as its first corner.
            let (q, w) = closest_on_triangle(p, a, b, c).unwrap_or((a, [1.0, 0.0, 0.0]));
            let d = (q - p).length_squared();
            if d < best.0 {
                best = (d, q, [(t[0], w[0]), (t[1], w[1]), (t[2], w[2])]);
            }
        }
        (best.1, best.2)
    }

    /// The quadric `q` of the vertex last gathered with each of its attribute vertices held at
    /// the values the surface replacing it has there: those of `transfer`'s loop vertices on
    /// that side, weighed by their shares (a half-edge collapse's: its target's). Decimation
    /// moves no vertex and solves no value, so appearance only charges the cost (Hoppe 1999's
    /// held form, [`crate::quadric::attributes::hold`]): removing a vertex on a colour edge
    /// costs what the edge's smearing does. `q` itself without attribute channels.
    fn held(&self, q: &Quadric, transfer: &[(u32, f64); 3]) -> Quadric {
        let Some(at) = &self.p.attrs else {
            return *q;
        };
        let (fan, m) = (&self.fan, at.layout.m);
        let mut h = *q;
        let mut values = [0.0; MAX_CHANNELS];
        for a in fan.centre_attrs() {
            values[..m].fill(0.0);
            let mut total = 0.0;
            for &(x, w) in transfer {
                if let (true, Some(ax)) = (x != u32::MAX && w > 0.0, fan.attr_on_side(a, x)) {
                    for (o, &val) in values.iter_mut().zip(at.values(ax)) {
                        *o += w * val;
                    }
                    total += w;
                }
            }
            if total > 0.0 {
                values[..m].iter_mut().for_each(|x| *x /= total);
            } else {
                values[..m].copy_from_slice(at.values(a));
            }
            h = hold(&h, &at.layout, at.sums_of(a), &values[..m]);
        }
        h
    }

    /// The two loop vertices nearest `p`, sharing a quadric in inverse proportion to their
    /// distance.
    fn nearest_two(&self, p: DVec3) -> [(u32, f64); 2] {
        let mut best = [(u32::MAX, f64::INFINITY); 2];
        for &x in &self.fan.x {
            let d = (DVec3::from_array(self.p.pos[x as usize]) - p).length();
            if d < best[0].1 {
                best[1] = best[0];
                best[0] = (x, d);
            } else if d < best[1].1 {
                best[1] = (x, d);
            }
        }
        let (d0, d1) = (best[0].1, best[1].1);
        let w0 = if d0 + d1 > 0.0 { d1 / (d0 + d1) } else { 0.5 };
        [(best[0].0, w0), (best[1].0, 1.0 - w0)]
    }

    /// Fills each side's polygon (the half-edge collapse's fan from `apex`, or loop splitting)
    /// into `new_faces` and checks every new face: not flipped against its side's average
    /// plane, not degenerate, no edge or face that exists outside the hole already.
    fn fill(&mut self, v: u32, sides: &[Side], apex: u32) -> bool {
        self.new_faces.clear();
        self.mark = self.mark.wrapping_add(1);
        if self.mark == 0 {
            self.face_mark.iter_mut().for_each(|m| *m = 0);
            self.mark = 1;
        }
        for &f in &self.fan.faces {
            self.face_mark[f as usize] = self.mark;
        }
        let n = self.fan.len();
        let worst_old = self
            .fan
            .faces
            .iter()
            .map(|&f| {
                let [a, b, c] = self.topo[f as usize].map(|x| self.p.pos[x as usize]);
                triangle_quality(a, b, c)
            })
            .fold(f64::INFINITY, f64::min);
        for side in sides {
            let len = side.verts;
            if len < 3 {
                continue;
            }
            // The polygon: the side's loop vertices with the attribute vertex each has on this
            // side (every edge inside a side is free of seams, so any of its faces gives it).
            self.poly.clear();
            for j in 0..len {
                let (i, corner) = if j < side.count {
                    ((side.start + j) % n.max(1), 1)
                } else {
                    ((side.start + side.count - 1) % n, 2)
                };
                let x = self.fan.x[(side.start + j) % self.fan.x.len()];
                self.poly.push((x, self.fan.attr[i][corner]));
            }
            self.pts.clear();
            for &(x, _) in &self.poly {
                self.pts.push(DVec3::from_array(self.p.pos[x as usize]));
            }
            let (normal, _) = self
                .fan
                .average_plane(&self.p.pos, (0..side.count).map(|k| (side.start + k) % n));
            if !side.closing_exists && self.edge_outside(self.poly[len - 1].0, self.poly[0].0) {
                return false;
            }
            match self.params.removal {
                Removal::HalfEdge => {
                    let Some(at) = self.poly.iter().position(|&(x, _)| x == apex) else {
                        return false;
                    };
                    fan_from(at, len, &mut self.tris);
                }
                Removal::LoopSplit => {
                    let (poly, topo, vf, marks, mark) =
                        (&self.poly, &self.topo, &self.vf, &self.face_mark, self.mark);
                    let mut exists = |i: usize, j: usize| {
                        edge_outside(vf, topo, marks, mark, poly[i].0, poly[j].0)
                    };
                    if !split_loop(
                        &self.pts,
                        normal,
                        &mut exists,
                        &mut self.tris,
                        &mut self.work,
                    ) {
                        return false;
                    }
                }
            }
            let origin = self.p.face_origin[self.fan.faces[side.start % n] as usize];
            // The side's reference normal: the mean of the input normals its faces stand for.
            let mut reference = DVec3::ZERO;
            for q in 0..side.count {
                let f = self.fan.faces[(side.start + q) % n] as usize;
                reference += DVec3::from_array(self.p.ref_normal[f].map(f64::from));
            }
            let reference = reference.normalize_or_zero();
            let reference_f32 = reference.to_array().map(|x| x as f32);
            for k in 0..self.tris.len() {
                let [i, j, l] = self.tris[k];
                let (a, b, c) = (self.pts[i], self.pts[j], self.pts[l]);
                let cr = (b - a).cross(c - a);
                let len_cr = cr.length();
                let quality = triangle_quality(a.to_array(), b.to_array(), c.to_array());
                // Not flipped against the side's average plane, nor against any face it
                // replaces, nor against the input's surface there (the faces' reference
                // normals, as the greedy QEM keeps them): the local checks alone let turns
                // pile up over many removals into a flip on a noisy sphere.
                let limit = self.params.normal_cos * len_cr;
                if len_cr == 0.0
                    || cr.dot(normal) <= limit
                    || cr.dot(reference) <= limit
                    || (0..side.count).any(|q| {
                        let nf = self.fan.normal[(side.start + q) % n];
                        nf != DVec3::ZERO && cr.dot(nf) <= limit
                    })
                    || (quality < self.params.min_quality && quality < worst_old)
                {
                    return false;
                }
                let t = [i, j, l].map(|q| self.poly[q].0);
                // The half-edge fan's diagonals were not checked while it was built; loop
                // splitting checked its own, so this finds only closing edges and duplicates.
                for e in 0..3 {
                    let (x, y) = (t[e], t[(e + 1) % 3]);
                    let (pi, pj) = ([i, j, l][e], [i, j, l][(e + 1) % 3]);
                    let polygon_edge = pi.abs_diff(pj) == 1 || pi.abs_diff(pj) == len - 1;
                    if !polygon_edge && self.edge_outside(x, y) {
                        return false;
                    }
                }
                if self.face_outside(t) {
                    return false;
                }
                self.new_faces
                    .push((t, [i, j, l].map(|q| self.poly[q].1), origin, reference_f32));
            }
        }
        // A vertex removal takes n faces and leaves n - 2 (n - 1 on a border).
        let expect = if self.fan.closed { n - 2 } else { n - 1 };
        debug_assert_eq!(self.new_faces.len(), expect, "hole of {v} filled wrongly");
        self.new_faces.len() == expect
    }

    fn edge_outside(&self, x: u32, y: u32) -> bool {
        edge_outside(&self.vf, &self.topo, &self.face_mark, self.mark, x, y)
    }

    /// Whether a live face outside the hole has the corners of `t` (in any order).
    fn face_outside(&self, t: [u32; 3]) -> bool {
        self.vf.get(t[0] as usize).iter().any(|&f| {
            let u = self.topo[f as usize];
            self.face_mark[f as usize] != self.mark
                && u[0] != DEAD
                && t.iter().all(|c| u.contains(c))
        })
    }

    /// Applies the plan `evaluate(v, true)` just returned: v's faces go, the new faces take
    /// their slots, v's quadric moves to the loop vertices, the fans around are rebuilt.
    pub fn apply(&mut self, v: u32, plan: &Plan) {
        let old = std::mem::take(&mut self.fan.faces);
        debug_assert!(old.len() > self.new_faces.len());
        for (k, &f) in old.iter().enumerate() {
            let f = f as usize;
            if let Some(&(t, a, origin, reference)) = self.new_faces.get(k) {
                self.topo[f] = t;
                self.p.faces[f] = a;
                self.p.face_origin[f] = origin;
                self.p.ref_normal[f] = reference;
            } else {
                self.topo[f] = [DEAD; 3];
                self.face_alive[f] = false;
            }
        }
        self.faces -= old.len() - self.new_faces.len();
        let q = self.p.quadrics[v as usize];
        for &(x, w) in &plan.transfer {
            if x != u32::MAX && w > 0.0 {
                let mut s = q;
                scale(&mut s, w);
                self.p.quadrics[x as usize].add(&s);
            }
        }
        self.transfer_sums(&plan.transfer);
        self.alive[v as usize] = false;
        self.version[v as usize] = self.version[v as usize].wrapping_add(1);
        let mark = self.mark;
        let mut extra = std::mem::take(&mut self.extra);
        for i in 0..self.fan.x.len() {
            let x = self.fan.x[i];
            extra.clear();
            extra.extend(
                old.iter()
                    .take(self.new_faces.len())
                    .filter(|&&f| self.topo[f as usize].contains(&x)),
            );
            let (topo, marks) = (&self.topo, &self.face_mark);
            self.vf.merge_into(
                x as usize,
                v as usize,
                |f| marks[f as usize] != mark && topo[f as usize].contains(&x),
                &extra,
            );
            self.version[x as usize] = self.version[x as usize].wrapping_add(1);
        }
        self.extra = extra;
        self.fan.faces = old;
    }

    /// With attribute channels, the attribute sums of the vertex last gathered go where its
    /// quadric goes (whose folded part they balance): each side's into the loop vertices'
    /// attribute vertices on that side, by their shares.
    fn transfer_sums(&mut self, transfer: &[(u32, f64); 3]) {
        let Some(at) = &mut self.p.attrs else {
            return;
        };
        let (fan, stride) = (&self.fan, at.layout.stride());
        for a in fan.centre_attrs() {
            for &(x, w) in transfer {
                if x == u32::MAX || w <= 0.0 {
                    continue;
                }
                let to = fan.attr_on_side(a, x);
                if let Some(to) = to.filter(|&to| to != a) {
                    let (from, to) = (a as usize * stride, to as usize * stride);
                    for k in 0..stride {
                        at.sums[to + k] += w * at.sums[from + k];
                    }
                }
            }
        }
    }

    /// The class of the vertex last gathered.
    pub fn last_class(&self) -> VertexClass {
        self.fan.class()
    }

    /// Loop vertices of the fan last gathered.
    pub fn loop_vertices(&self) -> &[u32] {
        &self.fan.x
    }
}

/// A quadric's error as an RMS distance.
fn rms(cost: f64, q: &Quadric) -> f64 {
    if q.weight > 0.0 {
        (cost / q.weight).sqrt()
    } else {
        0.0
    }
}

fn scale(q: &mut Quadric, w: f64) {
    q.a.iter_mut().for_each(|x| *x *= w);
    q.b.iter_mut().for_each(|x| *x *= w);
    q.c *= w;
    q.weight *= w;
}

/// Whether a live face not marked with `mark` (outside the hole) has the edge `(x, y)`.
fn edge_outside(
    vf: &VertFaces,
    topo: &[[u32; 3]],
    marks: &[u32],
    mark: u32,
    x: u32,
    y: u32,
) -> bool {
    vf.get(x as usize).iter().any(|&f| {
        let t = topo[f as usize];
        marks[f as usize] != mark && t[0] != DEAD && t.contains(&x) && t.contains(&y)
    })
}
