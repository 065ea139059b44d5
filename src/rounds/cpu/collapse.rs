//! Twin of shaders/rounds/collapse.wgsl: each winner moves its survivor to the new position, gives
//! it the sum of both quadrics (re-centred on the new position) and the removed vertex's border
//! bit, and points the removed vertex at the survivor; when the survivor is a seam vertex, the
//! removed vertex's corners take their attribute vertices by the seam rule `edge_errors` checked.
//! With appearance channels, the removed vertex's sides' attribute sums join those of the
//! survivor's sides they map to, and a survivor that moves takes the values best for the merged
//! sums at its new place (Hoppe 1999), kept valid: colours in 0..1, UVs within the two ends' range.
//! Winners share no face, hence no vertex (and each attribute vertex belongs to one vertex), so
//! these writes never meet.

use super::attributes::Channels;
use super::{Scatter, corner_on, face_of, faces_of, par_for};
use crate::compute::common::{V3, dot, quadric_add, quadric_shift, sub, xyz};
use crate::compute::types::{EdgeCandidate, FaceExtra, NO_ATTR, Params, Quadric, flag, state};

/// The attribute vertex a corner of the removed vertex takes under map `m` (see [`NO_ATTR`]).
fn mapped(m: [u32; 4], a: u32) -> u32 {
    if m[0] == NO_ATTR || a == m[0] {
        m[1]
    } else if a == m[2] {
        m[3]
    } else {
        a
    }
}

/// The faces and their attribute vertices, for rewriting the removed vertex's corners.
struct Corners<'a> {
    indices: &'a [u32],
    offsets: &'a [u32],
    vertex_faces: &'a [u32],
    face_extra: Scatter<'a, FaceExtra>,
}

impl Corners<'_> {
    /// The attribute vertex face `f` uses at its corner on vertex `v`.
    ///
    /// # Safety
    /// No other thread writes face `f` meanwhile.
    unsafe fn corner_attr(&self, f: u32, v: u32) -> u32 {
        let i = corner_on(self.indices, f, v);
        // SAFETY: the caller's.
        unsafe { self.face_extra.read(f as usize).attr[i] }
    }

    /// The removed vertex `r`'s corners onto seam vertex `k`: the map from the faces on the
    /// edge (locked since `edge_errors` checked it): each side's pair for a seam vertex sliding
    /// along its seam, `k`'s attribute vertex for all corners of a free one.
    ///
    /// Returns the map, for the attribute sums.
    ///
    /// # Safety
    /// The faces around `r` are this thread's alone (winners share no face: the selection).
    unsafe fn onto_seam(&self, flags: &Scatter<u32>, k: u32, r: u32) -> [u32; 4] {
        let faces = faces_of(self.offsets, self.vertex_faces, r);
        // SAFETY: the caller's: r's faces and flags are this winner's alone.
        unsafe {
            let slides = flags.read(r as usize) & flag::SEAM != 0;
            let mut m = [NO_ATTR; 4];
            let mut n = 0;
            for &f in faces {
                if face_of(self.indices, f).contains(&k) {
                    if !slides {
                        m[1] = self.corner_attr(f, k);
                    } else if n < 2 {
                        m[2 * n] = self.corner_attr(f, r);
                        m[2 * n + 1] = self.corner_attr(f, k);
                    }
                    n += 1;
                }
            }
            // The faces that stay (those on the edge go).
            for &f in faces {
                let t = face_of(self.indices, f);
                if t.contains(&k) {
                    continue;
                }
                let mut x = self.face_extra.read(f as usize);
                for (i, &u) in t.iter().enumerate() {
                    if u == r {
                        x.attr[i] = mapped(m, x.attr[i]);
                    }
                }
                self.face_extra.write(f as usize, x);
            }
            m
        }
    }
}

/// The attribute values and sums `collapse` merges.
struct Merge<'a> {
    ch: Channels,
    color_weight: f32,
    values: Scatter<'a, f32>,
    sums: Scatter<'a, f32>,
}

impl Merge<'_> {
    /// Attribute vertex `from`'s sums (measured from its vertex moved by `t`) added to `to`'s.
    ///
    /// # Safety
    /// Both attribute vertices belong to this winner's two vertices.
    unsafe fn join_sums(&self, to: u32, from: u32, t: V3) {
        let (m, s) = (self.ch.m, self.ch.stride());
        // Two attribute vertices of two vertices: never one, so the two ranges never overlap
        // (checked in release builds too, since the slices below rely on it).
        assert_ne!(to, from, "an attribute vertex joined to itself");
        let (to, from) = (to as usize * s, from as usize * s);
        // SAFETY: the caller's; `from` and `to` are distinct (asserted), so the ranges are disjoint.
        unsafe {
            let src = self.sums.range_mut(from, from + s);
            let dst = self.sums.range_mut(to, to + s);
            for j in 0..m {
                let g = [src[3 * j], src[3 * j + 1], src[3 * j + 2]];
                let d = src[3 * m + j] + dot(g, t);
                for k in 0..3 {
                    dst[3 * j + k] += src[3 * j + k];
                }
                dst[3 * m + j] += d;
            }
            dst[4 * m] += src[4 * m];
        }
    }

    /// Survivor attribute vertex `ak` moving by `tk` takes `ar`'s sums (moving by `tr`) and the
    /// best values for both at its new place, kept valid.
    ///
    /// # Safety
    /// Both attribute vertices belong to this winner's two vertices.
    unsafe fn merge_moving(&self, ak: u32, ar: u32, tk: V3, tr: V3) {
        let (m, s) = (self.ch.m, self.ch.stride());
        // SAFETY: the caller's.
        unsafe {
            {
                let own = self.sums.range_mut(ak as usize * s, (ak as usize + 1) * s);
                for j in 0..m {
                    let g = [own[3 * j], own[3 * j + 1], own[3 * j + 2]];
                    own[3 * m + j] += dot(g, tk);
                }
            }
            self.join_sums(ak, ar, tr);
            let own = self.sums.range_mut(ak as usize * s, (ak as usize + 1) * s);
            let w = own[4 * m];
            if w.is_nan() || w <= 0.0 {
                return;
            }
            let uv_end = self.ch.colors + if self.ch.uv { 2 } else { 0 };
            for j in 0..m {
                let mut x = own[3 * m + j] / w;
                let old_k = self.values.read(ak as usize * m + j);
                let old_r = self.values.read(ar as usize * m + j);
                // WGSL's clamp: min(max(x, lo), hi).
                if j < self.ch.colors {
                    x = x.max(0.0).min(self.color_weight);
                } else if j < uv_end {
                    x = x.max(old_k.min(old_r)).min(old_k.max(old_r));
                }
                self.values.write(ak as usize * m + j, x);
            }
        }
    }
}

#[allow(clippy::too_many_arguments)]
pub(crate) fn collapse(
    params: &Params,
    candidates: &[EdgeCandidate],   // per edge
    edge_state: &[u32],             // per edge
    edge_offsets: &[u32],           // per vertex + 1: the edge count at [vertex_count]
    indices: &[u32],                // per face × 3
    offsets: &[u32],                // per vertex + 1
    vertex_faces: &[u32],           // per corner
    vertex_attr: &[u32],            // per vertex
    positions: Scatter<[f32; 4]>,   // per vertex
    quadrics: Scatter<Quadric>,     // per vertex
    flags: Scatter<u32>,            // per vertex
    remap: Scatter<u32>,            // per vertex
    face_extra: Scatter<FaceExtra>, // per face
    attr_values: Scatter<f32>,      // per attribute vertex × m
    attr_sums: Scatter<f32>,        // per attribute vertex × (4m + 1)
) {
    let merge = Merge {
        ch: Channels::of(params),
        color_weight: params.color_weight,
        values: attr_values,
        sums: attr_sums,
    };
    let edge_count = edge_offsets[params.vertex_count as usize];
    let corners = Corners {
        indices,
        offsets,
        vertex_faces,
        face_extra,
    };
    par_for(edge_count, |e| {
        if edge_state[e as usize] != state::WON {
            return;
        }
        let c = &candidates[e as usize];
        let (k, r) = (c.keep as usize, c.remove as usize);
        // SAFETY: winners share no face and so no vertex (the selection; checked every round,
        // release builds included, by `select::shared_face`, after which `CpuRounds::select`
        // stops with an error instead of reaching this stage); each winner reads and writes only its own
        // two vertices and the faces around the removed one, which no other winner touches.
        unsafe {
            let mut map = [vertex_attr[r], vertex_attr[k], NO_ATTR, NO_ATTR];
            if flags.read(k) & flag::SEAM != 0 {
                let seam = corners.onto_seam(&flags, c.keep, c.remove);
                map[1] = seam[1];
                if flags.read(r) & flag::SEAM != 0 {
                    map = seam;
                }
            }
            let pk = positions.read(k);
            let pr = positions.read(r);
            let p = xyz(c.pos);
            if merge.ch.m != 0 {
                if flags.read(k) & (flag::PINNED | flag::SEAM) == 0 {
                    merge.merge_moving(map[1], map[0], sub(p, xyz(pk)), sub(p, xyz(pr)));
                } else {
                    // A survivor that stays put keeps its values; r's sides join the sides
                    // they map to.
                    let t = sub(xyz(pk), xyz(pr));
                    merge.join_sums(map[1], map[0], t);
                    if map[2] != NO_ATTR {
                        merge.join_sums(map[3], map[2], t);
                    }
                }
            }
            let q = quadric_add(
                &quadric_shift(&quadrics.read(k), sub(p, xyz(pk))),
                &quadric_shift(&quadrics.read(r), sub(p, xyz(pr))),
            );
            quadrics.write(k, q);
            let moved = if p != xyz(pk) { flag::MOVED } else { 0 };
            flags.write(k, flags.read(k) | (flags.read(r) & flag::BORDER) | moved);
            positions.write(k, [p[0], p[1], p[2], 1.0]);
            remap.write(r, k as u32);
        }
    });
}
