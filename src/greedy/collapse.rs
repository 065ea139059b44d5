//! Carrying out collapses: the state's set-up with every edge queued, applying a checked
//! collapse and queuing its edges again, and the loop that takes the cheapest valid collapse
//! until a target, a cost ceiling or an empty queue.

use super::evaluate::{Collapse, Evaluation};
use super::prepare::Prepared;
use super::queue::{Queue, key};
use super::state::{DEAD, State, VertFaces};
use crate::options::SimplifyOptions;

/// Vertices whose edges [`State::queue_all_edges`] works out as one task and keeps in one list.
const QUEUE_BLOCK: usize = 4096;

impl<'a> State<'a> {
    /// Applies a checked collapse; returns how many faces it removed.
    fn apply(&mut self, c: &Collapse) -> usize {
        let (k, r) = (c.keep as usize, c.remove as usize);
        self.p.pos[k] = c.pos;
        let qr = self.p.quadrics[r];
        self.p.quadrics[k].add(&qr);
        self.p.border[k] |= self.p.border[r];
        self.alive[r] = false;
        let mut removed = 0;
        // `remove`'s faces that stay go to the end of `keep`'s list, in order.
        let mut moved = std::mem::take(&mut self.scratch);
        moved.clear();
        for &f in self.vert_faces.get(r) {
            let fu = f as usize;
            if self.topo_faces[fu][0] == DEAD {
                continue;
            }
            if self.topo_faces[fu].contains(&c.keep) {
                self.face_alive[fu] = false;
                self.topo_faces[fu] = [DEAD; 3];
                removed += 1;
                continue;
            }
            for i in 0..3 {
                if self.topo_faces[fu][i] == c.remove {
                    self.topo_faces[fu][i] = c.keep;
                    // Debug builds keep the corners too, for `attr_face` to check against.
                    if self.faces_follow_topo && !cfg!(debug_assertions) {
                        continue;
                    }
                    let old = self.p.faces[fu][i];
                    let (_, new) = c
                        .attr_map
                        .iter()
                        .copied()
                        .find(|&(from, _)| from == old)
                        .expect("every attribute vertex of the removed vertex is mapped");
                    self.p.faces[fu][i] = new;
                }
            }
            moved.push(f);
        }
        if let Some(at) = self.p.attrs.as_mut() {
            // Only a survivor that moved takes solved values; one that stays put (a border, a
            // seam, a pin: a tile's border among them, so tiles still meet) keeps its own.
            let solve = self.p.mobility[k] == super::prepare::Mobility::Free;
            for &(from, to) in &c.attr_map {
                if from != u32::MAX {
                    at.merge_into(to, from, c.pos, solve);
                }
            }
        }
        let topo_faces = &self.topo_faces;
        self.vert_faces
            .merge_into(k, r, |f| topo_faces[f as usize][0] != DEAD, &moved);
        self.scratch = moved;
        self.version[k] = self.version[k].wrapping_add(1);
        self.version[r] = self.version[r].wrapping_add(1);
        removed
    }

    /// Queues every edge around `v` with its cheap lower-bound key.
    fn push_edges_of(&mut self, v: u32, heap: &mut Queue) {
        let m = self.next_mark();
        self.mark[v as usize] = m;
        // The neighbours first, their quadrics and positions asked of the cache as they are
        // found, then the placements: the loads overlap instead of each waiting on the last.
        let mut nbrs = std::mem::take(&mut self.scratch);
        nbrs.clear();
        for &f in self.vert_faces.get(v as usize) {
            for u in self.topo_faces[f as usize] {
                if self.mark[u as usize] != m {
                    self.mark[u as usize] = m;
                    self.prefetch_vertex(u);
                    nbrs.push(u);
                }
            }
        }
        for &u in &nbrs {
            if let Some((_, _, _, err)) = self.placement(v, u) {
                let (lo, hi) = if v < u { (v, u) } else { (u, v) };
                heap.push(key(err), lo, hi, self.stamp(lo, hi));
            }
        }
        self.scratch = nbrs;
    }
}

impl<'a> State<'a> {
    /// Sets up the collapse state and queues every unique edge once, keyed by its quadric error.
    pub(super) fn new(p: Prepared, opts: &'a SimplifyOptions) -> (State<'a>, Queue) {
        use rayon::prelude::*;
        let topo_faces: Vec<[u32; 3]> = p
            .faces
            .par_iter()
            .with_min_len(1 << 14)
            .map(|f| f.map(|v| p.topo[v as usize]))
            .collect();
        State::with_topo_faces(p, topo_faces, opts)
    }

    /// [`State::new`] with the faces' topological vertices given (`p.topo` is not read).
    pub(super) fn with_topo_faces(
        p: Prepared,
        topo_faces: Vec<[u32; 3]>,
        opts: &'a SimplifyOptions,
    ) -> (State<'a>, Queue) {
        let nt = p.pos.len();
        let nf = p.faces.len();
        assert_eq!(topo_faces.len(), nf, "one topological face per face");
        let vert_faces = VertFaces::new(nt, &topo_faces);
        let faces_follow_topo = !p.seam.contains(&true);
        let s = State {
            opts,
            p,
            topo_faces,
            face_alive: vec![true; nf],
            vert_faces,
            alive: vec![true; nt],
            version: vec![0; nt],
            mark: vec![0; nt],
            mark_gen: 0,
            cos_max_angle: opts.max_normal_angle_deg.to_radians().cos(),
            scratch: Vec::new(),
            faces: nf,
            collapses: 0,
            max_collapse_err2: 0.0,
            seeded_at: 0,
            refills: 0,
            one_thread: false,
            faces_follow_topo,
            hit_max_error: false,
        };
        let mut heap = Queue::new();
        s.queue_all_edges(&mut heap);
        (s, heap)
    }

    /// Queues every unique edge of the live faces once, keyed by its quadric error. Gathered
    /// per vertex from its face list instead of sorting all edge keys: measured on the 1M scan
    /// at 10%, the global sort was 0.55 G of the run's 15 G instructions. The keys are worked
    /// out on every core: the queue gives its entries back in their own order, whatever order
    /// they came in, so this changes nothing but the time. The entries are kept in blocks of
    /// vertices, each with room for its edges made at once, and pushed from there: one list
    /// per core grown entry by entry, then gathered into one, copied them into fresh memory
    /// again and again.
    fn queue_all_edges(&self, heap: &mut Queue) {
        use rayon::prelude::*;
        let n = self.p.pos.len();
        let block = |nbrs: &mut Vec<u32>, block: usize| {
            let vertices = block * QUEUE_BLOCK..((block + 1) * QUEUE_BLOCK).min(n);
            // A closed surface has about three edges a vertex (E ≈ 3V), each queued from its
            // lower end; room left unused is never written.
            let mut out = Vec::with_capacity(vertices.len() * 7 / 2);
            for a in vertices.map(|a| a as u32) {
                nbrs.clear();
                for &f in self.vert_faces.get(a as usize) {
                    let t = self.topo_faces[f as usize];
                    if t[0] != DEAD {
                        nbrs.extend(t.into_iter().filter(|&u| u > a));
                    }
                }
                nbrs.sort_unstable();
                nbrs.dedup();
                for &b in nbrs.iter() {
                    if let Some((_, _, _, err)) = self.placement(a, b) {
                        out.push((key(err), a, b, self.stamp(a, b)));
                    }
                }
            }
            out
        };
        let blocks = 0..n.div_ceil(QUEUE_BLOCK);
        let parts: Vec<Vec<(u32, u32, u32, u32)>> = if self.one_thread {
            let mut nbrs = Vec::new();
            blocks.map(|b| block(&mut nbrs, b)).collect()
        } else {
            blocks.into_par_iter().map_init(Vec::new, block).collect()
        };
        heap.push_all(&parts);
    }

    /// Collapses the cheapest valid edges until `target` faces remain, the queue runs dry, or
    /// the cheapest key exceeds `key_limit` (that entry stays queued). Returns true when it
    /// stopped at the key limit.
    pub(super) fn run(
        &mut self,
        heap: &mut Queue,
        target: usize,
        key_limit: u32,
        progress: &mut dyn FnMut(usize),
    ) -> bool {
        let max_err2 = self.opts.max_error.map(|e| e * e);
        let mut next_report = self.collapses;

        while self.faces > target {
            let Some((k, a, b, stamp)) = heap.pop(|a, b, stamp| self.stamp(a, b) == stamp) else {
                // An edge refused earlier (a flip, the link condition) can have become valid
                // through collapses around it that did not touch its endpoints: before giving
                // up, queue every live edge once more if anything changed since the last time.
                if self.collapses > self.seeded_at {
                    self.seeded_at = self.collapses;
                    self.refills += 1;
                    self.queue_all_edges(heap);
                    if heap.is_empty() {
                        return false;
                    }
                    continue;
                }
                return false;
            };
            if k > key_limit {
                heap.push(k, a, b, stamp);
                return true;
            }
            if let Some((na, nb)) = heap.peek() {
                self.prefetch_edge(na, nb);
            }
            // A removed vertex's version was bumped too, so one comparison retires every entry
            // whose edge changed or vanished.
            if self.stamp(a, b) != stamp {
                continue;
            }
            let c = match self.evaluate_below(a, b, k) {
                Evaluation::Collapse(c) => c,
                Evaluation::Later(full) => {
                    heap.push(full, a, b, stamp);
                    continue;
                }
                Evaluation::Refused => continue,
            };
            let q = self.p.quadrics[c.keep as usize].sum(&self.p.quadrics[c.remove as usize]);
            let err2 = if q.weight > 0.0 {
                c.error / q.weight
            } else {
                0.0
            };
            if max_err2.is_some_and(|m| err2 > m) {
                // Quadrics only grow, so this edge will not become acceptable again.
                self.hit_max_error = true;
                continue;
            }
            // At most two faces go per collapse and faces > target, so the result is at worst one
            // below the target.
            self.faces -= self.apply(&c);
            self.collapses += 1;
            self.max_collapse_err2 = self.max_collapse_err2.max(err2);
            self.push_edges_of(c.keep, heap);
            if self.collapses >= next_report {
                progress(self.faces);
                next_report = self.collapses + 4096;
                if self.opts.cancel.is_cancelled() {
                    // The caller turns this into Error::Cancelled.
                    return false;
                }
            }
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a mesh without seams, collapses that leave the faces' corners to
    /// [`State::sync_faces`] end with the corners that collapses writing them give; a mesh
    /// with a seam (a vertex with two UVs) has its corners written by every collapse. (The
    /// tests run in release, where the corners are left; debug builds write them and check
    /// every sync against them.)
    #[test]
    fn synced_corners_are_the_written_ones() {
        let m = crate::mesh::noisy_sphere(5, 0.01, 7);
        let opts = SimplifyOptions::with_ratio(m.triangles.len(), 0.1).unwrap();
        let run = |follow: bool| {
            let (mut s, mut heap) = State::new(Prepared::new(&m, &opts), &opts);
            assert!(
                s.faces_follow_topo,
                "no vertex of the sphere has two attribute vertices"
            );
            s.faces_follow_topo = follow;
            s.run(&mut heap, opts.target_faces, u32::MAX, &mut |_| {});
            s.sync_faces();
            let live: Vec<[u32; 3]> = (0..s.p.faces.len())
                .filter(|&f| s.face_alive[f])
                .map(|f| {
                    assert_eq!(s.attr_face(f), s.p.faces[f]);
                    s.p.faces[f]
                })
                .collect();
            (s.collapses, live)
        };
        let written = run(false);
        assert!(written.0 > 0 && written.1.len() <= opts.target_faces);
        assert_eq!(run(true), written);

        // Vertex 0 split in two by UV: its first face takes the copy.
        let mut seamed = m.clone();
        seamed.uvs = Some(vec![[0.0, 0.0]; m.positions.len()]);
        seamed.positions.push(m.positions[0]);
        seamed.uvs.as_mut().unwrap().push([1.0, 0.0]);
        let copy = (seamed.positions.len() - 1) as u32;
        let f = m.triangles.iter().position(|t| t.contains(&0)).unwrap();
        for v in &mut seamed.triangles[f] {
            if *v == 0 {
                *v = copy;
            }
        }
        let (s, _) = State::new(Prepared::new(&seamed, &opts), &opts);
        assert!(!s.faces_follow_topo);
    }
}
