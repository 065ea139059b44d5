//! Per-corner extras for the renderer, which pulls each corner's vertex: the UV and the colour
//! a corner shows, for a mesh (through its attribute vertices) and a DAG's levels alike.

use super::render::pack_color;
use crate::mesh::{Mesh, UvOrigin};

/// Each corner's UV: that of its attribute vertex (see `crate::rounds::corner_attributes`), so a seam
/// vertex shows each side's own. Counted from the image's bottom-left corner, as the shader
/// samples them (glTF's are flipped here).
pub(super) fn corner_uvs(welded: &Mesh, corner_attr: &[u32]) -> Option<Vec<[f32; 2]>> {
    let uv = welded.uvs_from(UvOrigin::BottomLeft)?;
    Some(corner_attr.iter().map(|&a| uv[a as usize]).collect())
}

/// Each corner's vertex colour, packed for the renderer: that of the vertex of `mesh` each
/// corner names.
pub(super) fn corner_colors(mesh: &Mesh, corners: impl Iterator<Item = u32>) -> Option<Vec<u32>> {
    let c = mesh.colors.as_ref()?;
    Some(corners.map(|v| pack_color(c[v as usize])).collect())
}
