//! The indexed triangle mesh every backend and format shares.
//!
//! Positions are f32 and indices u32, the layout GPU buffers use, so a mesh can be uploaded as is.
//! Attributes are optional and per vertex; materials and groups are per face. A vertex is one
//! combination of position and attributes: two vertices may share a position (an attribute seam).

mod first_use;
mod generate;
pub(crate) mod morton;
pub mod prepare;
pub mod sort;
pub(crate) mod topology;
pub(crate) mod weld;

pub(crate) use first_use::first_use;
pub use generate::*;
pub use topology::{Topology, topology};
pub use weld::{WeldResult, weld, weld_positions};

use crate::error::{Error, Result};
use glam::{DVec3, Vec3};

/// A named material, as OBJ `usemtl`/glTF materials name them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Material {
    pub name: String,
    /// The glTF material object as read, but for its name (PBR factors, texture references
    /// into [`Mesh::textures`], alpha mode, extensions), written back as it was; `None` for
    /// materials from OBJ (whose definitions stay in the `mtllib` file) and glTF materials that
    /// are only a name.
    pub gltf: Option<serde_json::Value>,
}

impl Material {
    pub fn named(name: impl Into<String>) -> Material {
        Material {
            name: name.into(),
            gltf: None,
        }
    }
}

/// The textures glTF materials refer to, carried through simplification so that a textured
/// scan comes out textured.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Textures {
    /// glTF `textures` entries as read: `source` and `sampler` index the lists below.
    pub textures: Vec<serde_json::Value>,
    /// glTF `samplers` entries as read.
    pub samplers: Vec<serde_json::Value>,
    pub images: Vec<TextureImage>,
    /// The glTF extensions the file required; the writer declares those the objects it writes
    /// still use (and every extension they use in `extensionsUsed`).
    pub extensions_required: Vec<String>,
}

impl Textures {
    pub fn is_empty(&self) -> bool {
        self.textures.is_empty() && self.samplers.is_empty() && self.images.is_empty()
    }
}

/// One texture image: its encoded bytes (PNG, JPEG, ...), embedded in the file or read from
/// the file its URI names; or, when that file could not be read, the URI alone.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TextureImage {
    pub name: Option<String>,
    pub mime_type: Option<String>,
    /// Shared: images naming the same bytes, and every copy of a mesh (welding, simplifying,
    /// the viewer's levels), hold one allocation.
    pub data: Option<std::sync::Arc<[u8]>>,
    /// The URI as the file gave it (none for an image embedded in a buffer view).
    pub uri: Option<String>,
}

/// An indexed triangle mesh.
///
/// Invariants (checked by [`Mesh::validate`], which readers call before returning):
/// every index < `positions.len()`, every optional attribute array is `positions.len()` long,
/// every per-face array is `triangles.len()` long, every material/group id is in range.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mesh {
    pub positions: Vec<[f32; 3]>,
    pub triangles: Vec<[u32; 3]>,
    pub normals: Option<Vec<[f32; 3]>>,
    pub uvs: Option<Vec<[f32; 2]>>,
    /// Which corner of the texture image `uvs` count from, as the file they came from does:
    /// kept as read, so a mesh written back in its own format has the same UVs bit for bit,
    /// and converted (v → 1 − v) only when it is written in a format of the other convention.
    /// The default (`BottomLeft`) when there are no UVs.
    pub uv_origin: UvOrigin,
    /// Linear RGBA in 0..=1.
    pub colors: Option<Vec<[f32; 4]>>,
    /// Per-face index into `materials`.
    pub face_materials: Option<Vec<u32>>,
    pub materials: Vec<Material>,
    /// OBJ `mtllib` file names, written back as they were read.
    pub material_libs: Vec<String>,
    /// Per-face index into `groups` (OBJ `o`/`g`, glTF meshes).
    pub face_groups: Option<Vec<u32>>,
    pub groups: Vec<String>,
    /// Textures the materials use (glTF).
    pub textures: Textures,
}

/// Where UV (0, 0) is in the texture image.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum UvOrigin {
    /// OBJ, PLY (and OpenGL): the bottom-left corner, v grows upwards.
    #[default]
    BottomLeft,
    /// glTF (and Vulkan, DirectX, Metal images): the top-left corner, v grows downwards.
    TopLeft,
}

impl UvOrigin {
    /// "bottom-left" or "top-left".
    pub fn name(self) -> &'static str {
        match self {
            UvOrigin::BottomLeft => "bottom-left",
            UvOrigin::TopLeft => "top-left",
        }
    }
}

/// Axis-aligned bounding box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    pub min: [f32; 3],
    pub max: [f32; 3],
}

impl Aabb {
    pub fn diagonal(&self) -> f64 {
        sub64(self.max, self.min).length()
    }
    pub fn center(&self) -> [f64; 3] {
        [0, 1, 2].map(|i| (self.min[i] as f64 + self.max[i] as f64) * 0.5)
    }
}

/// `a - b` in f64.
fn sub64(a: [f32; 3], b: [f32; 3]) -> DVec3 {
    Vec3::from_array(a).as_dvec3() - Vec3::from_array(b).as_dvec3()
}

impl Mesh {
    /// A mesh of positions and triangles only.
    pub fn new(positions: Vec<[f32; 3]>, triangles: Vec<[u32; 3]>) -> Self {
        Mesh {
            positions,
            triangles,
            ..Default::default()
        }
    }

    /// The UVs counted from `origin`: borrowed when that is how they are stored, else flipped
    /// (v → 1 − v, in f64 so that 1 − v rounds once).
    pub fn uvs_from(&self, origin: UvOrigin) -> Option<std::borrow::Cow<'_, [[f32; 2]]>> {
        let uvs = self.uvs.as_deref()?;
        Some(if origin == self.uv_origin {
            std::borrow::Cow::Borrowed(uvs)
        } else {
            std::borrow::Cow::Owned(
                uvs.iter()
                    .map(|&[u, v]| [u, (1.0 - v as f64) as f32])
                    .collect(),
            )
        })
    }

    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    pub fn face_count(&self) -> usize {
        self.triangles.len()
    }

    /// Checks the structural invariants listed on [`Mesh`] and that every position is finite.
    pub fn validate(&self) -> Result<()> {
        let n = self.positions.len();
        if n > u32::MAX as usize {
            return Err(Error::InvalidMesh(format!(
                "{n} vertices exceed the u32 index range"
            )));
        }
        // The first offending index, found on every core a chunk at a time: each chunk is
        // first checked by a plain loop the compiler vectorizes, and searched only when it
        // fails. Per item through rayon's `position_first` this took 0.011 s on the 1M scan
        // (`cluster` takes 0.08 s), this 0.001 s.
        use rayon::prelude::*;
        const CHUNK: usize = 1 << 14;
        let finite = |p: &[f32; 3]| p.iter().all(|c| c.is_finite());
        if let Some(i) = self
            .positions
            .par_chunks(CHUNK)
            .enumerate()
            .find_map_first(|(c, ps)| {
                let all = ps.iter().fold(true, |ok, p| ok & finite(p));
                (!all).then(|| {
                    c * CHUNK + ps.iter().position(|p| !finite(p)).expect("a failed chunk")
                })
            })
        {
            return Err(Error::InvalidMesh(format!(
                "vertex {i} has a non-finite coordinate {:?}",
                self.positions[i]
            )));
        }
        if let Some(f) = self
            .triangles
            .par_chunks(CHUNK)
            .enumerate()
            .find_map_first(|(c, ts)| {
                let top = ts.iter().fold(0u32, |m, t| m.max(t[0]).max(t[1]).max(t[2]));
                ((top as usize) >= n).then(|| {
                    let inside = |t: &[u32; 3]| t.iter().all(|&v| (v as usize) < n);
                    c * CHUNK + ts.iter().position(|t| !inside(t)).expect("a failed chunk")
                })
            })
        {
            let v = self.triangles[f]
                .into_iter()
                .find(|&v| v as usize >= n)
                .expect("the face found has an index out of range");
            return Err(Error::InvalidMesh(format!(
                "face {f} refers to vertex {v}, but the mesh has only {n} vertices"
            )));
        }
        let check_len = |name: &str, len: Option<usize>, want: usize| match len {
            Some(l) if l != want => Err(Error::InvalidMesh(format!(
                "{name} has {l} entries, expected {want}"
            ))),
            _ => Ok(()),
        };
        check_len("normals", self.normals.as_ref().map(Vec::len), n)?;
        check_len("uvs", self.uvs.as_ref().map(Vec::len), n)?;
        check_len("colors", self.colors.as_ref().map(Vec::len), n)?;
        // Attributes enter the collapse cost: a NaN there would poison every quadric near it.
        let bad = |name: &str, i: usize, v: &[f32]| {
            Err(Error::InvalidMesh(format!("vertex {i} has {name} {v:?}")))
        };
        if let Some(i) = self
            .normals
            .as_ref()
            .and_then(|a| a.iter().position(|x| !x.iter().all(|c| c.is_finite())))
        {
            return bad("a non-finite normal", i, &self.normals.as_ref().unwrap()[i]);
        }
        if let Some(i) = self
            .uvs
            .as_ref()
            .and_then(|a| a.iter().position(|x| !x.iter().all(|c| c.is_finite())))
        {
            return bad("a non-finite UV", i, &self.uvs.as_ref().unwrap()[i]);
        }
        if let Some(i) = self.colors.as_ref().and_then(|a| {
            a.iter()
                .position(|x| !x.iter().all(|c| (0.0..=1.0).contains(c)))
        }) {
            return bad(
                "a colour outside 0..1 (or not a number)",
                i,
                &self.colors.as_ref().unwrap()[i],
            );
        }
        let nf = self.triangles.len();
        check_len(
            "face_materials",
            self.face_materials.as_ref().map(Vec::len),
            nf,
        )?;
        check_len("face_groups", self.face_groups.as_ref().map(Vec::len), nf)?;
        // The first face whose id is not below `defined`, and that id.
        let undefined = |ids: &Option<Vec<u32>>, defined: usize| {
            let ids = ids.as_ref()?;
            let f = ids.iter().position(|&i| i as usize >= defined)?;
            Some((f, ids[f], defined))
        };
        if let Some((f, m, n)) = undefined(&self.face_materials, self.materials.len()) {
            return Err(Error::InvalidMesh(format!(
                "face {f} uses material {m}, but only {n} are defined"
            )));
        }
        if let Some((f, g, n)) = undefined(&self.face_groups, self.groups.len()) {
            return Err(Error::InvalidMesh(format!(
                "face {f} is in group {g}, but only {n} are defined"
            )));
        }
        Ok(())
    }

    /// Bounding box of the positions; `None` for a mesh without vertices.
    pub fn bounds(&self) -> Option<Aabb> {
        let first = *self.positions.first()?;
        let mut b = Aabb {
            min: first,
            max: first,
        };
        for p in &self.positions {
            b.min = [0, 1, 2].map(|i| b.min[i].min(p[i]));
            b.max = [0, 1, 2].map(|i| b.max[i].max(p[i]));
        }
        Some(b)
    }

    /// Twice the area vector (cross product of two edges) of face `f`, in f64.
    pub fn face_cross(&self, f: usize) -> [f64; 3] {
        let [a, b, c] = self.triangles[f].map(|v| self.positions[v as usize]);
        sub64(b, a).cross(sub64(c, a)).to_array()
    }

    pub fn face_area(&self, f: usize) -> f64 {
        0.5 * DVec3::from_array(self.face_cross(f)).length()
    }

    /// Unit normal of face `f`, or `None` when the face has no area.
    pub fn face_normal(&self, f: usize) -> Option<[f64; 3]> {
        let c = DVec3::from_array(self.face_cross(f));
        let l = c.length();
        (l > 0.0 && l.is_finite()).then(|| (c / l).to_array())
    }

    pub fn surface_area(&self) -> f64 {
        (0..self.triangles.len()).map(|f| self.face_area(f)).sum()
    }

    /// Signed volume by the divergence theorem; positive for a closed mesh with outward faces.
    /// Computed relative to the bounding-box centre so that far-away meshes keep precision.
    pub fn signed_volume(&self) -> f64 {
        let Some(b) = self.bounds() else { return 0.0 };
        let o = DVec3::from_array(b.center());
        let rel = |v: u32| Vec3::from_array(self.positions[v as usize]).as_dvec3() - o;
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(rel);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    /// Recomputes per-vertex normals as the area-weighted mean of the incident face normals.
    /// Vertices split at a seam keep their own side's normal, since they are separate vertices.
    pub fn recompute_normals(&mut self) {
        let mut acc = vec![DVec3::ZERO; self.positions.len()];
        for f in 0..self.triangles.len() {
            let c = DVec3::from_array(self.face_cross(f));
            for &v in &self.triangles[f] {
                acc[v as usize] += c;
            }
        }
        self.normals = Some(
            acc.into_iter()
                .map(|n| {
                    let l = n.length();
                    if l > 0.0 {
                        (n / l).as_vec3().to_array()
                    } else {
                        [0.0, 0.0, 1.0]
                    }
                })
                .collect(),
        );
    }

    /// Drops vertices no face uses, renumbering the rest in order of first use by the faces
    /// (a cache-friendly order for the output). Attributes follow their vertices.
    pub fn remove_unused_vertices(&mut self) {
        use rayon::prelude::*;
        let (order, place) = first_use(&self.triangles, self.positions.len(), |t| *t);
        self.triangles
            .par_iter_mut()
            .with_min_len(1 << 14)
            .for_each(|t| *t = t.map(|v| place[v as usize]));
        self.positions = pick(&order, &self.positions);
        self.normals = self.normals.as_deref().map(|s| pick(&order, s));
        self.uvs = self.uvs.as_deref().map(|s| pick(&order, s));
        self.colors = self.colors.as_deref().map(|s| pick(&order, s));
    }
}

/// The entries of `src` at `order`, in that order (a renumbering's vertex data), on every core.
pub(crate) fn pick<T: Copy + Send + Sync>(order: &[u32], src: &[T]) -> Vec<T> {
    use rayon::prelude::*;
    order
        .par_iter()
        .with_min_len(1 << 14)
        .map(|&v| src[v as usize])
        .collect()
}
