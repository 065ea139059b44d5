//! Twins of shaders/rounds/compact_mark.wgsl, compact_vertices.wgsl, compact_faces.wgsl and
//! draw_args.wgsl: removed vertices and faces that lost a corner are dropped by prefix-sum
//! compaction, the faces renumbered to the surviving vertices' new ids, and the indirect draw
//! arguments and counts written for the next round and for a renderer.

use super::edge_costs::{CounterField, counter};
use super::{Scatter, par_for};
use crate::compute::types::{DrawArgs, FaceExtra, Params, Quadric};
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

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

/// Per vertex: survivors move to their scanned slot.
#[allow(clippy::too_many_arguments)]
pub(crate) fn compact_vertices(
    params: &Params,
    vertex_keep: &[u32], // scanned
    positions: &[[f32; 4]],
    quadrics: &[Quadric],
    flags: &[u32],
    vertex_attr: &[u32],
    positions_out: Scatter<[f32; 4]>,
    quadrics_out: Scatter<Quadric>,
    flags_out: Scatter<u32>,
    vertex_attr_out: Scatter<u32>,
) {
    par_for(params.vertex_count, |v| {
        let v = v as usize;
        if vertex_keep[v + 1] != vertex_keep[v] {
            let n = vertex_keep[v] as usize;
            // SAFETY: the exclusive prefix sum of 0/1 flags gives each survivor its own slot.
            unsafe {
                positions_out.write(n, positions[v]);
                quadrics_out.write(n, quadrics[v]);
                flags_out.write(n, flags[v]);
                vertex_attr_out.write(n, vertex_attr[v]);
            }
        }
    });
}

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

/// One invocation: counts after compaction, and the indirect draw arguments.
pub fn draw_args(
    params: &Params,
    vertex_keep: &[u32],
    face_keep: &[u32],
    counters: &[AtomicU32],
    args: &mut DrawArgs,
) {
    let nv = vertex_keep[params.vertex_count as usize];
    let nf = face_keep[params.face_count as usize];
    counter(counters, CounterField::VerticesOut).store(nv, Relaxed);
    counter(counters, CounterField::FacesOut).store(nf, Relaxed);
    *args = DrawArgs {
        index_count: 3 * nf,
        instance_count: 1,
        ..Default::default()
    };
}
