//! The clustering stages, each a map, a sort or a gather over one kind of element, named as the
//! WGSL stages they stand for (`cell_keys`, `radix_sort`, `cell_ranges`, `cell_labels`,
//! `cluster_quadrics`, `cluster_faces`): every float is gathered in a fixed order (a cluster
//! walks its members in (key, id) order, a member its faces in id order), so the result does
//! not depend on the thread count, and integer outputs depend on positions and keys alone.

use super::grid::CellGrid;
pub use super::grid::SINGLETON;
use crate::compute::common::{
    V3, add, cross, dot, length, quadric_add, quadric_eval, quadric_from_plane, quadric_shift,
    scale, sub, xyz,
};
use crate::compute::types::Quadric;
use crate::prefetch::{AHEAD, prefetch};
use rayon::prelude::*;

/// The vertex→face lists (CSR): `faces_of(v) = vertex_faces[offsets[v]..offsets[v + 1]]`, each
/// list in increasing face order, the order the GPU's `adjacency_sort` leaves.
pub struct Csr {
    pub offsets: Vec<u32>,
    pub vertex_faces: Vec<u32>,
}

impl Csr {
    /// Counting, a prefix sum, then a fill in face order (which leaves every list sorted).
    pub fn new(vertices: usize, faces: &[[u32; 3]]) -> Csr {
        let mut offsets = vec![0u32; vertices + 1];
        for t in faces {
            for &v in t {
                offsets[v as usize + 1] += 1;
            }
        }
        for v in 0..vertices {
            offsets[v + 1] += offsets[v];
        }
        let mut cursor = offsets[..vertices].to_vec();
        let mut vertex_faces = vec![0u32; offsets[vertices] as usize];
        for (f, t) in faces.iter().enumerate() {
            for &v in t {
                let c = &mut cursor[v as usize];
                vertex_faces[*c as usize] = f as u32;
                *c += 1;
            }
        }
        Csr {
            offsets,
            vertex_faces,
        }
    }

    #[inline]
    pub fn faces_of(&self, v: u32) -> &[u32] {
        &self.vertex_faces[self.offsets[v as usize] as usize..self.offsets[v as usize + 1] as usize]
    }
}

/// `face_planes`: per face its unit normal and area (zero for a degenerate face).
pub fn face_planes(positions: &[[f32; 4]], faces: &[[u32; 3]]) -> Vec<[f32; 4]> {
    faces
        .par_iter()
        .with_min_len(4096)
        .map(|t| face_plane(positions, t))
        .collect()
}

/// One face's entry of [`face_planes`].
pub fn face_plane(positions: &[[f32; 4]], t: &[u32; 3]) -> [f32; 4] {
    let p = t.map(|v| xyz(positions[v as usize]));
    let c = cross(sub(p[1], p[0]), sub(p[2], p[0]));
    let l = length(c);
    if l > 0.0 {
        let n = scale(c, 1.0 / l);
        [n[0], n[1], n[2], 0.5 * l]
    } else {
        [0.0; 4]
    }
}

/// `cell_keys`: per vertex, the Morton key of its cell, or [`SINGLETON`] for a locked vertex.
pub fn cell_keys(grid: &CellGrid, positions: &[[f32; 4]], locked: &[bool]) -> Vec<u32> {
    positions
        .par_iter()
        .zip(locked)
        .with_min_len(4096)
        .map(|(p, &l)| if l { SINGLETON } else { grid.key(xyz(*p)) })
        .collect()
}

/// `radix_sort`, the twin of the GPU's radix passes (its documentation says how): in
/// [`crate::mesh::sort`], where the Morton order of every simplifier's set-up sorts with it too.
pub use crate::mesh::sort::radix_sort;

/// The cells of the sorted keys: where each starts in the sorted order (one more entry, the
/// end), and each vertex's cell. `cell_heads`, its prefix sum, and `cell_ranges` on the GPU.
pub struct Cells {
    pub start: Vec<u32>,
    /// Vertex ids in (key, id) order.
    pub members: Vec<u32>,
    pub vertex_cell: Vec<u32>,
    /// Per cell: its key.
    pub key: Vec<u32>,
}

pub fn cell_ranges(sorted_keys: &[u32], members: Vec<u32>) -> Cells {
    use std::sync::atomic::{AtomicU32, Ordering::Relaxed};
    let (n, k) = (sorted_keys.len(), sorted_keys);
    // The cells found and their members marked on every core (an ordered collect keeps the
    // starts rising): on one core this took 0.0030 s of `hybrid` on the 1M scan at 10%, on
    // two 0.0022 s (medians of 21 calls).
    let mut start: Vec<u32> = (0..n as u32)
        .into_par_iter()
        .with_min_len(RANGES_MIN_LEN)
        .filter(|&i| {
            let i = i as usize;
            // A singleton key is one cell per vertex.
            i == 0 || k[i] != k[i - 1] || k[i] == SINGLETON
        })
        .collect();
    let key: Vec<u32> = start.par_iter().map(|&i| k[i as usize]).collect();
    start.push(n as u32);
    // Each cell writes its members' entries: `members` is a permutation (the sort's ids), so
    // every entry is written once, by one cell.
    let cell: Vec<AtomicU32> = (0..n).into_par_iter().map(|_| AtomicU32::new(0)).collect();
    (0..key.len())
        .into_par_iter()
        .with_min_len(RANGES_MIN_LEN / 4)
        .for_each(|c| {
            for &m in &members[start[c] as usize..start[c + 1] as usize] {
                cell[m as usize].store(c as u32, Relaxed);
            }
        });
    Cells {
        start,
        members,
        vertex_cell: into_u32s(cell),
        key,
    }
}

/// Vertices per task in [`cell_ranges`].
const RANGES_MIN_LEN: usize = 1 << 14;

/// `v`'s values, in its block: no second pass and no fresh pages.
fn into_u32s(v: Vec<std::sync::atomic::AtomicU32>) -> Vec<u32> {
    let mut v = std::mem::ManuallyDrop::new(v);
    let (ptr, len, cap) = (v.as_mut_ptr(), v.len(), v.capacity());
    // SAFETY: `AtomicU32` has the size, alignment and bit validity of `u32` (std documents
    // it), so the block `v` owned (never freed: `ManuallyDrop`) holds `len` valid `u32`s in an
    // allocation of `cap` of them with the same layout, which the new `Vec` now owns alone;
    // nothing else can reach the atomics, as `v` was taken by value.
    unsafe { Vec::from_raw_parts(ptr.cast::<u32>(), len, cap) }
}

/// How many clusters ahead the placements ask for a cluster's members' positions, which lie
/// anywhere in the points. `cluster` on the 1M scan at 10%: 0.0083 -> 0.0075 s for the
/// placements (three rounds of 15 calls each way, turn about).
const PLACE_AHEAD: usize = 2;

/// Asks the cache, while cluster `k` is placed, for what placing later clusters reads first:
/// the members' positions [`PLACE_AHEAD`] clusters ahead and, for the gather (`csr`), their
/// face lists. The lists lie anywhere too: each list's bounds are asked for twice as far
/// ahead, so that its start can be asked for with the positions. The 1M scan at 10%
/// (`hybrid`): the placements 0.063-0.068 -> 0.057-0.061 s (three rounds of 12 calls each
/// way, turn about); asking for the lists' faces a third step ahead, or other distances, was
/// slower.
#[inline]
pub fn ask_ahead(
    clusters: &Clusters,
    cells: &Cells,
    positions: &[[f32; 4]],
    csr: Option<&Csr>,
    k: usize,
) {
    let cell_members = |k: usize| {
        clusters.cell.get(k).map_or(&[][..], |&c| {
            let (a, b) = (cells.start[c as usize], cells.start[c as usize + 1]);
            &cells.members[a as usize..b as usize]
        })
    };
    if let Some(csr) = csr {
        for &m in cell_members(k + 2 * PLACE_AHEAD) {
            prefetch(&csr.offsets, m as usize);
        }
    }
    for &m in cell_members(k + PLACE_AHEAD) {
        prefetch(positions, m as usize);
        if let Some(csr) = csr {
            prefetch(&csr.vertex_faces, csr.offsets[m as usize] as usize);
        }
    }
}

/// The clusters: a cell whole, or (split by connectivity) one in-cell component of it.
pub struct Clusters {
    /// Per cluster: its cell.
    pub cell: Vec<u32>,
    /// Per cluster: the lowest vertex id of its component, or `u32::MAX` for the whole cell.
    pub root: Vec<u32>,
    pub vertex_cluster: Vec<u32>,
}

impl Clusters {
    /// One cluster per cell: the cells' per-vertex list moves here (`cells.vertex_cell` is left
    /// empty), where a copy wrote 2 MB of fresh pages on a 1M-face mesh.
    pub fn whole_cells(cells: &mut Cells) -> Clusters {
        Clusters {
            cell: (0..cells.key.len() as u32).collect(),
            root: vec![u32::MAX; cells.key.len()],
            vertex_cluster: std::mem::take(&mut cells.vertex_cell),
        }
    }

    /// One cluster per in-cell component (`cluster_heads`, a prefix sum, `cluster_ids`): the
    /// clusters of a cell in the order of their roots, cells in key order.
    pub fn split(cells: &Cells, label: &[u32]) -> Clusters {
        let (mut cell, mut root) = (Vec::new(), Vec::new());
        let mut id_of_root = vec![u32::MAX; label.len()];
        for c in 0..cells.key.len() {
            for &m in &cells.members[cells.start[c] as usize..cells.start[c + 1] as usize] {
                if label[m as usize] == m {
                    id_of_root[m as usize] = cell.len() as u32;
                    cell.push(c as u32);
                    root.push(m);
                }
            }
        }
        let vertex_cluster = label.par_iter().map(|&l| id_of_root[l as usize]).collect();
        Clusters {
            cell,
            root,
            vertex_cluster,
        }
    }

    pub fn len(&self) -> usize {
        self.cell.len()
    }

    pub fn is_empty(&self) -> bool {
        self.cell.is_empty()
    }

    /// The members of cluster `k`, in (key, id) order.
    pub fn members<'a>(
        &'a self,
        cells: &'a Cells,
        label: Option<&'a [u32]>,
        k: usize,
    ) -> impl Iterator<Item = u32> + 'a {
        let c = self.cell[k] as usize;
        let root = self.root[k];
        cells.members[cells.start[c] as usize..cells.start[c + 1] as usize]
            .iter()
            .copied()
            .filter(move |&m| root == u32::MAX || label.is_some_and(|l| l[m as usize] == root))
    }
}

/// Which candidate placed a cluster's vertex (counted for the report).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Placement {
    /// One member: it stays where it is, bit for bit.
    Single,
    /// The regularised quadric minimum, clamped into the cell.
    Solve,
    /// The member of least error (meshoptimizer's sloppy rule).
    Member,
    /// The members' centroid.
    Centroid,
}

/// One cluster's vertex.
#[derive(Clone, Copy)]
pub struct Placed {
    pub pos: V3,
    /// The quadric of the cluster, relative to `pos`.
    pub quadric: Quadric,
    /// The member whose attributes the vertex takes: the nearest to `pos`.
    pub attr: u32,
    pub how: Placement,
}

/// What `cluster_quadrics` reads.
pub struct ClusterSurface<'a> {
    pub positions: &'a [[f32; 4]],
    pub faces: &'a [[u32; 3]],
    pub planes: &'a [[f32; 4]],
    pub csr: &'a Csr,
    /// Weight of the border constraint planes (Hoppe's), 0 for none.
    pub border_weight: f32,
}

/// Regularisation of the cluster solve, relative to A's mean eigenvalue: pulls the minimum
/// toward the centroid along the directions the quadric leaves free (a flat cell's plane), the
/// job Lindstrom's truncated pseudo-inverse does (Out-of-Core Simplification, 2000).
const REGULARISE: f32 = 1e-3;

/// `cluster_quadrics`, the gather: the cluster's quadric from its members' faces (each face
/// once per member corner, area-weighted, as the sum of the members' vertex quadrics would be)
/// and the border planes at its members, relative to the cell centre `o`; then [`place`].
pub fn cluster_quadric(s: &ClusterSurface, members: &[u32], o: V3, lo: V3, hi: V3) -> Placed {
    if members.len() == 1 {
        let p = xyz(s.positions[members[0] as usize]);
        return place(s.positions, gather(s, members, p), members, p, p, p);
    }
    place(s.positions, gather(s, members, o), members, o, lo, hi)
}

/// The cluster's vertex, at the least error of three candidates: the regularised minimum
/// clamped into the box `[lo, hi]`, the member of least error, the centroid (ties to the
/// earlier); `q` is relative to `o`. A single member stays where it is.
pub fn place(positions: &[[f32; 4]], q: Quadric, members: &[u32], o: V3, lo: V3, hi: V3) -> Placed {
    let p = |v: u32| xyz(positions[v as usize]);
    if members.len() == 1 {
        let m = members[0];
        return Placed {
            pos: p(m),
            quadric: quadric_shift(&q, sub(p(m), o)),
            attr: m,
            how: Placement::Single,
        };
    }
    let mut centroid = [0.0f32; 3];
    for &m in members {
        centroid = add(centroid, sub(p(m), o));
    }
    let centroid = scale(centroid, 1.0 / members.len() as f32);
    let mut best = (quadric_eval(&q, centroid), centroid, Placement::Centroid);
    let mut member = (f32::INFINITY, centroid);
    for &m in members {
        let y = sub(p(m), o);
        let e = quadric_eval(&q, y);
        if e < member.0 {
            member = (e, y);
        }
    }
    if member.0 < best.0 {
        best = (member.0, member.1, Placement::Member);
    }
    if let Some(y) = regularised_minimum(&q, centroid) {
        let y = [0, 1, 2].map(|i| y[i].clamp(lo[i] - o[i], hi[i] - o[i]));
        let e = quadric_eval(&q, y);
        if e <= best.0 {
            best = (e, y, Placement::Solve);
        }
    }
    let y = best.1;
    let mut attr = (f32::INFINITY, members[0]);
    for &m in members {
        let d = sub(sub(p(m), o), y);
        let d = dot(d, d);
        if d < attr.0 {
            attr = (d, m);
        }
    }
    Placed {
        pos: add(o, y),
        quadric: quadric_shift(&q, y),
        attr: attr.1,
        how: best.2,
    }
}

/// Faces that survive clustering: (face id, its clusters rotated lowest first), in face order.
pub type Marked = Vec<(u32, [u32; 3])>;

/// Chunks of faces [`scatter_quadrics`] sums apart, a fixed number so the sums do not depend
/// on the thread count.
const SCATTER_CHUNKS: usize = 4;

/// `cluster_quadrics` without vertex→face lists (`cluster`, which has no other use for them):
/// each face's area-weighted plane added to the clusters of its corners (once per corner),
/// relative to each cluster's `origin`. Faces are summed in [`SCATTER_CHUNKS`] fixed chunks,
/// each in face order, and the chunks added in order: deterministic for any thread count. It
/// saves building the lists (0.02 s of 0.13 s on the 1M scan); the GPU gathers instead, the
/// same sums in another order, equal to f32 rounding. The same pass marks the faces that
/// survive (`cluster_faces_mark`, in face order): reading every face's clusters twice cost
/// 0.02 s more on the 1M scan, whose faces are not in spatial order.
pub fn scatter_quadrics(
    positions: &[[f32; 4]],
    faces: &[[u32; 3]],
    vertex_cluster: &[u32],
    origins: &[V3],
) -> (Vec<Quadric>, Marked) {
    let n = origins.len();
    let chunk = faces.len().div_ceil(SCATTER_CHUNKS).max(1);
    let parts: Vec<(Vec<Quadric>, Marked)> = faces
        .par_chunks(chunk)
        .enumerate()
        .map(|(ci, part)| {
            let mut acc = vec![Quadric::default(); n];
            let mut kept = Vec::new();
            for (i, t) in part.iter().enumerate() {
                // The faces come in no spatial order: ask for a later face's vertices, and
                // for a nearer one's clusters' sums, while this one is added. The 1M scan at
                // 10%: 0.0163 -> 0.0129 s for this pass, best of 15 (same sums).
                if let Some(ahead) = part.get(i + AHEAD) {
                    for &v in ahead {
                        prefetch(positions, v as usize);
                        prefetch(vertex_cluster, v as usize);
                    }
                }
                if let Some(near) = part.get(i + AHEAD / 2) {
                    for &v in near {
                        prefetch(&acc, vertex_cluster[v as usize] as usize);
                    }
                }
                let k = t.map(|v| vertex_cluster[v as usize]);
                if let Some(r) = rotated(k) {
                    kept.push(((ci * chunk + i) as u32, r));
                }
                let p = t.map(|v| xyz(positions[v as usize]));
                let c = cross(sub(p[1], p[0]), sub(p[2], p[0]));
                let l = length(c);
                if l <= 0.0 {
                    continue;
                }
                let n = scale(c, 1.0 / l);
                let area = 0.5 * l;
                let mut add = |k: u32, times: f32| {
                    let d = dot(n, sub(origins[k as usize], p[0]));
                    let q = &mut acc[k as usize];
                    *q = quadric_add(q, &quadric_from_plane(n, d, times * area));
                };
                if k[0] == k[1] && k[1] == k[2] {
                    // Inside one cluster: the plane three times.
                    add(k[0], 3.0);
                } else {
                    for &ki in &k {
                        add(ki, 1.0);
                    }
                }
            }
            (acc, kept)
        })
        .collect();
    let mut kept = Vec::with_capacity(parts.iter().map(|p| p.1.len()).sum());
    let mut sum: Option<Vec<Quadric>> = None;
    for (part, marks) in parts {
        kept.extend(marks);
        match &mut sum {
            None => sum = Some(part),
            Some(sum) => sum
                .par_iter_mut()
                .zip(part)
                .with_min_len(4096)
                .for_each(|(s, p)| *s = quadric_add(s, &p)),
        }
    }
    (sum.unwrap_or_else(|| vec![Quadric::default(); n]), kept)
}

/// Σ over members and their faces of the face planes (and border planes), relative to `o`.
fn gather(s: &ClusterSurface, members: &[u32], o: V3) -> Quadric {
    let mut q = Quadric::default();
    // The members' faces are scattered through the mesh: every face's plane and corners asked
    // of the cache first, then the first corners' positions, then the sums, so the loads
    // overlap instead of each waiting on the last (on the 1M scan at 10%, `hybrid`, 12% off the
    // placements' time, median of 20 builds).
    for &m in members {
        for &f in s.csr.faces_of(m) {
            crate::prefetch::prefetch(s.planes, f as usize);
            crate::prefetch::prefetch(s.faces, f as usize);
        }
    }
    for &m in members {
        for &f in s.csr.faces_of(m) {
            crate::prefetch::prefetch(s.positions, s.faces[f as usize][0] as usize);
        }
    }
    for &m in members {
        let list = s.csr.faces_of(m);
        let pm = xyz(s.positions[m as usize]);
        // Only a vertex on a border edge is searched for border edges. Tested here, with its
        // faces at hand: a pass over every vertex's faces before the builds took 0.014-0.016 s
        // of `hybrid` on the 1M scan at 10%, this 0.008-0.009 s more of the gather's.
        let border = s.border_weight > 0.0 && on_border(s.faces, list, m);
        for &f in list {
            let pl = s.planes[f as usize];
            if pl[3] <= 0.0 {
                continue;
            }
            let n = xyz(pl);
            let t = s.faces[f as usize];
            let d = dot(n, sub(o, xyz(s.positions[t[0] as usize])));
            q = quadric_add(&q, &quadric_from_plane(n, d, pl[3]));
            if border {
                for u in t {
                    if u == m || on_two_faces(s, list, u) {
                        continue;
                    }
                    // A border edge (m, u): Hoppe's plane through it, perpendicular to the face.
                    let e = sub(xyz(s.positions[u as usize]), pm);
                    let c = cross(e, n);
                    let l = length(c);
                    if l > 0.0 {
                        let nb = scale(c, 1.0 / l);
                        let d = dot(nb, sub(o, pm));
                        q = quadric_add(
                            &q,
                            &quadric_from_plane(nb, d, s.border_weight * dot(e, e)),
                        );
                    }
                }
            }
        }
    }
    q
}

/// Whether `v`, whose faces are `list`, is on an edge of one face: a neighbour that only one
/// of them holds (a face counts once for each vertex it holds, however often it holds it).
/// Up to [`SMALL_FAN`] neighbour entries, each is counted against a fixed-width row, which the
/// compiler vectorizes (padded with no vertex: ids < vertex count); more are sorted. Over the
/// 1M scan, counting each neighbour's faces through the list took 0.018-0.029 s, sorting the
/// entries 0.009-0.018 s; the row took the small sorts from 6.5% to 5.0% of `hybrid`'s samples.
pub fn on_border(faces: &[[u32; 3]], list: &[u32], v: u32) -> bool {
    let mut row = [u32::MAX; SMALL_FAN];
    let (mut n, mut more) = (0, Vec::new());
    for &f in list {
        let t = faces[f as usize];
        for (i, &u) in t.iter().enumerate() {
            if u != v && !t[..i].contains(&u) {
                match row.get_mut(n) {
                    Some(r) => *r = u,
                    None => more.push(u),
                }
                n += 1;
            }
        }
    }
    if more.is_empty() {
        return row[..n]
            .iter()
            .any(|&u| row.iter().filter(|&&w| w == u).count() == 1);
    }
    more.extend_from_slice(&row);
    more.sort_unstable();
    more.chunk_by(|a, b| a == b).any(|run| run.len() == 1)
}

/// Neighbour entries (two per face) up to which [`on_border`] counts without sorting: eight
/// faces around a vertex.
const SMALL_FAN: usize = 16;

/// Whether two or more faces of `list` contain `u`.
fn on_two_faces(s: &ClusterSurface, list: &[u32], u: u32) -> bool {
    list.iter()
        .filter(|&&g| s.faces[g as usize].contains(&u))
        .nth(1)
        .is_some()
}

/// `(A + εI) y = ε c − b` for the quadric's `A` and `b`: the minimum pulled toward `c` by
/// ε = [`REGULARISE`] × trace(A)/3. `None` for a quadric without planes.
fn regularised_minimum(q: &Quadric, c: V3) -> Option<V3> {
    let [a00, a01, a02, a11] = q.q[0];
    let [a12, a22, b0, b1] = q.q[1];
    let b2 = q.q[2][0];
    let tr = a00 + a11 + a22;
    if tr <= 0.0 || !tr.is_finite() {
        return None;
    }
    let eps = REGULARISE * tr / 3.0;
    let (a00, a11, a22) = (a00 + eps, a11 + eps, a22 + eps);
    let r = [eps * c[0] - b0, eps * c[1] - b1, eps * c[2] - b2];
    let c00 = a11 * a22 - a12 * a12;
    let c01 = a02 * a12 - a01 * a22;
    let c02 = a01 * a12 - a02 * a11;
    let det = a00 * c00 + a01 * c01 + a02 * c02;
    if det <= 0.0 || !det.is_finite() {
        return None;
    }
    let c11 = a00 * a22 - a02 * a02;
    let c12 = a01 * a02 - a00 * a12;
    let c22 = a00 * a11 - a01 * a01;
    let inv = 1.0 / det;
    let y = [
        (c00 * r[0] + c01 * r[1] + c02 * r[2]) * inv,
        (c01 * r[0] + c11 * r[1] + c12 * r[2]) * inv,
        (c02 * r[0] + c12 * r[1] + c22 * r[2]) * inv,
    ];
    y.iter().all(|x| x.is_finite()).then_some(y)
}

/// `cluster_faces`: the faces whose three corners lie in three different clusters, over
/// clusters, rotated so the lowest cluster comes first (winding kept), with exact repeats
/// dropped (the lowest face id of each kept). With `drop_pairs`, a face and its opposite
/// winding, a thin part collapsed flat, are both dropped. Returns (face id, clusters) in face
/// order.
pub fn cluster_faces(
    faces: &[[u32; 3]],
    vertex_cluster: &[u32],
    clusters: usize,
    drop_pairs: bool,
) -> Vec<(u32, [u32; 3])> {
    let kept: Vec<(u32, [u32; 3])> = faces
        .par_iter()
        .enumerate()
        .with_min_len(4096)
        .filter_map(|(f, t)| Some((f as u32, rotated(t.map(|v| vertex_cluster[v as usize]))?)))
        .collect();
    dedupe_faces(kept, clusters, drop_pairs)
}

/// A face over clusters `[a, b, c]` if the three differ, rotated so the lowest comes first.
#[inline]
pub fn rotated([a, b, c]: [u32; 3]) -> Option<[u32; 3]> {
    if a == b || b == c || a == c {
        None
    } else if a < b && a < c {
        Some([a, b, c])
    } else if b < c {
        Some([b, c, a])
    } else {
        Some([c, a, b])
    }
}

/// The second half of [`cluster_faces`]: `kept` (face id, rotated clusters), in face order,
/// less exact repeats (and with `drop_pairs` opposite windings).
pub fn dedupe_faces(
    kept: Vec<(u32, [u32; 3])>,
    clusters: usize,
    drop_pairs: bool,
) -> Vec<(u32, [u32; 3])> {
    // Bucket by the first cluster (stable, so face order within), then sort each small bucket
    // by (b, c, face) as `adjacency_sort` sorts a vertex's faces.
    let (order, start) =
        crate::mesh::prepare::counting_sort(clusters, kept.len(), |i| kept[i].1[0]);
    let mut drop = vec![false; kept.len()];
    let buckets: Vec<(usize, usize)> = (0..clusters)
        .map(|k| (start[k] as usize, start[k + 1] as usize))
        .filter(|(a, b)| b - a > 1)
        .collect();
    // A scratch list a task: one a bucket (100k+) took 0.0082 s, this 0.0065 (hybrid, 1M, 10%).
    let dropped: Vec<u32> = buckets
        .par_iter()
        .with_min_len(256)
        .map_init(Vec::new, |bucket: &mut Vec<u32>, &(a, b)| {
            bucket.clear();
            bucket.extend_from_slice(&order[a..b]);
            bucket.sort_unstable_by_key(|&i| (kept[i as usize].1[1], kept[i as usize].1[2], i));
            let mut out = Vec::new();
            for j in 1..bucket.len() {
                let (p, q) = (kept[bucket[j - 1] as usize].1, kept[bucket[j] as usize].1);
                if p[1] == q[1] && p[2] == q[2] {
                    out.push(bucket[j]);
                }
            }
            if drop_pairs {
                // (a, b, c) against (a, c, b): look each up in the sorted bucket.
                for &i in bucket.iter() {
                    let t = kept[i as usize].1;
                    let probe = (t[2], t[1]);
                    if bucket
                        .binary_search_by_key(&probe, |&j| {
                            (kept[j as usize].1[1], kept[j as usize].1[2])
                        })
                        .is_ok()
                    {
                        out.push(i);
                    }
                }
            }
            out
        })
        .flatten_iter()
        .collect();
    dropped.iter().for_each(|&i| drop[i as usize] = true);
    kept.into_iter()
        .zip(drop)
        .filter_map(|(k, d)| (!d).then_some(k))
        .collect()
}
