//! Twin of shaders/rounds/select_win.wgsl, invocation by invocation: the selection's third pass: a
//! poster whose rank is the best at every face around it is a tentative winner, in the pass's list
//! ([`super::select`]).

use super::counters::{CounterField, counter};
use super::select::{around, live_count};
use super::{Scatter, par_for};
use crate::compute::common::tie_rank;
use crate::compute::types::state;
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

#[allow(clippy::too_many_arguments)]
pub(crate) fn select_win(
    offsets: &[u32],
    vertex_faces: &[u32],
    edges: &[[u32; 2]],
    live: &[u32],          // per listed candidate
    face_id: &[AtomicU32], // per face
    edge_state: &[AtomicU32],
    tentative: Scatter<u32>, // per winner of the pass
    counters: &[AtomicU32],
) {
    par_for(live_count(counters), |i| {
        let e = live[i as usize];
        let eu = e as usize;
        // Posters alone: every other candidate failed select_id's cost test already.
        if edge_state[eu].load(Relaxed) != state::POSTED {
            return;
        }
        let rank = !tie_rank(e);
        let wins = around(offsets, vertex_faces, edges[eu])
            .all(|f| face_id[f as usize].load(Relaxed) == rank);
        if !wins {
            edge_state[eu].store(state::CANDIDATE, Relaxed);
            return;
        }
        edge_state[eu].store(state::TENTATIVE, Relaxed);
        let slot = counter(counters, CounterField::Tentative).fetch_add(1, Relaxed);
        // SAFETY: the atomic counter hands out each slot once.
        unsafe { tentative.write(slot as usize, e) };
    });
}
