//! Cuts: the clusters a renderer draws at one threshold. A cluster is in the cut when its own
//! error passes the test and its group's fails it (a root's group always fails): since a
//! group's clusters and the clusters it made are tested with the same sphere and error, exactly
//! one of the two sets is drawn, and the surface stays closed (Karis 2021).

use super::{Cluster, Dag};
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

    /// The error `error` at the sphere `s` as seen from the eye, in pixels: its size at the
    /// sphere's nearest point (infinite from inside a sphere, unless the error is 0).
    pub fn projected(&self, s: [f32; 4], error: f32) -> f64 {
        if error <= 0.0 {
            return 0.0;
        }
        let d = (0..3)
            .map(|i| (s[i] as f64 - self.eye[i]).powi(2))
            .sum::<f64>()
            .sqrt()
            - s[3] as f64;
        if d <= 0.0 || !error.is_finite() {
            return f64::INFINITY;
        }
        let per_unit = self.height / (2.0 * (self.fov_deg.to_radians() * 0.5).tan());
        error as f64 / d * per_unit
    }
}

impl Dag {
    /// The clusters whose own error is at most `threshold` (mesh units) and whose group's is
    /// over it.
    pub fn cut_at_error(&self, threshold: f64) -> Vec<u32> {
        self.select(|c| c.error as f64 <= threshold && self.group_error(c) as f64 > threshold)
    }

    /// The clusters whose projected error from `cam` is at most `cam.pixels` and whose group's
    /// is over it.
    pub fn cut_from_camera(&self, cam: &CameraCut) -> Vec<u32> {
        self.select(|c| {
            let own = cam.projected(c.lod_sphere, c.error);
            let group = match self.groups.get(c.group as usize) {
                Some(g) => cam.projected(g.sphere, g.error),
                None => f64::INFINITY,
            };
            own <= cam.pixels && group > cam.pixels
        })
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
