//! Helpers shared by the integration tests: the generated test meshes and the invariant checks.
#![allow(dead_code)]

use meshslim::mesh::{self, topology};
use meshslim::{Mesh, SimplifyReport, StopReason};
use std::path::PathBuf;

/// The generated meshes every backend is checked on, by name.
pub fn generated_meshes() -> Vec<(&'static str, Mesh)> {
    vec![
        ("icosphere", mesh::icosphere(4)),
        ("uv_sphere", mesh::uv_sphere(48, 24)),
        ("torus", mesh::torus(1.0, 0.3, 64, 32)),
        ("double_torus", mesh::double_torus(6)),
        ("open_grid", mesh::grid(40)),
        ("sharp_cube", mesh::cube(12)),
        ("noisy_sphere", mesh::noisy_sphere(4, 0.01, 42)),
        (
            "duplicated_vertices",
            triangle_soup(&mesh::torus(1.0, 0.4, 80, 40)),
        ),
    ]
}

/// Every face with its own three vertices: welding must recover the surface.
pub fn triangle_soup(m: &Mesh) -> Mesh {
    let mut pos = Vec::new();
    let mut tris = Vec::new();
    for t in &m.triangles {
        let base = pos.len() as u32;
        pos.extend(t.iter().map(|&v| m.positions[v as usize]));
        tris.push([base, base + 1, base + 2]);
    }
    Mesh::new(pos, tris)
}

/// The shared models folder, when it is beside the project (or named by MESHSLIM_MODELS).
pub fn shared_models() -> Option<PathBuf> {
    let dir = std::env::var_os("MESHSLIM_MODELS")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/models"));
    dir.is_dir().then_some(dir)
}

fn normalize(v: [f64; 3]) -> [f64; 3] {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if l > 0.0 { v.map(|x| x / l) } else { v }
}

/// Area-weighted vertex normals of the input, for the flip check.
fn vertex_normals(m: &Mesh) -> Vec<[f64; 3]> {
    let mut n = vec![[0.0; 3]; m.positions.len()];
    for f in 0..m.triangles.len() {
        let c = m.face_cross(f);
        for &v in &m.triangles[f] {
            for k in 0..3 {
                n[v as usize][k] += c[k];
            }
        }
    }
    n.into_iter().map(normalize).collect()
}

/// Asserts the invariants every simplification must keep, with `name` in every message.
pub fn check_invariants(name: &str, input: &Mesh, out: &Mesh, report: &SimplifyReport) {
    out.validate()
        .unwrap_or_else(|e| panic!("{name}: invalid output: {e}"));
    assert!(
        out.positions.iter().flatten().all(|c| c.is_finite()),
        "{name}: NaN or inf in the output"
    );
    assert_eq!(
        report.output_faces,
        out.triangles.len(),
        "{name}: report disagrees with the mesh"
    );
    let ti = topology(input);
    let to = topology(out);
    if ti.is_manifold() {
        assert!(
            to.is_manifold(),
            "{name}: manifold input became non-manifold: {to:?}"
        );
    }
    assert_eq!(
        to.euler_characteristic, ti.euler_characteristic,
        "{name}: Euler characteristic changed"
    );
    assert_eq!(
        to.boundary_loops, ti.boundary_loops,
        "{name}: boundary loop count changed"
    );
    assert_eq!(
        to.connected_components, ti.connected_components,
        "{name}: components changed"
    );
    assert_eq!(
        to.degenerate_faces, 0,
        "{name}: degenerate faces in the output"
    );
    assert_eq!(
        to.duplicate_faces, 0,
        "{name}: duplicate faces in the output"
    );
    if ti.is_consistently_oriented() {
        assert!(to.is_consistently_oriented(), "{name}: orientation broke");
    }
    match report.stop_reason {
        StopReason::TargetReached => assert!(
            out.triangles.len().abs_diff(report.target_faces) <= 1,
            "{name}: {} faces for a target of {}",
            out.triangles.len(),
            report.target_faces
        ),
        _ => assert!(
            out.triangles.len() > report.target_faces,
            "{name}: stopped early ({:?}) yet below the target",
            report.stop_reason
        ),
    }
    // No face flipped against the input surface: each output face agrees with the normal of the
    // input vertex nearest its centroid.
    // Welded first, so a triangle soup's vertex normals average all faces at a point.
    let welded = meshslim::mesh::weld_positions(input).mesh;
    let input = &welded;
    let normals = vertex_normals(input);
    for f in 0..out.triangles.len() {
        let Some(n) = out.face_normal(f) else {
            continue;
        };
        let c = [0, 1, 2].map(|k| {
            out.triangles[f]
                .iter()
                .map(|&v| out.positions[v as usize][k] as f64)
                .sum::<f64>()
                / 3.0
        });
        let nearest = (0..input.positions.len())
            .min_by(|&a, &b| {
                let d = |v: usize| {
                    (0..3)
                        .map(|k| (input.positions[v][k] as f64 - c[k]).powi(2))
                        .sum::<f64>()
                };
                d(a).total_cmp(&d(b))
            })
            .expect("input has vertices");
        let dot: f64 = (0..3).map(|k| n[k] * normals[nearest][k]).sum();
        assert!(
            dot > 0.0,
            "{name}: output face {f} is flipped against the input (dot {dot:.3})"
        );
    }
}
