//! Helpers shared by the integration tests: the generated test meshes and the invariant checks.
#![allow(dead_code)]

use meshslim::mesh::{self, topology};
use meshslim::{Mesh, SimplifyReport, StopReason};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

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

/// A torus whose UV chart is cut open along one meridian: the 24 vertices there are stored
/// twice (same position, u = 0 and u = 1).
pub fn seamed_torus() -> Mesh {
    let (nu, nv) = (48usize, 24usize);
    let mut pos = Vec::new();
    let mut uvs = Vec::new();
    for j in 0..nv {
        for i in 0..=nu {
            let (a, b) = (
                (i % nu) as f64 / nu as f64 * std::f64::consts::TAU,
                j as f64 / nv as f64 * std::f64::consts::TAU,
            );
            let r = 1.0 + 0.35 * b.cos();
            pos.push([
                (r * a.cos()) as f32,
                (r * a.sin()) as f32,
                (0.35 * b.sin()) as f32,
            ]);
            uvs.push([i as f32 / nu as f32, j as f32 / nv as f32]);
        }
    }
    let id = |i: usize, j: usize| ((j % nv) * (nu + 1) + i) as u32;
    let mut tris = Vec::new();
    for j in 0..nv {
        for i in 0..nu {
            tris.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            tris.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    let mut m = Mesh::new(pos, tris);
    m.uvs = Some(uvs);
    m
}

/// How far apart a face's u coordinates are: near 1 for a face across the [`seamed_torus`]'s
/// seam.
pub fn u_spread(us: [f32; 3]) -> f32 {
    us.iter().fold(0f32, |m, &a| m.max(a)) - us.iter().fold(1f32, |m, &a| m.min(a))
}

/// A simplified [`seamed_torus`]: the invariants, the target reached (the seam may not pin it
/// away), UVs on every vertex, no face mixing the two sides of the seam (u near 0 with u near
/// 1), and the seam still there but thinned out (seam vertices slide along it).
pub fn check_seamed_torus(label: &str, input: &Mesh, out: &Mesh, report: &SimplifyReport) {
    check_invariants(label, input, out, report);
    assert_eq!(
        report.stop_reason,
        StopReason::TargetReached,
        "{label}: {report:?}"
    );
    let uv = out.uvs.as_ref().expect("UVs kept");
    assert_eq!(uv.len(), out.positions.len(), "{label}");
    for t in &out.triangles {
        let us = t.map(|v| uv[v as usize][0]);
        let spread = u_spread(us);
        assert!(
            spread < 0.5,
            "{label}: a face straddles the seam, u = {us:?}"
        );
    }
    // Some positions carry two vertices with u = 0 and u = 1.
    let seam = (0..out.positions.len())
        .filter(|&v| {
            uv[v][0] == 1.0
                && (0..out.positions.len())
                    .any(|w| uv[w][0] == 0.0 && out.positions[w] == out.positions[v])
        })
        .count();
    assert!(
        seam >= 3,
        "{label}: the seam vanished ({seam} split vertices left)"
    );
    // ... and it thinned out: it started with one vertex per ring, 24.
    assert!(
        seam < 24,
        "{label}: the seam kept all its {seam} vertices: seam vertices do not slide"
    );
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
    // None created; an input's own duplicates sit on non-manifold edges, which stay pinned.
    assert!(
        to.duplicate_faces <= ti.duplicate_faces,
        "{name}: {} duplicate faces in the output, {} in the input",
        to.duplicate_faces,
        ti.duplicate_faces
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
    // Vertex normals only describe "the input surface" where it is a manifold; on non-manifold
    // inputs (suzanne, teapot) the check would compare against fans of unrelated sheets.
    if !welded_is_manifold(input) {
        return;
    }
    let normals = vertex_normals(input);
    let grid = Grid::new(&input.positions);
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
        let nearest = grid.nearest(&input.positions, c);
        let agrees = |v: usize| (0..3).map(|k| n[k] * normals[v][k]).sum::<f64>() > 0.0;
        if agrees(nearest) {
            continue;
        }
        // Where the input is thin (an ear, a lid over a body) the nearest vertex can lie on the
        // other sheet: the face is flipped only if no input vertex within its own reach agrees.
        let reach2 = out.triangles[f]
            .iter()
            .map(|&v| {
                (0..3)
                    .map(|k| (out.positions[v as usize][k] as f64 - c[k]).powi(2))
                    .sum::<f64>()
            })
            .fold(0.0, f64::max);
        let near_agrees = (0..input.positions.len()).any(|v| {
            let d2: f64 = (0..3)
                .map(|k| (input.positions[v][k] as f64 - c[k]).powi(2))
                .sum();
            d2 <= reach2 && agrees(v)
        });
        assert!(
            near_agrees,
            "{name}: output face {f} is flipped against the input surface around it"
        );
    }
}

fn welded_is_manifold(m: &Mesh) -> bool {
    topology(m).is_manifold()
}

/// A uniform grid over points for nearest-point queries in the invariant checks (a brute-force
/// search over a 270k-vertex scan per output face would take minutes).
struct Grid {
    lo: [f64; 3],
    cell: f64,
    dims: [i64; 3],
    cells: std::collections::HashMap<[i64; 3], Vec<u32>>,
}

impl Grid {
    fn new(points: &[[f32; 3]]) -> Grid {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in points {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k] as f64);
                hi[k] = hi[k].max(p[k] as f64);
            }
        }
        let extent = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max).max(1e-12);
        let cell = extent / (points.len() as f64).cbrt().max(1.0);
        let dims = [0, 1, 2].map(|k| ((hi[k] - lo[k]) / cell) as i64 + 1);
        let mut g = Grid {
            lo,
            cell,
            dims,
            cells: Default::default(),
        };
        for (i, p) in points.iter().enumerate() {
            let c = g.cell_of([p[0] as f64, p[1] as f64, p[2] as f64]);
            g.cells.entry(c).or_default().push(i as u32);
        }
        g
    }
    fn cell_of(&self, p: [f64; 3]) -> [i64; 3] {
        [0, 1, 2]
            .map(|k| (((p[k] - self.lo[k]) / self.cell).floor() as i64).clamp(0, self.dims[k] - 1))
    }
    /// Index of the point nearest `q`: rings of cells outward until the ring is farther than
    /// the best point found.
    fn nearest(&self, points: &[[f32; 3]], q: [f64; 3]) -> usize {
        let c = self.cell_of(q);
        let mut best = (f64::INFINITY, 0usize);
        for r in 0i64.. {
            if best.0.is_finite() && ((r - 1) as f64 * self.cell).powi(2) > best.0 {
                break;
            }
            if r > self.dims.iter().copied().max().unwrap_or(0) + 1 {
                break;
            }
            for x in -r..=r {
                for y in -r..=r {
                    for z in -r..=r {
                        if x.abs().max(y.abs()).max(z.abs()) != r {
                            continue;
                        }
                        if let Some(list) = self.cells.get(&[c[0] + x, c[1] + y, c[2] + z]) {
                            for &i in list {
                                let p = points[i as usize];
                                let d: f64 = (0..3).map(|k| (p[k] as f64 - q[k]).powi(2)).sum();
                                if d < best.0 {
                                    best = (d, i as usize);
                                }
                            }
                        }
                    }
                }
            }
        }
        best.1
    }
}

/// Runs the `meshslim` binary with `args` in `dir`.
pub fn meshslim(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_meshslim"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run meshslim")
}

/// Asserts the exit code, showing both streams when it differs.
pub fn expect_code(o: &Output, code: i32) {
    assert_eq!(
        o.status.code(),
        Some(code),
        "stdout:\n{}\nstderr:\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
}

/// The process's GPU device, or None (with a note) when this machine has no adapter; with
/// CI=true a missing adapter fails the test instead.
pub fn gpu_context() -> Option<&'static meshslim::compute::context::GpuContext> {
    match meshslim::rounds::gpu::shared() {
        Ok((ctx, _)) => Some(ctx),
        Err(e) if std::env::var("CI").is_ok_and(|v| v == "true") => {
            panic!("CI=true but no GPU adapter: {e}")
        }
        Err(e) => {
            eprintln!("note: GPU tests skipped, no adapter: {e}");
            None
        }
    }
}

/// The adapter rounds every f32 operation of the WGSL as the CPU twins do: lavapipe (LLVM),
/// which CI runs, where the tests below compare bit for bit. Hardware GPUs fuse multiply-adds and
/// round division and square roots their own way (WGSL allows both): there a cost an ulp apart
/// can pick another of two near-equal collapses, and the tests compare to rounding and quality.
pub fn rounds_like_the_cpu() -> bool {
    // Asked once per face by `unit_close`: the adapter's name is looked at once per process.
    static LAVAPIPE: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *LAVAPIPE.get_or_init(|| {
        gpu_context().is_some_and(|c| c.adapter_name.to_lowercase().contains("llvmpipe"))
    })
}

/// Within `tol` of the larger magnitude, or of `scale` when both are smaller (a sum's entry that
/// cancels to near zero is as exact as the sum's largest term allows).
pub fn close(a: f32, b: f32, tol: f32, scale: f32) -> bool {
    (a - b).abs() <= tol * a.abs().max(b.abs()).max(scale).max(1e-30)
}

/// A face's unit normal and area: bit for bit where the adapter rounds as the CPU (lavapipe,
/// every test mesh's), else within `tol`, the normal's components of the vector's length (1),
/// the area of itself. A component that cancels to near zero carries the rounding of the cross
/// product's terms, whose size is the normal's: an H200, which fuses the cross product's
/// multiply-adds, wrote -5.6e-9 where the CPU wrote 0.
pub fn unit_close(a: &[f32; 4], b: &[f32; 4], tol: f32) -> bool {
    if rounds_like_the_cpu() {
        return a == b;
    }
    (0..3).all(|k| (a[k] - b[k]).abs() <= tol) && close(a[3], b[3], tol, 0.0)
}

/// A GPU buffer's bytes as `T`s.
pub fn pod<T: bytemuck::Pod>(bytes: Vec<u8>) -> Vec<T> {
    bytemuck::pod_collect_to_vec(&bytes)
}
