//! Twin of shaders/rounds/edge_errors.wgsl: per edge, where the collapse would put the survivor and
//! its quadric error, and the histogram of errors `cost_ceiling` picks the round's ceiling
//! from. The error is the cheap half of an edge's evaluation (a quadric solve on the two
//! endpoints); the faces that move are the costly half, and `edge_costs` checks them only for
//! the edges whose error is under the ceiling, the only ones that compete this round. Seam
//! vertices follow the greedy reference's rules: a free vertex may move onto one, and one may
//! slide along its seam onto a seam neighbour (`collapse` makes the attribute map again from
//! the same faces).

use super::attributes::Channels;
use super::counters::{CounterField, counter};
use super::{corner_attr, face_of, faces_of};
use crate::compute::common::*;
use crate::compute::types::{
    EdgeCandidate, FaceExtra, HIST_BINS, HIST_SHIFT, NO_ATTR, Params, Quadric, flag, state,
};
use rayon::prelude::*;
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

/// What `edge_errors` decided for one edge, before it is written out.
pub enum Verdict {
    Invalid,
    /// Valid so far, but its error exceeds the maximum.
    OverMaxError,
    Candidate(EdgeCandidate),
}

/// The faces and their attribute vertices, as the seam rules read them.
struct Corners<'a> {
    indices: &'a [u32],
    offsets: &'a [u32],
    vertex_faces: &'a [u32],
    face_extra: &'a [FaceExtra],
}

impl Corners<'_> {
    /// Free vertex `r` moving onto seam vertex `k`: its corners take the attribute vertex `k`
    /// has in the faces on the edge, which must agree (else the edge runs along the seam).
    fn onto_seam(&self, k: u32, r: u32) -> Option<[u32; 4]> {
        let mut to = NO_ATTR;
        for &f in faces_of(self.offsets, self.vertex_faces, r) {
            if face_of(self.indices, f).contains(&k) {
                let a = corner_attr(self.indices, self.face_extra, f, k);
                if to != NO_ATTR && to != a {
                    return None;
                }
                to = a;
            }
        }
        (to != NO_ATTR).then_some([NO_ATTR, to, NO_ATTR, NO_ATTR])
    }

    /// Seam vertex `r` sliding along edge (r, k) onto seam vertex `k` (the greedy's
    /// `seam_slide`): `r` is free to go (not pinned, not on a border), has two attribute
    /// vertices, and the two faces on the edge use different ones at both ends. Returns
    /// (from₁, to₁, from₂, to₂).
    fn seam_slide(&self, flags: &[u32], r: u32, k: u32) -> Option<[u32; 4]> {
        if flags[r as usize] & (flag::PINNED | flag::BORDER) != 0 {
            return None;
        }
        let mut attrs = [NO_ATTR; 2];
        let mut sides = [NO_ATTR; 4];
        let mut n = 0;
        for &f in faces_of(self.offsets, self.vertex_faces, r) {
            let a = corner_attr(self.indices, self.face_extra, f, r);
            if attrs[0] == NO_ATTR || attrs[0] == a {
                attrs[0] = a;
            } else if attrs[1] == NO_ATTR || attrs[1] == a {
                attrs[1] = a;
            } else {
                return None; // a seam junction stays
            }
            if face_of(self.indices, f).contains(&k) {
                if n == 2 {
                    return None;
                }
                sides[2 * n] = a;
                sides[2 * n + 1] = corner_attr(self.indices, self.face_extra, f, k);
                n += 1;
            }
        }
        (n == 2 && sides[0] != sides[2] && sides[1] != sides[3]).then_some(sides)
    }
}

/// The attribute state `placement` reads: per vertex its attribute vertex, per attribute vertex
/// its values and sums.
pub struct AttrState<'a> {
    pub vertex_attr: &'a [u32],
    pub values: &'a [f32],
    pub sums: &'a [f32],
}

impl Corners<'_> {
    /// Twin of `held` in shaders/rounds/edge_errors.wgsl: the quadric `q` (measured from `o`)
    /// of survivor `k` that stays put, each of its attribute vertices held at its values against
    /// its own sums and those of `r`'s side that joins it (`map`: r's (from, to) pairs from the
    /// seam rules; for a free `r`, its one attribute vertex onto k's on the edge). k's attribute
    /// vertices: a seam vertex's corners', each once; any other's one.
    #[allow(clippy::too_many_arguments)]
    fn held(
        &self,
        ch: &Channels,
        at: &AttrState,
        positions: &[[f32; 4]],
        flags: &[u32],
        q: &Quadric,
        (k, r): (u32, u32),
        map: [u32; 4],
        o: V3,
    ) -> Quadric {
        let tk = sub(o, xyz(positions[k as usize]));
        let tr = sub(o, xyz(positions[r as usize]));
        let va = at.vertex_attr;
        let mut m = map;
        if flags[r as usize] & flag::SEAM == 0 {
            m = [va[r as usize], va[k as usize], NO_ATTR, NO_ATTR];
            if flags[k as usize] & flag::SEAM != 0 {
                m[1] = map[1];
            }
        }
        let hold = |h: &Quadric, x: u32, t: V3, v: u32| ch.hold(at.sums, at.values, h, x, t, v);
        if flags[k as usize] & flag::SEAM == 0 {
            let kv = va[k as usize];
            let h = hold(q, kv, tk, kv);
            return hold(&h, m[0], tr, kv);
        }
        let list = faces_of(self.offsets, self.vertex_faces, k);
        let attr = |f: u32| corner_attr(self.indices, self.face_extra, f, k);
        let mut h = *q;
        for (i, &f) in list.iter().enumerate() {
            let kv = attr(f);
            if list[..i].iter().any(|&g| attr(g) == kv) {
                continue;
            }
            h = hold(&h, kv, tk, kv);
            if m[1] == kv {
                h = hold(&h, m[0], tr, kv);
            } else if m[3] == kv {
                h = hold(&h, m[2], tr, kv);
            }
        }
        h
    }
}

/// The survivor, its new position and the quadric error (`cost_bits`; `pos.w` = error relative
/// to the diagonal, squared). Two pinned ends, and seam vertices other than by the seam rules
/// (`flag::SEAM`), are refused here; the faces that move are `edge_costs`' to check.
#[allow(clippy::too_many_arguments)]
pub fn placement(
    params: &Params,
    positions: &[[f32; 4]],
    quadrics: &[Quadric],
    flags: &[u32],
    indices: &[u32],
    offsets: &[u32],
    vertex_faces: &[u32],
    face_extra: &[FaceExtra],
    at: &AttrState,
    a: u32,
    b: u32,
) -> Verdict {
    let ch = Channels::of(params);
    let (fla, flb) = (flags[a as usize], flags[b as usize]);
    // A closed group's vertex (grouped rounds) takes part in no collapse.
    if (fla | flb) & flag::CLOSED != 0 {
        return Verdict::Invalid;
    }
    let corners = Corners {
        indices,
        offsets,
        vertex_faces,
        face_extra,
    };
    // Seam vertices keep their position like pinned ones.
    let fixed = |fl: u32| fl & (flag::PINNED | flag::SEAM) != 0;
    let pa = xyz(positions[a as usize]);
    let pb = xyz(positions[b as usize]);
    let dab = sub(pb, pa);
    // b's quadric moved to a's origin: x - pb = (x - pa) + (pa - pb).
    let mut q = quadric_add(
        &quadrics[a as usize],
        &quadric_shift(&quadrics[b as usize], sub(pa, pb)),
    );
    let weight = q.q[2][2];
    let mut slides = false;
    let mut map = [NO_ATTR; 4];
    let (keep, remove, y) = if fixed(fla) && fixed(flb) {
        // Only a seam vertex sliding along its seam onto a seam neighbour; b first, as the
        // greedy tries.
        if fla & flb & flag::SEAM == 0 {
            return Verdict::Invalid;
        }
        slides = true;
        if let Some(m) = corners.seam_slide(flags, b, a) {
            map = m;
            (a, b, [0.0; 3])
        } else if let Some(m) = corners.seam_slide(flags, a, b) {
            map = m;
            (b, a, dab)
        } else {
            return Verdict::Invalid;
        }
    } else if fixed(fla) {
        (a, b, [0.0; 3])
    } else if fixed(flb) {
        (b, a, dab)
    } else {
        // Two free vertices: with appearance channels, each has one attribute vertex, and the
        // position and the values come from one solve of the reduced quadric.
        if ch.m != 0 {
            let va = at.vertex_attr;
            q = ch.reduce_pair(
                at.sums,
                &q,
                va[a as usize],
                [0.0; 3],
                va[b as usize],
                sub(pa, pb),
            );
        }
        // With appearance channels the reduced quadric may hold a vertex only weakly along the
        // surface: an optimum farther from the edge's midpoint than the edge is long would
        // slide it over its neighbours, so the ends and the midpoint compete instead.
        let near = |y: &V3| {
            let off = sub(*y, scale(dab, 0.5));
            ch.m == 0 || dot(off, off) <= dot(dab, dab)
        };
        let y = match quadric_optimum(&q).filter(near) {
            Some(y) => y,
            None => {
                let mut best = [0.0f32; 3];
                let mut best_e = quadric_eval(&q, best);
                for c in [dab, scale(dab, 0.5)] {
                    let e = quadric_eval(&q, c);
                    if e < best_e {
                        best = c;
                        best_e = e;
                    }
                }
                best
            }
        };
        // The survivor is the endpoint nearer the new position.
        if dot(y, y) <= dot(sub(y, dab), sub(y, dab)) {
            (a, b, y)
        } else {
            (b, a, y)
        }
    };
    if flags[keep as usize] & flag::SEAM != 0 && !slides {
        match corners.onto_seam(keep, remove) {
            Some(m) => map = m,
            None => return Verdict::Invalid,
        }
    }
    if ch.m != 0 && (fixed(fla) || fixed(flb)) {
        q = corners.held(&ch, at, positions, flags, &q, (keep, remove), map, pa);
    }
    let error = quadric_eval(&q, y);
    // A survivor that keeps its position keeps it bit for bit (pa + (pb - pa) need not be pb):
    // a seam vertex marked moved would leave its other attribute vertices behind.
    let pos = if flags[keep as usize] & (flag::PINNED | flag::SEAM) != 0 {
        xyz(positions[keep as usize])
    } else {
        add(pa, y)
    };

    let err2 = if weight > 0.0 { error / weight } else { 0.0 };
    if !(error.is_finite() && err2.is_finite() && pos.iter().all(|x| x.is_finite())) {
        return Verdict::Invalid;
    }
    if err2 > params.max_error2 {
        return Verdict::OverMaxError;
    }
    Verdict::Candidate(EdgeCandidate {
        pos: [pos[0], pos[1], pos[2], err2],
        keep,
        remove,
        cost_bits: error.to_bits(),
        faces: 0,
    })
}

/// Per edge (`edge_capacity` invocations; those past the edge count stop at once).
#[allow(clippy::too_many_arguments)]
pub fn edge_errors(
    params: &Params,
    positions: &[[f32; 4]],           // per vertex
    quadrics: &[Quadric],             // per vertex
    flags: &[u32],                    // per vertex
    indices: &[u32],                  // per face × 3
    offsets: &[u32],                  // per vertex + 1
    vertex_faces: &[u32],             // per corner
    edges: &[[u32; 2]],               // per edge
    edge_offsets: &[u32],             // per vertex + 1: the edge count at [vertex_count]
    face_extra: &[FaceExtra],         // per face
    vertex_attr: &[u32],              // per vertex
    attr_values: &[f32],              // per attribute vertex × m
    attr_sums: &[f32],                // per attribute vertex × (4m + 1)
    candidates: &mut [EdgeCandidate], // per edge
    edge_state: &mut [u32],           // per edge
    histogram: &[AtomicU32],          // HIST_BINS, cleared
    counters: &[AtomicU32],           // Counters, cleared
) {
    let ne = edge_offsets[params.vertex_count as usize] as usize;
    // Each chunk counts into its own histogram and adds it to the shared one at its end, as a
    // workgroup would in shared memory: one shared atomic add per edge (and one more on the
    // candidate counter) made the two cores fight over the same few cache lines, most edges of
    // a smooth scan falling in a few bins. On the 1M scan at 1% this stage took 1.03-1.13 s
    // with them, 0.45 s without.
    const CHUNK: usize = 1 << 14;
    let at = AttrState {
        vertex_attr,
        values: attr_values,
        sums: attr_sums,
    };
    candidates[..ne]
        .par_chunks_mut(CHUNK)
        .zip(edge_state[..ne].par_chunks_mut(CHUNK))
        .enumerate()
        .for_each(|(chunk, (outs, sts))| {
            let mut local = vec![0u32; HIST_BINS as usize];
            let (mut found, mut over) = (0u32, 0u32);
            for (i, (out, st)) in outs.iter_mut().zip(sts).enumerate() {
                let [a, b] = edges[chunk * CHUNK + i];
                let verdict = placement(
                    params,
                    positions,
                    quadrics,
                    flags,
                    indices,
                    offsets,
                    vertex_faces,
                    face_extra,
                    &at,
                    a,
                    b,
                );
                *st = state::OUT;
                *out = EdgeCandidate::INVALID;
                match verdict {
                    Verdict::Invalid => {}
                    Verdict::OverMaxError => over += 1,
                    Verdict::Candidate(c) => {
                        local[(c.cost_bits >> HIST_SHIFT) as usize] += 1;
                        found += 1;
                        *out = c;
                        *st = state::CANDIDATE;
                    }
                }
            }
            for (bin, &n) in local.iter().enumerate() {
                if n > 0 {
                    histogram[bin].fetch_add(n, Relaxed);
                }
            }
            counter(counters, CounterField::Candidates).fetch_add(found, Relaxed);
            counter(counters, CounterField::OverMaxError).fetch_add(over, Relaxed);
        });
}
