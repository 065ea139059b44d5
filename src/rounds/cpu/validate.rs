//! Twin of shaders/rounds/validate.wgsl: the edges a selection pass picked (TENTATIVE) get the
//! topological checks of the greedy reference — link condition, no border pinch, no lone triangle,
//! no tetrahedral fold. Those that fail drop out; the rest win and lock every vertex of the faces
//! around them (see `select`). Tentative winners share no face, so their checks cannot interfere.
//! Checking only the winners instead of every edge every round saves the costliest scans of
//! `edge_costs`.

use super::counters::{CounterField, counter};
use super::vertex_flags::count_containing;
use super::{Scatter, face_of, faces_of, par_for};
use crate::compute::types::{EdgeCandidate, Params, flag, state};
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

/// Faces on the collapse's edge (1 or 2), or `None` when the collapse would break the topology.
#[allow(clippy::too_many_arguments)]
pub fn check(
    _params: &Params,
    flags: &[u32],
    indices: &[u32],
    offsets: &[u32],
    vertex_faces: &[u32],
    c: &EdgeCandidate,
) -> Option<u32> {
    let (keep, remove) = (c.keep, c.remove);
    let lk = faces_of(offsets, vertex_faces, keep);
    let lr = faces_of(offsets, vertex_faces, remove);
    // Faces on the edge and their opposite vertices.
    let mut edge_faces = 0u32;
    let mut opp = [u32::MAX; 2];
    for &f in lk {
        let t = face_of(indices, f);
        if t.contains(&remove) {
            if edge_faces == 2 {
                return None;
            }
            opp[edge_faces as usize] = t
                .into_iter()
                .find(|&u| u != keep && u != remove)
                .unwrap_or(keep);
            edge_faces += 1;
        }
    }
    if edge_faces == 0 {
        return None;
    }
    // Link condition (Dey et al.): the common neighbours are exactly the opposite vertices.
    // Those always are common, so it fails when two faces share the edge with one opposite
    // vertex, or when any other neighbour of `remove` is also a neighbour of `keep` — no need to
    // count distinct neighbours.
    if edge_faces == 2 && opp[0] == opp[1] {
        return None;
    }
    for &f in lr {
        for u in face_of(indices, f) {
            if u != keep
                && u != remove
                && !opp[..edge_faces as usize].contains(&u)
                && lk.iter().any(|&g| face_of(indices, g).contains(&u))
            {
                return None;
            }
        }
    }
    let border = |v: u32| flags[v as usize] & flag::BORDER != 0;
    if edge_faces == 2 && border(keep) && border(remove) {
        return None; // joining two border vertices through the interior pinches
    }
    if edge_faces == 1 {
        let o = opp[0];
        if count_containing(indices, lk, o) == 1 && count_containing(indices, lr, o) == 1 {
            return None; // a lone triangle: the whole component would go
        }
    }
    // A tetrahedral fan: faces (keep, c, d) and (remove, c, d) would become one face twice.
    let mut on_cd = [false; 2];
    if edge_faces == 2 {
        for (side, (other, list)) in [(remove, lk), (keep, lr)].into_iter().enumerate() {
            on_cd[side] = list.iter().any(|&f| {
                let t = face_of(indices, f);
                !t.contains(&other) && t.contains(&opp[0]) && t.contains(&opp[1])
            });
        }
    }
    if on_cd[0] && on_cd[1] {
        return None; // faces (keep, c, d) and (remove, c, d) would coincide
    }
    Some(edge_faces)
}

/// Per listed tentative winner: it wins (and locks the vertices of its faces) or drops out.
#[allow(clippy::too_many_arguments)]
pub(crate) fn validate(
    params: &Params,
    flags: &[u32],
    indices: &[u32],
    offsets: &[u32],
    vertex_faces: &[u32],
    edges: &[[u32; 2]],
    tentative: &[u32], // per winner of the pass
    candidates: Scatter<EdgeCandidate>,
    edge_state: &[AtomicU32],
    vertex_lock: &[AtomicU32], // per vertex
    counters: &[AtomicU32],
) {
    let n = counter(counters, CounterField::Tentative).load(Relaxed);
    par_for(n, |id| {
        let eu = tentative[id as usize] as usize;
        debug_assert_eq!(edge_state[eu].load(Relaxed), state::TENTATIVE);
        // SAFETY: each invocation reads and writes only its own edge's candidate.
        let mut c = unsafe { candidates.read(eu) };
        let Some(faces) = check(params, flags, indices, offsets, vertex_faces, &c) else {
            edge_state[eu].store(state::OUT, Relaxed);
            return;
        };
        c.faces = faces;
        // SAFETY: as above.
        unsafe { candidates.write(eu, c) };
        edge_state[eu].store(state::WON, Relaxed);
        for v in edges[eu] {
            for &f in faces_of(offsets, vertex_faces, v) {
                for u in face_of(indices, f) {
                    vertex_lock[u as usize].store(1, Relaxed);
                }
            }
        }
        counter(counters, CounterField::Winners).fetch_add(1, Relaxed);
        counter(counters, CounterField::Removed).fetch_add(c.faces, Relaxed);
        counter(counters, CounterField::MaxErr2Bits).fetch_max(c.pos[3].to_bits(), Relaxed);
    });
}
