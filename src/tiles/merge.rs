//! `tiles merge`: the simplified tiles welded by their border vertices' global ids, then
//! simplified as one mesh to the target, the former borders free, so that no seam of pinned
//! full-resolution vertices survives.

use super::{Manifest, at, read_ids_for};
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::{SimplifyOptions, SimplifyReport};
use rustc_hash::FxHashMap;
use serde::Serialize;
use std::path::Path;

/// Heap bytes the greedy holds per face of the mesh it simplifies, the mesh included: 1.44 GB
/// for the 4.3M scan at 1% (`/usr/bin/time -f %M meshslim simplify scan-4m.ply o.ply --ratio
/// 0.01`: 1,436,060 KiB, 342 B a face), rounded up.
pub const GREEDY_BYTES_PER_FACE: u64 = 360;

/// What the merge did.
#[derive(Debug, Clone, Serialize)]
pub struct MergeReport {
    /// Faces of the welded tiles, before the final simplification.
    pub welded_faces: usize,
    pub welded_vertices: usize,
    /// Border vertices that more than one tile shared and the weld joined.
    pub joined_vertices: usize,
    /// What the greedy over the welded tiles would hold, and the budget it had.
    pub needed_bytes: u64,
    pub memory_budget: u64,
    /// When that did not fit: the coarser level's tiles (in `DIR/coarser`) and its merge.
    pub coarser: Option<Box<MergeReport>>,
    /// The final simplification of the welded tiles; `None` on a coarser level that still did
    /// not fit, whose welded tiles are the result (their seams at its cuts, at twice the
    /// target's density, not the input's).
    pub simplify: Option<SimplifyReport>,
}

/// Welds the simplified tiles of `dir` and simplifies them to the manifest's target, within
/// `memory` bytes (else through a coarser level of tiles, see the module).
pub fn merge(
    dir: &Path,
    memory: u64,
    progress: &mut dyn FnMut(f32),
) -> Result<(Mesh, MergeReport)> {
    let m = Manifest::read(dir)?;
    let (welded, joined) = weld(dir, &m)?;
    progress(0.1);
    let needed = welded.triangles.len() as u64 * GREEDY_BYTES_PER_FACE;
    let mut report = MergeReport {
        welded_faces: welded.triangles.len(),
        welded_vertices: welded.positions.len(),
        joined_vertices: joined,
        needed_bytes: needed,
        memory_budget: memory,
        coarser: None,
        simplify: None,
    };
    let coarser = m.shift != [0.0; 3];
    if needed > memory && m.tiles > 1 && !coarser {
        let (out, coarser) = coarser_level(dir, &m, welded, memory, progress)?;
        report.coarser = Some(Box::new(coarser));
        return Ok((out, report));
    }
    if needed > memory && coarser {
        // A coarser level that still does not fit: its tiles went to the target already.
        return Ok((welded, report));
    }
    // Over the budget with one tile (nothing to tile again), or within it: the greedy.
    let opts = SimplifyOptions {
        backend: m.backend()?,
        ..SimplifyOptions::with_faces(m.target_faces as usize)
    };
    let (out, simplify) =
        crate::simplify_with_progress(&welded, &opts, &mut |f| progress(0.1 + 0.9 * f))?;
    report.simplify = Some(simplify);
    Ok((out, report))
}

/// The welded tiles written out and tiled again in `dir/coarser`: a quarter of the tiles (at
/// least two), the cuts moved away from the first level's, each tile to its share of the
/// target; then merged.
fn coarser_level(
    dir: &Path,
    m: &Manifest,
    welded: Mesh,
    memory: u64,
    progress: &mut dyn FnMut(f32),
) -> Result<(Mesh, MergeReport)> {
    let level = dir.join("coarser");
    std::fs::create_dir_all(&level).map_err(|e| Error::io(&level, e))?;
    let input = level.join("welded.ply");
    crate::io::write(&input, &welded)?;
    drop(welded);
    let opts = super::SplitOptions {
        share: 1.0,
        after: Some(m.grid),
        backend: m.backend()?,
        ..super::SplitOptions::new(
            (m.tiles / 4).max(2),
            crate::cluster::stream::Target::Faces(m.target_faces as usize),
        )
    };
    let c = super::split(&input, &level, &opts, &mut |f| progress(0.1 + 0.1 * f))?;
    std::fs::remove_file(&input).map_err(|e| Error::io(&input, e))?;
    for i in 0..c.tiles {
        super::simplify_tile(&level, i, &mut |_| {})?;
        progress(0.2 + 0.7 * (i + 1) as f32 / c.tiles as f32);
    }
    merge(&level, memory, &mut |f| progress(0.9 + 0.1 * f))
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
    // Colours when every tile has them (a split of a coloured scan).
    let mut colors: Option<Vec<[f32; 4]>> = Some(Vec::new());
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
        let ids = read_ids_for(&at(dir, &t.output_ids), mesh.positions.len(), i)?;
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
        // A joined vertex is a pinned border vertex: every tile kept its colour as read.
        colors = match (colors, &mesh.colors) {
            (Some(mut all), Some(c)) => {
                let mut seen = all.len();
                for (v, &m) in map.iter().enumerate() {
                    if m as usize == seen {
                        all.push(c[v]);
                        seen += 1;
                    }
                }
                Some(all)
            }
            _ => None,
        };
        out.triangles
            .extend(mesh.triangles.iter().map(|t| t.map(|v| map[v as usize])));
    }
    out.colors = colors.filter(|c| c.len() == out.positions.len());
    Ok((out, joined))
}
