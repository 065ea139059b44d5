//! The parts of NSGA-II that know nothing of meshes (Deb, Pratap, Agarwal & Meyarivan, "A Fast
//! and Elitist Multiobjective Genetic Algorithm: NSGA-II", IEEE TEC 6(2), 2002): fast
//! non-dominated sorting, crowding distance, the crowded comparison, elitist survivor selection,
//! tournaments, and the exact hypervolume of a two-objective front. Both objectives are
//! minimized. Every tie is broken by index, so the same points always give the same answer.

use crate::mesh::SplitMix64;

/// A candidate's objectives, both minimized (here: vertices and error).
pub type Point = [f64; 2];

/// `a` is no worse than `b` in both objectives and better in one.
pub fn dominates(a: Point, b: Point) -> bool {
    a[0] <= b[0] && a[1] <= b[1] && (a[0] < b[0] || a[1] < b[1])
}

/// Fast non-dominated sorting (Deb et al. 2002, §III-A): the fronts, best first, each a list
/// of indices in ascending order. O(M N²) for N points.
pub fn non_dominated_sort(points: &[Point]) -> Vec<Vec<usize>> {
    let n = points.len();
    // Per point: whom it dominates, and by how many it is dominated.
    let mut dominated: Vec<Vec<usize>> = vec![Vec::new(); n];
    let mut count = vec![0usize; n];
    for i in 0..n {
        for j in i + 1..n {
            if dominates(points[i], points[j]) {
                dominated[i].push(j);
                count[j] += 1;
            } else if dominates(points[j], points[i]) {
                dominated[j].push(i);
                count[i] += 1;
            }
        }
    }
    let mut fronts = Vec::new();
    let mut current: Vec<usize> = (0..n).filter(|&i| count[i] == 0).collect();
    while !current.is_empty() {
        let mut next = Vec::new();
        for &i in &current {
            for &j in &dominated[i] {
                count[j] -= 1;
                if count[j] == 0 {
                    next.push(j);
                }
            }
        }
        next.sort_unstable();
        fronts.push(current);
        current = next;
    }
    fronts
}

/// Crowding distance of each member of `front` (Deb et al. 2002, §III-B), in `front`'s order:
/// per objective, the two extremes get infinity and every other member the gap between its
/// neighbours divided by the objective's range; the objectives' shares add up.
pub fn crowding_distance(points: &[Point], front: &[usize]) -> Vec<f64> {
    let n = front.len();
    let mut d = vec![0.0; n];
    if n <= 2 {
        return vec![f64::INFINITY; n];
    }
    for m in [0, 1] {
        let mut by: Vec<usize> = (0..n).collect();
        by.sort_by(|&a, &b| {
            points[front[a]][m]
                .total_cmp(&points[front[b]][m])
                .then(front[a].cmp(&front[b]))
        });
        let lo = points[front[by[0]]][m];
        let hi = points[front[by[n - 1]]][m];
        d[by[0]] = f64::INFINITY;
        d[by[n - 1]] = f64::INFINITY;
        if hi > lo {
            for k in 1..n - 1 {
                let gap = points[front[by[k + 1]]][m] - points[front[by[k - 1]]][m];
                d[by[k]] += gap / (hi - lo);
            }
        }
    }
    d
}

/// Every point's front (0 = non-dominated) and crowding distance within its front.
pub fn rank_and_crowding(points: &[Point]) -> Vec<(usize, f64)> {
    let mut out = vec![(0, 0.0); points.len()];
    for (r, front) in non_dominated_sort(points).iter().enumerate() {
        for (&i, c) in front.iter().zip(crowding_distance(points, front)) {
            out[i] = (r, c);
        }
    }
    out
}

/// The crowded comparison (Deb et al. 2002, §III-B): a lower front wins, then a larger crowding
/// distance, then the lower index.
pub fn crowded_better(a: usize, b: usize, rc: &[(usize, f64)]) -> bool {
    let (ra, ca) = rc[a];
    let (rb, cb) = rc[b];
    ra < rb || (ra == rb && (ca > cb || (ca == cb && a < b)))
}

/// Elitist survivor selection (Deb et al. 2002, §III-C): the `n` survivors of `points` (parents
/// and offspring together), whole fronts in order, the last front cut by descending crowding
/// distance. Returned in ascending index order.
pub fn select_survivors(points: &[Point], n: usize) -> Vec<usize> {
    let mut out = Vec::with_capacity(n);
    for front in non_dominated_sort(points) {
        if out.len() + front.len() <= n {
            out.extend_from_slice(&front);
        } else {
            let c = crowding_distance(points, &front);
            let mut by: Vec<usize> = (0..front.len()).collect();
            by.sort_by(|&a, &b| c[b].total_cmp(&c[a]).then(front[a].cmp(&front[b])));
            out.extend(by[..n - out.len()].iter().map(|&k| front[k]));
        }
        if out.len() == n {
            break;
        }
    }
    out.sort_unstable();
    out
}

/// Tournament selection: `size` draws with replacement from `0..rc.len()`, the crowded
/// comparison's best wins.
pub fn tournament(rc: &[(usize, f64)], size: usize, rng: &mut SplitMix64) -> usize {
    let draw = |rng: &mut SplitMix64| (rng.next_u64() % rc.len() as u64) as usize;
    let mut best = draw(rng);
    for _ in 1..size.max(1) {
        let c = draw(rng);
        if crowded_better(c, best, rc) {
            best = c;
        }
    }
    best
}

/// The exact hypervolume of `points` against `reference` (both objectives minimized): the area
/// the points dominate inside the box they span with the reference, by one sweep along the
/// first objective. Points outside the reference box add nothing.
pub fn hypervolume(points: &[Point], reference: Point) -> f64 {
    let mut inside: Vec<Point> = points
        .iter()
        .copied()
        .filter(|p| p[0] < reference[0] && p[1] < reference[1])
        .collect();
    inside.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    let mut area = 0.0;
    // Left to right, a point whose second objective is no better than one before it is
    // dominated; every other point owns the strip from its first objective to the next
    // non-dominated point's, from its second objective up to the reference.
    let mut best = reference[1];
    for (k, p) in inside.iter().enumerate() {
        if p[1] >= best {
            continue;
        }
        let next = inside[k + 1..]
            .iter()
            .find(|q| q[1] < p[1])
            .map_or(reference[0], |q| q[0]);
        area += (next - p[0]) * (reference[1] - p[1]);
        best = p[1];
    }
    area
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dominance_needs_one_strict_improvement() {
        assert!(dominates([1.0, 1.0], [2.0, 1.0]));
        assert!(!dominates([1.0, 1.0], [1.0, 1.0]));
        assert!(!dominates([1.0, 3.0], [2.0, 1.0]));
    }
}
