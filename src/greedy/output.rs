//! The output mesh built from the final state.

use super::prepare::Prepared;
use crate::mesh::Mesh;

/// The output mesh: live faces with their materials and groups, positions moved back out of the
/// normalized frame, unused vertices dropped, normals recomputed when the input had normals.
pub(crate) fn build_output(
    p: &Prepared,
    face_alive: &[bool],
    vertex_alive: &[bool],
    normals: bool,
) -> Mesh {
    let mut out = p.mesh.clone_without_geometry();
    out.positions = p.mesh.positions.clone();
    out.uvs = p.mesh.uvs.clone();
    out.colors = p.mesh.colors.clone();
    for (v, pos) in out.positions.iter_mut().enumerate() {
        let t = p.topo[v] as usize;
        // Only moved vertices go back through the frame: a round trip through f64 could shift
        // a vertex that stayed (a locked border, a seam) by one float step.
        if vertex_alive[t] && p.pos[t] != p.normalize(*pos) {
            *pos = p.denormalize(p.pos[t]);
        }
    }
    let live: Vec<usize> = (0..p.faces.len()).filter(|&f| face_alive[f]).collect();
    out.triangles = live.iter().map(|&f| p.faces[f]).collect();
    let origin = |f: usize| p.face_origin[f] as usize;
    out.face_materials = p
        .mesh
        .face_materials
        .as_ref()
        .map(|m| live.iter().map(|&f| m[origin(f)]).collect());
    out.face_groups = p
        .mesh
        .face_groups
        .as_ref()
        .map(|g| live.iter().map(|&f| g[origin(f)]).collect());
    out.remove_unused_vertices();
    if normals {
        out.recompute_normals();
    }
    out
}
