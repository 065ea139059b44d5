//! Twin of shaders/rounds/select_cost.wgsl, invocation by invocation: the selection's first pass:
//! each candidate not at a locked vertex raises the faces around it to its inverted cost
//! ([`super::select`] tells the selection whole).

use super::par_for;
use super::select::{around, live_count};
use crate::compute::types::{EdgeCandidate, state};
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

#[allow(clippy::too_many_arguments)]
pub fn select_cost(
    offsets: &[u32],
    vertex_faces: &[u32],
    edges: &[[u32; 2]],
    live: &[u32], // per listed candidate
    candidates: &[EdgeCandidate],
    vertex_lock: &[AtomicU32], // per vertex
    counters: &[AtomicU32],
    edge_state: &[AtomicU32], // per edge
    face_best: &[AtomicU32],  // per face, cleared
) {
    par_for(live_count(counters), |i| {
        let e = live[i as usize] as usize;
        if edge_state[e].load(Relaxed) != state::CANDIDATE {
            return;
        }
        let c = &candidates[e];
        // At a vertex of a face around an earlier winner: it touches that face.
        if edges[e]
            .iter()
            .any(|&v| vertex_lock[v as usize].load(Relaxed) != 0)
        {
            edge_state[e].store(state::OUT, Relaxed);
            return;
        }
        let inv = !c.cost_bits;
        for f in around(offsets, vertex_faces, edges[e]) {
            // The atomic read-modify-write only where it can raise the value: max is
            // idempotent, and most faces already hold a key at least as good.
            let slot = &face_best[f as usize];
            if slot.load(Relaxed) < inv {
                slot.fetch_max(inv, Relaxed);
            }
        }
    });
}
