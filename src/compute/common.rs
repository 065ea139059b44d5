//! Quadric and triangle math in f32, the twin of the functions in shaders/common.inc.wgsl: the same
//! operations in the same order, so CPU and GPU floats agree to rounding (the GPU may fuse
//! multiply-adds).

use crate::compute::types::Quadric;

pub type V3 = [f32; 3];

#[inline]
pub fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
#[inline]
pub fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
#[inline]
pub fn scale(a: V3, s: f32) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}
#[inline]
pub fn dot(a: V3, b: V3) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
#[inline]
pub fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
#[inline]
pub fn length(a: V3) -> f32 {
    dot(a, a).sqrt()
}
#[inline]
pub fn xyz(p: [f32; 4]) -> V3 {
    [p[0], p[1], p[2]]
}

/// Tie-break rank of edge `e` among candidates of equal cost: a bijective integer hash (Chris
/// Wellons' lowbias32), so ranks never tie, yet neighbours get unrelated ranks. Ranking by the id
/// itself let only a few local minima of a monotone id wave win per pass on flat regions, where
/// every cost is zero (a 40 × 40 grid took 127 rounds to 1%).
pub fn tie_rank(e: u32) -> u32 {
    let mut x = e;
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^ (x >> 16)
}

/// `weight · (n·y + d)²` for the plane `n·y + d = 0` (unit `n`), in the frame of the vertex.
pub fn quadric_from_plane(n: V3, d: f32, w: f32) -> Quadric {
    let [a00, a01, a02, a11, a12, a22, b0, b1, b2, c] = crate::quadric::plane_terms(n, d, w);
    Quadric {
        q: [[a00, a01, a02, a11], [a12, a22, b0, b1], [b2, c, w, 0.0]],
    }
}

pub fn quadric_add(a: &Quadric, b: &Quadric) -> Quadric {
    let mut r = *a;
    for i in 0..3 {
        for j in 0..4 {
            r.q[i][j] += b.q[i][j];
        }
    }
    r
}

/// `A y`.
#[inline]
fn mul_a(q: &Quadric, y: V3) -> V3 {
    let [a00, a01, a02, a11] = q.q[0];
    let [a12, a22, _, _] = q.q[1];
    [
        a00 * y[0] + a01 * y[1] + a02 * y[2],
        a01 * y[0] + a11 * y[1] + a12 * y[2],
        a02 * y[0] + a12 * y[1] + a22 * y[2],
    ]
}

#[inline]
fn b_of(q: &Quadric) -> V3 {
    [q.q[1][2], q.q[1][3], q.q[2][0]]
}

/// The same quadric with its origin moved to `origin + t`... measured from the new origin `o'`,
/// a point is `y' = x - o'` and `x - o = y' + t` with `t = o' - o`: `E'(y') = E(y' + t)`, so
/// `b' = b + A t` and `c' = E(t)`. With `t` an edge length the terms stay small.
pub fn quadric_shift(q: &Quadric, t: V3) -> Quadric {
    let at = mul_a(q, t);
    let b = b_of(q);
    let nb = add(b, at);
    let c = dot(t, at) + 2.0 * dot(b, t) + q.q[2][1];
    let mut r = *q;
    r.q[1][2] = nb[0];
    r.q[1][3] = nb[1];
    r.q[2][0] = nb[2];
    r.q[2][1] = c;
    r
}

/// `E(y)`, clamped at zero (rounding can make it slightly negative).
pub fn quadric_eval(q: &Quadric, y: V3) -> f32 {
    let v = dot(y, mul_a(q, y)) + 2.0 * dot(b_of(q), y) + q.q[2][1];
    v.max(0.0)
}

/// The `y` minimising the quadric when `A` is well conditioned: the determinant compared with
/// the cube of A's trace (as `crate::quadric::Quadric::optimum`), so near-planar
/// neighbourhoods fall back to endpoints or the midpoint instead of sliding along the plane.
pub fn quadric_optimum(q: &Quadric) -> Option<V3> {
    let [a00, a01, a02, a11] = q.q[0];
    let [a12, a22, _, _] = q.q[1];
    let c00 = a11 * a22 - a12 * a12;
    let c01 = a02 * a12 - a01 * a22;
    let c02 = a01 * a12 - a02 * a11;
    let det = a00 * c00 + a01 * c01 + a02 * c02;
    let tr = a00 + a11 + a22;
    // Written so that NaN fails too.
    let conditioned = tr > 0.0 && det.abs() > 1e-6 * tr * tr * tr;
    if !conditioned {
        return None;
    }
    let c11 = a00 * a22 - a02 * a02;
    let c12 = a01 * a02 - a00 * a12;
    let c22 = a00 * a11 - a01 * a01;
    let inv = 1.0 / det;
    let b = b_of(q);
    let y = [
        -(c00 * b[0] + c01 * b[1] + c02 * b[2]) * inv,
        -(c01 * b[0] + c11 * b[1] + c12 * b[2]) * inv,
        -(c02 * b[0] + c12 * b[1] + c22 * b[2]) * inv,
    ];
    y.iter().all(|x| x.is_finite()).then_some(y)
}

/// Quality from |cross| already at hand (the flip test computes it): the same value as
/// [`triangle_quality`], one cross product and square root fewer.
pub fn quality_from_area2(area2: f32, p0: V3, p1: V3, p2: V3) -> f32 {
    let d10 = sub(p1, p0);
    let d20 = sub(p2, p0);
    let d12 = sub(p1, p2);
    let longest = dot(d10, d10).max(dot(d20, d20)).max(dot(d12, d12));
    if longest > 0.0 { area2 / longest } else { 0.0 }
}

/// |cross| / longest edge²: 0 for a needle, √3/2 for an equilateral triangle (vcglib's measure,
/// as the greedy's `triangle_quality` in src/greedy/evaluate.rs).
pub fn triangle_quality(p0: V3, p1: V3, p2: V3) -> f32 {
    let d10 = sub(p1, p0);
    let d20 = sub(p2, p0);
    let d12 = sub(p1, p2);
    let area2 = length(cross(d10, d20));
    let longest = dot(d10, d10).max(dot(d20, d20)).max(dot(d12, d12));
    if longest > 0.0 { area2 / longest } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shifted_quadric_evaluates_the_same_point() {
        let mut q = quadric_from_plane([0.0, 0.0, 1.0], -0.25, 2.0);
        q = quadric_add(&q, &quadric_from_plane([0.6, 0.8, 0.0], 0.1, 0.5));
        let t = [0.01, -0.02, 0.03];
        let s = quadric_shift(&q, t);
        for y in [[0.0, 0.0, 0.0], [0.1, 0.2, -0.3]] {
            let direct = quadric_eval(&q, add(y, t));
            let shifted = quadric_eval(&s, y);
            assert!(
                (direct - shifted).abs() <= 1e-6 * direct.max(1.0),
                "{direct} {shifted}"
            );
        }
    }

    #[test]
    fn three_planes_meet_at_their_corner() {
        let mut q = quadric_from_plane([1.0, 0.0, 0.0], -0.1, 1.0);
        q = quadric_add(&q, &quadric_from_plane([0.0, 1.0, 0.0], -0.2, 1.0));
        q = quadric_add(&q, &quadric_from_plane([0.0, 0.0, 1.0], -0.3, 1.0));
        let y = quadric_optimum(&q).unwrap();
        for (a, b) in y.iter().zip([0.1, 0.2, 0.3]) {
            assert!((a - b).abs() < 1e-6);
        }
        assert_eq!(
            quadric_optimum(&quadric_from_plane([0.0, 0.0, 1.0], 0.0, 1.0)),
            None
        );
    }
}
