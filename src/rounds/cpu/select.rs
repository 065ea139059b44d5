//! Twins of shaders/rounds/select_cost.wgsl, select_id.wgsl and select_win.wgsl: one pass of the
//! independent-set selection, one invocation per candidate on the live list. An edge wins when its key (cost bits, then edge id) is the
//! smallest over every candidate touching any face around either endpoint: 32-bit atomicMax of
//! inverted keys per face, first on the cost, then on a hash of the id among equal costs (64-bit atomics
//! are not portable). Two winners then share no face, so the checks each passed in
//! `validate` stay true when both collapse. The pass's winners are TENTATIVE until `validate`
//! checks them; confirmed winners lock the vertices of their faces (`validate`); a candidate at a
//! locked vertex touches a winner's face and drops out at the next pass, and the others compete
//! again (Luby-style).

use super::edge_costs::{CounterField, counter};
use super::{Scatter, faces_of, par_for};
use crate::compute::common::tie_rank;
use crate::compute::types::{EdgeCandidate, state};
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

/// Faces around either endpoint of edge `e` (those on the edge come twice, harmlessly).
fn around<'a>(
    offsets: &[u32],
    vertex_faces: &'a [u32],
    e: [u32; 2],
) -> impl Iterator<Item = u32> + 'a {
    let la = faces_of(offsets, vertex_faces, e[0]);
    let lb = faces_of(offsets, vertex_faces, e[1]);
    la.iter().chain(lb).copied()
}

/// Invocations of the passes: one per candidate on the live list.
fn live_count(counters: &[AtomicU32]) -> u32 {
    counter(counters, CounterField::Live).load(Relaxed)
}

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

/// A face two of the round's winners (`state::WON`) both reach, with those two winners: the
/// promise `collapse` rests on broken. `collapse` writes every winner's vertices and faces
/// through a [`Scatter`] without synchronisation, which is sound only if each face is around
/// at most one winner's endpoints; so every round checks it, in release builds too, before
/// `collapse` runs (parallel, into `owner`, one word per face; the cost is measured in
/// docs/PERFORMANCE.md). `None` when the winners share no face.
pub fn shared_face(
    offsets: &[u32],
    vertex_faces: &[u32],
    edges: &[[u32; 2]],
    edge_state: &[u32],
    owner: &mut Vec<u32>,
    face_count: usize,
) -> Option<SharedFace> {
    owner.clear();
    owner.resize(face_count, u32::MAX);
    let first = AtomicU32::new(u32::MAX);
    {
        let owner = super::atomics(owner);
        par_for(edges.len() as u32, |e| {
            if edge_state[e as usize] != state::WON {
                return;
            }
            for f in around(offsets, vertex_faces, edges[e as usize]) {
                match owner[f as usize].compare_exchange(u32::MAX, e, Relaxed, Relaxed) {
                    Ok(_) => {}
                    Err(o) if o == e => {}
                    Err(_) => {
                        first.fetch_min(f, Relaxed);
                    }
                }
            }
        });
    }
    let face = first.into_inner();
    if face == u32::MAX {
        return None;
    }
    // Rare and fatal: name the lowest shared face's first two winners, serially, so the report
    // is the same whatever the threads did.
    let mut winners = (0..edges.len() as u32).filter(|&e| {
        edge_state[e as usize] == state::WON
            && around(offsets, vertex_faces, edges[e as usize]).any(|f| f == face)
    });
    let a = winners.next().unwrap_or(u32::MAX);
    let b = winners.next().unwrap_or(u32::MAX);
    Some(SharedFace {
        face,
        winners: [a, b],
    })
}

/// What [`shared_face`] found: a face and two winners around it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SharedFace {
    pub face: u32,
    pub winners: [u32; 2],
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A strip of four triangles over vertices 0..6:
    ///
    /// ```text
    ///   1 --- 3 --- 5
    ///   | \   | \   |
    ///   |  \  |  \  |
    ///   0 --- 2 --- 4
    /// ```
    /// faces (0,2,1) (1,2,3) (2,4,3) (3,4,5); vertex→face lists by vertex.
    fn strip() -> (Vec<u32>, Vec<u32>) {
        let faces = [[0u32, 2, 1], [1, 2, 3], [2, 4, 3], [3, 4, 5]];
        let mut lists = vec![Vec::new(); 6];
        for (f, t) in faces.iter().enumerate() {
            for &v in t {
                lists[v as usize].push(f as u32);
            }
        }
        let mut offsets = vec![0u32];
        let mut vertex_faces = Vec::new();
        for l in lists {
            vertex_faces.extend(l);
            offsets.push(vertex_faces.len() as u32);
        }
        (offsets, vertex_faces)
    }

    #[test]
    fn winners_apart_share_no_face_and_neighbours_do() {
        let (offsets, vf) = strip();
        let edges = [[0u32, 1], [4, 5], [2, 3]];
        let mut owner = Vec::new();
        let mut check = |w: &[usize]| {
            let mut st = vec![state::CANDIDATE; edges.len()];
            for &e in w {
                st[e] = state::WON;
            }
            shared_face(&offsets, &vf, &edges, &st, &mut owner, 4)
        };
        // (0,1) holds faces 0 and 1; (4,5) holds faces 2 and 3: disjoint.
        assert_eq!(check(&[0, 1]), None);
        // (2,3) holds all four faces, so it meets either, first at the lowest face they share.
        assert_eq!(
            check(&[0, 2]),
            Some(SharedFace {
                face: 0,
                winners: [0, 2]
            })
        );
        assert_eq!(
            check(&[1, 2]),
            Some(SharedFace {
                face: 2,
                winners: [1, 2]
            })
        );
        assert_eq!(check(&[2]), None);
        assert_eq!(check(&[]), None);
    }
}
