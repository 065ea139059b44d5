//! Twin of shaders/rounds/edges_count.wgsl, the first of the edge list's two stages (then
//! edges_fill.rs). The unique edges (a, b), a < b, of the current faces. Each vertex lists its
//! higher-id neighbours in the order of its sorted face list (first occurrence), so edge ids are
//! the same on every run and on CPU and GPU. `edges_count` enumerates them once into two slots per
//! corner of the vertex's list (a face adds at most two neighbours), and `edges_fill` copies them
//! to the scanned offsets: enumerating twice cost 1.8 s of lavapipe time on the 1M scan.

use super::{Scatter, face_of, faces_of, par_for};
use crate::compute::types::Params;

/// Lists every neighbour `u > v` of `v` once, in face-list order, into `slots` (two per face of
/// `list`: a face adds at most two), and returns how many. A neighbour is new when the listed
/// ones lack it, as in the shader (which reads them back for want of a private array).
fn higher_neighbours(indices: &[u32], list: &[u32], v: u32, slots: &mut [u32]) -> usize {
    debug_assert_eq!(slots.len(), 2 * list.len());
    let mut n = 0;
    for &f in list {
        for u in face_of(indices, f) {
            if u > v && !slots[..n].contains(&u) {
                slots[n] = u;
                n += 1;
            }
        }
    }
    n
}

/// Per vertex: its higher neighbours into `neighbours[2 · offsets[v]..]` and their count; also
/// resets the vertex's collapse remap to itself.
#[allow(clippy::too_many_arguments)]
pub(crate) fn edges_count(
    params: &Params,
    indices: &[u32],           // per face × 3
    offsets: &[u32],           // per vertex + 1
    vertex_faces: &[u32],      // per corner
    edge_counts: Scatter<u32>, // per vertex + 1
    remap: Scatter<u32>,       // per vertex
    neighbours: Scatter<u32>,  // 2 per corner
) {
    par_for(params.vertex_count, |v| {
        let (lo, hi) = (
            offsets[v as usize] as usize,
            offsets[v as usize + 1] as usize,
        );
        // SAFETY: vertex v alone owns slots [2·offsets[v], 2·offsets[v+1]).
        let slots = unsafe { neighbours.range_mut(2 * lo, 2 * hi) };
        let n = higher_neighbours(indices, faces_of(offsets, vertex_faces, v), v, slots);
        // SAFETY: each invocation writes only index v.
        unsafe {
            edge_counts.write(v as usize, n as u32);
            remap.write(v as usize, v);
        }
    });
}
