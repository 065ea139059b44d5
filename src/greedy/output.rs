//! The output mesh built from the final state.

use super::prepare::Prepared;
use crate::mesh::Mesh;
use rayon::prelude::*;

/// What the output's normals are.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum OutputNormals {
    None,
    /// From the output's faces (the QEM methods move vertices).
    Recompute,
    /// The input's, per kept vertex (decimation keeps vertices where they were).
    Keep,
}

impl OutputNormals {
    pub(crate) fn recompute_if(had: bool) -> OutputNormals {
        if had {
            OutputNormals::Recompute
        } else {
            OutputNormals::None
        }
    }
}

/// The output mesh: live faces with their materials and groups, positions moved back out of the
/// normalized frame, unused vertices dropped, normals as `normals` says.
pub(crate) fn build_output(
    p: &Prepared,
    face_alive: &[bool],
    vertex_alive: &[bool],
    normals: OutputNormals,
) -> Mesh {
    let mut out = p.mesh.clone_without_geometry();
    out.positions = p.mesh.positions.clone();
    out.uvs = p.mesh.uvs.clone();
    out.colors = p.mesh.colors.clone();
    if normals == OutputNormals::Keep {
        out.normals = p.mesh.normals.clone();
    }
    // Solved normals (a normal weight above zero) are the output's; otherwise they are made
    // again from the output's faces.
    let solved_normals = p.attrs.as_ref().is_some_and(|a| a.layout.normal);
    if solved_normals {
        out.normals = p.mesh.normals.clone();
    }
    if let Some(at) = &p.attrs {
        at.write(&mut out);
    }
    // Each vertex and face on its own, so on every core.
    out.positions
        .par_iter_mut()
        .enumerate()
        .with_min_len(1 << 14)
        .for_each(|(v, pos)| {
            let t = p.topo[v] as usize;
            // Only moved vertices go back through the frame: a round trip through f64 could
            // shift a vertex that stayed (a locked border, a seam) by one float step.
            if vertex_alive[t] && p.pos[t] != p.normalize(*pos) {
                *pos = p.denormalize(p.pos[t]);
            }
        });
    let live: Vec<usize> = (0..p.faces.len())
        .into_par_iter()
        .with_min_len(1 << 14)
        .filter(|&f| face_alive[f])
        .collect();
    out.triangles = live.par_iter().map(|&f| p.faces[f]).collect();
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
    if normals == OutputNormals::Recompute && !solved_normals {
        out.recompute_normals();
    }
    out
}
