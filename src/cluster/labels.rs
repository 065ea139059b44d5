//! The `cell_labels` stage, one of the clustering stages beside those of [`super::stages`]:
//! the connected components of each cell's members, by a union-find on every core.

use super::stages::Cells;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

/// `cell_labels`: each vertex's label becomes the lowest vertex id of its connected component
/// inside its cell, components joined by the edges of faces and by coincident vertices (an
/// unwelded seam's two sides are one surface). Separate sheets of the surface that pass
/// through one cell, or a sheet that passes through it twice, keep separate labels.
///
/// On the CPU a union-find that always hangs the larger root under the smaller, so each root
/// is its component's lowest id: the fixed point the GPU reaches by rounds of taking the least
/// label over in-cell neighbours and pointer jumping. Those rounds took 0.18 s on the 1M scan
/// on two cores, a sequential union-find a tenth of it.
pub fn cell_labels(cells: &Cells, faces: &[[u32; 3]], positions: &[[f32; 4]]) -> Vec<u32> {
    cell_labels_where(cells, faces, positions, |_, _| true)
}

/// [`cell_labels`] joining only the edges `join` allows (the hybrid's: no colour step).
pub fn cell_labels_where(
    cells: &Cells,
    faces: &[[u32; 3]],
    positions: &[[f32; 4]],
    join: impl Fn(u32, u32) -> bool + Sync,
) -> Vec<u32> {
    let u = CellUnion::new(cells.vertex_cell.len());
    u.join_faces_where(cells, faces, join);
    u.labels(cells, positions)
}

/// [`cell_labels`] fed its faces a block at a time (a streamed file's).
///
/// The faces are joined on every core at once: a link is a compare-and-swap that hangs a root
/// under a smaller root only while it is still a root, so links only ever point to smaller
/// ids (no cycle can form) and no join is lost; whatever order the threads join in, each root
/// ends as its component's lowest id, so the labels are the same on any number of threads.
/// (Anderson & Woll, "Wait-free parallel algorithms for the union-find problem", 1991.)
/// Sequentially, with the coincident members' sorts, this was 0.024 s of a build on the 1M
/// scan at 10% and 0.047-0.052 s at 1%; on two cores 0.019-0.024 s and 0.023-0.024 s.
pub struct CellUnion {
    parent: Vec<AtomicU32>,
}

impl CellUnion {
    pub fn new(n: usize) -> CellUnion {
        CellUnion {
            parent: (0..n as u32).into_par_iter().map(AtomicU32::new).collect(),
        }
    }

    /// The root of `v`'s tree, halving the path on the way (each node then points to its
    /// grandparent: still an ancestor, whatever other threads link meanwhile).
    fn find(&self, mut v: u32) -> u32 {
        loop {
            let p = self.parent[v as usize].load(Relaxed);
            if p == v {
                return v;
            }
            let g = self.parent[p as usize].load(Relaxed);
            if g != p {
                self.parent[v as usize].store(g, Relaxed);
            }
            v = g;
        }
    }

    fn union(&self, a: u32, b: u32) {
        let (mut a, mut b) = (a, b);
        loop {
            (a, b) = (self.find(a), self.find(b));
            if a == b {
                return;
            }
            let (lo, hi) = (a.min(b), a.max(b));
            // Linked only if `hi` is still a root; else another thread linked it first and the
            // roots are found again.
            if self.parent[hi as usize]
                .compare_exchange(hi, lo, Relaxed, Relaxed)
                .is_ok()
            {
                return;
            }
        }
    }

    /// Joins the corners of each face that share a cell.
    pub fn join_faces(&self, cells: &Cells, faces: &[[u32; 3]]) {
        self.join_faces_where(cells, faces, |_, _| true)
    }

    /// [`CellUnion::join_faces`] over the edges `join` allows.
    pub fn join_faces_where(
        &self,
        cells: &Cells,
        faces: &[[u32; 3]],
        join: impl Fn(u32, u32) -> bool + Sync,
    ) {
        let cell = &cells.vertex_cell;
        faces.par_iter().with_min_len(4096).for_each(|t| {
            for i in 0..3 {
                let (a, b) = (t[i], t[(i + 1) % 3]);
                if cell[a as usize] == cell[b as usize] && join(a, b) {
                    self.union(a, b);
                }
            }
        });
    }

    /// Joins coincident members of each cell, then each vertex's label (its component's
    /// lowest id).
    pub fn labels(self, cells: &Cells, positions: &[[f32; 4]]) -> Vec<u32> {
        // Coincident members of a cell joined: in a cell of up to SMALL_CELL members each pair,
        // the positions read once; in a larger one, the members sorted by position and equal
        // neighbours joined. Both join the same vertices into one component, and a label is its
        // component's lowest id, so the labels are the same. Sorting every cell read each
        // position at every comparison: on the 1M scan at 10% (`hybrid`, two cores, median of
        // 21 builds) this pass took 0.0083 s sorted, 0.0029 s by pairs.
        let bits = |v: u32| {
            let p = positions[v as usize];
            [p[0], p[1], p[2]].map(|x| if x == 0.0 { 0 } else { x.to_bits() })
        };
        (0..cells.key.len())
            .into_par_iter()
            .with_min_len(256)
            .for_each_init(Vec::new, |run: &mut Vec<u32>, c| {
                let members = &cells.members[cells.start[c] as usize..cells.start[c + 1] as usize];
                if members.len() < 2 {
                    return;
                }
                if members.len() <= SMALL_CELL {
                    let mut b = [[0u32; 3]; SMALL_CELL];
                    for (b, &v) in b.iter_mut().zip(members) {
                        *b = bits(v);
                    }
                    for i in 1..members.len() {
                        for j in 0..i {
                            if b[i] == b[j] {
                                self.union(members[j], members[i]);
                            }
                        }
                    }
                    return;
                }
                run.clear();
                run.extend_from_slice(members);
                run.sort_unstable_by_key(|&v| (bits(v), v));
                for w in run.windows(2) {
                    if bits(w[0]) == bits(w[1]) {
                        self.union(w[0], w[1]);
                    }
                }
            });
        (0..self.parent.len() as u32)
            .into_par_iter()
            .with_min_len(4096)
            .map(|v| self.find(v))
            .collect()
    }
}

/// Members up to which [`CellUnion::labels`] compares each pair of a cell's members (120
/// comparisons at most); most cells hold a handful.
const SMALL_CELL: usize = 16;

#[cfg(test)]
mod tests {
    use super::super::grid::CellGrid;
    use super::super::stages::{cell_keys, cell_ranges, radix_sort};
    use super::*;

    /// The labels match a plain sequential search of each cell's graph (in-cell face edges and
    /// coincident members), in cells that compare their members pair by pair and in cells too
    /// large for that, which sort them.
    #[test]
    fn labels_join_coincident_members_in_small_and_large_cells() {
        // A 12×12 grid of squares, each with four vertices of its own: squares touch only
        // through coincident corners, so every join between them is a coincidence.
        let n = 12;
        let mut positions: Vec<[f32; 4]> = Vec::new();
        let mut faces: Vec<[u32; 3]> = Vec::new();
        for y in 0..n {
            for x in 0..n {
                let b = positions.len() as u32;
                for (dx, dy) in [(0, 0), (1, 0), (1, 1), (0, 1)] {
                    positions.push([(x + dx) as f32, (y + dy) as f32, 0.0, 1.0]);
                }
                faces.extend([[b, b + 1, b + 2], [b, b + 2, b + 3]]);
            }
        }
        let nv = positions.len();
        let hi = [n as f32, n as f32, 0.0];
        for (h, large) in [(1.5f32, false), (7.0, true)] {
            let grid = CellGrid::new([0.0; 3], hi, h);
            let (sorted, members) = radix_sort(cell_keys(&grid, &positions, &vec![false; nv]));
            let cells = cell_ranges(&sorted, members);
            let largest = (0..cells.key.len())
                .map(|c| cells.start[c + 1] - cells.start[c])
                .max()
                .unwrap_or(0) as usize;
            assert_eq!(
                largest > SMALL_CELL,
                large,
                "cell size {h}: largest cell {largest}"
            );
            let labels = cell_labels(&cells, &faces, &positions);

            let mut parent: Vec<usize> = (0..nv).collect();
            fn root(p: &mut [usize], mut x: usize) -> usize {
                while p[x] != x {
                    x = p[x];
                }
                x
            }
            let mut join = |a: usize, b: usize| {
                let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
                parent[ra.max(rb)] = ra.min(rb);
            };
            let cell = &cells.vertex_cell;
            for t in &faces {
                for i in 0..3 {
                    let (a, b) = (t[i] as usize, t[(i + 1) % 3] as usize);
                    if cell[a] == cell[b] {
                        join(a, b);
                    }
                }
            }
            for a in 0..nv {
                for b in 0..a {
                    if cell[a] == cell[b] && positions[a] == positions[b] {
                        join(a, b);
                    }
                }
            }
            let expected: Vec<u32> = (0..nv).map(|v| root(&mut parent, v) as u32).collect();
            assert_eq!(labels, expected, "cell size {h}");
            let joined = (0..nv).filter(|&v| labels[v] as usize != v).count();
            assert!(
                joined > nv / 2,
                "cell size {h}: only {joined} vertices joined"
            );
        }
    }
}
