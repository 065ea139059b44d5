//! The half-edge mesh the remesher edits: split, collapse and flip with their legality checks.
//!
//! Half-edges come in pairs: edge `e` is half-edges `2e` and `2e + 1`, so the twin of `h` is
//! `h ^ 1`. A border half-edge has no face; the border ones are linked into loops by
//! `next`/`prev` like the inner ones, so a vertex's one-ring is walked the same way inside and
//! on a border. A border vertex's `out` is its border half-edge, which makes "is this vertex on
//! a border" one lookup. Deleted elements stay in the arrays (marked) until [`HalfEdges::to_mesh`]
//! compacts them: indices stay valid through a whole remeshing step.

use glam::DVec3;

use crate::{Error, Mesh, Result};

/// No element: a border half-edge's face, a deleted vertex's or face's half-edge.
pub(crate) const NONE: u32 = u32::MAX;

#[derive(Debug, Clone, Default)]
pub(crate) struct HalfEdges {
    pub pos: Vec<DVec3>,
    /// An outgoing half-edge per vertex, the border one on a border; `NONE` once deleted.
    pub out: Vec<u32>,
    pub to: Vec<u32>,
    pub next: Vec<u32>,
    pub prev: Vec<u32>,
    /// The face left of each half-edge, `NONE` on a border.
    pub face: Vec<u32>,
    /// A half-edge of each face; `NONE` once deleted.
    pub fhe: Vec<u32>,
    /// Per edge: deleted by a collapse.
    pub dead_edge: Vec<bool>,
    /// For each face built from the mesh, its index there (faces that repeat a vertex are
    /// left out, so the two can differ).
    pub origin: Vec<u32>,
}

#[inline]
pub(crate) fn twin(h: u32) -> u32 {
    h ^ 1
}

impl HalfEdges {
    /// Builds the half-edges of a manifold, consistently oriented mesh. Faces that repeat a
    /// vertex are left out (they have no area and no place in a half-edge mesh); an edge with
    /// more than two faces, two faces that traverse an edge the same way, or a vertex whose
    /// faces form more than one fan are refused, with the vertex indices in the message.
    pub fn from_mesh(m: &Mesh) -> Result<HalfEdges> {
        let nv = m.positions.len();
        let (origin, faces): (Vec<u32>, Vec<[u32; 3]>) = m
            .triangles
            .iter()
            .enumerate()
            .filter(|(_, t)| t[0] != t[1] && t[1] != t[2] && t[2] != t[0])
            .map(|(f, t)| (f as u32, *t))
            .unzip();
        // (low, high, corner slot 3f + k, forward = the face goes low → high).
        let mut directed: Vec<(u32, u32, u32, bool)> = Vec::with_capacity(faces.len() * 3);
        for (f, t) in faces.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                directed.push((a.min(b), a.max(b), (3 * f + k) as u32, a < b));
            }
        }
        directed.sort_unstable();
        let mut he_of_slot = vec![NONE; faces.len() * 3];
        let mut to = Vec::with_capacity(directed.len() + directed.len() / 8);
        for (e, run) in directed
            .chunk_by(|x, y| (x.0, x.1) == (y.0, y.1))
            .enumerate()
        {
            let (lo, hi) = (run[0].0, run[0].1);
            let e = e as u32;
            // The half-edge of each face goes from one end to the other; its twin the other way.
            let end = |forward: bool| if forward { (hi, lo) } else { (lo, hi) };
            match run {
                [(_, _, s, fw)] => {
                    he_of_slot[*s as usize] = 2 * e;
                    let (t0, t1) = end(*fw);
                    to.extend([t0, t1]);
                }
                [(_, _, s0, fw0), (_, _, s1, fw1)] => {
                    if fw0 == fw1 {
                        return Err(Error::InvalidMesh(format!(
                            "faces {} and {} traverse the edge ({lo}, {hi}) the same way: the \
                             mesh is not consistently oriented, which remeshing needs",
                            s0 / 3,
                            s1 / 3
                        )));
                    }
                    he_of_slot[*s0 as usize] = 2 * e;
                    he_of_slot[*s1 as usize] = 2 * e + 1;
                    let (t0, t1) = end(*fw0);
                    to.extend([t0, t1]);
                }
                _ => {
                    return Err(Error::InvalidMesh(format!(
                        "the edge ({lo}, {hi}) has {} faces: remeshing needs a manifold mesh",
                        run.len()
                    )));
                }
            }
        }
        let nh = to.len();
        let mut he = HalfEdges {
            pos: m
                .positions
                .iter()
                .map(|p| DVec3::from_array(p.map(f64::from)))
                .collect(),
            out: vec![NONE; nv],
            to,
            next: vec![NONE; nh],
            prev: vec![NONE; nh],
            face: vec![NONE; nh],
            fhe: vec![NONE; faces.len()],
            origin,
            dead_edge: vec![false; nh / 2],
        };
        for f in 0..faces.len() {
            for k in 0..3 {
                let h = he_of_slot[3 * f + k];
                let n = he_of_slot[3 * f + (k + 1) % 3];
                he.next[h as usize] = n;
                he.prev[n as usize] = h;
                he.face[h as usize] = f as u32;
            }
            he.fhe[f] = he_of_slot[3 * f];
        }
        // Every vertex's outgoing half-edge, a border one where there is one (at most one: two
        // would be two fans meeting at the vertex).
        let mut border_out = vec![NONE; nv];
        for h in 0..nh as u32 {
            let from = he.to[twin(h) as usize] as usize;
            if he.face[h as usize] == NONE {
                if border_out[from] != NONE {
                    return Err(non_manifold_vertex(from));
                }
                border_out[from] = h;
            }
            if he.out[from] == NONE {
                he.out[from] = h;
            }
        }
        for (out, &b) in he.out.iter_mut().zip(&border_out) {
            if b != NONE {
                *out = b;
            }
        }
        // Border loops: the border half-edge into v is followed by the one out of v.
        for h in 0..nh as u32 {
            if he.face[h as usize] == NONE {
                let n = border_out[he.to[h as usize] as usize];
                he.next[h as usize] = n;
                he.prev[n as usize] = h;
            }
        }
        // A vertex whose one-ring walk misses some of its half-edges has several fans.
        let mut outgoing = vec![0u32; nv];
        for h in 0..nh {
            outgoing[he.to[twin(h as u32) as usize] as usize] += 1;
        }
        for (v, &n) in outgoing.iter().enumerate() {
            if he.out[v] != NONE && he.valence(v as u32) != n {
                return Err(non_manifold_vertex(v));
            }
        }
        Ok(he)
    }

    /// The live faces and the vertices they use, renumbered in order.
    pub fn to_mesh(&self) -> Mesh {
        let mut id = vec![NONE; self.pos.len()];
        let mut positions = Vec::new();
        for (v, &o) in self.out.iter().enumerate() {
            if o != NONE {
                id[v] = positions.len() as u32;
                positions.push(self.pos[v].as_vec3().to_array());
            }
        }
        let triangles = self
            .fhe
            .iter()
            .filter(|&&h| h != NONE)
            .map(|&h| self.face_vertices_of(h).map(|v| id[v as usize]))
            .collect();
        Mesh::new(positions, triangles)
    }

    pub fn from(&self, h: u32) -> u32 {
        self.to[twin(h) as usize]
    }

    pub fn edge_count(&self) -> usize {
        self.dead_edge.len()
    }

    pub fn is_border_he(&self, h: u32) -> bool {
        self.face[h as usize] == NONE
    }

    pub fn is_border_edge(&self, e: u32) -> bool {
        self.is_border_he(2 * e) || self.is_border_he(2 * e + 1)
    }

    pub fn is_border_vertex(&self, v: u32) -> bool {
        let o = self.out[v as usize];
        o != NONE && self.is_border_he(o)
    }

    pub fn live_vertex(&self, v: u32) -> bool {
        self.out[v as usize] != NONE
    }

    /// The corners of the face of `h`, starting at `h`'s target.
    pub fn face_vertices_of(&self, h: u32) -> [u32; 3] {
        let n = self.next[h as usize];
        [
            self.to[h as usize],
            self.to[n as usize],
            self.to[self.next[n as usize] as usize],
        ]
    }

    /// The next outgoing half-edge around `from(h)`.
    #[inline]
    pub fn rotate(&self, h: u32) -> u32 {
        twin(self.prev[h as usize])
    }

    /// Calls `f` with every outgoing half-edge of `v`.
    pub fn for_out(&self, v: u32, mut f: impl FnMut(u32)) {
        let start = self.out[v as usize];
        if start == NONE {
            return;
        }
        let mut h = start;
        loop {
            f(h);
            h = self.rotate(h);
            if h == start {
                break;
            }
        }
    }

    pub fn valence(&self, v: u32) -> u32 {
        let mut n = 0;
        self.for_out(v, |_| n += 1);
        n
    }

    pub fn face_normal(&self, h: u32) -> DVec3 {
        let [a, b, c] = self.face_vertices_of(h).map(|v| self.pos[v as usize]);
        (b - a).cross(c - a)
    }

    pub fn edge_len2(&self, e: u32) -> f64 {
        let h = 2 * e;
        self.pos[self.to[h as usize] as usize].distance_squared(self.pos[self.from(h) as usize])
    }

    /// Points `out[v]` at its border half-edge if it has one, else at any live outgoing one.
    fn fix_out(&mut self, v: u32, some_out: u32) {
        self.out[v as usize] = some_out;
        let mut border = NONE;
        self.for_out(v, |h| {
            if self.face[h as usize] == NONE {
                border = h;
            }
        });
        if border != NONE {
            self.out[v as usize] = border;
        }
    }

    fn new_vertex(&mut self, p: DVec3) -> u32 {
        self.pos.push(p);
        self.out.push(NONE);
        (self.pos.len() - 1) as u32
    }

    /// A new edge from `a` to `b`; returns its half-edge a → b (the twin is b → a).
    fn new_edge(&mut self, a: u32, b: u32) -> u32 {
        let h = self.to.len() as u32;
        self.to.extend([b, a]);
        self.next.extend([NONE, NONE]);
        self.prev.extend([NONE, NONE]);
        self.face.extend([NONE, NONE]);
        self.dead_edge.push(false);
        h
    }

    fn new_face(&mut self) -> u32 {
        self.fhe.push(NONE);
        (self.fhe.len() - 1) as u32
    }

    fn link(&mut self, a: u32, b: u32) {
        self.next[a as usize] = b;
        self.prev[b as usize] = a;
    }

    fn set_face(&mut self, hs: [u32; 3], f: u32) {
        for (k, &h) in hs.iter().enumerate() {
            self.link(h, hs[(k + 1) % 3]);
            self.face[h as usize] = f;
        }
        self.fhe[f as usize] = hs[0];
    }

    /// Splits edge `e` at `p`: the new vertex joins the opposite corner of each face, so one
    /// face becomes two on each side. Returns the new vertex; its half-edge pair continuing
    /// `e` is the last edge added before the ones to the opposite corners.
    pub fn split(&mut self, e: u32, p: DVec3) -> (u32, u32) {
        let h0 = 2 * e;
        let o0 = h0 + 1;
        let v1 = self.to[h0 as usize];
        let v = self.new_vertex(p);
        let (f0, f1) = (self.face[h0 as usize], self.face[o0 as usize]);
        let (hn, hp) = (self.next[h0 as usize], self.prev[h0 as usize]);
        let (on, op) = (self.next[o0 as usize], self.prev[o0 as usize]);
        // h0: v0 → v, h1: v → v1 (o1: v1 → v), o0: v → v0.
        let h1 = self.new_edge(v, v1);
        let o1 = twin(h1);
        self.to[h0 as usize] = v;
        self.split_side(v, f0, [hp, h0, h1, hn]);
        self.split_side(v, f1, [op, o1, o0, on]);
        if self.out[v1 as usize] == o0 {
            self.out[v1 as usize] = o1;
        }
        self.fix_out(v, h1);
        (v, h1 / 2)
    }

    /// One side of a split edge: `prev → first → second → next` around face `f`, where `first`
    /// and `second` are the halves of the edge (`first` ends at `v`). A border side is relinked
    /// in that order; a face (c0, c1, a) becomes (c0, v, a) and (v, c1, a). The two sides are
    /// mirror images, so one function serves both.
    fn split_side(&mut self, v: u32, f: u32, [prev, first, second, next]: [u32; 4]) {
        if f == NONE {
            self.link(prev, first);
            self.link(first, second);
            self.link(second, next);
        } else {
            let a = self.to[next as usize];
            let x = self.new_edge(v, a);
            let g = self.new_face();
            self.set_face([first, x, prev], f);
            self.set_face([second, next, twin(x)], g);
        }
    }

    /// Whether `e` can be flipped without breaking the mesh: two faces, distinct opposite
    /// corners not already joined, and both ends keeping at least three edges.
    pub fn can_flip(&self, e: u32) -> bool {
        let (h, o) = (2 * e, 2 * e + 1);
        if self.is_border_he(h) || self.is_border_he(o) {
            return false;
        }
        let (a, b) = (self.from(h), self.to[h as usize]);
        let c = self.to[self.next[h as usize] as usize];
        let d = self.to[self.next[o as usize] as usize];
        if c == d || self.valence(a) <= 3 || self.valence(b) <= 3 {
            return false;
        }
        let mut joined = false;
        self.for_out(c, |g| joined |= self.to[g as usize] == d);
        !joined
    }

    /// Flips `e`: faces (a, b, c) and (b, a, d) become (a, d, c) and (b, c, d).
    pub fn flip(&mut self, e: u32) {
        let (h, o) = (2 * e, 2 * e + 1);
        let (f0, f1) = (self.face[h as usize], self.face[o as usize]);
        let (hn, hp) = (self.next[h as usize], self.prev[h as usize]);
        let (on, op) = (self.next[o as usize], self.prev[o as usize]);
        let (a, b) = (self.from(h), self.to[h as usize]);
        let c = self.to[hn as usize];
        let d = self.to[on as usize];
        self.to[h as usize] = c;
        self.to[o as usize] = d;
        // (a → d, d → c, c → a) and (b → c, c → d, d → b).
        self.set_face([on, h, hp], f0);
        self.set_face([hn, o, op], f1);
        if self.out[a as usize] == h {
            self.out[a as usize] = on;
        }
        if self.out[b as usize] == o {
            self.out[b as usize] = hn;
        }
    }

    /// Whether removing `from(h)` into `to(h)` keeps the mesh a manifold with the same
    /// topology: the link condition (Dey et al. 1999) — the two ends share no neighbour but
    /// the corners opposite the edge — with the border cases it implies.
    pub fn can_collapse(&self, h: u32, mark: &mut Vec<u32>, stamp: u32) -> bool {
        let o = twin(h);
        let (v0, v1) = (self.from(h), self.to[h as usize]);
        let mut opposite = [NONE; 2];
        for (k, g) in [h, o].into_iter().enumerate() {
            if self.is_border_he(g) {
                continue;
            }
            let (n, p) = (self.next[g as usize], self.prev[g as usize]);
            // A face with two border edges besides this one would be left hanging by an edge.
            if self.is_border_he(twin(n)) && self.is_border_he(twin(p)) {
                return false;
            }
            let c = self.to[n as usize];
            // The opposite corner loses an edge; inside it must keep three.
            if !self.is_border_vertex(c) && self.valence(c) <= 3 {
                return false;
            }
            opposite[k] = c;
        }
        // Two border vertices joined by an inner edge: collapsing it would pinch the surface.
        if self.is_border_vertex(v0)
            && self.is_border_vertex(v1)
            && !self.is_border_he(h)
            && !self.is_border_he(o)
        {
            return false;
        }
        if mark.len() < self.pos.len() {
            mark.resize(self.pos.len(), 0);
        }
        self.for_out(v0, |g| mark[self.to[g as usize] as usize] = stamp);
        let mut ok = true;
        self.for_out(v1, |g| {
            let w = self.to[g as usize];
            if mark[w as usize] == stamp && !opposite.contains(&w) {
                ok = false;
            }
        });
        ok
    }

    /// Removes `from(h)`, joining it into `to(h)` (which keeps its position). The faces on
    /// both sides of the edge go, and each one's other two edges become one: returns those
    /// pairs as (gone edge, kept edge), `NONE` on a border side.
    pub fn collapse(&mut self, h: u32) -> [(u32, u32); 2] {
        let o = twin(h);
        let (v0, v1) = (self.from(h), self.to[h as usize]);
        let mut incoming = Vec::with_capacity(8);
        self.for_out(v0, |g| incoming.push(twin(g)));
        let mut keep_out = NONE;
        let mut merged = [(NONE, NONE); 2];
        for (k, g) in [h, o].into_iter().enumerate() {
            let (n, p) = (self.next[g as usize], self.prev[g as usize]);
            let f = self.face[g as usize];
            if f == NONE {
                // Border: the edge leaves its loop.
                self.link(p, n);
                continue;
            }
            // Face (from g, to g, c): of its edges to c, the one at v0 goes and the one at v1
            // stays, taking the place of the gone one's twin in the neighbouring face.
            let (gone, stay) = if g == h { (p, n) } else { (n, p) };
            let gone_t = twin(gone);
            let c = self.to[n as usize];
            let (gn, gp, gf) = (
                self.next[gone_t as usize],
                self.prev[gone_t as usize],
                self.face[gone_t as usize],
            );
            self.link(gp, stay);
            self.link(stay, gn);
            self.face[stay as usize] = gf;
            if gf != NONE {
                self.fhe[gf as usize] = stay;
            }
            self.dead_edge[(gone / 2) as usize] = true;
            merged[k] = (gone / 2, stay / 2);
            self.fhe[f as usize] = NONE;
            // c's outgoing half-edge may have been the gone c → v0 (`gone` on h's side,
            // `gone_t` on o's); the kept c → v1 stands in.
            let (dying, c_out) = if g == h {
                (gone, twin(stay))
            } else {
                (gone_t, stay)
            };
            if self.out[c as usize] == dying {
                self.out[c as usize] = c_out;
            }
            self.fix_out(c, self.out[c as usize]);
            if keep_out == NONE {
                keep_out = if g == h { n } else { twin(p) };
            }
        }
        for g in incoming {
            if !self.dead_edge[(g / 2) as usize] {
                self.to[g as usize] = v1;
            }
        }
        self.dead_edge[(h / 2) as usize] = true;
        self.out[v0 as usize] = NONE;
        if keep_out == NONE {
            keep_out = self.next[o as usize];
        }
        self.fix_out(v1, keep_out);
        merged
    }
}

fn non_manifold_vertex(v: usize) -> Error {
    Error::InvalidMesh(format!(
        "vertex {v} joins several fans of faces: remeshing needs a manifold mesh"
    ))
}
