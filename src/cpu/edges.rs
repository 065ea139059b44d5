//! Twins of shaders/edges_count.wgsl and edges_fill.wgsl: the unique edges (a, b), a < b, of
//! the current faces. Each vertex lists its higher-id neighbours in the order of its sorted face
//! list (first occurrence), so edge ids are the same on every run and on CPU and GPU.
//! `edges_count` enumerates them once into two slots per corner of the vertex's list (a face adds
//! at most two neighbours), and `edges_fill` copies them to the scanned offsets: enumerating
//! twice cost 1.8 s of lavapipe time on the 1M scan.

use super::{Scatter, face_of, faces_of, par_for};
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

/// Per vertex: its higher neighbours into `neighbours[2 · offsets[v]..]` and their count; also
/// resets the vertex's collapse remap to itself.
#[allow(clippy::too_many_arguments)]
pub fn edges_count(
    params: &Params,
    indices: &[u32],           // per face × 3
    offsets: &[u32],           // per vertex + 1
    vertex_faces: &[u32],      // per corner
    edge_counts: Scatter<u32>, // per vertex + 1
    remap: Scatter<u32>,       // per vertex
    neighbours: Scatter<u32>,  // 2 per corner
) {
    par_for(params.vertex_count, |v| {
        let base = 2 * offsets[v as usize] as usize;
        let mut n = 0;
        higher_neighbours(indices, faces_of(offsets, vertex_faces, v), v, |u| {
            // SAFETY: vertex v owns slots [2·offsets[v], 2·offsets[v+1]); a face adds at most two
            // neighbours, so n stays inside them.
            unsafe { neighbours.write(base + n, u) };
            n += 1;
        });
        // SAFETY: each invocation writes only index v.
        unsafe {
            edge_counts.write(v as usize, n as u32);
            remap.write(v as usize, v);
        }
    });
}

/// Per vertex: copies its listed neighbours to its scanned edge offset.
pub fn edges_fill(
    params: &Params,
    offsets: &[u32],          // per vertex + 1
    neighbours: &[u32],       // 2 per corner
    edge_offsets: &[u32],     // per vertex + 1 (scanned counts)
    edges: Scatter<[u32; 2]>, // per edge
) {
    par_for(params.vertex_count, |v| {
        let (lo, hi) = (edge_offsets[v as usize], edge_offsets[v as usize + 1]);
        let base = 2 * offsets[v as usize];
        for i in 0..hi - lo {
            // SAFETY: vertex v owns slots [edge_offsets[v], edge_offsets[v+1]), disjoint from
            // every other vertex's, and writes each once.
            unsafe { edges.write((lo + i) as usize, [v, neighbours[(base + i) as usize]]) };
        }
    });
}
