//! Twin of shaders/rounds/compact_mark.wgsl, the first of the compaction's four stages (then
//! compact_vertices.rs, compact_faces.rs, draw_args.rs). Removed vertices and faces that lost a
//! corner are dropped by prefix-sum compaction, the faces renumbered to the surviving vertices' new
//! ids, and the indirect draw arguments and counts written for the next round and for a renderer.

use super::{Scatter, par_for};
use crate::compute::types::Params;

/// Per max(vertex, face): 1 for a surviving vertex, 1 for a face whose remapped corners are
/// still three distinct vertices.
pub fn compact_mark(
    params: &Params,
    indices: &[u32],
    remap: &[u32],
    vertex_keep: &mut [u32], // per vertex + 1
    face_keep: &mut [u32],   // per face + 1
) {
    let (nv, nf) = (params.vertex_count as usize, params.face_count as usize);
    let vk = Scatter::new(vertex_keep);
    let fk = Scatter::new(face_keep);
    par_for(nv.max(nf) as u32, |id| {
        let id = id as usize;
        // SAFETY: each invocation writes only index `id` of each buffer.
        unsafe {
            if id < nv {
                vk.write(id, (remap[id] == id as u32) as u32);
            }
            if id < nf {
                let t = [0, 1, 2].map(|k| remap[indices[3 * id + k] as usize]);
                fk.write(id, (t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) as u32);
            }
        }
    });
}
