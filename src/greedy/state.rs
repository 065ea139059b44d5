//! The collapse state of one run: the prepared surface as it changes, the faces around each
//! vertex, liveness, versions that retire stale queue entries, and the run's statistics.

use super::prepare::Prepared;
use crate::options::SimplifyOptions;
use crate::prefetch::{prefetch, prefetch_ptr};

/// The faces around each vertex, all in one arena: a vertex's list is `data[start..start + len]`
/// with room up to `cap`. Built in vertex (Morton) order, so the lists of neighbours sit side by
/// side; a list that outgrows its room moves into the removed vertex's (a neighbour's, so still
/// nearby) or else to the end. Measured on the 1M scan at 10%: one `Vec` per vertex spent
/// 0.45 G of 15 G instructions in malloc/realloc/free, and each list was a cache miss of its own.
#[derive(Clone)]
pub(crate) struct VertFaces {
    /// Per vertex: start, len, cap.
    span: Vec<[u32; 3]>,
    data: Vec<u32>,
}

impl VertFaces {
    /// Lists in face order, from each face's vertices.
    pub(crate) fn new(nt: usize, topo_faces: &[[u32; 3]]) -> VertFaces {
        let mut span = vec![[0u32; 3]; nt];
        for t in topo_faces {
            for &v in t {
                span[v as usize][2] += 1;
            }
        }
        let mut at = 0u32;
        for s in &mut span {
            s[0] = at;
            at += s[2];
        }
        let mut data = vec![0u32; at as usize];
        // Room for the lists that will move: a collapse grows one list by a few faces.
        data.reserve(at as usize / 8);
        for (f, t) in topo_faces.iter().enumerate() {
            for &v in t {
                let s = &mut span[v as usize];
                data[(s[0] + s[1]) as usize] = f as u32;
                s[1] += 1;
            }
        }
        VertFaces { span, data }
    }

    #[inline]
    pub(crate) fn get(&self, v: usize) -> &[u32] {
        let [start, len, _] = self.span[v];
        &self.data[start as usize..(start + len) as usize]
    }

    /// Replaces `keep`'s list by its own entries that pass `live`, then `extra`; `remove`'s list
    /// is emptied and its room may be reused.
    pub(crate) fn merge_into(
        &mut self,
        keep: usize,
        remove: usize,
        live: impl Fn(u32) -> bool,
        extra: &[u32],
    ) {
        let [start, len, cap] = self.span[keep];
        let (start, cap) = (start as usize, cap as usize);
        let mut n = start;
        for i in start..start + len as usize {
            let f = self.data[i];
            if live(f) {
                self.data[n] = f;
                n += 1;
            }
        }
        let kept = n - start;
        let need = kept + extra.len();
        let [rs, _, rc] = self.span[remove];
        self.span[remove] = [rs, 0, 0];
        let (start, cap) = if need <= cap {
            (start, cap)
        } else if need <= rc as usize {
            self.data.copy_within(start..start + kept, rs as usize);
            (rs as usize, rc as usize)
        } else {
            let at = self.data.len();
            let cap = need + need / 2;
            self.data.resize(at + cap, 0);
            self.data.copy_within(start..start + kept, at);
            (at, cap)
        };
        self.data[start + kept..start + need].copy_from_slice(extra);
        self.span[keep] = [start as u32, need as u32, cap as u32];
    }
}

/// `topo_faces` entry of a removed face. The hot loops test this instead of `face_alive`: the
/// face's vertices are read next anyway, so liveness costs no extra cache line.
pub(super) const DEAD: u32 = u32::MAX;

pub(super) struct State<'a> {
    pub(super) opts: &'a SimplifyOptions,
    pub(super) p: Prepared,
    pub(super) topo_faces: Vec<[u32; 3]>,
    pub(super) face_alive: Vec<bool>,
    /// Live (and some dead, pruned lazily) faces around each vertex.
    pub(super) vert_faces: VertFaces,
    pub(super) alive: Vec<bool>,
    pub(super) version: Vec<u32>,
    pub(super) mark: Vec<u32>,
    pub(super) mark_gen: u32,
    pub(super) cos_max_angle: f64,
    pub(super) scratch: Vec<u32>,
    /// Live faces.
    pub(super) faces: usize,
    pub(super) collapses: usize,
    /// `collapses` when every live edge was last queued: the queue is filled again when it runs
    /// dry only if something collapsed since. Kept across `run` calls, so a run cut into
    /// epochs by cost ceilings refills exactly where an uninterrupted one would.
    pub(super) seeded_at: usize,
    /// Times the queue was filled again.
    pub(super) refills: usize,
    /// Refills queue the edges on this thread alone: a partitioned level's region, which runs
    /// on a thread that rayon's pool may not be free to help (see `epochs`).
    pub(super) one_thread: bool,
    /// No vertex has more than one attribute vertex (no seam), so a live face's attribute
    /// vertices are its topological vertices' only ones (`p.first_attr`), and collapses leave
    /// `p.faces` to [`State::sync_faces`]: rewriting each moved face's corner there was a cache
    /// miss of its own, 6.7% of the collapse loop's samples on the 1M scan at 10%.
    pub(super) faces_follow_topo: bool,
    pub(super) max_collapse_err2: f64,
    pub(super) hit_max_error: bool,
}

impl<'a> State<'a> {
    pub(super) fn next_mark(&mut self) -> u32 {
        self.next_marks(1)
    }

    /// `n` fresh mark values `m..m + n`; returns `m`.
    pub(super) fn next_marks(&mut self, n: u32) -> u32 {
        if self.mark_gen > u32::MAX - n {
            self.mark.iter_mut().for_each(|m| *m = 0);
            self.mark_gen = 0;
        }
        let m = self.mark_gen + 1;
        self.mark_gen += n;
        m
    }

    /// Live face `f`'s attribute vertices (the corners `p.faces` holds once synced).
    #[inline]
    pub(super) fn attr_face(&self, f: usize) -> [u32; 3] {
        if self.faces_follow_topo {
            let t = self.topo_faces[f].map(|t| self.p.first_attr[t as usize]);
            debug_assert_eq!(t, self.p.faces[f], "face {f} strayed from its vertices");
            t
        } else {
            self.p.faces[f]
        }
    }

    /// Brings `p.faces` up to date for the live faces (see `faces_follow_topo`); a no-op
    /// where collapses rewrite it themselves.
    pub(super) fn sync_faces(&mut self) {
        use rayon::prelude::*;
        if !self.faces_follow_topo {
            return;
        }
        let (topo_faces, first_attr) = (&self.topo_faces, &self.p.first_attr);
        self.p
            .faces
            .par_iter_mut()
            .zip(topo_faces)
            .with_min_len(1 << 14)
            .filter(|(_, t)| t[0] != DEAD)
            .for_each(|(face, t)| {
                let synced = t.map(|t| first_attr[t as usize]);
                debug_assert_eq!(synced, *face, "a face strayed from its vertices");
                *face = synced;
            });
    }

    /// The live mesh as a prepared problem (positions, quadrics and flags as they are now), to
    /// go on from with a new state: the next level of detail.
    pub(super) fn into_prepared(mut self) -> Prepared {
        fn live<T: Copy>(v: &[T], alive: &[bool]) -> Vec<T> {
            v.iter().zip(alive).filter(|p| *p.1).map(|p| *p.0).collect()
        }
        self.sync_faces();
        let mut p = self.p;
        p.faces = live(&p.faces, &self.face_alive);
        p.face_origin = live(&p.face_origin, &self.face_alive);
        p.ref_normal = live(&p.ref_normal, &self.face_alive);
        p
    }

    /// Asks the cache for what evaluating edge (a, b) reads first: the run calls it for the
    /// queue's next entry while it evaluates this one. The evaluation was bound by the chain of
    /// misses from a vertex to its face list to the faces (`perf annotate`: 38% of its samples
    /// on those three loads); with this and [`State::prefetch_vertex`] the 1M scan at 10% took
    /// 0.80 s against 0.92 s (the best of five interleaved runs, same output).
    #[inline]
    pub(super) fn prefetch_edge(&self, a: u32, b: u32) {
        for v in [a as usize, b as usize] {
            let faces = self.vert_faces.get(v);
            prefetch(faces, 0);
            for &f in faces.iter().take(8) {
                prefetch(&self.topo_faces, f as usize);
                // Read beside the corners by every moved face's normal check.
                prefetch(&self.p.ref_normal, f as usize);
            }
            self.prefetch_vertex(v as u32);
            prefetch(&self.version, v);
        }
    }

    /// Asks the cache for what a placement reads of `v`.
    #[inline]
    pub(super) fn prefetch_vertex(&self, v: u32) {
        let v = v as usize;
        prefetch(&self.p.pos, v);
        // A quadric's 88 bytes span up to three lines.
        let q = self.p.quadrics.as_ptr().wrapping_add(v) as *const u8;
        for offset in [0, 64, std::mem::size_of::<crate::quadric::Quadric>() - 1] {
            prefetch_ptr(q.wrapping_add(offset));
        }
    }

    pub(super) fn stamp(&self, a: u32, b: u32) -> u32 {
        self.version[a as usize].wrapping_add(self.version[b as usize])
    }
}
