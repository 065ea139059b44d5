//! Twin of shaders/collapse.wgsl: each winner moves its survivor to the new position, gives it
//! the sum of both quadrics (re-centred on the new position) and the removed vertex's border
//! bit, and points the removed vertex at the survivor. Winners share no face, hence no vertex,
//! so these writes never meet.

use super::common::{quadric_add, quadric_shift, sub, xyz};
use super::{Scatter, par_for};
use crate::gpu::types::{EdgeCandidate, Params, Quadric, flag, state};

#[allow(clippy::too_many_arguments)]
pub fn collapse(
    params: &Params,
    candidates: &[EdgeCandidate], // per edge
    edge_state: &[u32],           // per edge
    edge_offsets: &[u32],         // per vertex + 1: the edge count at [vertex_count]
    positions: Scatter<[f32; 4]>, // per vertex
    quadrics: Scatter<Quadric>,   // per vertex
    flags: Scatter<u32>,          // per vertex
    remap: Scatter<u32>,          // per vertex
) {
    let edge_count = edge_offsets[params.vertex_count as usize];
    par_for(edge_count, |e| {
        if edge_state[e as usize] != state::WON {
            return;
        }
        let c = &candidates[e as usize];
        let (k, r) = (c.keep as usize, c.remove as usize);
        // SAFETY: winners share no face and so no vertex (select_win); each winner reads and
        // writes only its own two vertices.
        unsafe {
            let pk = positions.read(k);
            let pr = positions.read(r);
            let p = xyz(c.pos);
            let q = quadric_add(
                &quadric_shift(&quadrics.read(k), sub(p, xyz(pk))),
                &quadric_shift(&quadrics.read(r), sub(p, xyz(pr))),
            );
            quadrics.write(k, q);
            let moved = if p != xyz(pk) { flag::MOVED } else { 0 };
            flags.write(k, flags.read(k) | (flags.read(r) & flag::BORDER) | moved);
            positions.write(k, [p[0], p[1], p[2], 1.0]);
            remap.write(r, k as u32);
        }
    });
}
