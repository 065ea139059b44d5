//! `tiles merge`: the simplified tiles welded by their border vertices' global ids, then
//! simplified as one mesh to the target, the former borders free, so that no seam of pinned
//! full-resolution vertices survives.

use super::{Manifest, at, read_ids};
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::{SimplifyOptions, SimplifyReport};
use rustc_hash::FxHashMap;
use serde::Serialize;
use std::path::Path;

/// What the merge did.
#[derive(Debug, Clone, Serialize)]
pub struct MergeReport {
    /// Faces of the welded tiles, before the final simplification.
    pub welded_faces: usize,
    pub welded_vertices: usize,
    /// Border vertices that more than one tile shared and the weld joined.
    pub joined_vertices: usize,
    /// The final simplification of the welded tiles.
    pub simplify: SimplifyReport,
}

/// Welds the simplified tiles of `dir` and simplifies them to the manifest's target.
pub fn merge(dir: &Path, progress: &mut dyn FnMut(f32)) -> Result<(Mesh, MergeReport)> {
    let m = Manifest::read(dir)?;
    let (welded, joined) = weld(dir, &m)?;
    progress(0.1);
    let opts = SimplifyOptions {
        backend: m.backend()?,
        ..SimplifyOptions::with_faces(m.target_faces as usize)
    };
    let (out, simplify) =
        crate::simplify_with_progress(&welded, &opts, &mut |f| progress(0.1 + 0.9 * f))?;
    Ok((
        out,
        MergeReport {
            welded_faces: welded.triangles.len(),
            welded_vertices: welded.positions.len(),
            joined_vertices: joined,
            simplify,
        },
    ))
}

/// The simplified tiles of `dir` welded, before the merge simplifies them: the seams of pinned
/// vertices still there (examples/tiles_borders.rs shows them).
pub fn welded(dir: &Path) -> Result<Mesh> {
    Ok(weld(dir, &Manifest::read(dir)?)?.0)
}

/// The tiles' outputs in index order as one mesh, vertices with the same global id joined;
/// also how many vertices were joined to one of an earlier tile.
fn weld(dir: &Path, m: &Manifest) -> Result<(Mesh, usize)> {
    let mut out = Mesh::default();
    let mut by_gid: FxHashMap<u32, u32> = FxHashMap::default();
    let mut joined = 0;
    for (i, t) in m.tile.iter().enumerate() {
        let path = at(dir, &t.output);
        if !path.is_file() {
            return Err(Error::InvalidOption(format!(
                "tile {i} has no output yet ({}): run `meshslim tiles simplify {} --index {i}`, \
                 or `meshslim tiles run {}`",
                path.display(),
                dir.display(),
                dir.display()
            )));
        }
        let mesh = crate::io::read(&path)?;
        let ids_path = at(dir, &t.output_ids);
        let ids = read_ids(&ids_path)?;
        if ids.len() != mesh.positions.len() {
            return Err(Error::parse(
                &ids_path,
                crate::Location::Unknown,
                format!(
                    "{} ids for the tile's {} output vertices: simplify tile {i} again",
                    ids.len(),
                    mesh.positions.len()
                ),
            ));
        }
        let map: Vec<u32> = mesh
            .positions
            .iter()
            .zip(&ids)
            .map(|(&p, &g)| {
                let fresh = out.positions.len() as u32;
                let v = if g == u32::MAX {
                    fresh
                } else {
                    *by_gid.entry(g).or_insert(fresh)
                };
                if v == fresh {
                    out.positions.push(p);
                } else {
                    joined += 1;
                }
                v
            })
            .collect();
        out.triangles
            .extend(mesh.triangles.iter().map(|t| t.map(|v| map[v as usize])));
    }
    Ok((out, joined))
}
