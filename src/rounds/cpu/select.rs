//! The independent-set selection, shared by its three stages' twins (select_cost.rs, select_id.rs,
//! select_win.rs), and the check its winners pass before they collapse ([`shared_face`]). One pass
//! of the selection: one invocation per candidate on the live list. An edge wins when its key (cost
//! bits, then edge id) is the smallest over every candidate touching any face around either
//! endpoint: 32-bit atomicMax of inverted keys per face, first on the cost, then on a hash of the
//! id among equal costs (64-bit atomics are not portable). Two winners then share no face, so the
//! checks each passed in `validate` stay true when both collapse. The pass's winners are TENTATIVE
//! until `validate` checks them; confirmed winners lock the vertices of their faces (`validate`); a
//! candidate at a locked vertex touches a winner's face and drops out at the next pass, and the
//! others compete again (Luby-style).

use super::counters::{CounterField, counter};
use super::{faces_of, par_for};
use crate::compute::types::state;
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

/// Faces around either endpoint of edge `e` (those on the edge come twice, harmlessly).
pub(super) fn around<'a>(
    offsets: &[u32],
    vertex_faces: &'a [u32],
    e: [u32; 2],
) -> impl Iterator<Item = u32> + 'a {
    let la = faces_of(offsets, vertex_faces, e[0]);
    let lb = faces_of(offsets, vertex_faces, e[1]);
    la.iter().chain(lb).copied()
}

/// Invocations of the passes: one per candidate on the live list.
pub(super) fn live_count(counters: &[AtomicU32]) -> u32 {
    counter(counters, CounterField::Live).load(Relaxed)
}

/// A face two of the round's winners (`state::WON`) both reach, with those two winners: the
/// promise `collapse` rests on broken. `collapse` writes every winner's vertices and faces
/// through a [`Scatter`](super::Scatter) without synchronisation, which is sound only if each face is around
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
