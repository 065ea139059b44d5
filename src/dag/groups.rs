//! Groups: neighbouring clusters that are simplified together, their outer border locked.
//!
//! Greedy growth over the cluster graph, seeds in Morton order: a group takes the unassigned
//! neighbour it shares most edges with, counting twice the edges the last level locked (those
//! between clusters of different parent groups), so that this level frees them (Karis 2021:
//! "the boundary of one level must fall inside a group of the next"). A group whose neighbours
//! are all taken while it is under half its size goes on with the nearest unassigned cluster in
//! Morton order, so the small pieces of a scan still reach one root.

use super::meshlets::{edge_key, morton_order, sort};
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
pub fn group(members: &[Member<'_>], class: &[u32], size: usize) -> Vec<Vec<u32>> {
    assert!(size >= 1);
    let n = members.len();
    let links = links(members, class);
    let centers: Vec<[f32; 3]> = members.iter().map(|m| m.center).collect();
    let order = morton_order(&centers);
    let mut group_of = vec![u32::MAX; n];
    let mut groups: Vec<Vec<u32>> = Vec::new();
    let mut seed = 0usize;
    loop {
        while seed < n && group_of[order[seed] as usize] != u32::MAX {
            seed += 1;
        }
        if seed == n {
            break;
        }
        let id = groups.len() as u32;
        let mut g: Vec<u32> = Vec::new();
        let mut weight: FxHashMap<u32, u32> = FxHashMap::default();
        let mut next = Some(order[seed]);
        let mut fallback = seed;
        while let Some(c) = next {
            group_of[c as usize] = id;
            g.push(c);
            weight.remove(&c);
            for &(o, w) in links.of(c) {
                if group_of[o as usize] == u32::MAX {
                    *weight.entry(o).or_insert(0) += w;
                }
            }
            if g.len() == size {
                break;
            }
            next = strongest(&weight, &centers, &g);
            if next.is_none() && g.len() < size.div_ceil(2) {
                while fallback < n && group_of[order[fallback] as usize] != u32::MAX {
                    fallback += 1;
                }
                next = order.get(fallback).copied();
            }
        }
        groups.push(g);
    }
    merge_small(groups, &group_of, &links, size)
}

/// Groups under half `size` (the leftovers a greedy sweep strands between full groups) joined
/// to the neighbouring group they share most edges with, while that stays within 1.5 `size`:
/// a small group has a long pinned border for its triangles, and halving it anyway gave the
/// 1M scan's DAG its largest errors, which every coarser group then inherits.
fn merge_small(
    mut groups: Vec<Vec<u32>>,
    group_of: &[u32],
    links: &Links,
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
    groups.retain(|g| !g.is_empty());
    groups
}

/// The candidate with the largest weight, then nearest the group's centre, then lowest id.
fn strongest(weight: &FxHashMap<u32, u32>, centers: &[[f32; 3]], g: &[u32]) -> Option<u32> {
    let mut c = [0.0f64; 3];
    for &m in g {
        for i in 0..3 {
            c[i] += centers[m as usize][i] as f64 / g.len() as f64;
        }
    }
    let d = |o: u32| -> f64 {
        let p = centers[o as usize];
        (0..3).map(|i| (p[i] as f64 - c[i]).powi(2)).sum()
    };
    weight
        .iter()
        .map(|(&o, &w)| (w, d(o), o))
        .max_by(|a, b| a.0.cmp(&b.0).then(b.1.total_cmp(&a.1)).then(b.2.cmp(&a.2)))
        .map(|k| k.2)
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
    let mut edges: Vec<(u64, u32)> = Vec::new();
    for (c, m) in members.iter().enumerate() {
        for t in m.triangles {
            for k in 0..3 {
                let (a, b) = (class[t[k] as usize], class[t[(k + 1) % 3] as usize]);
                if a != b {
                    edges.push((edge_key(a, b), c as u32));
                }
            }
        }
    }
    sort(&mut edges);
    edges.dedup();
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
