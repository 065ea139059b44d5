//! Twin of shaders/rounds/attributes.inc.wgsl: the appearance channels the rounds carry, Hoppe's
//! memory-efficient attribute quadric (H. Hoppe, *New quadric metric for simplifying meshes with
//! appearance attributes*, IEEE Visualization 1999) as [`crate::quadric::attributes`] gives the
//! greedy reference, in f32. Per attribute vertex of the welded input: its `m` weighted values
//! and its sums (stride `4m + 1`: `G` per channel, then `D` per channel, then `W`), relative to
//! its vertex's position like the quadrics.

use crate::compute::common::{V3, dot};
use crate::compute::types::{Params, Quadric, attr_layout};

/// The channels of the round (`Params::attributes`).
#[derive(Clone, Copy)]
pub struct Channels {
    pub m: usize,
    pub colors: usize,
    pub uv: bool,
}

impl Channels {
    pub fn of(p: &Params) -> Channels {
        Channels {
            m: attr_layout::channels(p.attributes) as usize,
            colors: attr_layout::colors(p.attributes) as usize,
            uv: attr_layout::uv(p.attributes),
        }
    }

    pub fn stride(&self) -> usize {
        4 * self.m + 1
    }

    /// Channel `j`'s `G` of attribute vertex `x`.
    #[inline]
    pub fn g(&self, sums: &[f32], x: u32, j: usize) -> V3 {
        let o = x as usize * self.stride() + 3 * j;
        [sums[o], sums[o + 1], sums[o + 2]]
    }

    /// Channel `j`'s `D` of attribute vertex `x`, measured from its vertex's position moved by
    /// `t`.
    #[inline]
    pub fn d(&self, sums: &[f32], x: u32, j: usize, t: V3) -> f32 {
        sums[x as usize * self.stride() + 3 * self.m + j] + dot(self.g(sums, x, j), t)
    }

    #[inline]
    pub fn w(&self, sums: &[f32], x: u32) -> f32 {
        sums[x as usize * self.stride() + 4 * self.m]
    }

    /// `q` less what the best values take away for the group of attribute vertices `a` and `b`
    /// (their sums measured from their vertices moved by `ta` and `tb`). A group without area
    /// takes nothing away.
    pub fn reduce_pair(
        &self,
        sums: &[f32],
        q: &Quadric,
        a: u32,
        ta: V3,
        b: u32,
        tb: V3,
    ) -> Quadric {
        let w = self.w(sums, a) + self.w(sums, b);
        let mut r = *q;
        if w.is_nan() || w <= 0.0 {
            return r;
        }
        let inv = 1.0 / w;
        for j in 0..self.m {
            let (ga, gb) = (self.g(sums, a, j), self.g(sums, b, j));
            let g = [ga[0] + gb[0], ga[1] + gb[1], ga[2] + gb[2]];
            let d = self.d(sums, a, j, ta) + self.d(sums, b, j, tb);
            let [q0, q1, q2] = &mut r.q;
            q0[0] -= g[0] * g[0] * inv;
            q0[1] -= g[0] * g[1] * inv;
            q0[2] -= g[0] * g[2] * inv;
            q0[3] -= g[1] * g[1] * inv;
            q1[0] -= g[1] * g[2] * inv;
            q1[1] -= g[2] * g[2] * inv;
            q1[2] -= d * g[0] * inv;
            q1[3] -= d * g[1] * inv;
            q2[0] -= d * g[2] * inv;
            q2[1] -= d * d * inv;
        }
        r
    }

    /// `q` with attribute vertex `x`'s sums (measured from its vertex moved by `t`) held at
    /// attribute vertex `v`'s values.
    pub fn hold(
        &self,
        sums: &[f32],
        values: &[f32],
        q: &Quadric,
        x: u32,
        t: V3,
        v: u32,
    ) -> Quadric {
        let m = self.m;
        let w = self.w(sums, x);
        let mut r = *q;
        for j in 0..m {
            let s = values[v as usize * m + j];
            let g = self.g(sums, x, j);
            r.q[1][2] -= s * g[0];
            r.q[1][3] -= s * g[1];
            r.q[2][0] -= s * g[2];
            r.q[2][1] += w * s * s - 2.0 * s * self.d(sums, x, j, t);
        }
        r
    }
}
