//! f64 vector helpers for the set-up and the collapse checks, on glam's `DVec3`: the greedy keeps
//! positions as `[f64; 3]` (plain arrays in its vertex tables), and these convert at no cost.
//! glam's `cross` and `dot` do the same operations in the same order as the hand-written ones
//! they replaced, so results are bit for bit the same.

use glam::DVec3;

#[inline]
pub(super) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    (DVec3::from_array(a) - DVec3::from_array(b)).to_array()
}
#[inline]
pub(super) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    DVec3::from_array(a).cross(DVec3::from_array(b)).to_array()
}
#[inline]
pub(super) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    DVec3::from_array(a).dot(DVec3::from_array(b))
}
#[inline]
pub(super) fn norm(a: [f64; 3]) -> f64 {
    DVec3::from_array(a).length()
}
