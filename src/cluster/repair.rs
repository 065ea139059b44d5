//! The hybrid's repairs: clusters that pinch a non-manifold edge or fold a face over, found
//! and taken apart until none is left, each repair worked out from the build before rather
//! than built again (its cost on the 1M scan: docs/PERFORMANCE.md, "Speed against meshoptimizer").

use super::grid::CellGrid;
use super::stages::face_plane;
use super::{Built, ClusterReport, Work, cluster_to};
use crate::compute::common::xyz;
use crate::error::Result;
use rayon::prelude::*;

/// `hybrid` takes clusters on non-manifold edges apart at most this many times.
const MAX_REPAIRS: usize = 4;

/// The clusters at either end of an edge that more than two faces share, or that two faces
/// run the same way (a fold), sorted. The half-edges are bucketed by their lower cluster (a
/// counting sort) and each small bucket sorted alone: sorting all of them by (edge, direction)
/// took 0.02-0.04 s a check on the 1M scan at 10% (three checks), this 0.013-0.016 s, the
/// same clusters on every scan and shared model at 10% and 1%.
fn pinched_clusters(b: &Built) -> Vec<u32> {
    let half = |i: usize| {
        let t = b.faces[i / 3].1;
        let (a, c) = (t[i % 3], t[(i + 1) % 3]);
        (a.min(c), a.max(c), a < c)
    };
    let (order, start) =
        crate::mesh::prepare::counting_sort(b.clusters, b.faces.len() * 3, |i| half(i).0);
    let mut bad: Vec<u32> = (0..b.clusters)
        .into_par_iter()
        .with_min_len(1024)
        .fold(
            || (Vec::new(), Vec::new()),
            |(mut ends, mut out): (Vec<(u32, bool)>, Vec<u32>), k| {
                let bucket = &order[start[k] as usize..start[k + 1] as usize];
                if bucket.len() < 2 {
                    return (ends, out);
                }
                ends.clear();
                ends.extend(bucket.iter().map(|&i| {
                    let (_, c, forward) = half(i as usize);
                    (c, forward)
                }));
                ends.sort_unstable();
                pinched_ends(&ends, &mut |c| out.extend([k as u32, c]));
                (ends, out)
            },
        )
        .map(|(_, out)| out)
        .reduce(Vec::new, |mut a, b| {
            a.extend(b);
            a
        });
    bad.par_sort_unstable();
    bad.dedup();
    bad
}

/// Of the half-edges from one cluster (`(other end, runs forward)`, sorted), the other end of
/// each edge that more than two faces share or that two faces run the same way.
fn pinched_ends(ends: &[(u32, bool)], pinched: &mut dyn FnMut(u32)) {
    let mut i = 0;
    while i < ends.len() {
        let mut j = i + 1;
        while j < ends.len() && ends[j].0 == ends[i].0 {
            j += 1;
        }
        if j - i > 2 || (j - i == 2 && ends[i].1 == ends[i + 1].1) {
            pinched(ends[i].0);
        }
        i = j;
    }
}

/// A cluster face turned more than 60° from the input face it came from counts as folded.
const FOLD_COS: f32 = 0.5;

/// Per face of `b`: the unit normal of the input face it came from (its origin). The second
/// phase (the greedy queue or the rounds) measures turning from these, not from the clusters'
/// faces. A streamed input's faces are read in blocks for them; faces in memory are looked up:
/// walking all the input's faces for the few that survive took 0.006-0.007 s a build on the 1M
/// scan at 1% (five builds with the repairs), the lookup 0.003-0.005 s. Faces in memory have
/// their planes already (the gather's), whose normals are these.
fn origin_normals(work: &Work, b: &Built) -> Result<Vec<[f32; 3]>> {
    if work.gather.is_some() {
        return Ok(b
            .faces
            .par_iter()
            .with_min_len(4096)
            .map(|&(origin, _)| input_normal(work, origin))
            .collect());
    }
    let mut at: Vec<u32> = Vec::new();
    for (k, &(origin, _)) in b.faces.iter().enumerate() {
        let o = origin as usize;
        if o >= at.len() {
            at.resize(o + 1, u32::MAX);
        }
        at[o] = k as u32;
    }
    let mut normals = vec![[0.0f32; 3]; b.faces.len()];
    work.pts.blocks(&mut |first, faces| {
        for (i, t) in faces.iter().enumerate() {
            if let Some(&k) = at.get(first + i).filter(|&&k| k != u32::MAX) {
                normals[k as usize] = xyz(face_plane(&work.pts.positions, t));
            }
        }
        Ok(())
    })?;
    Ok(normals)
}

/// The unit normal of input face `origin` (zero for a degenerate face), from the gather's
/// planes: one entry of [`origin_normals`] for faces in memory.
fn input_normal(work: &Work, origin: u32) -> [f32; 3] {
    let g = work
        .gather
        .as_ref()
        .expect("faces in memory have the gather's planes");
    xyz(g.planes[origin as usize])
}

/// The clusters of each face turned more than 60° from the input face it came from (`normals`,
/// [`origin_normals`]), sorted: a cell can fold a sheet over, and two clusters a colour step
/// split in one cell can stand a face on edge; the second phase may turn a face up to
/// `max_normal_angle_deg` further, so a face left nearly on edge here could end up flipped.
fn folded_clusters(b: &Built, normals: &[[f32; 3]]) -> Vec<u32> {
    let mut bad: Vec<u32> = b
        .faces
        .par_iter()
        .zip(normals)
        .filter_map(|(&(_, t), &o)| folds(b, t, o).then_some(t))
        .flatten_iter()
        .collect();
    bad.par_sort_unstable();
    bad.dedup();
    bad
}

/// Whether the face on clusters `t` of `b` is turned more than 60° from `normal`.
fn folds(b: &Built, t: [u32; 3], normal: [f32; 3]) -> bool {
    use crate::compute::common::{cross, dot, length, sub};
    let p = t.map(|k| b.placed[k as usize].pos);
    let n = cross(sub(p[1], p[0]), sub(p[2], p[0]));
    dot(n, normal) < FOLD_COS * length(n)
}

/// [`pinched_clusters`] and [`folded_clusters`] of `b` together, sorted, each once.
fn checked(b: &Built, normals: &[[f32; 3]]) -> Vec<u32> {
    // Side by side, since the first starts with one core's counting sort: 0.016-0.020 s one
    // after the other on the 1M scan at 10%, 0.013-0.019 s.
    let (mut bad, folded) = rayon::join(|| pinched_clusters(b), || folded_clusters(b, normals));
    bad.extend(folded);
    bad.sort_unstable();
    bad.dedup();
    bad
}

/// [`checked`] of `b`, a repair of a build in which every cluster it found was taken apart
/// ([`take_apart`]; `at_fresh`: the indices of its faces at a new singleton). Only what the
/// repair changed is looked at, the same clusters found: a face without a new singleton was in
/// the build before, on clusters that stayed, and so neither folded nor on an edge that
/// pinched; an edge whose faces changed is on a face at a new singleton, so both its ends are
/// among those faces' clusters (an edge between two of them that no such face holds only lost
/// faces, and was not pinched before). The two checks after the repairs took 0.010 s each on
/// the 1M scan at 10%, looking at every face. `normal` gives a face's input normal by its
/// index in `b.faces`; only the faces at new singletons are asked for theirs, so after a
/// repair only the last build's normals are worked out for every face.
fn rechecked(b: &Built, normal: impl Fn(usize) -> [f32; 3], at_fresh: &[u32]) -> Vec<u32> {
    let mut touched = vec![false; b.clusters];
    let mut bad = Vec::new();
    for &i in at_fresh {
        let t = b.faces[i as usize].1;
        for k in t {
            touched[k as usize] = true;
        }
        if folds(b, t, normal(i as usize)) {
            bad.extend(t);
        }
    }
    // Every half-edge between two touched clusters as one word, (lower end, other end, runs
    // forward) from the top bit down, sorted. With those from a touched lower end to any
    // cluster, as tuples, and the faces at new singletons picked out of all, the check after
    // the first repair takes 0.0033-0.0053 s on the 1M scan at 10% (`hybrid`), against 0.0068 s
    // for the check these words replaced.
    assert!(b.clusters <= 1 << 31, "cluster ids fit 31 bits");
    let touched = &touched;
    let mut half: Vec<u64> = b
        .faces
        .par_iter()
        .with_min_len(4096)
        .flat_map_iter(|&(_, t)| {
            (0..3).filter_map(move |i| {
                let (a, c) = (t[i], t[(i + 1) % 3]);
                (touched[a as usize] && touched[c as usize]).then(|| {
                    (u64::from(a.min(c)) << 33) | (u64::from(a.max(c)) << 1) | u64::from(a < c)
                })
            })
        })
        .collect();
    half.par_sort_unstable();
    let mut ends = Vec::new();
    for run in half.chunk_by(|x, y| x >> 33 == y >> 33) {
        ends.clear();
        ends.extend(run.iter().map(|&h| ((h >> 1) as u32, h & 1 == 1)));
        pinched_ends(&ends, &mut |c| bad.extend([(run[0] >> 33) as u32, c]));
    }
    bad.sort_unstable();
    bad.dedup();
    bad
}

/// The hybrid's clustering: to at least `intermediate` faces (the second phase then goes to
/// `target`), clusters that pinch a non-manifold edge or fold a face over taken apart until
/// none is left. Returns the grid, the build and its faces' input normals ([`origin_normals`]:
/// the second phase's reference for turning, worked out for the first build, for each whole
/// build again and for the last build, since a streamed input reads its file for them).
pub(super) fn cluster_repaired(
    work: &mut Work,
    intermediate: usize,
    target: usize,
    report: &mut ClusterReport,
) -> Result<(CellGrid, Built, Vec<[f32; 3]>)> {
    // The probes the preparation counted for this target, beside its vertex→face lists.
    let probes = work
        .probed
        .take()
        .and_then(|(t, p)| (t == intermediate).then_some(p));
    let (grid, mut built, _) = cluster_to(work, intermediate, None, Some(target), probes, report)?;
    // The faces' input normals for the build in `built`; `None` after a repair worked out from
    // the build before, whose check asks only for its new faces' normals.
    let mut normals = Some(origin_normals(work, &built)?);
    // Splitting cells by connectivity keeps separate sheets apart, but a sheet folded inside
    // one cell can still pinch into a non-manifold edge: take the clusters on one apart (their
    // members each their own cluster) and build again, until none is left. After a repair
    // worked out from the build before, only what it changed is checked (`fresh`: the indices
    // of its faces at new singletons).
    let mut fresh: Option<Vec<u32>> = None;
    for _ in 0..MAX_REPAIRS {
        let bad = match (&fresh, &normals) {
            (Some(fresh), _) => {
                // Repairs worked out from the build before need the vertex→face lists, so the
                // gather's planes are there.
                rechecked(&built, |i| input_normal(work, built.faces[i].0), fresh)
            }
            (None, Some(normals)) => checked(&built, normals),
            (None, None) => unreachable!("a whole build's normals are worked out with it"),
        };
        if bad.is_empty() {
            break;
        }
        (built, fresh) = match work.gather {
            Some(_) => {
                let (b, f) = take_apart(work, &grid, built, &bad);
                (b, Some(f))
            }
            // Streamed: no vertex→face lists to place the new singletons by, so a whole build.
            None => {
                for (v, &k) in built.vertex_cluster.iter().enumerate() {
                    if bad.binary_search(&k).is_ok() {
                        work.locked[v] = true;
                    }
                }
                (work.build(&grid)?, None)
            }
        };
        normals = match fresh {
            Some(_) => None,
            None => Some(origin_normals(work, &built)?),
        };
        report.builds += 1;
        report.repaired_clusters += bad.len();
    }
    let normals = match normals {
        Some(normals) => normals,
        None => origin_normals(work, &built)?,
    };
    Ok((grid, built, normals))
}

/// What [`Work::build`] at `grid` gives once the members of the `bad` clusters (sorted ids of
/// `b`, the build at `grid` before) are locked, which this does too: worked out from `b`
/// instead of built again. A cluster is one connected component of its cell, so locking its
/// members takes it out of the cell whole; every other cluster keeps its members, its box,
/// its placement and its place in the order the clusters are numbered in (cells in key order,
/// a cell's clusters by root, the locked vertices last in id order). Only the new singletons
/// are placed, and the faces at them taken again ([`faces_taken_apart`]). Measured on the 1M
/// scan at 10%: a whole build took 0.09 s of each of the two repairs' 0.12 s. Returns the
/// build and the indices of its faces at a new singleton, rising.
fn take_apart(work: &mut Work, grid: &CellGrid, b: Built, bad: &[u32]) -> (Built, Vec<u32>) {
    use super::stages::cluster_quadric;
    // The build's arrays are rewritten where they are: copies into fresh blocks paid for every
    // page they touched (see `placed` below).
    let Built {
        mut placed,
        faces,
        mut vertex_cluster,
        clusters: before,
        cells: cells_before,
    } = b;
    let mut is_bad = vec![false; before];
    for &k in bad {
        is_bad[k as usize] = true;
    }
    // The locked vertices, in id order: the singleton clusters at the end of the numbering, with
    // their placement where they were singletons before. Picked out on every core (an ordered
    // collect keeps the id order).
    let singles: Vec<(u32, Option<super::stages::Placed>)> = work
        .locked
        .par_iter_mut()
        .zip(&vertex_cluster)
        .enumerate()
        .with_min_len(1 << 14)
        .filter_map(|(v, (locked, &k))| {
            if *locked {
                Some((v as u32, Some(placed[k as usize])))
            } else if is_bad[k as usize] {
                *locked = true;
                Some((v as u32, None))
            } else {
                None
            }
        })
        .collect();
    // The singletons before are the last clusters, each its own cell; a cluster stays unless it
    // is one of them or taken apart now (every member of a cluster is locked or none is).
    let was_single = singles.iter().filter(|s| s.1.is_some()).count();
    let first_single = before - was_single;
    assert!(
        singles
            .iter()
            .all(|&(v, old)| old.is_none() || vertex_cluster[v as usize] as usize >= first_single),
        "the singletons are numbered last"
    );
    // The cells that stay: the build's less its singletons and the cells whose every cluster
    // is taken apart. Looking up every cluster's cell to count them took 0.0034-0.0035 s of
    // each repair on the 1M scan at 10% (`hybrid`); this looks up the bad ones' and their
    // neighbours'.
    let positions = &work.pts.positions;
    let cells =
        cells_before - was_single - cells_taken(grid, positions, &placed, bad, first_single);
    // The placements that stay moved down in their order (`par_extend` below makes the
    // singletons' room at once): copied into a new block, a repair's median was 0.0158 s on the
    // 1M scan at 10%, in place 0.0140 s.
    let mut new_id = vec![u32::MAX; before];
    let mut kept = 0;
    for k in (0..first_single).filter(|&k| !is_bad[k]) {
        new_id[k] = kept as u32;
        placed[kept] = placed[k];
        kept += 1;
    }
    placed.truncate(kept);
    let surface = work
        .surface()
        .expect("taking clusters apart places singletons by the vertex→face lists");
    // A singleton's box is its vertex, as `build` gives it.
    placed.par_extend(singles.par_iter().map(|&(v, old)| {
        old.unwrap_or_else(|| {
            let p = xyz(positions[v as usize]);
            cluster_quadric(&surface, &[v], p, p, p)
        })
    }));
    // A singleton from before keeps its placement under its new id (read from the old ids, so
    // before they are rewritten); then every vertex's cluster renumbered, the singletons' last.
    for (i, &(v, old)) in singles.iter().enumerate() {
        if old.is_some() {
            new_id[vertex_cluster[v as usize] as usize] = (kept + i) as u32;
        }
    }
    vertex_cluster
        .par_iter_mut()
        .with_min_len(1 << 14)
        .for_each(|k| *k = new_id[*k as usize]);
    for (i, &(v, _)) in singles.iter().enumerate() {
        vertex_cluster[v as usize] = (kept + i) as u32;
    }
    let clusters = placed.len();
    let (faces, at_fresh) = faces_taken_apart(
        &surface,
        faces,
        &new_id,
        &singles,
        &vertex_cluster,
        clusters,
    );
    let built = Built {
        faces,
        placed,
        vertex_cluster,
        clusters,
        cells: cells + singles.len(),
    };
    (built, at_fresh)
}

/// Of the cells of clusters `0..first_single` of a build (`placed`; a cell's clusters are
/// consecutive ids sharing its key), how many have all their clusters in `bad` (sorted): a run
/// of consecutive bad ids in one cell, with neither neighbour id in that cell.
fn cells_taken(
    grid: &CellGrid,
    positions: &[[f32; 4]],
    placed: &[super::stages::Placed],
    bad: &[u32],
    first_single: usize,
) -> usize {
    let key = |k: usize| grid.key(xyz(positions[placed[k].attr as usize]));
    let bad = &bad[..bad.partition_point(|&k| (k as usize) < first_single)];
    let (mut taken, mut i) = (0, 0);
    while i < bad.len() {
        let first = bad[i] as usize;
        let (cell, mut last) = (key(first), first);
        i += 1;
        while i < bad.len() && bad[i] as usize == last + 1 && key(last + 1) == cell {
            last += 1;
            i += 1;
        }
        let alone_before = first == 0 || key(first - 1) != cell;
        let alone_after = last + 1 == first_single || key(last + 1) != cell;
        if alone_before && alone_after {
            taken += 1;
        }
    }
    taken
}

/// The faces of [`take_apart`]'s build. The new numbering keeps the order of the clusters
/// that stay (`new_id`, `u32::MAX` for those taken apart), so a face of the build before
/// (`faces_before`, whose block this reuses) on them keeps its place and its rotation; every
/// other face has a new singleton (a vertex of `singles` without a placement before) at a
/// corner, and faces that repeat one another have the same clusters, so the faces at the new
/// singletons are deduplicated among themselves and merged in, in face order. Taking every
/// face again was 0.013 s of a repair on the 1M scan; with this and [`origin_normals`]' lookup
/// the hybrid at 1% took 0.334 s against 0.384 s (best of five interleaved in-process runs).
/// Returns the faces and the indices of those at a new singleton, rising.
fn faces_taken_apart(
    s: &super::stages::ClusterSurface,
    faces_before: Vec<(u32, [u32; 3])>,
    new_id: &[u32],
    singles: &[(u32, Option<super::stages::Placed>)],
    vertex_cluster: &[u32],
    clusters: usize,
) -> (Vec<(u32, [u32; 3])>, Vec<u32>) {
    use super::stages::{dedupe_faces, rotated};
    let input = s.faces;
    let mut around: Vec<u32> = singles
        .iter()
        .filter(|single| single.1.is_none())
        .flat_map(|&(v, _)| s.csr.faces_of(v).iter().copied())
        .collect();
    around.sort_unstable();
    around.dedup();
    let fresh = dedupe_faces(
        around
            .iter()
            .filter_map(|&f| {
                let t = input[f as usize].map(|v| vertex_cluster[v as usize]);
                Some((f, rotated(t)?))
            })
            .collect(),
        clusters,
        true,
    );
    // The faces that stay, renumbered where they are, then the fresh ones merged in from the
    // back: the merge reads and writes the one block.
    let mut out = faces_before;
    out.par_iter_mut()
        .with_min_len(4096)
        .for_each(|(_, t)| *t = t.map(|k| new_id[k as usize]));
    out.retain(|(_, t)| !t.contains(&u32::MAX));
    let stay = out.len();
    out.resize(stay + fresh.len(), (0, [0; 3]));
    let (mut i, mut j) = (stay, fresh.len());
    let mut at_fresh = Vec::with_capacity(fresh.len());
    for w in (0..out.len()).rev() {
        // Once the fresh faces are all placed, the rest already stand where they belong.
        if j == 0 {
            break;
        }
        // Face ids are distinct (a face at a new singleton did not stay): larger id last.
        if i > 0 && out[i - 1].0 > fresh[j - 1].0 {
            out[w] = out[i - 1];
            i -= 1;
        } else {
            out[w] = fresh[j - 1];
            at_fresh.push(w as u32);
            j -= 1;
        }
    }
    at_fresh.reverse();
    (out, at_fresh)
}

#[cfg(test)]
mod tests {
    use super::super::{Points, prepare};
    use super::*;
    use crate::options::{Method, SimplifyOptions};

    /// Placements, faces, vertex clusters and the cluster and cell counts.
    type Bits<'a> = (
        Vec<Vec<u32>>,
        &'a [(u32, [u32; 3])],
        &'a [u32],
        usize,
        usize,
    );

    /// A build's every output as bits, to compare two builds exactly.
    fn bits(b: &Built) -> Bits<'_> {
        let placed = b
            .placed
            .iter()
            .map(|p| {
                let mut v: Vec<u32> = p.pos.iter().map(|x| x.to_bits()).collect();
                v.extend(bytemuck::cast_slice::<_, u32>(std::slice::from_ref(
                    &p.quadric,
                )));
                v.push(p.attr);
                v.push(p.how as u32);
                v
            })
            .collect();
        (placed, &b.faces, &b.vertex_cluster, b.clusters, b.cells)
    }

    /// An edge with three faces pinches both its clusters, as does one that two faces run the
    /// same way; an edge two faces run opposite ways does not.
    /// An edge with three faces pinches both its clusters, as does one that two faces run the
    /// same way; an edge two faces run opposite ways does not.
    #[test]
    fn pinched_clusters_are_three_face_edges_and_folds() {
        let faces = [
            [0, 1, 2],
            [1, 0, 3],
            [0, 1, 4],
            [2, 3, 4],
            [2, 3, 5],
            [3, 6, 5],
        ];
        let b = Built {
            placed: Vec::new(),
            faces: faces
                .iter()
                .enumerate()
                .map(|(f, &t)| (f as u32, t))
                .collect(),
            vertex_cluster: Vec::new(),
            clusters: 7,
            cells: 7,
        };
        assert_eq!(pinched_clusters(&b), [0, 1, 2, 3]);
        // Without the third face on (0, 1) and the second face running 2 -> 3: none.
        let b = Built {
            faces: [faces[0], faces[1], faces[3], [3, 2, 5]]
                .iter()
                .enumerate()
                .map(|(f, &t)| (f as u32, t))
                .collect(),
            ..b
        };
        assert!(pinched_clusters(&b).is_empty());
    }

    /// After a repair, looking only at what it changed finds what looking at everything finds,
    /// repair after repair, on meshes whose clusterings pinch and fold (checked: some second
    /// check finds clusters, so the shortcut is tried on a real repair's leftovers).
    #[test]
    fn rechecked_finds_what_the_whole_check_finds() {
        let mut leftovers = 0;
        for (seed, noise) in [(3, 0.03), (5, 0.06), (8, 0.1)] {
            let mesh = crate::mesh::noisy_sphere(6, noise, seed);
            let mut opts = SimplifyOptions::with_ratio(mesh.triangles.len(), 0.05).unwrap();
            opts.method = Method::Hybrid;
            let mut pts = Points::new(&mesh);
            let mut work = prepare(&mut pts, &opts, true, None).unwrap();
            let mut report = ClusterReport::default();
            let target = opts.target_faces;
            let (grid, mut built, _) =
                cluster_to(&work, 2 * target, None, Some(target), None, &mut report).unwrap();
            let whole = |b: &Built, work: &Work| checked(b, &origin_normals(work, b).unwrap());
            let mut bad = whole(&built, &work);
            assert!(!bad.is_empty(), "seed {seed}: nothing to repair");
            for repair in 0..MAX_REPAIRS {
                if bad.is_empty() {
                    break;
                }
                let at_fresh;
                (built, at_fresh) = take_apart(&mut work, &grid, built, &bad);
                bad = whole(&built, &work);
                let normals = origin_normals(&work, &built).unwrap();
                assert_eq!(
                    rechecked(&built, |i| normals[i], &at_fresh),
                    bad,
                    "seed {seed}, repair {repair}"
                );
                leftovers += bad.len();
            }
        }
        assert!(leftovers > 0, "no repair left anything to find");
    }

    /// Taking clusters apart from the build before gives, bit for bit, what building again with
    /// their members locked gives: for any set of clusters (singletons among them), twice in a
    /// row, on a painted sphere whose colour steps split cells, on a grid whose border is
    /// locked from the start, and on a sphere with repeated, reversed and degenerate faces
    /// (whose clustered faces the deduplication drops).
    #[test]
    fn take_apart_equals_a_whole_build() {
        let mut painted = crate::mesh::noisy_sphere(5, 0.01, 7);
        crate::mesh::paint(&mut painted);
        let mut repeated = crate::mesh::noisy_sphere(5, 0.01, 9);
        let n = repeated.triangles.len();
        for f in (0..n).step_by(7) {
            let [a, b, c] = repeated.triangles[f];
            repeated.triangles.extend([[a, b, c], [a, c, b], [a, a, b]]);
        }
        let cases = [
            (painted, false, 0.5),
            (crate::mesh::grid(60), true, 0.0),
            (repeated, false, 0.0),
        ];
        for (mesh, lock_border, color) in cases {
            let mut opts = SimplifyOptions::with_ratio(mesh.triangles.len(), 0.1).unwrap();
            opts.lock_border = lock_border;
            opts.attributes.color = color;
            let mut pts = Points::new(&mesh);
            let mut work = prepare(&mut pts, &opts, true, None).unwrap();
            work.colors = super::super::colors::ColourSplit::of(&mesh, color);
            let mut report = ClusterReport::default();
            let target = opts.target_faces;
            let (grid, mut built, _) =
                cluster_to(&work, 3 * target, None, Some(target), None, &mut report).unwrap();
            let what = format!("{} faces, lock_border {lock_border}", mesh.triangles.len());
            if color > 0.0 {
                assert!(built.clusters > built.cells, "{what}: no cell was split");
            }
            // Every fifth cluster, every third, then two in every four (whole cells of several
            // clusters among them); each time every other locked vertex's singleton too.
            for (step, width) in [(5usize, 1), (3, 1), (4, 2)] {
                let mut bad: Vec<u32> = (0..built.clusters as u32)
                    .filter(|&k| (1..=width).contains(&(k as usize % step)))
                    .collect();
                bad.extend(
                    (0..work.locked.len())
                        .filter(|&v| work.locked[v])
                        .map(|v| built.vertex_cluster[v])
                        .step_by(2),
                );
                bad.sort_unstable();
                bad.dedup();
                let before = built.clusters;
                let was_locked = work.locked.clone();
                let (apart, at_fresh) = take_apart(&mut work, &grid, built, &bad);
                let whole = work.build(&grid).unwrap();
                // The faces at a new singleton: a cluster of a vertex locked just now.
                let mut fresh = vec![false; whole.clusters];
                for (v, &k) in whole.vertex_cluster.iter().enumerate() {
                    fresh[k as usize] |= work.locked[v] && !was_locked[v];
                }
                let expected: Vec<u32> = (0..whole.faces.len() as u32)
                    .filter(|&i| whole.faces[i as usize].1.iter().any(|&k| fresh[k as usize]))
                    .collect();
                assert!(!expected.is_empty(), "{what}: no face at a new singleton");
                assert_eq!(at_fresh, expected, "{what}: the faces at new singletons");
                assert_eq!(
                    bits(&apart),
                    bits(&whole),
                    "{what}: {width} in {step} clusters"
                );
                assert!(whole.clusters > before, "{what}: nothing taken apart");
                built = whole;
            }
        }
    }
}
