//! The one preparation every simplifier starts from: the input welded, its positions grouped
//! into classes (a seam's attribute vertices share one) numbered along a Morton curve, the faces
//! that still have three distinct classes in the order of their lowest class, each class's seam
//! flag and representative, and the frame that normalizes positions. The greedy reference
//! (`greedy::Prepared`) and the rounds (`parallel::Upload`) build their own state from it, and
//! so will every family to come.

use super::morton::spatial_order;
use super::weld::position_classes;
use super::{Mesh, weld};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering::Relaxed};

/// The welded surface in position classes, in Morton order.
pub struct Surface {
    /// The input after exact welding: its vertices are the attribute vertices written out.
    pub welded: Mesh,
    /// Per attribute vertex of `welded`: its position class.
    pub class: Vec<u32>,
    /// Per class: its representative attribute vertex, the lowest-numbered one the kept faces
    /// use (a collapse maps the removed vertex's corners from it), or the class's first vertex
    /// when no kept face uses the class.
    pub representative: Vec<u32>,
    /// Per class: how many attribute vertices the kept faces use; more than one is a seam. An
    /// unused vertex with other attributes at the same point does not make one.
    pub attr_count: Vec<u32>,
    /// Faces with three distinct classes, as attribute vertices, in the order of their lowest
    /// class (a vertex's faces sit close in memory), faces with the same lowest class in input
    /// order.
    pub faces: Vec<[u32; 3]>,
    /// Each kept face's index in `welded.triangles` (materials and groups follow it).
    pub face_origin: Vec<u32>,
    /// Faces dropped because two corners share a class.
    pub dropped_degenerate: usize,
    /// Per input vertex: the vertex of `welded` it became.
    pub weld_remap: Vec<u32>,
    /// The frame: positions are centred on the bounding box and divided by its diagonal, so
    /// errors are relative to the diagonal and f32 GPU twins keep precision.
    pub center: [f64; 3],
    pub scale: f64,
}

impl Surface {
    pub fn new(input: &Mesh) -> Surface {
        Surface::in_frame(input, None)
    }

    /// As [`Surface::new`], normalized with the given `(center, scale)` instead of the input's
    /// own box (the hybrid method's clustered mesh keeps the original's frame, so the quadrics
    /// it carries keep their units).
    pub fn in_frame(input: &Mesh, frame: Option<([f64; 3], f64)>) -> Surface {
        let weld::WeldResult {
            mesh: welded,
            remap: weld_remap,
        } = weld(input);
        // Without attributes `weld` merged by position already: every position is its own class,
        // and hashing them all again cost 0.03 s of 0.4 s here on the 1M scan.
        let one_each = input.normals.is_none() && input.uvs.is_none() && input.colors.is_none();
        let (class, firsts) = if one_each {
            let id: Vec<u32> = (0..welded.positions.len() as u32).collect();
            (id.clone(), id)
        } else {
            position_classes(&welded.positions)
        };
        let (class, mut representative) = spatial_order(&welded.positions, class, firsts);
        let nc = representative.len();
        // The faces kept and the vertices they use, on every core: one core took 0.007 s of
        // the greedy's set-up on the 1M scan for these passes.
        let kept: Vec<u32> = (0..welded.triangles.len() as u32)
            .into_par_iter()
            .with_min_len(1 << 14)
            .filter(|&f| {
                let [a, b, c] = welded.triangles[f as usize].map(|v| class[v as usize]);
                a != b && b != c && a != c
            })
            .collect();
        let dropped_degenerate = welded.triangles.len() - kept.len();
        let used: Vec<AtomicBool> = (0..welded.positions.len())
            .into_par_iter()
            .map(|_| AtomicBool::new(false))
            .collect();
        // Every store writes `true`: the result is the same whatever the order.
        kept.par_iter().with_min_len(1 << 14).for_each(|&f| {
            for v in welded.triangles[f as usize] {
                used[v as usize].store(true, Relaxed);
            }
        });
        let used: Vec<bool> = used.into_par_iter().map(AtomicBool::into_inner).collect();
        let attr_count: Vec<u32> = if one_each {
            // One vertex a class (no attributes; the Morton order only renumbered them): it
            // counts if used, and stays its class's representative.
            representative
                .par_iter()
                .map(|&v| used[v as usize] as u32)
                .collect()
        } else {
            let mut attr_count = vec![0u32; nc];
            for (v, &c) in class.iter().enumerate() {
                attr_count[c as usize] += used[v] as u32;
                if used[v] && !used[representative[c as usize] as usize] {
                    representative[c as usize] = v as u32;
                }
            }
            attr_count
        };
        let lowest = |f: u32| {
            welded.triangles[f as usize]
                .map(|v| class[v as usize])
                .into_iter()
                .min()
                .unwrap_or(0)
        };
        let (order, _) = counting_sort(nc, kept.len(), |i| lowest(kept[i]));
        let face_origin: Vec<u32> = order.par_iter().map(|&i| kept[i as usize]).collect();
        let faces = face_origin
            .par_iter()
            .map(|&f| welded.triangles[f as usize])
            .collect();
        let (center, scale) = frame.unwrap_or_else(|| frame_of(&welded));
        Surface {
            welded,
            class,
            representative,
            attr_count,
            faces,
            face_origin,
            dropped_degenerate,
            weld_remap,
            center,
            scale,
        }
    }

    /// Position classes, used by faces or not.
    pub fn class_count(&self) -> usize {
        self.representative.len()
    }

    /// Whether class `c` is a seam: its faces use more than one of its attribute vertices.
    pub fn is_seam(&self, c: usize) -> bool {
        self.attr_count[c] > 1
    }

    /// Into the normalized frame; every backend uses this arithmetic, so a vertex that never
    /// moved compares equal.
    pub fn normalize(&self, p: [f32; 3]) -> [f64; 3] {
        normalize(p, self.center, self.scale)
    }
}

/// The frame of `mesh`: its box's centre, and one over its diagonal.
pub fn frame_of(mesh: &Mesh) -> ([f64; 3], f64) {
    frame_of_box(mesh.bounds())
}

/// The frame of a box: its centre, and one over its diagonal.
pub fn frame_of_box(b: Option<crate::mesh::Aabb>) -> ([f64; 3], f64) {
    match b {
        Some(b) if b.diagonal() > 0.0 => (b.center(), 1.0 / b.diagonal()),
        Some(b) => (b.center(), 1.0),
        None => ([0.0; 3], 1.0),
    }
}

/// `(p - center) * scale`, in f64.
pub fn normalize(p: [f32; 3], center: [f64; 3], scale: f64) -> [f64; 3] {
    [0, 1, 2].map(|i| (p[i] as f64 - center[i]) * scale)
}

/// Out of the normalized frame.
pub fn denormalize(p: [f64; 3], center: [f64; 3], scale: f64) -> [f32; 3] {
    [0, 1, 2].map(|i| (p[i] / scale + center[i]) as f32)
}

/// Indices `0..n` ordered by `key(i) < buckets`, stable (a counting sort), and where each
/// bucket starts in that order (`buckets + 1` entries).
pub(crate) fn counting_sort(
    buckets: usize,
    n: usize,
    key: impl Fn(usize) -> u32 + Sync,
) -> (Vec<u32>, Vec<u32>) {
    let keys: Vec<u32> = (0..n).into_par_iter().map(&key).collect();
    let mut start = vec![0u32; buckets + 1];
    for &k in &keys {
        start[k as usize + 1] += 1;
    }
    for b in 0..buckets {
        start[b + 1] += start[b];
    }
    let begin = start.clone();
    let mut out = vec![0u32; n];
    for (i, &k) in keys.iter().enumerate() {
        out[start[k as usize] as usize] = i as u32;
        start[k as usize] += 1;
    }
    (out, begin)
}
