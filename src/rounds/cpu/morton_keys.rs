//! Twin of shaders/rounds/morton_keys.wgsl, invocation by invocation: one of the preparation's
//! stages, which [`super::prepare::prepare`] runs in the schedule's order.

use crate::compute::types::PrepParams;

/// The pad key (`PREP_PAD`): sorts after every class and every face's lowest class.
pub const PREP_PAD: u32 = u32::MAX;

/// Twin of `morton_keys`, in the host's own f32 arithmetic (`mesh::morton::grid_codes`), which
/// the shader's f64 quotient reproduces.
pub fn morton_keys(
    p: &PrepParams,
    in_positions: &[f32],
    weld_first: &[u32],
    welded_id: &[u32],
    welded_input: &mut [u32],
    sort_keys: &mut [u32],
    sort_vals: &mut [u32],
) {
    let n = p.vertex_count as usize;
    for v in 0..n {
        if weld_first[v] == v as u32 {
            let w = welded_id[v] as usize;
            welded_input[w] = v as u32;
            let q =
                |i: usize| (((in_positions[3 * v + i] - p.grid[i]) / p.grid[3]) * 1023.0) as u32;
            sort_keys[w] = crate::mesh::morton::morton3(q(0), q(1), q(2));
            sort_vals[w] = w as u32;
        }
        if v as u32 >= welded_id[n] {
            sort_keys[v] = PREP_PAD;
            sort_vals[v] = v as u32;
        }
    }
}
