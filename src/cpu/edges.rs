//! Twins of shaders/edges_count.wgsl and edges_fill.wgsl: the unique edges (a, b), a < b, of
//! the current faces. Each vertex lists its higher-id neighbours in the order of its sorted face
//! list (first occurrence), so edge ids are the same on every run and on CPU and GPU.

use super::{Scatter, face_of, faces_of, par_for, par_for_mut};
use crate::gpu::types::Params;

/// Calls `each(u)` for every neighbour `u > v` of `v`, once, in face-list order.
fn higher_neighbours(indices: &[u32], list: &[u32], v: u32, mut each: impl FnMut(u32)) {
    for (i, &f) in list.iter().enumerate() {
        for u in face_of(indices, f) {
            if u > v && !list[..i].iter().any(|&g| face_of(indices, g).contains(&u)) {
                each(u);
            }
        }
    }
}

/// Per vertex: how many edges it owns; also resets the vertex's collapse remap to itself.
pub fn edges_count(
    params: &Params,
    indices: &[u32],         // per face × 3
    offsets: &[u32],         // per vertex + 1
    vertex_faces: &[u32],    // per corner
    edge_counts: &mut [u32], // per vertex + 1
    remap: &mut [u32],       // per vertex
) {
    par_for_mut(
        &mut edge_counts[..params.vertex_count as usize],
        |v, count| {
            let mut n = 0;
            higher_neighbours(indices, faces_of(offsets, vertex_faces, v), v, |_| n += 1);
            *count = n;
        },
    );
    par_for_mut(&mut remap[..params.vertex_count as usize], |v, r| *r = v);
}

/// Per vertex: writes its edges at its scanned offset.
pub fn edges_fill(
    params: &Params,
    indices: &[u32],
    offsets: &[u32],
    vertex_faces: &[u32],
    edge_offsets: &[u32],     // per vertex + 1 (scanned counts)
    edges: Scatter<[u32; 2]>, // per edge
) {
    par_for(params.vertex_count, |v| {
        let mut slot = edge_offsets[v as usize] as usize;
        higher_neighbours(indices, faces_of(offsets, vertex_faces, v), v, |u| {
            // SAFETY: vertex v owns slots [edge_offsets[v], edge_offsets[v+1]), disjoint from
            // every other vertex's, and writes each once.
            unsafe { edges.write(slot, [v, u]) };
            slot += 1;
        });
    });
}
