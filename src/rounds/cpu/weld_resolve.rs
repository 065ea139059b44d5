//! Twin of shaders/rounds/weld_resolve.wgsl, invocation by invocation: one of the preparation's
//! stages, which [`super::prepare::prepare`] runs in the schedule's order.

use crate::compute::types::PrepParams;

/// Twin of `weld_resolve`.
pub fn weld_resolve(
    p: &PrepParams,
    weld_table: &[u32],
    weld_slot: &[u32],
    weld_first: &mut [u32],
    welded_id: &mut [u32],
) {
    for v in 0..p.vertex_count as usize {
        let first = weld_table[weld_slot[v] as usize] - 1;
        weld_first[v] = first;
        welded_id[v] = (first == v as u32) as u32;
    }
}
