//! The four steps of one remeshing iteration (Botsch & Kobbelt 2004, section 4): split long
//! edges, collapse short ones, flip towards regular valence, relax tangentially and project
//! back onto the input. Splits, collapses and flips run in edge order on one core (each
//! changes what the next may do); relaxation and projection are per vertex, in parallel, and
//! write into new arrays, so the result does not depend on the thread count.

use glam::DVec3;
use rayon::prelude::*;

use super::halfedge::{HalfEdges, NONE, twin};
use crate::metrics::TriangleBvh;

/// Edge flags.
pub(super) const FEATURE: u8 = 1;
/// A border under `--lock-border`: never split, collapsed, flipped or moved.
pub(super) const LOCKED: u8 = 2;
/// A UV seam (with `FEATURE`): the UV chart is cut there, so the line stays.
pub(super) const SEAM: u8 = 4;
/// Vertex flags: on a feature line (or a border), moving only along it.
pub(super) const ON_FEATURE: u8 = 1;
/// A corner of the feature lines (one, or three or more feature edges), or a locked border
/// vertex: it keeps its place and is never removed.
pub(super) const FIXED: u8 = 2;

/// Collapse and split passes stop after this many sweeps over the edges even if there is
/// still work: a sweep that keeps finding some is a rare pathological loop, not progress.
const MAX_SWEEPS: usize = 10;

pub(super) struct Remesher<'a> {
    pub he: HalfEdges,
    pub edge_flags: Vec<u8>,
    pub vertex_flags: Vec<u8>,
    /// The face of the input each vertex was last projected onto (a start for the next query).
    pub hint: Vec<u32>,
    pub surface: &'a TriangleBvh,
    /// The input's feature edges as degenerate triangles (a, b, b): feature vertices project
    /// onto these, so the lines stay where they were.
    pub lines: &'a TriangleBvh,
    /// Twice the area below which a relaxed face counts as flattened.
    pub min_double_area: f64,
    /// With adaptive sizing, each vertex's target length as a share of the longest (0..=1];
    /// an edge aims at the mean of its ends'. `None`: every edge aims at the one length.
    pub size: Option<Vec<f64>>,
    /// Scratch for the link condition.
    mark: Vec<u32>,
    stamp: u32,
}

impl<'a> Remesher<'a> {
    pub fn new(
        he: HalfEdges,
        edge_flags: Vec<u8>,
        vertex_flags: Vec<u8>,
        surface: &'a TriangleBvh,
        lines: &'a TriangleBvh,
        length: f64,
        size: Option<Vec<f64>>,
    ) -> Self {
        let hint = vec![NONE; he.pos.len()];
        Remesher {
            he,
            edge_flags,
            vertex_flags,
            hint,
            surface,
            lines,
            // A face with edges of about `length` has twice its area near length²; a
            // millionth of that is flat for any purpose.
            min_double_area: length * length * 1e-6,
            size,
            mark: Vec::new(),
            stamp: 0,
        }
    }

    /// Splits every edge longer than `high` at its midpoint, the halves too, until none is.
    pub fn split_long(&mut self, high: f64) -> usize {
        let high2 = high * high;
        let mut splits = 0;
        let mut e = 0u32;
        // New edges are appended, so one sweep reaches the halves of the edges it split.
        while (e as usize) < self.he.edge_count() {
            if !self.he.dead_edge[e as usize]
                && self.edge_flags[e as usize] & LOCKED == 0
                && self.he.edge_len2(e) > high2 * self.factor2(e)
            {
                let h = 2 * e;
                let (a, b) = (self.he.from(h), self.he.to[h as usize]);
                let mid = (self.he.pos[a as usize] + self.he.pos[b as usize]) * 0.5;
                // An edge a rounding step long has no midpoint of its own: leave it.
                if mid == self.he.pos[a as usize] || mid == self.he.pos[b as usize] {
                    e += 1;
                    continue;
                }
                if let Some(size) = &mut self.size {
                    size.push(0.5 * (size[a as usize] + size[b as usize]));
                }
                let first_new_edge = self.he.edge_count();
                let (v, cont) = self.he.split(e, mid);
                let flags = self.edge_flags[e as usize];
                self.edge_flags.resize(self.he.edge_count(), 0);
                self.edge_flags[cont as usize] = flags;
                debug_assert_eq!(cont as usize, first_new_edge);
                let on_line = if flags & FEATURE != 0 { ON_FEATURE } else { 0 };
                self.vertex_flags.push(on_line);
                // Hints are faces of the surface or of the lines, by the vertex's flag: a's
                // is good only if it projects onto the same.
                let same = self.vertex_flags[a as usize] & ON_FEATURE == on_line;
                self.hint
                    .push(if same { self.hint[a as usize] } else { NONE });
                debug_assert_eq!(self.vertex_flags.len(), v as usize + 1);
                splits += 1;
                continue; // the shortened edge may still be too long
            }
            e += 1;
        }
        splits
    }

    /// Collapses every edge shorter than `low` whose collapse is legal, creates no edge longer
    /// than `high`, keeps the feature lines and turns no face over.
    pub fn collapse_short(&mut self, low: f64, high: f64) -> usize {
        let (low2, high2) = (low * low, high * high);
        let mut collapses = 0;
        for _ in 0..MAX_SWEEPS {
            let mut sweep = 0;
            for e in 0..self.he.edge_count() as u32 {
                if self.he.dead_edge[e as usize]
                    || self.edge_flags[e as usize] & LOCKED != 0
                    || self.he.edge_len2(e) >= low2 * self.factor2(e)
                {
                    continue;
                }
                let h = 2 * e;
                let (v0, v1) = (self.he.from(h), self.he.to[h as usize]);
                let ok01 = self.collapse_ok(h, high2);
                let ok10 = self.collapse_ok(twin(h), high2);
                // Both ways legal: remove the end with fewer edges, as pmp-library does, so
                // the kept vertex's valence stays nearer six.
                let chosen = match (ok01, ok10) {
                    (true, true) if self.he.valence(v0) < self.he.valence(v1) => h,
                    (true, true) => twin(h),
                    (true, false) => h,
                    (false, true) => twin(h),
                    (false, false) => continue,
                };
                for (gone, kept) in self.he.collapse(chosen) {
                    if gone != NONE {
                        let f = self.edge_flags[gone as usize];
                        self.edge_flags[kept as usize] |= f;
                    }
                }
                sweep += 1;
            }
            collapses += sweep;
            if sweep == 0 {
                break;
            }
        }
        collapses
    }

    /// The square of edge `e`'s target as a share of the longest: 1 without adaptive sizing.
    fn factor2(&self, e: u32) -> f64 {
        match &self.size {
            None => 1.0,
            Some(s) => {
                let (a, b) = (self.he.from(2 * e), self.he.to[2 * e as usize]);
                (0.5 * (s[a as usize] + s[b as usize])).powi(2)
            }
        }
    }

    /// Whether `from(h)` may be removed into `to(h)`.
    fn collapse_ok(&mut self, h: u32, high2: f64) -> bool {
        let (v0, v1) = (self.he.from(h), self.he.to[h as usize]);
        let f0 = self.vertex_flags[v0 as usize];
        if f0 & FIXED != 0 {
            return false;
        }
        // A vertex on a feature line may only slide along it.
        if f0 & ON_FEATURE != 0 && self.edge_flags[(h / 2) as usize] & FEATURE == 0 {
            return false;
        }
        self.stamp = self.stamp.wrapping_add(1);
        if self.stamp == 0 {
            self.mark.iter_mut().for_each(|m| *m = 0);
            self.stamp = 1;
        }
        if !self.he.can_collapse(h, &mut self.mark, self.stamp) {
            return false;
        }
        let p1 = self.he.pos[v1 as usize];
        let mut ok = true;
        let he = &self.he;
        he.for_out(v0, |g| {
            if !ok {
                return;
            }
            let w = he.to[g as usize];
            let f2 = match &self.size {
                None => 1.0,
                Some(s) => (0.5 * (s[v1 as usize] + s[w as usize])).powi(2),
            };
            if w != v1 && he.pos[w as usize].distance_squared(p1) > high2 * f2 {
                ok = false;
                return;
            }
            // The face left of g, (v0, w, x): unless it has v1, it must not turn over or
            // flatten when v0 moves to v1.
            if he.face[g as usize] == NONE {
                return;
            }
            let x = he.to[he.next[g as usize] as usize];
            if w == v1 || x == v1 {
                return;
            }
            let (pw, px) = (he.pos[w as usize], he.pos[x as usize]);
            let before = (pw - he.pos[v0 as usize]).cross(px - he.pos[v0 as usize]);
            let after = (pw - p1).cross(px - p1);
            if before.dot(after) <= 0.0 || sliver(p1, pw, px) {
                ok = false;
            }
        });
        ok
    }

    /// Flips every edge whose flip brings the four corners' valences closer to 6 inside and
    /// 4 on a border (summed absolute deviation) without folding the two faces.
    pub fn flip_towards_regular(&mut self) -> usize {
        // Valences and targets once, kept up to date by each flip: walking four one-rings
        // per edge and sweep took most of the step's time on igea.
        let he = &self.he;
        let (mut valence, target): (Vec<i32>, Vec<i32>) = (0..he.pos.len() as u32)
            .into_par_iter()
            .map(|v| {
                let t = if he.is_border_vertex(v) { 4 } else { 6 };
                (he.valence(v) as i32, t)
            })
            .unzip();
        let mut flips = 0;
        for _ in 0..MAX_SWEEPS {
            let mut sweep = 0;
            for e in 0..self.he.edge_count() as u32 {
                if self.he.dead_edge[e as usize]
                    || self.edge_flags[e as usize] != 0
                    || self.he.is_border_edge(e)
                {
                    continue;
                }
                let (h, o) = (2 * e, 2 * e + 1);
                let he = &self.he;
                let (a, b) = (he.from(h), he.to[h as usize]);
                let c = he.to[he.next[h as usize] as usize];
                let d = he.to[he.next[o as usize] as usize];
                let dev =
                    |v: u32, change: i32| (valence[v as usize] + change - target[v as usize]).abs();
                let before = dev(a, 0) + dev(b, 0) + dev(c, 0) + dev(d, 0);
                let after = dev(a, -1) + dev(b, -1) + dev(c, 1) + dev(d, 1);
                if after >= before || !he.can_flip(e) {
                    continue;
                }
                let [pa, pb, pc, pd] = [a, b, c, d].map(|v| he.pos[v as usize]);
                let old = (pb - pa).cross(pc - pa) + (pa - pb).cross(pd - pb);
                let n0 = (pd - pa).cross(pc - pa);
                let n1 = (pc - pb).cross(pd - pb);
                if n0.dot(old) <= 0.0
                    || n1.dot(old) <= 0.0
                    || sliver(pa, pd, pc)
                    || sliver(pb, pc, pd)
                {
                    continue;
                }
                self.he.flip(e);
                valence[a as usize] -= 1;
                valence[b as usize] -= 1;
                valence[c as usize] += 1;
                valence[d as usize] += 1;
                sweep += 1;
            }
            flips += sweep;
            if sweep == 0 {
                break;
            }
        }
        flips
    }

    /// Moves every free vertex towards the centroid of its neighbours, within its
    /// tangent plane (along its line for a feature vertex), then projects it onto the input:
    /// the surface, or the feature lines for a feature vertex.
    pub fn relax_and_project(&mut self) {
        let he = &self.he;
        let flags = &self.vertex_flags;
        let edge_flags = &self.edge_flags;
        let hints = &self.hint;
        let (surface, lines) = (self.surface, self.lines);
        let moved: Vec<Option<(DVec3, u32)>> = (0..he.pos.len() as u32)
            .into_par_iter()
            .map(|v| {
                let f = flags[v as usize];
                if !he.live_vertex(v) || f & FIXED != 0 {
                    return None;
                }
                let p = he.pos[v as usize];
                let target = if f & ON_FEATURE != 0 {
                    along_line(he, edge_flags, v)?
                } else {
                    in_tangent_plane(he, v)?
                };
                let hint = Some(hints[v as usize]).filter(|&h| h != NONE);
                let index = if f & ON_FEATURE != 0 { lines } else { surface };
                let (q, hit) = index.closest_point(target, hint)?;
                (q != p).then_some((q, hit.face))
            })
            .collect();
        let before = self.he.pos.clone();
        for (v, m) in moved.iter().enumerate() {
            if let Some((q, face)) = *m {
                self.he.pos[v] = q;
                self.hint[v] = face;
            }
        }
        self.undo_folds(&before);
    }

    /// Puts back the corners of every face that the parallel moves turned over or flattened
    /// (each vertex moved knowing only its neighbours' old places), until none is left; all
    /// corners back where they were is the valid mesh of before, so this ends.
    fn undo_folds(&mut self, before: &[DVec3]) {
        let tiny = self.min_double_area;
        loop {
            let he = &self.he;
            let bad: Vec<u32> = (0..he.fhe.len())
                .into_par_iter()
                .filter_map(|f| {
                    let h = he.fhe[f];
                    if h == NONE {
                        return None;
                    }
                    let corners = he.face_vertices_of(h);
                    if corners
                        .iter()
                        .all(|&v| he.pos[v as usize] == before[v as usize])
                    {
                        return None;
                    }
                    let [a, b, c] = corners.map(|v| before[v as usize]);
                    let old = (b - a).cross(c - a);
                    let new = he.face_normal(h);
                    (old.dot(new) <= 0.0 || new.length() <= tiny).then_some(f as u32)
                })
                .collect();
            if bad.is_empty() {
                break;
            }
            for f in bad {
                for v in self.he.face_vertices_of(self.he.fhe[f as usize]) {
                    self.he.pos[v as usize] = before[v as usize];
                }
            }
        }
    }
}

/// The centroid of `v`'s neighbours moved into `v`'s tangent plane (normal: the area-weighted
/// face normal): Botsch and Kobbelt's uniform Laplacian. The area-weighted centroid of the
/// faces (CGAL's choice) gave worse triangles on horse at twice the mean edge length without
/// features: mean smallest angle 52.11 degrees against 53.11.
fn in_tangent_plane(he: &HalfEdges, v: u32) -> Option<DVec3> {
    let p = he.pos[v as usize];
    let (mut c, mut k, mut normal) = (DVec3::ZERO, 0.0, DVec3::ZERO);
    he.for_out(v, |g| {
        c += he.pos[he.to[g as usize] as usize];
        k += 1.0;
        if he.face[g as usize] != NONE {
            normal += he.face_normal(g);
        }
    });
    let n = normal.try_normalize()?;
    let u = c / k - p;
    Some(p + u - n * n.dot(u))
}

/// Whether the face (a, b, c) is a sliver: twice its area under a twentieth of its longest
/// edge squared, which is a smallest angle under about 3 degrees. A collapse or flip that
/// makes one is refused: relaxation could not open it again (three border vertices on a
/// straight border, say, stay in line).
fn sliver(a: DVec3, b: DVec3, c: DVec3) -> bool {
    let longest = a
        .distance_squared(b)
        .max(b.distance_squared(c))
        .max(c.distance_squared(a));
    (b - a).cross(c - a).length() < 0.05 * longest
}

/// The midpoint of `v`'s two feature neighbours, moved onto the line through them.
fn along_line(he: &HalfEdges, edge_flags: &[u8], v: u32) -> Option<DVec3> {
    let mut ends = [DVec3::ZERO; 2];
    let mut k = 0;
    he.for_out(v, |g| {
        if edge_flags[(g / 2) as usize] & FEATURE != 0 && k < 2 {
            ends[k] = he.pos[he.to[g as usize] as usize];
            k += 1;
        }
    });
    if k < 2 {
        return None;
    }
    let p = he.pos[v as usize];
    let d = (ends[1] - ends[0]).try_normalize()?;
    let u = (ends[0] + ends[1]) * 0.5 - p;
    Some(p + d * d.dot(u))
}
