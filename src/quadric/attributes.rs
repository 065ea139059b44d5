//! Appearance attributes in the quadric: H. Hoppe, *New quadric metric for simplifying meshes
//! with appearance attributes*, IEEE Visualization 1999 (after M. Garland, P. Heckbert,
//! *Simplifying surfaces with color and texture using quadric error metrics*, 1998).
//!
//! Over a face, each attribute channel `s` (a colour component, a UV coordinate, a normal
//! component) is the linear function `s(p) = g·p + d` that matches its three corners, with `g`
//! in the face's plane. A face adds `area · (g·p + d − s)²` per channel to the error of placing
//! a vertex at `p` with value `s`. Expanded, the `p`-only part (`area · g gᵀ`, `area · d g`,
//! `area · d²`) folds into the vertex's geometric [`Quadric`]; what is left per channel is
//! `G = Σ area · g` and `D = Σ area · d`, and once per vertex `W = Σ area` — Hoppe's
//! memory-efficient form, 10 + 4m numbers for m channels. For a given `p` the best value of a
//! channel is `(G·p + D) / W`; put back in, the error is the quadric reduced by
//! `G Gᵀ / W`, `D G / W` and `D² / W` per channel ([`reduce_pair`]), whose minimum is a 3×3 solve like the
//! geometric one. So the survivor of a collapse gets its position and its attribute values from
//! one solve, and a collapse that would smear a colour edge or stretch a texture costs what it
//! does to the look.
//!
//! The quadrics sit with the topological vertex (position class), the attribute sums with each
//! attribute vertex: a seam vertex has one set of sums per side, so sides never blur into each
//! other.

use super::Quadric;
use crate::mesh::Mesh;
use crate::options::AttributeWeights;

/// RGBA, UV and a normal at most.
pub(crate) const MAX_CHANNELS: usize = 9;
/// The attribute sums of one attribute vertex: `G` (3 per channel), `D` (1 per channel), `W`.
pub(crate) const MAX_STRIDE: usize = 4 * MAX_CHANNELS + 1;

/// Which channels take part, where each sits in a vertex's values, and its weight.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Layout {
    /// Channels in all: the colour's first (3, or 4 when some alpha is not 1), then the UV's,
    /// then the normal's.
    pub m: usize,
    pub color: usize,
    pub uv: bool,
    pub normal: bool,
    /// Per channel: the user's weight for its kind (a value difference of 1 costs like a
    /// displacement of `weight` bounding-box diagonals).
    pub weight: [f64; MAX_CHANNELS],
}

impl Layout {
    /// The channels of `mesh` that have a weight above zero, or `None` when none does.
    pub(crate) fn new(mesh: &Mesh, w: &AttributeWeights) -> Option<Layout> {
        let color = match &mesh.colors {
            Some(c) if w.color > 0.0 => {
                if c.iter().any(|c| c[3] != 1.0) {
                    4
                } else {
                    3
                }
            }
            _ => 0,
        };
        let uv = mesh.uvs.is_some() && w.uv > 0.0;
        let normal = mesh.normals.is_some() && w.normal > 0.0;
        let m = color + 2 * uv as usize + 3 * normal as usize;
        if m == 0 {
            return None;
        }
        let mut weight = [0.0; MAX_CHANNELS];
        weight[..color].fill(w.color);
        let uv_at = color;
        if uv {
            weight[uv_at..uv_at + 2].fill(w.uv);
        }
        if normal {
            let n_at = uv_at + 2 * uv as usize;
            weight[n_at..n_at + 3].fill(w.normal);
        }
        Some(Layout {
            m,
            color,
            uv,
            normal,
            weight,
        })
    }

    /// `n` colour channels alone, weight 1: for fitting colours without a collapse cost (the
    /// best values do not depend on the weight).
    pub(crate) fn colors(n: usize) -> Layout {
        let mut weight = [0.0; MAX_CHANNELS];
        weight[..n].fill(1.0);
        Layout {
            m: n,
            color: n,
            uv: false,
            normal: false,
            weight,
        }
    }

    /// Numbers per attribute vertex in [`Attributes::sums`].
    pub(crate) fn stride(&self) -> usize {
        4 * self.m + 1
    }

    pub(crate) fn uv_at(&self) -> usize {
        self.color
    }

    pub(crate) fn normal_at(&self) -> usize {
        self.color + 2 * self.uv as usize
    }
}

/// The attribute state of a simplification: per attribute vertex its values (as read, then as
/// collapses solve them) and its attribute sums.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Attributes {
    pub layout: Layout,
    /// `m` values per attribute vertex, unweighted.
    pub value: Vec<f64>,
    /// `stride` numbers per attribute vertex (see [`MAX_STRIDE`]).
    pub sums: Vec<f64>,
}

impl Attributes {
    /// The values of `mesh`'s attribute vertices in `layout`'s channels, and zero sums.
    pub(crate) fn new(mesh: &Mesh, layout: Layout) -> Attributes {
        let n = mesh.positions.len();
        let m = layout.m;
        let mut value = vec![0.0; n * m];
        for (v, out) in value.chunks_exact_mut(m).enumerate() {
            if let Some(c) = &mesh.colors {
                for (o, &x) in out[..layout.color].iter_mut().zip(&c[v]) {
                    *o = f64::from(x);
                }
            }
            if layout.uv
                && let Some(t) = &mesh.uvs
            {
                let at = layout.uv_at();
                out[at] = f64::from(t[v][0]);
                out[at + 1] = f64::from(t[v][1]);
            }
            if layout.normal
                && let Some(nr) = &mesh.normals
            {
                let at = layout.normal_at();
                for k in 0..3 {
                    out[at + k] = f64::from(nr[v][k]);
                }
            }
        }
        let sums = vec![0.0; n * layout.stride()];
        Attributes {
            layout,
            value,
            sums,
        }
    }

    pub(crate) fn values(&self, v: u32) -> &[f64] {
        let m = self.layout.m;
        &self.value[v as usize * m..(v as usize + 1) * m]
    }

    pub(crate) fn sums_of(&self, v: u32) -> &[f64] {
        let s = self.layout.stride();
        &self.sums[v as usize * s..(v as usize + 1) * s]
    }

    /// `from`'s sums go into `to`, whose values become the best for the merged sums at `p`,
    /// kept valid: colours in 0..1, UVs within the range the two had (so a UV never leaves the
    /// span of the chart it came from), normals as solved (unit length on output).
    pub(crate) fn merge_into(&mut self, to: u32, from: u32, p: [f64; 3], solve: bool) {
        let (s, m) = (self.layout.stride(), self.layout.m);
        let (t, f) = (to as usize, from as usize);
        if t != f {
            for k in 0..s {
                self.sums[t * s + k] += self.sums[f * s + k];
            }
        }
        if !solve {
            return;
        }
        let mut best = [0.0; MAX_CHANNELS];
        if !optimum_values(&self.layout, &self.sums[t * s..(t + 1) * s], p, &mut best) {
            return;
        }
        let uv = self.layout.uv_at()..self.layout.uv_at() + 2 * self.layout.uv as usize;
        for (j, &x) in best.iter().enumerate().take(m) {
            let (old_t, old_f) = (self.value[t * m + j], self.value[f * m + j]);
            self.value[t * m + j] = if j < self.layout.color {
                x.clamp(0.0, 1.0)
            } else if uv.contains(&j) {
                x.clamp(old_t.min(old_f), old_t.max(old_f))
            } else {
                x
            };
        }
    }

    /// Writes the values into `mesh`'s colours, UVs and normals (unit length).
    pub(crate) fn write(&self, mesh: &mut Mesh) {
        let l = &self.layout;
        let m = l.m;
        if l.color > 0
            && let Some(c) = &mut mesh.colors
        {
            for (out, v) in c.iter_mut().zip(self.value.chunks_exact(m)) {
                for k in 0..l.color {
                    out[k] = v[k] as f32;
                }
            }
        }
        if l.uv
            && let Some(t) = &mut mesh.uvs
        {
            let at = l.uv_at();
            for (out, v) in t.iter_mut().zip(self.value.chunks_exact(m)) {
                *out = [v[at] as f32, v[at + 1] as f32];
            }
        }
        if l.normal
            && let Some(nr) = &mut mesh.normals
        {
            let at = l.normal_at();
            for (out, v) in nr.iter_mut().zip(self.value.chunks_exact(m)) {
                let n = [v[at], v[at + 1], v[at + 2]];
                let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                if len > 0.0 {
                    *out = n.map(|x| (x / len) as f32);
                }
            }
        }
    }
}

/// One face's attribute functions: per channel the gradient `g` (in the face's plane) and
/// offset `d` of `weight · s(p) = g·p + d` through its three corners. Filled in place
/// ([`FaceTerms::set`]) by a loop that keeps one: returned by value (300 bytes) and zeroed per
/// face, it was 90M of 1.43G instructions simplifying the painted horse to 1%.
#[derive(Default)]
pub(crate) struct FaceTerms {
    g: [[f64; 3]; MAX_CHANNELS],
    d: [f64; MAX_CHANNELS],
    m: usize,
}

impl FaceTerms {
    /// `p`: the corners; `s`: their values (unweighted). `None` for a face without area.
    #[cfg(test)]
    pub(crate) fn new(layout: &Layout, p: [[f64; 3]; 3], s: [&[f64]; 3]) -> Option<FaceTerms> {
        let mut t = FaceTerms::default();
        t.set(layout, p, s).then_some(t)
    }

    /// This face's functions in place of the last; false (and unusable) for a face without
    /// area.
    #[inline]
    pub(crate) fn set(&mut self, layout: &Layout, p: [[f64; 3]; 3], s: [&[f64]; 3]) -> bool {
        let t = self;
        let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let (e1, e2) = (sub(p[1], p[0]), sub(p[2], p[0]));
        let (a, b, c) = (dot(e1, e1), dot(e1, e2), dot(e2, e2));
        let det = a * c - b * b;
        if det.is_nan() || det <= 0.0 {
            return false;
        }
        t.m = layout.m;
        for (j, &w) in layout.weight.iter().enumerate().take(t.m) {
            let (s0, s1, s2) = (w * s[0][j], w * s[1][j], w * s[2][j]);
            let (d1, d2) = (s1 - s0, s2 - s0);
            // g = α e1 + β e2 with g·e1 = d1 and g·e2 = d2 (the Gram system of the two edges).
            let alpha = (c * d1 - b * d2) / det;
            let beta = (a * d2 - b * d1) / det;
            let g = [0, 1, 2].map(|k| alpha * e1[k] + beta * e2[k]);
            t.g[j] = g;
            t.d[j] = s0 - dot(g, p[0]);
        }
        true
    }

    /// Adds `area · Σ (g·p + d)²` to the quadric (its weight is the face's already).
    pub(crate) fn fold_into(&self, q: &mut Quadric, area: f64) {
        for j in 0..self.m {
            let ([g0, g1, g2], d) = (self.g[j], self.d[j]);
            q.a[0] += area * g0 * g0;
            q.a[1] += area * g0 * g1;
            q.a[2] += area * g0 * g2;
            q.a[3] += area * g1 * g1;
            q.a[4] += area * g1 * g2;
            q.a[5] += area * g2 * g2;
            q.b[0] += area * d * g0;
            q.b[1] += area * d * g1;
            q.b[2] += area * d * g2;
            q.c += area * d * d;
        }
    }

    /// Adds this face's `G`, `D` and `W` (see [`MAX_STRIDE`]) to an attribute vertex's sums.
    pub(crate) fn add_to(&self, sums: &mut [f64], area: f64) {
        let m = self.m;
        for j in 0..m {
            for k in 0..3 {
                sums[3 * j + k] += area * self.g[j][k];
            }
            sums[3 * m + j] += area * self.d[j];
        }
        sums[4 * m] += area;
    }
}

/// The quadric with the best values put in for the group two attribute vertices' sums make
/// together: what is left of the error once each channel takes `(G·p + D) / W` (Hoppe 1999,
/// section 5). A group without area takes nothing away. Read straight from the two sums:
/// forming the group first spent 5% of the run in memmove on the painted 1M scan.
#[inline]
pub(crate) fn reduce_pair(q: &Quadric, m: usize, a: &[f64], b: &[f64]) -> Quadric {
    let mut r = *q;
    let w = a[4 * m] + b[4 * m];
    if w.is_nan() || w <= 0.0 {
        return r;
    }
    let inv = 1.0 / w;
    for j in 0..m {
        let g0 = a[3 * j] + b[3 * j];
        let g1 = a[3 * j + 1] + b[3 * j + 1];
        let g2 = a[3 * j + 2] + b[3 * j + 2];
        let d = a[3 * m + j] + b[3 * m + j];
        r.a[0] -= g0 * g0 * inv;
        r.a[1] -= g0 * g1 * inv;
        r.a[2] -= g0 * g2 * inv;
        r.a[3] -= g1 * g1 * inv;
        r.a[4] -= g1 * g2 * inv;
        r.a[5] -= g2 * g2 * inv;
        r.b[0] -= d * g0 * inv;
        r.b[1] -= d * g1 * inv;
        r.b[2] -= d * g2 * inv;
        r.c -= d * d * inv;
    }
    r
}

/// The quadric with a group's channels held at `values` (unweighted), `q(p) − 2 Σ s (G·p + D)
/// plus W Σ s²` over each channel's weighted value `s`: the error of a survivor that keeps its
/// values.
pub(crate) fn hold(q: &Quadric, layout: &Layout, g: &[f64], values: &[f64]) -> Quadric {
    let m = layout.m;
    let mut r = *q;
    let w = g[4 * m];
    for j in 0..m {
        let s = layout.weight[j] * values[j];
        for k in 0..3 {
            r.b[k] -= s * g[3 * j + k];
        }
        r.c += w * s * s - 2.0 * s * g[3 * m + j];
    }
    r
}

/// The best values of a group's channels at `p`, unweighted; false for a group without area.
pub(crate) fn optimum_values(
    layout: &Layout,
    g: &[f64],
    p: [f64; 3],
    out: &mut [f64; MAX_CHANNELS],
) -> bool {
    let m = layout.m;
    let w = g[4 * m];
    if w.is_nan() || w <= 0.0 {
        return false;
    }
    for j in 0..m {
        let s = (g[3 * j] * p[0] + g[3 * j + 1] * p[1] + g[3 * j + 2] * p[2] + g[3 * m + j]) / w;
        out[j] = s / layout.weight[j];
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    fn layout(m: usize, weight: f64) -> Layout {
        let mut w = [0.0; MAX_CHANNELS];
        w[..m].fill(weight);
        Layout {
            m,
            color: m,
            uv: false,
            normal: false,
            weight: w,
        }
    }

    /// A linear colour ramp over a flat patch of faces: every face's function is the ramp, so
    /// the reduced quadric has zero error everywhere on the plane and the best value at any
    /// point is the ramp's value there.
    #[test]
    fn a_linear_ramp_is_reproduced_exactly() {
        let l = layout(3, 0.5);
        let ramp = |p: [f64; 3]| [0.2 + p[0], 0.5 - 0.3 * p[1], 0.1 + 0.2 * p[0] + 0.4 * p[1]];
        let pts = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
        ];
        let mut q = Quadric::default();
        let mut sums = [0.0; MAX_STRIDE];
        for f in [[0, 1, 2], [1, 3, 2]] {
            let p = f.map(|i| pts[i]);
            let vals = p.map(ramp);
            let t = FaceTerms::new(&l, p, [&vals[0], &vals[1], &vals[2]]).unwrap();
            let pq = Quadric::from_plane([0.0, 0.0, 1.0], 0.0, 0.5);
            q.add(&pq);
            t.fold_into(&mut q, 0.5);
            t.add_to(&mut sums, 0.5);
        }
        let r = reduce_pair(&q, 3, &sums, &[0.0; MAX_STRIDE]);
        for p in [[0.3, 0.7, 0.0], [0.9, 0.1, 0.0], [2.0, -1.0, 0.0]] {
            assert!(r.eval(p) < 1e-12, "error {} at {p:?}", r.eval(p));
            let mut s = [0.0; MAX_CHANNELS];
            assert!(optimum_values(&l, &sums, p, &mut s));
            for (a, b) in s.iter().zip(ramp(p)) {
                assert!((a - b).abs() < 1e-12, "{a} against {b}");
            }
        }
        // Off the plane the geometric part still counts.
        assert!((r.eval([0.3, 0.3, 0.1]) - 1.0 * 0.01).abs() < 1e-12);
    }

    /// A colour step across a shared edge costs more than nothing at the edge's midpoint, and
    /// more the larger its weight.
    #[test]
    fn a_colour_step_has_a_cost_that_grows_with_its_weight() {
        let cost = |w: f64| {
            let l = layout(1, w);
            let pts = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
            let mut q = Quadric::from_plane([0.0, 0.0, 1.0], 0.0, 0.5);
            let vals: [[f64; 1]; 3] = [[0.0], [1.0], [0.0]];
            let t = FaceTerms::new(&l, pts, [&vals[0], &vals[1], &vals[2]]).unwrap();
            t.fold_into(&mut q, 0.5);
            let mut sums = [0.0; MAX_STRIDE];
            t.add_to(&mut sums, 0.5);
            // Held at the ramp's own value there, 1: no error; at 0.5, a quarter of the raw.
            let l1 = layout(1, w);
            assert!(hold(&q, &l1, &sums, &[1.0]).eval([1.0, 0.0, 0.0]) < 1e-12);
            let half = hold(&q, &l1, &sums, &[0.5]).eval([1.0, 0.0, 0.0]);
            assert!((half - 0.25 * q.eval([1.0, 0.0, 0.0])).abs() < 1e-12);
            // Reduced: the best value at (1, 0, 0); raw: the value 0 kept there.
            (
                reduce_pair(&q, 1, &sums, &[0.0; MAX_STRIDE]).eval([1.0, 0.0, 0.0]),
                q.eval([1.0, 0.0, 0.0]),
            )
        };
        let (best1, raw1) = cost(1.0);
        let (_, raw2) = cost(2.0);
        assert!(best1 < 1e-12, "the best value fits a linear face exactly");
        assert!((raw1 - 0.5).abs() < 1e-12, "raw {raw1}");
        assert!((raw2 - 4.0 * raw1).abs() < 1e-12);
    }
}
