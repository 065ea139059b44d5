//! Twin of shaders/rounds/prep_vertices.wgsl, invocation by invocation: one of the preparation's
//! stages, which [`super::prepare::prepare`] runs in the schedule's order.

use crate::compute::types::PrepParams;

/// Twin of `prep_vertices`, in f64 as `mesh::prepare::normalize`.
#[allow(clippy::too_many_arguments)]
pub fn prep_vertices(
    p: &PrepParams,
    in_positions: &[f32],
    welded_id: &[u32],
    welded_input: &[u32],
    class_welded: &[u32],
    class_used: &[u32],
    positions: &mut [[f32; 4]],
    flags: &mut [u32],
    vertex_attr: &mut [u32],
) {
    for c in 0..welded_id[p.vertex_count as usize] as usize {
        if class_used[c + 1] == class_used[c] {
            continue;
        }
        let d = class_used[c] as usize;
        let v = welded_input[class_welded[c] as usize] as usize;
        let q =
            [0, 1, 2].map(|i| ((in_positions[3 * v + i] as f64 - p.frame[i]) * p.frame[3]) as f32);
        positions[d] = [q[0], q[1], q[2], 1.0];
        flags[d] = 0;
        vertex_attr[d] = v as u32;
    }
}
