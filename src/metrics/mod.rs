//! How far a simplified mesh is from its original, and what else changed.
//!
//! The distance is Metro's (P. Cignoni, C. Rocchini, R. Scopigno, "Metro: Measuring Error on
//! Simplified Surfaces", Computer Graphics Forum 1998), the measure MeshLab's "Hausdorff
//! Distance" filter implements: points sampled uniformly by area on the faces of one mesh, each
//! point's distance to the closest point of the other mesh's surface, in both directions.
//! On top of the random face samples every vertex is measured, and points along every edge (as
//! many as the face samples' spacing asks for, the midpoint at least, and more near the largest
//! distance until the edge's maximum is known within 0.1%), so that the maximum (usually at a
//! vertex or along a crease) is not missed; the mean and RMS use the face samples only, so that
//! they estimate the mean over the surface as MeshLab's do.
//!
//! Deterministic: the samples depend on the seed alone, and the sums are formed in fixed chunks
//! added in a fixed order, so the figures do not depend on the number of threads.
//!
//! ```
//! use meshslim::metrics::{compare, CompareOptions};
//! use meshslim::mesh::icosphere;
//! let c = compare(&icosphere(3), &icosphere(2), &CompareOptions::default()).unwrap();
//! assert!(c.distance.two_sided.max_rel > 0.0 && c.distance.two_sided.max_rel < 0.05);
//! ```

mod appearance;
mod bvh;
mod distance;

pub use appearance::{Appearance, AttributeStats, Texture};
pub(crate) use appearance::{mix, weights_at};
pub(crate) use bvh::closest_on_triangle;
pub use bvh::{Hit, TriangleBvh, point_triangle_dist2};
pub use distance::{DirectionStats, Distances};

use serde::Serialize;

use crate::error::{Error, Result};
use crate::mesh::{Mesh, Topology, topology};

/// The fewest face samples per direction by default (see [`CompareOptions::face_samples`]):
/// 0.03 s of queries, and a mean within about 0.5% from seed to seed.
pub const MIN_FACE_SAMPLES: usize = 100_000;

/// What to sample.
#[derive(Debug, Clone, PartialEq)]
pub struct CompareOptions {
    /// Face samples in each direction; `None`: one per face on the denser mesh and ten per face
    /// on the coarser one, at least [`MIN_FACE_SAMPLES`] (each mesh's samples scale with its
    /// own faces, as Metro's and MeshLab's do; see [`CompareOptions::face_samples`]).
    pub samples: Option<usize>,
    /// Seed of the sample positions; the same seed gives the same figures.
    pub seed: u64,
    /// Also measure every vertex and points along every edge (for the maximum).
    pub vertices_and_edges: bool,
    /// The texture both meshes' UVs look up: adds the texture colour's deviation to the
    /// appearance.
    pub texture: Option<std::sync::Arc<Texture>>,
}

impl Default for CompareOptions {
    fn default() -> Self {
        CompareOptions {
            samples: None,
            seed: 1,
            vertices_and_edges: true,
            texture: None,
        }
    }
}

impl CompareOptions {
    /// Face samples on a mesh of `faces` faces compared with one of `other` faces: `samples`
    /// when set, else `faces` on the denser of the two (one per face) and `10 · faces` on the
    /// coarser (or on either, when they have as many faces), and never fewer than
    /// `10 · min(faces, other)`, so that a denser mesh less than ten times as dense as the
    /// other still gets ten samples per face of the coarser one, nor than
    /// [`MIN_FACE_SAMPLES`], so that the mean of a mesh of a few faces is not left to a few
    /// hundred random points (14 faces, 140 samples: ±10% from seed to seed).
    pub fn face_samples(&self, faces: usize, other: usize) -> usize {
        self.samples.unwrap_or(
            if faces > other {
                faces.max(10 * other)
            } else {
                10 * faces
            }
            .max(MIN_FACE_SAMPLES),
        )
    }
}

/// Both directions of the distance, and the two combined.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Distance {
    /// Bounding-box diagonal of A, the unit of every `*_rel` figure.
    pub diagonal: f64,
    /// Samples on A (the reference), distances to B.
    pub a_to_b: DirectionStats,
    /// Samples on B, distances to A.
    pub b_to_a: DirectionStats,
    /// Both directions: `max` is the larger maximum (the Hausdorff distance); `mean` is the
    /// plain average of the two directions' means, (mean(A→B) + mean(B→A)) / 2, not weighted by
    /// sample counts; `rms` is sqrt((rms(A→B)² + rms(B→A)²) / 2). MeshLab's filter reports each
    /// direction separately; this is how `benches/meshlab_compare.py` combines them.
    pub two_sided: Distances,
}

/// A measure of A and of B, and B's change relative to A.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Change {
    pub a: f64,
    pub b: f64,
    /// (b − a) / |a|; `None` when a is 0.
    pub relative: Option<f64>,
}

impl Change {
    fn new(a: f64, b: f64) -> Change {
        Change {
            a,
            b,
            relative: (a != 0.0).then(|| (b - a) / a.abs()),
        }
    }
}

/// Upper bounds of the aspect-ratio histogram's bins; the last bin is everything above the last
/// bound, degenerate faces included.
pub const ASPECT_RATIO_BINS: [f64; 7] = [1.5, 2.0, 3.0, 5.0, 10.0, 100.0, f64::INFINITY];

/// Triangle shape of B.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TriangleQuality {
    /// Smallest interior angle over the faces with area, in degrees (60 for equilateral).
    pub min_angle_deg: f64,
    /// Mean over the faces with area of each face's smallest angle, in degrees.
    pub mean_min_angle_deg: f64,
    /// Faces of zero area (or a repeated vertex): counted in the last histogram bin.
    pub degenerate_faces: usize,
    /// Aspect ratio = circumradius / (2 · inradius): 1 for an equilateral triangle, growing
    /// without bound for slivers. Faces per bin; bin i holds ratios in
    /// [`ASPECT_RATIO_BINS`][i − 1] (1 for i = 0) up to but excluding `ASPECT_RATIO_BINS`[i].
    pub aspect_ratio_histogram: Vec<HistogramBin>,
    /// Largest aspect ratio; `None` (JSON null) when a face is degenerate (infinite).
    pub max_aspect_ratio: Option<f64>,
    /// Share of the faces whose smallest angle is under 30 degrees (degenerate ones included):
    /// what remeshing is judged by.
    pub share_under_30_deg: f64,
    /// Share of the faces whose smallest angle is under 10 degrees (degenerate ones included).
    pub share_under_10_deg: f64,
    /// The vertices in faces by valence (the edges meeting there), fewest first; only the
    /// valences that occur.
    pub valence_histogram: Vec<ValenceBin>,
    /// Share of the vertices in faces with the regular valence: 6 inside, 4 on a border (the
    /// valences of an equilateral tiling, which isotropic remeshing flips towards).
    pub regular_valence_share: f64,
}

/// Vertices of one valence, inside and on a border.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct ValenceBin {
    pub valence: usize,
    pub interior: usize,
    pub border: usize,
}

/// The valence histogram of `m` and the share of regular vertices: each distinct edge counts
/// once at both ends, and an edge of one face makes its ends border vertices.
fn valences(m: &Mesh) -> (Vec<ValenceBin>, f64) {
    let mut edges: Vec<(u32, u32)> = m
        .triangles
        .iter()
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
        .filter(|(a, b)| a != b)
        .map(|(a, b)| (a.min(b), a.max(b)))
        .collect();
    edges.sort_unstable();
    let n = m.positions.len();
    let (mut valence, mut border) = (vec![0usize; n], vec![false; n]);
    for run in edges.chunk_by(|x, y| x == y) {
        let (a, b) = (run[0].0 as usize, run[0].1 as usize);
        valence[a] += 1;
        valence[b] += 1;
        if run.len() == 1 {
            border[a] = true;
            border[b] = true;
        }
    }
    let mut bins: std::collections::BTreeMap<usize, ValenceBin> = Default::default();
    let (mut used, mut regular) = (0usize, 0usize);
    for (v, &k) in valence.iter().enumerate().filter(|(_, k)| **k > 0) {
        let bin = bins.entry(k).or_insert(ValenceBin {
            valence: k,
            interior: 0,
            border: 0,
        });
        used += 1;
        if border[v] {
            bin.border += 1;
            regular += (k == 4) as usize;
        } else {
            bin.interior += 1;
            regular += (k == 6) as usize;
        }
    }
    let share = if used > 0 {
        regular as f64 / used as f64
    } else {
        0.0
    };
    (bins.into_values().collect(), share)
}

/// One bin of a histogram: values below `upper` (and at or above the previous bin's upper).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HistogramBin {
    /// `None` for the last, open bin.
    pub upper: Option<f64>,
    pub count: usize,
}

/// The topology figures a simplifier should keep.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct TopologyCounts {
    pub euler_characteristic: i64,
    pub boundary_loops: i64,
    pub non_manifold_edges: i64,
    pub non_manifold_vertices: i64,
    pub connected_components: i64,
}

impl TopologyCounts {
    fn of(t: &Topology) -> TopologyCounts {
        TopologyCounts {
            euler_characteristic: t.euler_characteristic,
            boundary_loops: t.boundary_loops as i64,
            non_manifold_edges: t.non_manifold_edges as i64,
            non_manifold_vertices: t.non_manifold_vertices as i64,
            connected_components: t.connected_components as i64,
        }
    }
    fn minus(self, o: TopologyCounts) -> TopologyCounts {
        TopologyCounts {
            euler_characteristic: self.euler_characteristic - o.euler_characteristic,
            boundary_loops: self.boundary_loops - o.boundary_loops,
            non_manifold_edges: self.non_manifold_edges - o.non_manifold_edges,
            non_manifold_vertices: self.non_manifold_vertices - o.non_manifold_vertices,
            connected_components: self.connected_components - o.connected_components,
        }
    }
}

/// A's and B's topology and the difference B − A (all zero when the topology is kept).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TopologyDelta {
    pub a: TopologyCounts,
    pub b: TopologyCounts,
    pub difference: TopologyCounts,
    /// Genus of each, `None` where the surface is not manifold.
    pub genus_a: Option<i64>,
    pub genus_b: Option<i64>,
}

impl TopologyDelta {
    /// True when B has A's Euler characteristic, boundary loops, components and non-manifold
    /// counts.
    pub fn unchanged(&self) -> bool {
        self.a == self.b
    }
}

/// Everything `meshslim compare` reports.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Comparison {
    pub faces_a: usize,
    pub faces_b: usize,
    pub vertices_a: usize,
    pub vertices_b: usize,
    pub seed: u64,
    pub distance: Distance,
    pub area: Change,
    /// Signed volume (meaningful for closed, consistently oriented meshes).
    pub volume: Change,
    pub quality_b: TriangleQuality,
    pub topology: TopologyDelta,
    /// The vertex colours' and normals' difference at the same samples, for the attributes both
    /// meshes have (absent, and not in the JSON, when they share none).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub appearance: Option<Appearance>,
}

/// Compares B with A, the reference: the Metro distance both ways, area and volume change,
/// B's triangle quality and the topology delta.
///
/// Errors when either mesh has no faces, or fails [`Mesh::validate`].
pub fn compare(a: &Mesh, b: &Mesh, opts: &CompareOptions) -> Result<Comparison> {
    for (name, m) in [("A", a), ("B", b)] {
        m.validate()
            .map_err(|e| Error::InvalidMesh(format!("mesh {name}: {e}")))?;
        if m.triangles.is_empty() {
            return Err(Error::InvalidMesh(format!(
                "mesh {name} has no faces: there is no surface to measure a distance to"
            )));
        }
    }
    if opts.samples == Some(0) {
        return Err(Error::InvalidOption(
            "the number of samples must be at least 1".into(),
        ));
    }
    let diagonal = a.bounds().map_or(0.0, |bb| bb.diagonal());
    let (fa, fb) = (a.face_count(), b.face_count());
    let (na, nb) = (opts.face_samples(fa, fb), opts.face_samples(fb, fa));
    // The two directions use different streams of the one seed.
    let seed_ab = opts.seed;
    let seed_ba = opts.seed ^ SEED_BA;

    let ((ta, tb), ((a_to_b, b_to_a), appearance)) = rayon::join(
        || rayon::join(|| topology(a), || topology(b)),
        || {
            let (bvh_a, bvh_b) = rayon::join(|| TriangleBvh::new(a), || TriangleBvh::new(b));
            let look = appearance::appearance(
                a,
                b,
                (&bvh_a, &bvh_b),
                (na, nb),
                (seed_ab, seed_ba),
                opts.texture.as_deref(),
            );
            let distance = rayon::join(
                || {
                    distance::one_direction(
                        a,
                        &bvh_b,
                        na,
                        opts.vertices_and_edges,
                        seed_ab,
                        diagonal,
                    )
                },
                || {
                    distance::one_direction(
                        b,
                        &bvh_a,
                        nb,
                        opts.vertices_and_edges,
                        seed_ba,
                        diagonal,
                    )
                },
            );
            (distance, look)
        },
    );
    let two_sided = Distances::two_sided(&a_to_b.distances, &b_to_a.distances, diagonal);
    let (ca, cb) = (TopologyCounts::of(&ta), TopologyCounts::of(&tb));
    Ok(Comparison {
        faces_a: a.face_count(),
        faces_b: b.face_count(),
        vertices_a: a.vertex_count(),
        vertices_b: b.vertex_count(),
        seed: opts.seed,
        distance: Distance {
            diagonal,
            a_to_b,
            b_to_a,
            two_sided,
        },
        area: Change::new(ta.surface_area, tb.surface_area),
        volume: Change::new(ta.signed_volume, tb.signed_volume),
        quality_b: triangle_quality(b),
        topology: TopologyDelta {
            a: ca,
            b: cb,
            difference: cb.minus(ca),
            genus_a: ta.genus,
            genus_b: tb.genus,
        },
        appearance,
    })
}

/// The stream of B's samples: A's seed with these bits flipped.
const SEED_BA: u64 = 0xA076_1D64_78BD_642F;

/// The two-sided mean distance of many meshes from one reference A, as [`compare`] measures it
/// with the same options: the same face samples from the same seeds, so the same figure to the
/// last bit, without what a mean does not need (A's BVH is built once; no vertex or edge
/// samples, topology or quality). The Pareto search measures hundreds of candidates this way.
pub struct MeanDistance<'a> {
    a: &'a Mesh,
    bvh_a: TriangleBvh,
    diagonal: f64,
    opts: CompareOptions,
}

impl<'a> MeanDistance<'a> {
    pub fn new(a: &'a Mesh, opts: &CompareOptions) -> Result<MeanDistance<'a>> {
        a.validate()
            .map_err(|e| Error::InvalidMesh(format!("mesh A: {e}")))?;
        if a.triangles.is_empty() {
            return Err(Error::InvalidMesh("mesh A has no faces".into()));
        }
        Ok(MeanDistance {
            a,
            bvh_a: TriangleBvh::new(a),
            diagonal: a.bounds().map_or(0.0, |bb| bb.diagonal()),
            opts: opts.clone(),
        })
    }

    /// `compare(A, b, opts).distance.two_sided.mean_rel`.
    pub fn mean_rel(&self, b: &Mesh) -> Result<f64> {
        if b.triangles.is_empty() || self.opts.samples == Some(0) {
            return Ok(compare(self.a, b, &self.opts)?.distance.two_sided.mean_rel);
        }
        let (fa, fb) = (self.a.face_count(), b.face_count());
        let (na, nb) = (
            self.opts.face_samples(fa, fb),
            self.opts.face_samples(fb, fa),
        );
        let seed = self.opts.seed;
        let bvh_b = TriangleBvh::new(b);
        let (ab, ba) = rayon::join(
            || distance::one_direction(self.a, &bvh_b, na, false, seed, self.diagonal),
            || {
                let seed_ba = seed ^ SEED_BA;
                distance::one_direction(b, &self.bvh_a, nb, false, seed_ba, self.diagonal)
            },
        );
        if ab.face_samples == 0 || ba.face_samples == 0 {
            // A surface of no area: its mean comes from vertex and edge samples.
            return Ok(compare(self.a, b, &self.opts)?.distance.two_sided.mean_rel);
        }
        Ok(Distances::two_sided(&ab.distances, &ba.distances, self.diagonal).mean_rel)
    }
}

/// Smallest angle (degrees) and aspect ratio of one face; `None` when it has no area.
fn face_shape(p: [[f64; 3]; 3]) -> Option<(f64, f64)> {
    let p = p.map(glam::DVec3::from_array);
    let (ab, bc, ca) = (p[1] - p[0], p[2] - p[1], p[0] - p[2]);
    let (la, lb, lc) = (ab.length(), bc.length(), ca.length());
    let twice_area = ab.cross(-ca).length();
    if twice_area <= 0.0 || !twice_area.is_finite() {
        return None;
    }
    // The smallest angle is opposite the shortest edge: sin = 2·area / (product of the others).
    let (short, o1, o2) = if la <= lb && la <= lc {
        (la, lb, lc)
    } else if lb <= lc {
        (lb, la, lc)
    } else {
        (lc, la, lb)
    };
    // atan2 of (sin, cos) is accurate for tiny and near-right angles alike.
    let cos = (o1 * o1 + o2 * o2 - short * short) / (2.0 * o1 * o2);
    let sin = twice_area / (o1 * o2);
    let angle = sin.atan2(cos).to_degrees();
    // R / (2r) = abc·s / (8·K²), with s the semi-perimeter and K the area.
    let k = 0.5 * twice_area;
    let s = 0.5 * (la + lb + lc);
    let aspect = la * lb * lc * s / (8.0 * k * k);
    Some((angle, aspect))
}

/// A mesh's triangle quality: smallest angles, aspect ratios and valences.
pub fn triangle_quality(m: &Mesh) -> TriangleQuality {
    let mut counts = [0usize; ASPECT_RATIO_BINS.len()];
    let mut min_angle = f64::INFINITY;
    let mut angle_sum = 0.0;
    let mut good = 0usize;
    let mut degenerate = 0usize;
    let mut max_aspect: f64 = 1.0;
    let (mut under_30, mut under_10) = (0usize, 0usize);
    for t in &m.triangles {
        let p = t.map(|v| m.positions[v as usize].map(|c| c as f64));
        match face_shape(p) {
            Some((angle, aspect)) => {
                under_30 += (angle < 30.0) as usize;
                under_10 += (angle < 10.0) as usize;
                min_angle = min_angle.min(angle);
                angle_sum += angle;
                good += 1;
                max_aspect = max_aspect.max(aspect);
                let bin = ASPECT_RATIO_BINS
                    .iter()
                    .position(|&u| aspect < u)
                    .unwrap_or(ASPECT_RATIO_BINS.len() - 1);
                counts[bin] += 1;
            }
            None => {
                degenerate += 1;
                counts[ASPECT_RATIO_BINS.len() - 1] += 1;
            }
        }
    }
    if degenerate > 0 {
        max_aspect = f64::INFINITY;
    }
    let share = |k: usize| k as f64 / m.triangles.len().max(1) as f64;
    let (valence_histogram, regular_valence_share) = valences(m);
    TriangleQuality {
        share_under_30_deg: share(under_30 + degenerate),
        share_under_10_deg: share(under_10 + degenerate),
        valence_histogram,
        regular_valence_share,
        min_angle_deg: if good > 0 { min_angle } else { 0.0 },
        mean_min_angle_deg: if good > 0 {
            angle_sum / good as f64
        } else {
            0.0
        },
        degenerate_faces: degenerate,
        aspect_ratio_histogram: ASPECT_RATIO_BINS
            .iter()
            .zip(counts)
            .map(|(&u, count)| HistogramBin {
                upper: u.is_finite().then_some(u),
                count,
            })
            .collect(),
        max_aspect_ratio: max_aspect.is_finite().then_some(max_aspect),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equilateral_triangle_has_60_degrees_and_aspect_1() {
        let h = 3f64.sqrt() / 2.0;
        let (angle, aspect) =
            face_shape([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, h, 0.0]]).unwrap();
        assert!((angle - 60.0).abs() < 1e-9, "{angle}");
        assert!((aspect - 1.0).abs() < 1e-12, "{aspect}");
        // Right isosceles: 45 degrees, R/(2r) = (sqrt(2)/2) / (2 · (1 - sqrt(2)/2)) = (1 + sqrt(2))/2.
        let (angle, aspect) =
            face_shape([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]).unwrap();
        assert!((angle - 45.0).abs() < 1e-9, "{angle}");
        assert!(
            (aspect - (1.0 + 2f64.sqrt()) / 2.0).abs() < 1e-12,
            "{aspect}"
        );
        assert!(face_shape([[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]]).is_none());
    }

    /// An icosphere has 12 vertices of valence 5 and the rest 6; a lone triangle's corners
    /// are border vertices of valence 2; slivers count under 30 and 10 degrees, and so do
    /// degenerate faces.
    #[test]
    fn valences_and_small_angle_shares() {
        let m = crate::mesh::icosphere(2);
        let q = triangle_quality(&m);
        let n = m.positions.len();
        assert_eq!(
            q.valence_histogram,
            [
                ValenceBin {
                    valence: 5,
                    interior: 12,
                    border: 0
                },
                ValenceBin {
                    valence: 6,
                    interior: n - 12,
                    border: 0
                }
            ]
        );
        assert!((q.regular_valence_share - (n - 12) as f64 / n as f64).abs() < 1e-12);
        assert_eq!((q.share_under_30_deg, q.share_under_10_deg), (0.0, 0.0));

        let lone = Mesh {
            positions: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.5, 0.05, 0.0],
                [3.0, 0.0, 0.0],
                [4.0, 0.0, 0.0],
                [3.0, 0.3, 0.0],
                [5.0, 0.0, 0.0],
            ],
            // A sliver (about 5.7 degrees), a 16.7-degree triangle, and a face with no area.
            triangles: vec![[0, 1, 2], [3, 4, 5], [4, 6, 4]],
            ..Mesh::default()
        };
        let q = triangle_quality(&lone);
        assert_eq!(q.share_under_30_deg, 1.0);
        assert!((q.share_under_10_deg - 2.0 / 3.0).abs() < 1e-12);
        assert_eq!(q.degenerate_faces, 1);
        // The degenerate face adds the edge 4-6 twice (so not a border edge): vertex 4 has
        // valence 3, vertex 6 valence 1.
        let by = |k: usize| q.valence_histogram.iter().find(|b| b.valence == k).cloned();
        assert_eq!(by(1).map(|b| (b.interior, b.border)), Some((1, 0)));
        assert_eq!(by(2).map(|b| b.border), Some(5));
        assert_eq!(by(3).map(|b| b.border), Some(1));
        assert_eq!(q.regular_valence_share, 0.0);
    }
}
