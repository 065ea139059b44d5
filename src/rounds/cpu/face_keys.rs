//! Twin of shaders/rounds/face_keys.wgsl, invocation by invocation: one of the preparation's
//! stages, which [`super::prepare::prepare`] runs in the schedule's order.

use super::morton_keys::PREP_PAD;
use crate::compute::types::{PrepCounts, PrepParams};

/// Twin of `face_keys`.
#[allow(clippy::too_many_arguments)]
pub fn face_keys(
    p: &PrepParams,
    in_indices: &[u32],
    weld_first: &[u32],
    welded_id: &[u32],
    class_of: &[u32],
    sort_keys: &mut [u32],
    sort_vals: &mut [u32],
    class_used: &mut [u32],
    prep_counts: &mut PrepCounts,
) {
    for f in 0..p.face_count as usize {
        let c = [0, 1, 2].map(|j| {
            class_of[welded_id[weld_first[in_indices[3 * f + j] as usize] as usize] as usize]
        });
        sort_vals[f] = f as u32;
        if c[0] == c[1] || c[1] == c[2] || c[0] == c[2] {
            sort_keys[f] = PREP_PAD;
            continue;
        }
        sort_keys[f] = c[0].min(c[1]).min(c[2]);
        for x in c {
            class_used[x as usize] = 1;
        }
        prep_counts.kept += 1;
    }
}
