//! Twin of shaders/rounds/compact_faces.wgsl, invocation by invocation: one of the compaction's
//! stages, which [`super::compact_mark`] tells whole.

use super::{Scatter, par_for};
use crate::compute::types::{FaceExtra, Params};

/// Per face: kept faces move to their scanned slot with corners renumbered.
#[allow(clippy::too_many_arguments)]
pub(crate) fn compact_faces(
    params: &Params,
    indices: &[u32],
    face_normals: &[[f32; 4]],
    face_extra: &[FaceExtra],
    remap: &[u32],
    vertex_keep: &[u32], // scanned
    face_keep: &[u32],   // scanned
    indices_out: Scatter<u32>,
    face_normals_out: Scatter<[f32; 4]>,
    face_extra_out: Scatter<FaceExtra>,
) {
    par_for(params.face_count, |f| {
        let f = f as usize;
        if face_keep[f + 1] != face_keep[f] {
            let n = face_keep[f] as usize;
            // SAFETY: the exclusive prefix sum of 0/1 flags gives each kept face its own slot.
            unsafe {
                for k in 0..3 {
                    let v = remap[indices[3 * f + k] as usize] as usize;
                    indices_out.write(3 * n + k, vertex_keep[v]);
                }
                face_normals_out.write(n, face_normals[f]);
                face_extra_out.write(n, face_extra[f]);
            }
        }
    });
}
