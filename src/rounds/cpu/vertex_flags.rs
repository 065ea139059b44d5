//! Twin of shaders/rounds/vertex_flags.wgsl (first round): which vertices lie on a border and which
//! must stay pinned — a non-manifold edge (more than two faces), more than one fan of faces (a
//! bow-tie), or a border under `lock_border`. Collapses keep a manifold manifold and carry the
//! border bit to the survivor, so these flags stay true without being recomputed each round.

use super::{face_of, faces_of, par_for_mut};
use crate::compute::types::{Params, flag};

/// Faces of `list` containing `u`.
pub fn count_containing(indices: &[u32], list: &[u32], u: u32) -> u32 {
    list.iter()
        .filter(|&&f| face_of(indices, f).contains(&u))
        .count() as u32
}

/// Faces reachable from the first face of `list` by crossing edges at `v` that two faces share.
fn fan_size(indices: &[u32], list: &[u32], v: u32) -> usize {
    let first = list[0];
    let t = face_of(indices, first);
    let others: Vec<u32> = t.iter().copied().filter(|&u| u != v).collect();
    let mut visited = 1;
    for &start in &others {
        let (mut cur, mut through) = (first, start);
        for _ in 0..list.len() {
            let next = list
                .iter()
                .copied()
                .find(|&g| g != cur && face_of(indices, g).contains(&through));
            let Some(g) = next else { break };
            if g == first {
                return visited; // a closed fan: both directions meet
            }
            visited += 1;
            let tg = face_of(indices, g);
            through = tg
                .into_iter()
                .find(|&u| u != v && u != through)
                .unwrap_or(v);
            cur = g;
        }
    }
    visited
}

pub fn vertex_flags(
    params: &Params,
    indices: &[u32],      // per face × 3
    offsets: &[u32],      // per vertex + 1
    vertex_faces: &[u32], // per corner
    flags: &mut [u32],    // per vertex: in SEAM and the caller's PINNED, out with BORDER too
) {
    par_for_mut(&mut flags[..params.vertex_count as usize], |v, fl| {
        let list = faces_of(offsets, vertex_faces, v);
        let (mut border, mut pinned) = (false, false);
        for &f in list {
            for u in face_of(indices, f) {
                if u != v {
                    match count_containing(indices, list, u) {
                        1 => border = true,
                        2 => {}
                        _ => pinned = true,
                    }
                }
            }
        }
        if !list.is_empty() && !pinned && fan_size(indices, list, v) < list.len() {
            pinned = true;
        }
        if border && params.lock_border != 0 {
            pinned = true;
        }
        *fl = (*fl & (flag::SEAM | flag::PINNED))
            | if border { flag::BORDER } else { 0 }
            | if pinned { flag::PINNED } else { 0 };
    });
}
