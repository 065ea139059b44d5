//! The quadric error metric (Garland & Heckbert 1997): the one definition the CPU paths use.
//!
//! A quadric stores the symmetric 4×4 form of a sum of weighted squared plane distances,
//! `E(p) = pᵀAp + 2bᵀp + c`, and the summed weight, so that `E / weight` is a mean squared
//! distance: the simplifier reports `sqrt(E / weight)` as an error in units of length.

pub(crate) mod attributes;

/// The terms of `w·(n·p + d)²` in storage order: A's upper triangle, b, c. One definition for
/// the f64 quadric here and the f32 one the rounds' shaders and their twins keep.
pub fn plane_terms<T: Copy + std::ops::Mul<Output = T>>(n: [T; 3], d: T, w: T) -> [T; 10] {
    [
        w * n[0] * n[0],
        w * n[0] * n[1],
        w * n[0] * n[2],
        w * n[1] * n[1],
        w * n[1] * n[2],
        w * n[2] * n[2],
        w * n[0] * d,
        w * n[1] * d,
        w * n[2] * d,
        w * d * d,
    ]
}

/// A weighted sum of squared distances to planes. All f64: f32 loses the small differences of
/// large sums on million-triangle meshes.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Quadric {
    /// Upper triangle of A: a00 a01 a02 a11 a12 a22.
    pub a: [f64; 6],
    pub b: [f64; 3],
    pub c: f64,
    pub weight: f64,
}

impl Quadric {
    /// `weight · (n·p + d)²` for the plane `n·p + d = 0` (`n` of unit length).
    pub fn from_plane(n: [f64; 3], d: f64, weight: f64) -> Self {
        let [a00, a01, a02, a11, a12, a22, b0, b1, b2, c] = plane_terms(n, d, weight);
        Quadric {
            a: [a00, a01, a02, a11, a12, a22],
            b: [b0, b1, b2],
            c,
            weight,
        }
    }

    pub fn add(&mut self, o: &Quadric) {
        for i in 0..6 {
            self.a[i] += o.a[i];
        }
        for i in 0..3 {
            self.b[i] += o.b[i];
        }
        self.c += o.c;
        self.weight += o.weight;
    }

    pub fn sum(&self, o: &Quadric) -> Quadric {
        let mut q = *self;
        q.add(o);
        q
    }

    /// The weighted sum of squared distances at `p`, clamped at zero (rounding can make it
    /// slightly negative).
    pub fn eval(&self, p: [f64; 3]) -> f64 {
        let [a00, a01, a02, a11, a12, a22] = self.a;
        let [x, y, z] = p;
        let v = a00 * x * x
            + a11 * y * y
            + a22 * z * z
            + 2.0 * (a01 * x * y + a02 * x * z + a12 * y * z)
            + 2.0 * (self.b[0] * x + self.b[1] * y + self.b[2] * z)
            + self.c;
        v.max(0.0)
    }

    /// The point minimising the quadric, when `A` is well conditioned.
    ///
    /// The determinant is compared with the cube of A's scale (its trace) so the test does not
    /// depend on mesh size or on how much weight the quadric carries; 1e-6 keeps near-planar and
    /// near-cylindrical neighbourhoods (rank 1 or 2) out, where the solve would place the vertex
    /// far along the flat direction.
    #[inline]
    pub fn optimum(&self) -> Option<[f64; 3]> {
        let [a00, a01, a02, a11, a12, a22] = self.a;
        let c00 = a11 * a22 - a12 * a12;
        let c01 = a02 * a12 - a01 * a22;
        let c02 = a01 * a12 - a02 * a11;
        let det = a00 * c00 + a01 * c01 + a02 * c02;
        let scale = a00 + a11 + a22;
        if scale.is_nan() || scale <= 0.0 || det.abs() <= 1e-6 * scale * scale * scale {
            return None;
        }
        let c11 = a00 * a22 - a02 * a02;
        let c12 = a01 * a02 - a00 * a12;
        let c22 = a00 * a11 - a01 * a01;
        let inv = 1.0 / det;
        let [b0, b1, b2] = self.b;
        // p = -A⁻¹ b, A⁻¹ = adj(A) / det with the symmetric cofactors above.
        let p = [
            -(c00 * b0 + c01 * b1 + c02 * b2) * inv,
            -(c01 * b0 + c11 * b1 + c12 * b2) * inv,
            -(c02 * b0 + c12 * b1 + c22 * b2) * inv,
        ];
        p.iter().all(|x| x.is_finite()).then_some(p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn three_planes_meet_at_their_corner() {
        // x = 1, y = 2, z = 3 as unit planes: the optimum is (1, 2, 3) with zero error.
        let mut q = Quadric::from_plane([1., 0., 0.], -1.0, 1.0);
        q.add(&Quadric::from_plane([0., 1., 0.], -2.0, 2.0));
        q.add(&Quadric::from_plane([0., 0., 1.], -3.0, 0.5));
        let p = q.optimum().unwrap();
        for (a, b) in p.iter().zip([1.0, 2.0, 3.0]) {
            assert!((a - b).abs() < 1e-12);
        }
        assert!(q.eval(p) < 1e-12);
        // One unit away from the x-plane costs its weight.
        assert!((q.eval([2.0, 2.0, 3.0]) - 1.0).abs() < 1e-12);
        assert_eq!(q.weight, 3.5);
    }

    #[test]
    fn a_single_plane_has_no_unique_optimum() {
        assert_eq!(Quadric::from_plane([0., 0., 1.], 0.0, 1.0).optimum(), None);
    }
}
