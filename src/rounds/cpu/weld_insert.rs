//! Twin of shaders/rounds/weld_insert.wgsl, invocation by invocation: one of the preparation's
//! stages, which [`super::prepare::prepare`] runs in the schedule's order.

use crate::compute::types::PrepParams;

fn weld_key(in_positions: &[f32], v: usize) -> [u32; 3] {
    [0, 1, 2].map(|i| crate::mesh::weld::bits(in_positions[3 * v + i]))
}

fn weld_hash(k: [u32; 3]) -> u32 {
    let mut h = k[0].wrapping_mul(0xcc9e2d51)
        ^ k[1].wrapping_mul(0x1b873593)
        ^ k[2].wrapping_mul(0x85ebca6b);
    h ^= h >> 16;
    h = h.wrapping_mul(0x85ebca6b);
    h ^= h >> 13;
    h = h.wrapping_mul(0xc2b2ae35);
    h ^ (h >> 16)
}

/// Twin of `weld_insert`: the vertices in index order, so the first at a position claims its
/// slot and the others find it (the GPU's slots may differ; each position's lowest vertex, what
/// `weld_resolve` reads, does not).
pub fn weld_insert(
    p: &PrepParams,
    in_positions: &[f32],
    weld_table: &mut [u32],
    weld_slot: &mut [u32],
) {
    let n = p.vertex_count as usize;
    for (v, slot) in weld_slot.iter_mut().enumerate().take(n) {
        let k = weld_key(in_positions, v);
        let mut h = (weld_hash(k) & p.table_mask) as usize;
        loop {
            let held = weld_table[h];
            if held == 0 {
                weld_table[h] = v as u32 + 1;
                break;
            }
            if weld_key(in_positions, held as usize - 1) == k {
                weld_table[h] = weld_table[h].min(v as u32 + 1);
                break;
            }
            h = (h + 1) & p.table_mask as usize;
        }
        *slot = h as u32;
    }
}
