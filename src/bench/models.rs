//! The benchmark's inputs: the reference meshes of `../shared/models` when present, the
//! deterministic 1M-triangle scan, and the ratios the criterion benches run at.

use std::path::{Path, PathBuf};

use crate::error::Result;
use crate::io;
use crate::mesh::{self, Mesh};

/// Environment variable naming the folder of reference meshes.
pub const MODELS_ENV: &str = "MESHSLIM_MODELS";

/// Ratios every benchmark runs at: a light and a heavy simplification.
pub const RATIOS: [f64; 2] = [0.1, 0.01];

/// Models benchmarked when present in [`models_dir`], in this order.
pub const BENCH_MODELS: [&str; 2] = ["horse.ply", "igea.ply"];

/// The folder of reference meshes: `$MESHSLIM_MODELS`, else `../shared/models` beside the crate
/// (`CARGO_MANIFEST_DIR`, at run time when cargo sets it, else as it was at build time), else
/// `../shared/models` relative to the current directory. `None` when none of them is a folder.
pub fn models_dir() -> Option<PathBuf> {
    let mut candidates = Vec::new();
    if let Some(dir) = std::env::var_os(MODELS_ENV).filter(|d| !d.is_empty()) {
        candidates.push(PathBuf::from(dir));
    }
    if let Some(dir) = std::env::var_os("CARGO_MANIFEST_DIR") {
        candidates.push(Path::new(&dir).join("../shared/models"));
    }
    candidates.push(Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/models"));
    candidates.push(PathBuf::from("../shared/models"));
    candidates.into_iter().find(|d| d.is_dir())
}

/// Reads `name` from [`models_dir`]: `None` when the folder or the file is missing.
pub fn load_model(name: &str) -> Option<Result<Mesh>> {
    let path = models_dir()?.join(name);
    path.is_file().then(|| io::read(&path))
}

/// A deterministic scan of about a million triangles: igea.ply subdivided once at the edge
/// midpoints (268,686 → 1,074,744 triangles) with noise of 1e-4 of the diagonal along the
/// normals (seed 1), so that the flat subdivided triangles are not trivially collapsible.
/// Without the models folder, `displaced_sphere(1_000_000, 1)` (1,310,720 triangles).
/// The string names which of the two it is.
pub fn million_triangle_scan() -> Result<(String, Mesh)> {
    match load_model("igea.ply") {
        Some(igea) => {
            let mut m = mesh::subdivide_midpoint(&igea?);
            mesh::add_noise(&mut m, 1e-4, 1);
            Ok(("igea-subdivided".to_string(), m))
        }
        None => Ok((
            "displaced-sphere".to_string(),
            mesh::displaced_sphere(1_000_000, 1),
        )),
    }
}

/// The inputs of the benchmark: [`BENCH_MODELS`] that are present, then the million-triangle
/// scan. Each with a short name.
pub fn inputs() -> Result<Vec<(String, Mesh)>> {
    let mut out = Vec::new();
    for name in BENCH_MODELS {
        if let Some(m) = load_model(name) {
            let stem = name.rsplit_once('.').map_or(name, |(s, _)| s);
            out.push((stem.to_string(), m?));
        }
    }
    out.push(million_triangle_scan()?);
    Ok(out)
}
