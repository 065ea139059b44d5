//! Groups: neighbouring clusters that are simplified together, their outer border locked.
//!
//! Agglomerative grouping over the cluster graph (see [`group`]), counting twice the edges the
//! last level locked (those between clusters of different parent groups), so that this level
//! frees them (Karis 2021: "the boundary of one level must fall inside a group of the next").
//! A group left under half its size joins a neighbour, or, with none (a separate piece of a
//! scan), the nearest group along the Morton curve, so the pieces still reach one root.

use super::dist2;
use super::meshlets::{edge_key, morton_order, sort};
use rayon::prelude::*;
use rustc_hash::FxHashMap;

/// What the grouping needs of one cluster.
pub struct Member<'a> {
    pub triangles: &'a [[u32; 3]],
    /// The group that made it ([`super::NONE`] at depth 0).
    pub parent_group: u32,
    pub center: [f32; 3],
}

/// The clusters `members` in groups of at most `size`: indices into `members`, each group's in
/// the order taken. `class[v]` is vertex `v`'s position class.
///
/// Agglomerative (T. Kurita, "An efficient agglomerative clustering algorithm using a heap",
/// 1991, as meshoptimizer's `meshopt_partitionClusters` uses it): every cluster starts as a
/// group; the group with the fewest vertices joins the neighbour whose shared edges weigh most
/// against both their expected borders (the square roots of their vertex counts), while the
/// two fit in `size`, until none is under `size` or none can grow. Growing one group at a time
/// from Morton-order seeds instead left groups whose border held 22% of their vertices at the
/// 1M scan's first level and 43% at its fifth, and the fifth level's largest error was 3.4
/// times its median, an error every coarser group inherits.
pub fn group(members: &[Member<'_>], class: &[u32], size: usize) -> Vec<Vec<u32>> {
    use std::cmp::Reverse;
    use std::collections::BinaryHeap;
    assert!(size >= 1);
    let n = members.len();
    let links = links(members, class);
    let mut group_of: Vec<u32> = (0..n as u32).collect();
    let mut parts: Vec<Vec<u32>> = (0..n as u32).map(|c| vec![c]).collect();
    let mut verts: Vec<u32> = members
        .par_iter()
        .map(|m| {
            let mut v: Vec<u32> = m
                .triangles
                .iter()
                .flatten()
                .map(|&v| class[v as usize])
                .collect();
            v.sort_unstable();
            v.dedup();
            v.len() as u32
        })
        .collect();
    let mut heap: BinaryHeap<Reverse<(u32, u32)>> = (0..n as u32)
        .map(|g| Reverse((verts[g as usize], g)))
        .collect();
    let mut shared: FxHashMap<u32, u32> = FxHashMap::default();
    while let Some(Reverse((v, g))) = heap.pop() {
        let gi = g as usize;
        if parts[gi].is_empty() || v != verts[gi] || parts[gi].len() >= size {
            continue;
        }
        shared.clear();
        for &c in &parts[gi] {
            for &(o, w) in links.of(c) {
                let h = group_of[o as usize];
                if h != g {
                    *shared.entry(h).or_insert(0) += w;
                }
            }
        }
        let own = 1.0 / (verts[gi] as f64).sqrt();
        let best = shared
            .iter()
            .filter(|&(&h, _)| parts[gi].len() + parts[h as usize].len() <= size)
            .map(|(&h, &w)| {
                (
                    w as f64 * (own + 1.0 / (verts[h as usize] as f64).sqrt()),
                    h,
                    w,
                )
            })
            .max_by(|a, b| a.0.total_cmp(&b.0).then(b.1.cmp(&a.1)));
        let Some((_, h, w)) = best else { continue };
        let moved = std::mem::take(&mut parts[h as usize]);
        for &c in &moved {
            group_of[c as usize] = g;
        }
        parts[gi].extend(moved);
        verts[gi] = (verts[gi] + verts[h as usize]).saturating_sub(w).max(1);
        verts[h as usize] = 0;
        heap.push(Reverse((verts[gi], g)));
    }
    // The groups renumbered densely, in order of their first cluster.
    let mut dense = vec![u32::MAX; n];
    let mut groups: Vec<Vec<u32>> = Vec::new();
    for &g in &group_of {
        let g = g as usize;
        if dense[g] == u32::MAX {
            dense[g] = groups.len() as u32;
            groups.push(std::mem::take(&mut parts[g]));
        }
    }
    let group_of: Vec<u32> = group_of.iter().map(|&g| dense[g as usize]).collect();
    let centers: Vec<[f32; 3]> = members.iter().map(|m| m.center).collect();
    merge_small(groups, &group_of, &links, &centers, size)
}

/// Groups under half `size` (those whose every neighbour was too large to join) joined to the
/// neighbouring group they share most edges with, while that stays within 1.5 `size`, or, with
/// no neighbour, to the nearest group along the Morton curve: a small group has a long pinned
/// border for its triangles, and halving it anyway gave the 1M scan's DAG its largest errors
/// (with the earlier greedy grouping), which every coarser group then inherits.
fn merge_small(
    mut groups: Vec<Vec<u32>>,
    group_of: &[u32],
    links: &Links,
    centers: &[[f32; 3]],
    size: usize,
) -> Vec<Vec<u32>> {
    let mut into: Vec<u32> = (0..groups.len() as u32).collect();
    let root = |into: &[u32], mut g: u32| {
        while into[g as usize] != g {
            g = into[g as usize];
        }
        g
    };
    for gi in 0..groups.len() {
        if groups[gi].len() * 2 >= size || groups[gi].is_empty() {
            continue;
        }
        let mut w: FxHashMap<u32, u32> = FxHashMap::default();
        for &c in &groups[gi] {
            for &(o, x) in links.of(c) {
                let h = root(&into, group_of[o as usize]);
                if h != gi as u32 {
                    *w.entry(h).or_insert(0) += x;
                }
            }
        }
        let best = w
            .into_iter()
            .filter(|&(h, _)| groups[h as usize].len() + groups[gi].len() <= size + size / 2)
            .max_by(|a, b| a.1.cmp(&b.1).then(b.0.cmp(&a.0)));
        if let Some((h, _)) = best {
            let moved = std::mem::take(&mut groups[gi]);
            groups[h as usize].extend(moved);
            into[gi] = h;
        }
    }
    // Pieces with no neighbour at all: the nearest of the groups a few places either side along
    // the Morton curve of group centres that has room.
    const WINDOW: usize = 8;
    let centre = |g: &[u32]| {
        let mut c = [0.0f64; 3];
        for &m in g {
            for i in 0..3 {
                c[i] += centers[m as usize][i] as f64 / g.len() as f64;
            }
        }
        c.map(|x| x as f32)
    };
    let live: Vec<u32> = (0..groups.len() as u32)
        .filter(|&g| !groups[g as usize].is_empty())
        .collect();
    let mids: Vec<[f32; 3]> = live.iter().map(|&g| centre(&groups[g as usize])).collect();
    let order: Vec<u32> = morton_order(&mids)
        .into_iter()
        .map(|i| live[i as usize])
        .collect();
    let mid_of: FxHashMap<u32, [f32; 3]> = live.iter().copied().zip(mids).collect();
    for k in 0..order.len() {
        let gi = order[k] as usize;
        if groups[gi].len() * 2 >= size || groups[gi].is_empty() {
            continue;
        }
        let here = mid_of[&(gi as u32)];
        let best = order[k.saturating_sub(WINDOW)..(k + WINDOW + 1).min(order.len())]
            .iter()
            .map(|&h| root(&into, h))
            .filter(|&h| {
                h as usize != gi
                    && !groups[h as usize].is_empty()
                    && groups[h as usize].len() + groups[gi].len() <= size + size / 2
            })
            .map(|h| (dist2(here, mid_of[&h]), h))
            .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        if let Some((_, h)) = best {
            let moved = std::mem::take(&mut groups[gi]);
            groups[h as usize].extend(moved);
            into[gi] = h;
        }
    }
    groups.retain(|g| !g.is_empty());
    groups
}

/// The cluster graph: per cluster, its neighbours and the weight of the edges they share.
struct Links {
    start: Vec<u32>,
    to: Vec<(u32, u32)>,
}

impl Links {
    fn of(&self, c: u32) -> &[(u32, u32)] {
        &self.to[self.start[c as usize] as usize..self.start[c as usize + 1] as usize]
    }
}

fn links(members: &[Member<'_>], class: &[u32]) -> Links {
    // Each cluster's border first, on every core: the edges only one of its triangles has (an
    // edge two of them share cannot be another cluster's on a manifold surface). Sorting every
    // edge of the level at once instead took most of the grouping's 0.27 s on the 1M scan's
    // first level; its borders are a tenth of its edges.
    let mut edges: Vec<(u64, u32)> = members
        .par_iter()
        .enumerate()
        .flat_map_iter(|(c, m)| {
            let mut own: Vec<u64> = Vec::with_capacity(3 * m.triangles.len());
            for t in m.triangles {
                for k in 0..3 {
                    let (a, b) = (class[t[k] as usize], class[t[(k + 1) % 3] as usize]);
                    if a != b {
                        own.push(edge_key(a, b));
                    }
                }
            }
            own.sort_unstable();
            own.chunk_by(|a, b| a == b)
                .filter(|run| run.len() == 1)
                .map(|run| (run[0], c as u32))
                .collect::<Vec<_>>()
        })
        .collect();
    sort(&mut edges);
    let mut pairs: Vec<(u32, u32, u32)> = Vec::new();
    for run in edges.chunk_by(|a, b| a.0 == b.0) {
        for (i, a) in run.iter().enumerate() {
            for b in &run[i + 1..] {
                let locked =
                    members[a.1 as usize].parent_group != members[b.1 as usize].parent_group;
                let w = 1 + locked as u32;
                pairs.push((a.1, b.1, w));
                pairs.push((b.1, a.1, w));
            }
        }
    }
    sort(&mut pairs);
    let mut to: Vec<(u32, u32)> = Vec::new();
    let mut start = vec![0u32; members.len() + 1];
    for run in pairs.chunk_by(|a, b| (a.0, a.1) == (b.0, b.1)) {
        start[run[0].0 as usize + 1] += 1;
        to.push((run[0].1, run.iter().map(|p| p.2).sum()));
    }
    for i in 0..members.len() {
        start[i + 1] += start[i];
    }
    Links { start, to }
}
