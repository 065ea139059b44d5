//! Cuts: the clusters a renderer draws at one threshold. A cluster is in the cut when its own
//! error passes the test and its group's fails it (a root's group always fails): since a
//! group's clusters and the clusters it made are tested with the same sphere and error, exactly
//! one of the two sets is drawn, and the surface stays closed (Karis 2021).

use super::{Cluster, Dag};
use crate::compute::types::{CornerDraw, CutCluster, CutParams};
use crate::error::{Error, Result};
use crate::mesh::Mesh;

/// A view-dependent cut's camera: projected error at most `pixels`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraCut {
    pub eye: [f64; 3],
    pub pixels: f64,
    /// Vertical field of view, degrees.
    pub fov_deg: f64,
    /// Viewport height, pixels.
    pub height: f64,
}

impl CameraCut {
    pub fn check(&self) -> Result<()> {
        let ok = self.eye.iter().all(|x| x.is_finite())
            && self.pixels.is_finite()
            && self.pixels > 0.0
            && self.fov_deg > 0.0
            && self.fov_deg < 180.0
            && self.height >= 1.0
            && self.height.is_finite();
        if ok {
            Ok(())
        } else {
            Err(Error::InvalidOption(format!(
                "camera cut needs a finite eye, pixels > 0, a field of view in (0, 180) degrees \
                 and a height of at least 1 pixel; got {self:?}"
            )))
        }
    }

    /// The camera as the cut stage's uniform, for `clusters` clusters and no frustum: the eye
    /// in f32 and the pixels per unit of error at unit distance over the threshold, which is
    /// all [`passes`] needs.
    pub fn params(&self, clusters: usize) -> CutParams {
        let per_unit = self.height / (2.0 * (self.fov_deg.to_radians() * 0.5).tan());
        let e = self.eye.map(|x| x as f32);
        CutParams {
            eye: [e[0], e[1], e[2], 0.0],
            planes: [[0.0, 0.0, 0.0, 1.0]; 6],
            scale: (per_unit / self.pixels) as f32,
            clusters: clusters as u32,
            cull: 0,
            number: 0,
        }
    }
}

impl Dag {
    /// The clusters whose own error is at most `threshold` (mesh units) and whose group's is
    /// over it.
    pub fn cut_at_error(&self, threshold: f64) -> Vec<u32> {
        self.select(|c| c.error as f64 <= threshold && self.group_error(c) as f64 > threshold)
    }

    /// The clusters whose projected error from `cam` is at most `cam.pixels` and whose group's
    /// is over it: the test the window's cut runs on the device ([`passes`], [`dag_cut`]), so
    /// the two agree cluster for cluster.
    pub fn cut_from_camera(&self, cam: &CameraCut) -> Vec<u32> {
        let p = cam.params(self.clusters.len());
        let clusters = self.cut_clusters();
        (0..clusters.len() as u32)
            .filter(|&i| in_cut(&p, &clusters[i as usize]))
            .collect()
    }

    /// The clusters as the cut stage reads them, each with its group's sphere and error.
    pub fn cut_clusters(&self) -> Vec<CutCluster> {
        self.clusters
            .iter()
            .map(|c| {
                let g = self.groups.get(c.group as usize);
                CutCluster {
                    lod_sphere: c.lod_sphere,
                    bounds: c.bounds,
                    group_sphere: g.map_or([0.0; 4], |g| g.sphere),
                    error: c.error,
                    group_error: g.map_or(0.0, |g| g.error),
                    first_triangle: c.first_triangle,
                    triangle_count: c.triangle_count,
                    root: g.is_none() as u32,
                    depth: c.depth,
                    _pad: [0; 2],
                }
            })
            .collect()
    }

    /// The finest object-space cut with at most `triangles` triangles (the root's cut when
    /// none is that small), and its threshold: the cut only changes at a group's error, so
    /// those are the thresholds tried, by bisection.
    pub fn cut_to_triangles(&self, triangles: usize) -> (Vec<u32>, f64) {
        let mut at: Vec<f64> = self.groups.iter().map(|g| g.error as f64).collect();
        at.push(0.0);
        at.sort_by(f64::total_cmp);
        at.dedup();
        let count = |t: f64| -> usize {
            self.cut_at_error(t)
                .iter()
                .map(|&c| self.clusters[c as usize].triangle_count as usize)
                .sum()
        };
        // The smallest threshold whose cut fits; the largest always does (the roots).
        let (mut lo, mut hi) = (0usize, at.len() - 1);
        while lo < hi {
            let mid = (lo + hi) / 2;
            if count(at[mid]) <= triangles {
                hi = mid;
            } else {
                lo = mid + 1;
            }
        }
        (self.cut_at_error(at[lo]), at[lo])
    }

    fn select(&self, keep: impl Fn(&Cluster) -> bool) -> Vec<u32> {
        (0..self.clusters.len() as u32)
            .filter(|&i| keep(&self.clusters[i as usize]))
            .collect()
    }

    /// The mesh of the clusters `ids`: their triangles, the vertices they use.
    pub fn mesh_of(&self, ids: &[u32]) -> Mesh {
        let mut m = self.mesh.clone();
        m.triangles = ids
            .iter()
            .flat_map(|&i| self.triangles(&self.clusters[i as usize]).iter().copied())
            .collect();
        m.remove_unused_vertices();
        m
    }
}

/// Whether the error `e` at the sphere `s` projects to at most the threshold of `p`, with no
/// square root or division, so the GPU's f32 gives the CPU's answer: `e * scale / (|s - eye| -
/// r) <= 1`, i.e. `(e * scale + r)^2 <= |s - eye|^2` (from inside the sphere the projection is
/// unbounded and the test fails, unless `e` is 0). Twin of `passes` in
/// shaders/dag/dag_cut.wgsl, term for term.
pub fn passes(p: &CutParams, s: [f32; 4], e: f32) -> bool {
    if e <= 0.0 {
        return true;
    }
    let d = [0, 1, 2].map(|i| s[i] - p.eye[i]);
    let reach = e * p.scale + s[3];
    reach * reach <= d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
}

/// Whether cluster `k` is in the cut: its own error passes, its group's does not (a root has
/// none, and is always coarse enough).
pub fn in_cut(p: &CutParams, k: &CutCluster) -> bool {
    passes(p, k.lod_sphere, k.error) && (k.root != 0 || !passes(p, k.group_sphere, k.group_error))
}

/// Whether the sphere `b` meets the frustum of `p`. Twin of `in_view` in
/// shaders/dag/dag_cut.wgsl.
pub fn in_view(p: &CutParams, b: [f32; 4]) -> bool {
    p.planes
        .iter()
        .all(|n| n[0] * b[0] + n[1] * b[1] + n[2] * b[2] + n[3] >= -b[3])
}

/// The frustum of the view-projection `view_proj` (clip depth 0..1, as wgpu's) as six planes,
/// inside where `n·p + w >= 0`, each scaled to a unit normal so a sphere's radius compares
/// with its distance (Gribb & Hartmann 2001); a plane with no normal (the far plane of an
/// infinite projection) holds everything.
pub fn frustum_planes(view_proj: glam::Mat4) -> [[f32; 4]; 6] {
    let r = [0, 1, 2, 3].map(|i| view_proj.row(i));
    [
        r[3] + r[0],
        r[3] - r[0],
        r[3] + r[1],
        r[3] - r[1],
        r[2],
        r[3] - r[2],
    ]
    .map(|p| {
        let len = p.truncate().length();
        if len > 0.0 && len.is_finite() {
            (p / len).to_array()
        } else {
            [0.0, 0.0, 0.0, 1.0]
        }
    })
}

/// Per cluster: whether it is in the cut for `p` and, with `p.cull`, in the view, as its
/// indirect draw over its corners (one instance when drawn, none otherwise); `counts` gets
/// the clusters in the cut, the clusters drawn and their triangles. Twin of `dag_cut` in
/// shaders/dag/dag_cut.wgsl.
pub fn dag_cut(
    p: &CutParams,
    clusters: &[CutCluster],
    draws: &mut [CornerDraw],
    counts: &mut [u32; 4],
) {
    *counts = [0; 4];
    for (c, (k, d)) in clusters.iter().zip(draws.iter_mut()).enumerate() {
        let cut = in_cut(p, k);
        let drawn = cut && (p.cull == 0 || in_view(p, k.bounds));
        *d = CornerDraw {
            vertex_count: 3 * k.triangle_count,
            instance_count: drawn as u32,
            first_vertex: 3 * k.first_triangle,
            first_instance: if p.number != 0 {
                (k.depth.min(255) << 24) | c as u32
            } else {
                0
            },
        };
        counts[0] += cut as u32;
        counts[1] += drawn as u32;
        counts[2] += if drawn { k.triangle_count } else { 0 };
    }
}
