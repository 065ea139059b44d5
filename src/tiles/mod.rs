//! Tiles: a scan cut into spatial tiles that independent jobs simplify apart (a Slurm array, a
//! Kubernetes Indexed Job, or `tiles run` on one machine), then welded and simplified again
//! across the former borders.
//!
//! The scheme is Hoppe's for terrain ("Smooth view-dependent level-of-detail control and its
//! application to terrain rendering", IEEE Visualization 1998): blocks simplified with their
//! shared borders preserved, then stitched, then simplified again so that no seam of
//! full-resolution vertices survives. Here:
//! - [`split`] streams the input (the positions held, the faces read twice in blocks) and
//!   writes each tile as a binary PLY of the faces whose centroid falls in its cell of a grid
//!   over the box, with its vertices' global ids beside it, and a manifest naming each tile's
//!   border vertices (those on faces of more than one tile).
//! - [`simplify_tile`] simplifies one tile with its border vertices pinned
//!   ([`crate::SimplifyOptions::pin`]): they neither move nor go, so the neighbours still meet
//!   there. Each tile is simplified to [`TILE_SHARE`] times its share of the target, leaving the
//!   merge room to thin the seams like the rest. A tile's output depends only on its files and
//!   the manifest, so the result is the same whoever ran it.
//! - [`merge`] welds the tiles' outputs by the border vertices' global ids and runs the greedy
//!   over the whole to the target, borders free. When the greedy over the welded mesh would
//!   need more than the memory budget, it is tiled again, coarser, with the cuts moved away from the first level's, so its
//!   seams are simplified inside the second level's tiles (meshoptimizer's clusterlod and
//!   Nanite regroup the same way); the second level's tiles go straight to the target.

mod merge;
mod simplify;
mod split;

pub use merge::{GREEDY_BYTES_PER_FACE, MergeReport, merge, welded};
pub use simplify::{TileReport, simplify_tile};
pub use split::{SplitOptions, split};

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The manifest's file name in a tiles folder.
pub const MANIFEST: &str = "manifest.json";
/// The manifest's `format` field; a reader refuses any other.
pub const FORMAT: &str = "meshslim-tiles/1";
/// Each tile is simplified to this many times its share of the final target, so the merge still
/// has collapses to make across the seams (pinned vertices and their strip of faces): measured
/// on the 4.3M scan at 1% in 16 tiles, 2 gave a mean distance within 1.1x the whole-mesh
/// greedy's (docs/PERFORMANCE.md, "Tiles").
pub const TILE_SHARE: f64 = 2.0;

/// What `tiles split` wrote and every later step reads.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// [`FORMAT`].
    pub format: String,
    /// The input file, as given to `split`.
    pub input: String,
    pub input_faces: u64,
    pub input_vertices: u64,
    /// The faces the merge stops at.
    pub target_faces: u64,
    /// The backend that simplifies the tiles and the merge (its name, as `--backend` takes it).
    pub backend: String,
    /// Cells per axis of the grid over the input's box.
    pub grid: [u32; 3],
    /// The number of tiles (`grid`'s product): array indices run from 0 to `tiles - 1`.
    pub tiles: usize,
    /// The cut planes' offset per axis, in cells: zero, or for a coarser level what moves its
    /// cuts away from the level before's.
    #[serde(default)]
    pub shift: [f64; 3],
    pub tile: Vec<Tile>,
}

/// One tile's entry in the manifest; file names are relative to the tiles folder.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Tile {
    /// The tile's faces (binary PLY), its vertices numbered locally.
    pub file: String,
    /// Per local vertex, its global id (the input's vertex index), as little-endian u32.
    pub ids: String,
    /// Where `tiles simplify` writes the simplified tile (binary PLY).
    pub output: String,
    /// Per output vertex, the global id of the pinned border vertex it is, or `u32::MAX`.
    pub output_ids: String,
    pub faces: u64,
    pub vertices: u64,
    /// The faces `tiles simplify` aims at.
    pub target_faces: u64,
    /// Global ids of the tile's border vertices (on faces of more than one tile), ascending.
    pub border: Vec<u32>,
}

impl Manifest {
    pub fn read(dir: &Path) -> Result<Manifest> {
        let path = dir.join(MANIFEST);
        let text = std::fs::read_to_string(&path).map_err(|e| Error::io(&path, e))?;
        let m: Manifest = serde_json::from_str(&text).map_err(|e| Error::Parse {
            path: path.clone(),
            location: crate::error::Location::Line(e.line() as u64),
            message: format!("not a tiles manifest: {e}"),
        })?;
        if m.format != FORMAT || m.tile.len() != m.tiles {
            return Err(Error::Parse {
                path,
                location: crate::error::Location::Unknown,
                message: format!(
                    "format {:?} with {} of {} tiles; this meshslim reads {FORMAT}: split again",
                    m.format,
                    m.tile.len(),
                    m.tiles
                ),
            });
        }
        // Checked here, so no later step works from a list it cannot trust.
        let bad = |message: String| {
            Err(Error::parse(
                &path,
                crate::error::Location::Unknown,
                message,
            ))
        };
        if m.backend != "cpu" {
            return bad(format!(
                "backend {:?}: tiles are simplified by cpu",
                m.backend
            ));
        }
        for (i, t) in m.tile.iter().enumerate() {
            let names = [&t.file, &t.ids, &t.output, &t.output_ids];
            if let Some(n) = names.iter().find(|n| {
                let mut c = Path::new(n.as_str()).components();
                !matches!(
                    (c.next(), c.next()),
                    (Some(std::path::Component::Normal(_)), None)
                )
            }) {
                return bad(format!(
                    "tile {i}: {n:?} is not a file name inside the folder"
                ));
            }
            if !t.border.windows(2).all(|w| w[0] < w[1]) {
                return bad(format!(
                    "tile {i}: its border ids are not strictly ascending"
                ));
            }
        }
        Ok(m)
    }

    pub fn write(&self, dir: &Path) -> Result<()> {
        let path = dir.join(MANIFEST);
        let text =
            serde_json::to_string_pretty(self).map_err(|e| Error::Internal(e.to_string()))?;
        crate::io::write_atomic(&path, |w| std::io::Write::write_all(w, text.as_bytes()))
    }

    /// The tile at `index`, or an error naming the valid range.
    pub fn tile(&self, index: usize) -> Result<&Tile> {
        self.tile.get(index).ok_or_else(|| {
            Error::InvalidOption(format!(
                "tile index {index} is out of range: the manifest has tiles 0 to {}",
                self.tiles.saturating_sub(1)
            ))
        })
    }

    pub fn backend(&self) -> Result<crate::Backend> {
        use crate::Backend::*;
        [Cpu, CpuParallel, Gpu, Auto]
            .into_iter()
            .find(|b| b.name() == self.backend)
            .ok_or_else(|| {
                Error::InvalidOption(format!(
                    "the manifest's backend {:?} is unknown",
                    self.backend
                ))
            })
    }
}

/// Cells per axis for `n` tiles over a box of extents `e`: of the factorizations of `n` into
/// three, the one whose cuts have the least area (the fewest border vertices to pin), ties to
/// the first in x, y, z order, so the grid depends only on `n` and the box.
pub fn grid_for(n: usize, e: [f64; 3]) -> [u32; 3] {
    let mut best = ([n as u32, 1, 1], f64::INFINITY);
    for x in 1..=n {
        if !n.is_multiple_of(x) {
            continue;
        }
        for y in 1..=n / x {
            if !(n / x).is_multiple_of(y) {
                continue;
            }
            let z = n / x / y;
            let cut = (x - 1) as f64 * e[1] * e[2]
                + (y - 1) as f64 * e[0] * e[2]
                + (z - 1) as f64 * e[0] * e[1];
            if cut < best.1 {
                best = ([x as u32, y as u32, z as u32], cut);
            }
        }
    }
    best.0
}

/// Reads an ids file: little-endian u32s.
pub(crate) fn read_ids(path: &Path) -> Result<Vec<u32>> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    if bytes.len() % 4 != 0 {
        return Err(Error::Parse {
            path: path.to_path_buf(),
            location: crate::error::Location::Byte(bytes.len() as u64),
            message: "an ids file holds 4-byte ids; this one ends mid-id".into(),
        });
    }
    Ok(bytes
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect())
}

/// Reads the ids file of tile `tile`, which must hold one id per vertex of its mesh (`n`).
pub(crate) fn read_ids_for(path: &Path, n: usize, tile: usize) -> Result<Vec<u32>> {
    let ids = read_ids(path)?;
    if ids.len() != n {
        return Err(Error::parse(
            path,
            crate::error::Location::Unknown,
            format!(
                "{} ids for tile {tile}'s {n} vertices: the folder is damaged; split or \
                 simplify the tile again",
                ids.len()
            ),
        ));
    }
    Ok(ids)
}

/// Writes an ids file atomically.
pub(crate) fn write_ids(path: &Path, ids: &[u32]) -> Result<()> {
    crate::io::write_atomic(path, |w| {
        ids.iter()
            .try_for_each(|i| std::io::Write::write_all(w, &i.to_le_bytes()))
    })
}

/// `dir/name`.
pub(crate) fn at(dir: &Path, name: &str) -> PathBuf {
    dir.join(name)
}

#[cfg(test)]
mod tests {
    use super::grid_for;

    #[test]
    fn the_grid_cuts_across_the_long_axes() {
        assert_eq!(grid_for(16, [4.0, 4.0, 0.1]), [4, 4, 1]);
        assert_eq!(grid_for(16, [16.0, 1.0, 1.0]), [16, 1, 1]);
        assert_eq!(grid_for(8, [1.0, 1.0, 1.0]), [2, 2, 2]);
        assert_eq!(grid_for(1, [1.0, 2.0, 3.0]), [1, 1, 1]);
        assert_eq!(grid_for(7, [1.0, 2.0, 3.0]), [1, 1, 7]);
    }
}
