//! Twin of shaders/rounds/prep_faces.wgsl, invocation by invocation: one of the preparation's
//! stages, which [`super::prepare::prepare`] runs in the schedule's order.

use crate::compute::types::{FaceExtra, PrepCounts};

/// Twin of `prep_faces`.
#[allow(clippy::too_many_arguments)]
pub fn prep_faces(
    in_indices: &[u32],
    weld_first: &[u32],
    welded_id: &[u32],
    class_of: &[u32],
    class_used: &[u32],
    sort_vals: &[u32],
    prep_counts: &PrepCounts,
    indices: &mut [u32],
    face_extra: &mut [FaceExtra],
) {
    for i in 0..prep_counts.kept as usize {
        let f = sort_vals[i] as usize;
        let a = [0, 1, 2].map(|j| weld_first[in_indices[3 * f + j] as usize]);
        for j in 0..3 {
            indices[3 * i + j] = class_used[class_of[welded_id[a[j] as usize] as usize] as usize];
        }
        face_extra[i] = FaceExtra {
            attr: a,
            origin: f as u32,
        };
    }
}
