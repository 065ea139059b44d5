//! Twin of shaders/rounds/select_id.wgsl, invocation by invocation: the selection's second pass: a
//! candidate with the best cost at every face around it posts its tie rank there
//! ([`super::select`]).

use super::par_for;
use super::select::{around, live_count};
use crate::compute::common::tie_rank;
use crate::compute::types::{EdgeCandidate, state};
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

#[allow(clippy::too_many_arguments)]
pub fn select_id(
    offsets: &[u32],
    vertex_faces: &[u32],
    edges: &[[u32; 2]],
    live: &[u32], // per listed candidate
    candidates: &[EdgeCandidate],
    face_best: &[AtomicU32],
    counters: &[AtomicU32],
    edge_state: &[AtomicU32],
    face_id: &[AtomicU32], // per face, cleared
) {
    par_for(live_count(counters), |i| {
        let e = live[i as usize];
        let eu = e as usize;
        if edge_state[eu].load(Relaxed) != state::CANDIDATE {
            return;
        }
        let inv = !candidates[eu].cost_bits;
        // Only an edge with the best cost at every face around it can win; the others need not
        // post their rank (a winner is still the only one best at each of its faces).
        if !around(offsets, vertex_faces, edges[eu])
            .all(|f| face_best[f as usize].load(Relaxed) == inv)
        {
            return;
        }
        let rank = !tie_rank(e);
        for f in around(offsets, vertex_faces, edges[eu]) {
            let slot = &face_id[f as usize];
            if slot.load(Relaxed) < rank {
                slot.fetch_max(rank, Relaxed);
            }
        }
        edge_state[eu].store(state::POSTED, Relaxed);
    });
}
