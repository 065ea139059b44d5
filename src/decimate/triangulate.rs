//! Filling the hole a removed vertex leaves: recursive loop splitting (Schroeder, Zarge &
//! Lorensen 1992, section 3.3) or the fan of a half-edge collapse (Schroeder 1997). Both give
//! triangles as indices into the hole's polygon, in its winding order, so that the new faces
//! wind as the old ones did.

use glam::DVec3;

/// The smallest aspect ratio of a split (the nearest loop vertex's distance to the split plane
/// over the diagonal's length) loop splitting accepts. Schroeder et al. split at the best ratio
/// and give up below a threshold; 0.02 refuses only splits whose triangles would be slivers
/// (the quality check refuses those anyway) while letting the long thin loops of a decimated
/// feature line close.
pub const MIN_SPLIT_ASPECT: f64 = 0.02;

/// Triangulates the closed polygon `pts` (winding counter-clockwise seen from `normal`) by
/// recursive loop splitting into `out`. `exists(i, j)` says whether the edge between polygon
/// vertices `i` and `j` is already in the mesh outside the hole: a diagonal there would give
/// that edge a third face. Returns false (and `out` is unusable) when some sub-loop has no
/// split whose plane separates its two halves with at least [`MIN_SPLIT_ASPECT`].
pub fn split_loop(
    pts: &[DVec3],
    normal: DVec3,
    exists: &mut dyn FnMut(usize, usize) -> bool,
    out: &mut Vec<[usize; 3]>,
    work: &mut Vec<usize>,
) -> bool {
    out.clear();
    work.clear();
    work.extend(0..pts.len());
    split(pts, normal, exists, out, work, 0, pts.len())
}

/// Splits the sub-loop `work[from..to]` (polygon indices in cyclic winding order).
fn split(
    pts: &[DVec3],
    normal: DVec3,
    exists: &mut dyn FnMut(usize, usize) -> bool,
    out: &mut Vec<[usize; 3]>,
    work: &mut Vec<usize>,
    from: usize,
    to: usize,
) -> bool {
    let n = to - from;
    if n < 3 {
        return true;
    }
    if n == 3 {
        out.push([work[from], work[from + 1], work[from + 2]]);
        return true;
    }
    // The diagonal (i, j) with the best aspect ratio whose plane (through the diagonal, along
    // the normal) has the two halves strictly on its two sides.
    let mut best: Option<(f64, usize, usize)> = None;
    for i in 0..n {
        for j in i + 2..n {
            if i == 0 && j == n - 1 {
                continue;
            }
            let (a, b) = (work[from + i], work[from + j]);
            let d = pts[b] - pts[a];
            let len = d.length();
            let m = d.cross(normal);
            let ml = m.length();
            if len == 0.0 || ml == 0.0 {
                continue;
            }
            let m = m / ml;
            let mut worst = f64::INFINITY;
            // One half is i+1..j, the other j+1..n then 0..i; their signed distances must have
            // opposite, non-zero signs.
            let side = |k: usize| m.dot(pts[work[from + k]] - pts[a]);
            let first = side(i + 1).signum();
            let ok = (i + 1..j).all(|k| {
                let s = side(k);
                worst = worst.min(s.abs());
                s.signum() == first && s != 0.0
            }) && (j + 1..n).chain(0..i).all(|k| {
                let s = side(k);
                worst = worst.min(s.abs());
                s.signum() == -first && s != 0.0
            });
            let aspect = worst / len;
            if ok && aspect >= MIN_SPLIT_ASPECT && best.is_none_or(|(r, _, _)| aspect > r) {
                if exists(a, b) {
                    continue;
                }
                best = Some((aspect, i, j));
            }
        }
    }
    let Some((_, i, j)) = best else {
        return false;
    };
    // Both halves, each in cyclic order, appended after the current range: (i..=j) and
    // (j..n, 0..=i).
    let base = work.len();
    for k in i..=j {
        work.push(work[from + k]);
    }
    let mid = work.len();
    for k in (j..n).chain(0..=i) {
        work.push(work[from + k]);
    }
    let end = work.len();
    split(pts, normal, exists, out, work, base, mid)
        && split(pts, normal, exists, out, work, mid, end)
}

/// The fan from polygon vertex `apex` over the rest of the closed polygon of `n` vertices: the
/// triangles a half-edge collapse of the removed vertex into `apex` leaves.
pub fn fan_from(apex: usize, n: usize, out: &mut Vec<[usize; 3]>) {
    out.clear();
    for k in 1..n.saturating_sub(1) {
        out.push([apex, (apex + k) % n, (apex + k + 1) % n]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A triangle and a square: the triangle is itself; the square is split along one of its
    /// diagonals into two triangles that wind as it does.
    #[test]
    fn small_loops() {
        let z = DVec3::Z;
        let (mut out, mut work) = (Vec::new(), Vec::new());
        let tri = [DVec3::ZERO, DVec3::X, DVec3::Y];
        assert!(split_loop(&tri, z, &mut |_, _| false, &mut out, &mut work));
        assert_eq!(out, vec![[0, 1, 2]]);
        let sq = [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y];
        assert!(split_loop(&sq, z, &mut |_, _| false, &mut out, &mut work));
        assert_eq!(out.len(), 2);
        for t in &out {
            let [a, b, c] = t.map(|i| sq[i]);
            assert!((b - a).cross(c - a).dot(z) > 0.0, "{t:?} winds backwards");
        }
        fan_from(2, 5, &mut out);
        assert_eq!(out, vec![[2, 3, 4], [2, 4, 0], [2, 0, 1]]);
    }
}
