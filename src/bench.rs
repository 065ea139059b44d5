//! Inputs and the meshoptimizer baseline for benchmarks: shared by `benches/simplify.rs` and the
//! `meshslim bench` command, so that both measure the same meshes the same way.
//!
//! The reference meshes live outside the crate (`../shared/models`, see its README); without
//! them every function here falls back to a procedural mesh so that benches still run.

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

/// Simplifies with meshoptimizer's `meshopt_simplify` (edge collapse with quadrics, not the
/// sloppy clustering) to `target_faces`, the baseline the `cpu` backend is held against.
///
/// The target error is 1.0 (the whole mesh extent) so that the face count alone stops it, and
/// no flag is set: the border is free to move, as in our default options. meshoptimizer
/// works on positions only; attributes are carried along for the vertices it keeps, per-face
/// materials and groups are dropped. The output is compacted to the vertices it uses.
pub fn meshopt_simplify(mesh: &Mesh, target_faces: usize) -> Mesh {
    let indices: &[u32] = bytemuck::cast_slice(&mesh.triangles);
    let vertices = meshopt::VertexDataAdapter::new(
        bytemuck::cast_slice(&mesh.positions),
        std::mem::size_of::<[f32; 3]>(),
        0,
    )
    .expect("a [f32; 3] slice is a valid vertex buffer");
    let out = meshopt::simplify(
        indices,
        &vertices,
        target_faces * 3,
        1.0,
        meshopt::SimplifyOptions::None,
        None,
    );
    let mut m = Mesh {
        positions: mesh.positions.clone(),
        triangles: bytemuck::cast_slice(&out).to_vec(),
        normals: mesh.normals.clone(),
        uvs: mesh.uvs.clone(),
        colors: mesh.colors.clone(),
        ..Default::default()
    };
    m.remove_unused_vertices();
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn meshopt_reaches_the_face_target_on_a_sphere() {
        let sphere = mesh::icosphere(4); // 5120 faces
        let out = meshopt_simplify(&sphere, 512);
        assert!(out.face_count() <= 512, "{} faces", out.face_count());
        assert!(out.face_count() >= 400, "{} faces", out.face_count());
        out.validate().unwrap();
        assert!(out.vertex_count() < sphere.vertex_count());
    }
}
