//! Twin of shaders/rounds/class_rank.wgsl, invocation by invocation: one of the preparation's
//! stages, which [`super::prepare::prepare`] runs in the schedule's order.

use crate::compute::types::PrepParams;

/// Twin of `class_rank`.
pub fn class_rank(
    p: &PrepParams,
    welded_id: &[u32],
    sort_vals: &[u32],
    class_of: &mut [u32],
    class_welded: &mut [u32],
) {
    for i in 0..welded_id[p.vertex_count as usize] as usize {
        let w = sort_vals[i];
        class_of[w as usize] = i as u32;
        class_welded[i] = w;
    }
}
