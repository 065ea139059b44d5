//! `tiles simplify`: one tile, its border pinned, to its share of the target.

use super::{Manifest, at, read_ids_for, write_ids};
use crate::error::Result;
use crate::mesh::Mesh;
use crate::{SimplifyOptions, StopReason};
use rustc_hash::FxHashMap;
use serde::Serialize;
use std::path::Path;
use std::time::Instant;

/// What one tile's simplification did.
#[derive(Debug, Clone, Serialize)]
pub struct TileReport {
    pub index: usize,
    pub input_faces: u64,
    pub target_faces: u64,
    pub output_faces: u64,
    /// Border vertices pinned.
    pub border_vertices: usize,
    /// `None` for an empty tile (nothing to simplify).
    pub stop_reason: Option<StopReason>,
    pub seconds: f64,
}

/// Simplifies tile `index` of the tiles folder `dir`, writing its output PLY and ids.
pub fn simplify_tile(
    dir: &Path,
    index: usize,
    progress: &mut dyn FnMut(f32),
) -> Result<TileReport> {
    let t0 = Instant::now();
    let m = Manifest::read(dir)?;
    let tile = m.tile(index)?;
    let mesh = crate::io::read(&at(dir, &tile.file))?;
    let ids = read_ids_for(&at(dir, &tile.ids), mesh.positions.len(), index)?;
    let pin: Vec<u32> = (0..ids.len() as u32)
        .filter(|&l| tile.border.binary_search(&ids[l as usize]).is_ok())
        .collect();
    let (out, stop_reason) = if mesh.triangles.is_empty() {
        (Mesh::default(), None)
    } else {
        let opts = SimplifyOptions {
            backend: m.backend()?,
            pin: pin.clone(),
            ..SimplifyOptions::with_faces(tile.target_faces as usize)
        };
        let (out, r) = crate::simplify_with_progress(&mesh, &opts, progress)?;
        (out, Some(r.stop_reason))
    };
    let out_ids = output_ids(&mesh, &ids, &pin, &out);
    crate::io::write_with(
        &at(dir, &tile.output),
        &out,
        &crate::io::WriteOptions::default(),
    )?;
    write_ids(&at(dir, &tile.output_ids), &out_ids)?;
    Ok(TileReport {
        index,
        input_faces: tile.faces,
        target_faces: tile.target_faces,
        output_faces: out.triangles.len() as u64,
        border_vertices: pin.len(),
        stop_reason,
        seconds: t0.elapsed().as_secs_f64(),
    })
}

/// Per output vertex, the global id of the pinned vertex it is, else `u32::MAX`. Pinned
/// vertices keep their input coordinates bit for bit (every backend writes an unmoved vertex's
/// input position), so they are found by position; inputs that repeat a position under several
/// ids get the smallest, and the merge's greedy, which welds equal positions, joins the rest.
fn output_ids(mesh: &Mesh, ids: &[u32], pin: &[u32], out: &Mesh) -> Vec<u32> {
    let key = |p: &[f32; 3]| p.map(f32::to_bits);
    let mut gid: FxHashMap<[u32; 3], u32> = FxHashMap::default();
    for &l in pin {
        let g = ids[l as usize];
        gid.entry(key(&mesh.positions[l as usize]))
            .and_modify(|x| *x = (*x).min(g))
            .or_insert(g);
    }
    out.positions
        .iter()
        .map(|p| gid.get(&key(p)).copied().unwrap_or(u32::MAX))
        .collect()
}
