//! Inputs and the meshoptimizer baseline for benchmarks: shared by `benches/simplify.rs` and the
//! `meshslim bench` command, so that both measure the same meshes the same way.
//!
//! The reference meshes live outside the crate (`../shared/models`, see its README); without
//! them every function here falls back to a procedural mesh so that benches still run.
//!
//! [`run`] is the benchmark itself: every mesh × ratio × backend of [`BACKENDS`], timed
//! (median over repeats), its peak heap measured ([`alloc`]) and its two-sided Metro distance
//! to the input measured with [`crate::metrics::compare`]. [`write_table`] and [`plot_svg`]
//! present the [`Report`]; it serializes to the JSON of `meshslim bench --json`.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::Serialize;

use crate::error::{Error, Result};
use crate::io;
use crate::mesh::{self, Mesh};
use crate::metrics::{self, CompareOptions};
use crate::simplify::SimplifyOptions;

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
    with_meshopt(mesh, |indices, vertices| {
        meshopt::simplify(
            indices,
            vertices,
            target_faces * 3,
            1.0,
            meshopt::SimplifyOptions::None,
            None,
        )
    })
}

/// Simplifies with meshoptimizer's `meshopt_simplifySloppy` (vertex clustering on a grid, no
/// topology kept) to about `target_faces`: the throughput end of the scale. The target error
/// is 1.0 so that the face count alone stops it. Positions only, as [`meshopt_simplify`]; the
/// output is compacted to the vertices it uses.
pub fn meshopt_simplify_sloppy(mesh: &Mesh, target_faces: usize) -> Mesh {
    with_meshopt(mesh, |indices, vertices| {
        meshopt::simplify_sloppy(indices, vertices, target_faces * 3, 1.0, None)
    })
}

/// Runs a meshoptimizer index-buffer simplifier on `mesh`'s positions and turns its output
/// back into a mesh, attributes carried along, compacted to the vertices it uses.
fn with_meshopt(
    mesh: &Mesh,
    simplify: impl FnOnce(&[u32], &meshopt::VertexDataAdapter) -> Vec<u32>,
) -> Mesh {
    let indices: &[u32] = bytemuck::cast_slice(&mesh.triangles);
    let vertices = meshopt::VertexDataAdapter::new(
        bytemuck::cast_slice(&mesh.positions),
        std::mem::size_of::<[f32; 3]>(),
        0,
    )
    .expect("a [f32; 3] slice is a valid vertex buffer");
    let out = simplify(indices, &vertices);
    let mut m = Mesh {
        positions: mesh.positions.clone(),
        triangles: bytemuck::cast_slice(&out).to_vec(),
        normals: mesh.normals.clone(),
        uvs: mesh.uvs.clone(),
        uv_origin: mesh.uv_origin,
        colors: mesh.colors.clone(),
        ..Default::default()
    };
    m.remove_unused_vertices();
    m
}

/// Ratios `meshslim bench` runs at when none are given.
pub const DEFAULT_RATIOS: [f64; 3] = [0.5, 0.1, 0.01];

/// One implementation the benchmark can run. A new backend (cpu-parallel, gpu) is one entry in
/// [`BACKENDS`]: its name, a line of help, the simplify call that is timed, and the device
/// that runs it (a GPU backend names its adapter there).
#[derive(Debug)]
pub struct BenchBackend {
    /// The `--backends` name, also the `backend` field of each row.
    pub name: &'static str,
    /// One line for `meshslim bench --help`.
    pub about: &'static str,
    /// Simplifies the mesh to about this many faces: the call that is timed and measured.
    pub simplify: fn(&Mesh, usize) -> Result<Mesh>,
    /// The device that runs it, named in every row.
    pub device: fn() -> String,
}

/// Every backend `meshslim bench` knows, in the order of the table and the plot legend.
pub static BACKENDS: &[BenchBackend] = &[
    BenchBackend {
        name: "cpu",
        about: "meshslim's greedy quadric edge collapse (the quality reference)",
        simplify: |m, faces| Ok(crate::simplify(m, &SimplifyOptions::with_faces(faces))?.0),
        device: cpu_name,
    },
    BenchBackend {
        name: "cpu-parallel",
        about: "meshslim's GPU rounds run on the CPU's cores (rayon)",
        simplify: |m, faces| {
            Ok(crate::simplify(m, &with_backend(faces, crate::Backend::CpuParallel))?.0)
        },
        device: cpu_name,
    },
    BenchBackend {
        name: "gpu",
        about: "meshslim's rounds as WGSL compute passes (wgpu)",
        simplify: |m, faces| Ok(crate::simplify(m, &with_backend(faces, crate::Backend::Gpu))?.0),
        device: gpu_name,
    },
    BenchBackend {
        name: "meshopt",
        about: "meshoptimizer's simplify (quadric edge collapse)",
        simplify: |m, faces| Ok(meshopt_simplify(m, faces)),
        device: cpu_name,
    },
    BenchBackend {
        name: "meshopt-sloppy",
        about: "meshoptimizer's simplifySloppy (vertex clustering, topology not kept)",
        simplify: |m, faces| Ok(meshopt_simplify_sloppy(m, faces)),
        device: cpu_name,
    },
];

fn with_backend(faces: usize, backend: crate::Backend) -> SimplifyOptions {
    let mut o = SimplifyOptions::with_faces(faces);
    o.backend = backend;
    o
}

/// The GPU adapter's name, or why there is none.
pub fn gpu_name() -> String {
    static NAME: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    NAME.get_or_init(|| match crate::gpu::shared() {
        Ok((c, _)) => c.adapter_name.clone(),
        Err(e) => format!("no GPU ({e})"),
    })
    .clone()
}

/// Every backend this machine can run: all of [`BACKENDS`], less `gpu` without an adapter.
pub fn available_backends() -> Vec<&'static BenchBackend> {
    let gpu = crate::gpu::shared().is_ok();
    BACKENDS.iter().filter(|b| gpu || b.name != "gpu").collect()
}

/// The backend called `name` in [`BACKENDS`].
pub fn backend(name: &str) -> Option<&'static BenchBackend> {
    BACKENDS.iter().find(|b| b.name == name)
}

/// The CPU's model name (`model name` in /proc/cpuinfo, else the architecture).
pub fn cpu_name() -> String {
    static NAME: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    NAME.get_or_init(|| {
        std::fs::read_to_string("/proc/cpuinfo")
            .ok()
            .and_then(|info| {
                info.lines()
                    .filter_map(|l| l.split_once(':'))
                    .find(|(k, _)| matches!(k.trim(), "model name" | "Model" | "Hardware"))
                    .map(|(_, v)| v.split_whitespace().collect::<Vec<_>>().join(" "))
            })
            .filter(|n| !n.is_empty())
            .unwrap_or_else(|| format!("unknown {} CPU", std::env::consts::ARCH))
    })
    .clone()
}

/// The machine a report was measured on.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Machine {
    /// CPU model name.
    pub cpu: String,
    /// Hardware threads available to the process.
    pub cores: usize,
}

impl Machine {
    pub fn this() -> Machine {
        Machine {
            cpu: cpu_name(),
            cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
        }
    }
}

/// What to run.
#[derive(Debug, Clone)]
pub struct BenchOptions {
    /// Fractions of the input faces to keep, each in (0, 1].
    pub ratios: Vec<f64>,
    pub backends: Vec<&'static BenchBackend>,
    /// Timed runs per case; the median is reported.
    pub repeat: usize,
    /// How the error is measured.
    pub compare: CompareOptions,
}

impl Default for BenchOptions {
    fn default() -> Self {
        BenchOptions {
            ratios: DEFAULT_RATIOS.to_vec(),
            backends: available_backends(),
            repeat: 3,
            compare: CompareOptions::default(),
        }
    }
}

/// One mesh × ratio × backend.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Row {
    pub mesh: String,
    pub input_faces: usize,
    pub ratio: f64,
    pub target_faces: usize,
    pub backend: String,
    /// What ran it: the CPU model for CPU backends, the adapter for GPU ones.
    pub device: String,
    pub output_faces: usize,
    /// The run stopped above its target (the error columns then compare a larger mesh);
    /// the table marks it with `*`.
    pub missed_target: bool,
    /// Median wall time of the simplify call over the repeats, seconds.
    pub median_s: f64,
    /// Every repeat's wall time, seconds, in run order.
    pub times_s: Vec<f64>,
    /// Input triangles per second at the median time, millions.
    pub mtri_per_s: f64,
    /// Peak heap bytes held during the simplify call above what was held before it (the output
    /// included; largest over the repeats); `None` when the counting allocator
    /// ([`alloc::CountingAlloc`]) is not the global allocator. Rust heap only: the scratch
    /// memory meshoptimizer's C++ takes from `malloc` is not seen (the meshopt crate does not
    /// expose `meshopt_setAllocator`), so its rows count little more than the output.
    pub peak_bytes: Option<u64>,
    /// `peak_bytes` in MiB.
    pub peak_mib: Option<f64>,
    /// Bounding-box diagonal of the input, the unit of the `*_rel` errors.
    pub diagonal: f64,
    /// Two-sided Metro distances (see [`crate::metrics::Distance::two_sided`]); `None` when the
    /// output has no faces left to measure.
    pub mean_err: Option<f64>,
    pub max_err: Option<f64>,
    pub mean_err_rel: Option<f64>,
    pub max_err_rel: Option<f64>,
}

/// Everything `meshslim bench` measured; serializes to its JSON.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Report {
    pub machine: Machine,
    pub repeat: usize,
    /// Face samples per direction when set; `null`: the metrics' default.
    pub samples: Option<usize>,
    pub rows: Vec<Row>,
}

/// Runs every mesh × ratio × backend of `opts`, in that nesting order. `progress` gets the
/// fraction done (0..=1) after every timed run and every measurement.
pub fn run(
    inputs: &[(String, Mesh)],
    opts: &BenchOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<Report> {
    if opts.repeat == 0 {
        return Err(Error::InvalidOption("repeat must be at least 1".into()));
    }
    if opts.backends.is_empty() || opts.ratios.is_empty() {
        return Err(Error::InvalidOption(
            "at least one backend and one ratio are needed".into(),
        ));
    }
    let targets = opts
        .ratios
        .iter()
        .map(|&r| SimplifyOptions::with_ratio(1, r).map(|_| r))
        .collect::<Result<Vec<f64>>>()?;
    let steps = inputs.len() * targets.len() * opts.backends.len() * (opts.repeat + 1);
    let mut done = 0;
    let mut step = || {
        done += 1;
        progress(done as f32 / steps.max(1) as f32)
    };
    let mut rows = Vec::new();
    for (name, mesh) in inputs {
        mesh.validate()
            .map_err(|e| Error::InvalidMesh(format!("{name}: {e}")))?;
        let faces = mesh.face_count();
        let diagonal = mesh.bounds().map_or(0.0, |b| b.diagonal());
        for &ratio in &targets {
            let target = SimplifyOptions::with_ratio(faces, ratio)?.target_faces;
            for backend in &opts.backends {
                let mut times = Vec::with_capacity(opts.repeat);
                let mut peak: Option<u64> = None;
                let mut out = None;
                for _ in 0..opts.repeat {
                    drop(out.take()); // the previous output is not part of this run's baseline
                    let (result, bytes) = alloc::measure(|| {
                        let t = Instant::now();
                        let r = (backend.simplify)(mesh, target);
                        (r, t.elapsed().as_secs_f64())
                    });
                    let (simplified, seconds) = result;
                    out = Some(simplified?);
                    times.push(seconds);
                    peak = bytes.map(|b| peak.map_or(b, |p| p.max(b)));
                    step();
                }
                let out = out.expect("repeat is at least 1");
                let d = if out.face_count() == 0 {
                    None
                } else {
                    Some(
                        metrics::compare(mesh, &out, &opts.compare)?
                            .distance
                            .two_sided,
                    )
                };
                step();
                let median_s = median(&times);
                rows.push(Row {
                    mesh: name.clone(),
                    input_faces: faces,
                    ratio,
                    target_faces: target,
                    backend: backend.name.to_string(),
                    device: (backend.device)(),
                    output_faces: out.face_count(),
                    missed_target: out.face_count() > target,
                    median_s,
                    times_s: times,
                    mtri_per_s: faces as f64 / median_s.max(1e-9) / 1e6,
                    peak_bytes: peak,
                    peak_mib: peak.map(|b| b as f64 / (1024.0 * 1024.0)),
                    diagonal,
                    mean_err: d.as_ref().map(|d| d.mean),
                    max_err: d.as_ref().map(|d| d.max),
                    mean_err_rel: d.as_ref().map(|d| d.mean_rel),
                    max_err_rel: d.as_ref().map(|d| d.max_rel),
                });
            }
        }
    }
    Ok(Report {
        machine: Machine::this(),
        repeat: opts.repeat,
        samples: opts.compare.samples,
        rows,
    })
}

fn median(xs: &[f64]) -> f64 {
    let mut v = xs.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// The report as a table, one row per line, errors relative to the input's diagonal.
pub fn write_table(out: &mut impl Write, report: &Report) -> std::io::Result<()> {
    let mesh_w = report
        .rows
        .iter()
        .map(|r| r.mesh.len())
        .chain([4])
        .max()
        .unwrap_or(4);
    let backend_w = report
        .rows
        .iter()
        .map(|r| r.backend.len())
        .chain([7])
        .max()
        .unwrap_or(7);
    writeln!(
        out,
        "{:<mesh_w$} {:>9} {:>6} {:<backend_w$} {:>9} {:>9} {:>7} {:>8} {:>9} {:>9}",
        "mesh",
        "faces",
        "ratio",
        "backend",
        "out faces",
        "median s",
        "Mtri/s",
        "peak MiB",
        "mean err",
        "max err"
    )?;
    let opt = |v: Option<f64>, prec: usize, e: bool| match (v, e) {
        (None, _) => "n/a".to_string(),
        (Some(v), true) => format!("{v:.prec$e}"),
        (Some(v), false) => format!("{v:.prec$}"),
    };
    for r in &report.rows {
        writeln!(
            out,
            "{:<mesh_w$} {:>9} {:>6} {:<backend_w$} {:>9} {:>9.4} {:>7.2} {:>8} {:>9} {:>9}",
            r.mesh,
            r.input_faces,
            r.ratio,
            r.backend,
            if r.missed_target {
                format!("{}*", r.output_faces)
            } else {
                r.output_faces.to_string()
            },
            r.median_s,
            r.mtri_per_s,
            opt(r.peak_mib, 1, false),
            opt(r.mean_err_rel, 2, true),
            opt(r.max_err_rel, 2, true),
        )?;
    }
    let devices: Vec<&str> = report.rows.iter().fold(Vec::new(), |mut v, r| {
        if !v.contains(&r.device.as_str()) {
            v.push(&r.device);
        }
        v
    });
    writeln!(
        out,
        "\nmedian of {} run(s) of the simplify call; errors are two-sided Metro distances \
         relative to the input's bounding-box diagonal; peak MiB is heap held above the \
         baseline during the call (output included; Rust heap only, meshoptimizer's C++ scratch \
         memory is not counted)",
        report.repeat
    )?;
    if let Some(r) = report.rows.iter().find(|r| r.missed_target) {
        writeln!(
            out,
            "* stopped above its target (e.g. {} {} at {}: {} faces for {}): no collapse was \
             left that keeps the topology and the constraints (`meshslim simplify` says why); \
             its errors are those of a larger mesh",
            r.mesh, r.backend, r.ratio, r.output_faces, r.target_faces
        )?;
    }
    writeln!(
        out,
        "device: {} ({} cores)",
        devices.join(", "),
        report.machine.cores
    )
}

/// Marker shapes and colours (Okabe–Ito, safe for colour-blind readers) by index in
/// [`BACKENDS`], so that a backend looks the same in every plot.
const STYLES: [(&str, &str); 8] = [
    ("circle", "#0072B2"),
    ("square", "#E69F00"),
    ("triangle", "#009E73"),
    ("diamond", "#D55E00"),
    ("down", "#CC79A7"),
    ("circle", "#56B4E9"),
    ("square", "#000000"),
    ("triangle", "#F0E442"),
];

fn style(backend: &str) -> (&'static str, &'static str) {
    let i = BACKENDS
        .iter()
        .position(|b| b.name == backend)
        .unwrap_or(BACKENDS.len());
    STYLES[i % STYLES.len()]
}

fn marker(shape: &str, x: f64, y: f64, colour: &str) -> String {
    let r = 5.5;
    let paint = format!(r##"fill="{colour}" stroke="#222" stroke-width="0.8""##);
    match shape {
        "square" => format!(
            r##"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" {paint}/>"##,
            x - r * 0.9,
            y - r * 0.9,
            r * 1.8,
            r * 1.8
        ),
        "triangle" | "down" => {
            let s = if shape == "down" { -1.0 } else { 1.0 };
            format!(
                r##"<polygon points="{:.1},{:.1} {:.1},{:.1} {:.1},{:.1}" {paint}/>"##,
                x,
                y - s * r * 1.2,
                x - r * 1.1,
                y + s * r * 0.8,
                x + r * 1.1,
                y + s * r * 0.8
            )
        }
        "diamond" => format!(
            r##"<polygon points="{x:.1},{:.1} {:.1},{y:.1} {x:.1},{:.1} {:.1},{y:.1}" {paint}/>"##,
            y - r * 1.3,
            x + r * 1.3,
            y + r * 1.3,
            x - r * 1.3
        ),
        _ => format!(r##"<circle cx="{x:.1}" cy="{y:.1}" r="{r}" {paint}/>"##),
    }
}

fn xml(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A decade range covering `values` (positive ones), at least one decade wide.
fn log_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| *v > 0.0 && v.is_finite())
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if !lo.is_finite() {
        return (-1.0, 0.0);
    }
    let (a, b) = (lo.log10().floor(), hi.log10().ceil());
    (a, if b > a { b } else { a + 1.0 })
}

/// A tick label for 10^e times `m`: plain decimals between 0.001 and 10,000, else `1e-5`.
fn tick_label(m: f64, e: f64) -> String {
    let v = m * 10f64.powf(e);
    if (-3.0..=4.0).contains(&e) {
        let digits = (-e).max(0.0) as usize;
        format!("{v:.digits$}")
    } else {
        format!("{m}e{e}")
    }
}

/// Error against time, log-log: one panel per ratio (shared axes, so panels compare), one
/// marker shape and colour per backend, each backend's markers in one
/// `<g class="series" data-backend="NAME">` group. Rows without an error are left out.
pub fn plot_svg(report: &Report) -> String {
    use std::fmt::Write as _;
    let mut ratios: Vec<f64> = Vec::new();
    let mut backends: Vec<&str> = Vec::new();
    let mut meshes: Vec<&str> = Vec::new();
    for r in &report.rows {
        if !ratios.contains(&r.ratio) {
            ratios.push(r.ratio);
        }
        if !backends.contains(&r.backend.as_str()) {
            backends.push(&r.backend);
        }
        if !meshes.contains(&r.mesh.as_str()) {
            meshes.push(&r.mesh);
        }
    }
    let points: Vec<&Row> = report
        .rows
        .iter()
        .filter(|r| r.mean_err_rel.is_some_and(|e| e > 0.0) && r.median_s > 0.0)
        .collect();
    let (x0, x1) = log_range(points.iter().map(|r| r.median_s));
    let (y0, y1) = log_range(points.iter().filter_map(|r| r.mean_err_rel));

    let (pw, ph) = (400.0, 330.0); // one panel, plot area and its margins
    let (ml, mr, mt, mb) = (78.0, 18.0, 76.0, 52.0);
    let legend_w = 190.0;
    let n = ratios.len().max(1) as f64;
    let width = n * (ml + pw + mr) + legend_w;
    let height = mt + ph + mb;
    let mut s = String::new();
    let _ = writeln!(
        s,
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" viewBox="0 0 {width} {height}" font-family="DejaVu Sans, Helvetica, Arial, sans-serif" font-size="12">"##
    );
    let _ = writeln!(
        s,
        r##"<rect width="{width}" height="{height}" fill="white"/>"##
    );
    let _ = writeln!(
        s,
        r##"<text x="12" y="24" font-size="16" font-weight="bold">Mean two-sided error against simplify time (log-log; lower left is better)</text>"##
    );
    let _ = writeln!(
        s,
        r##"<text x="12" y="44" fill="#444">{} · {} · {} cores · median of {} run(s)</text>"##,
        xml(&meshes.join(", ")),
        xml(&report.machine.cpu),
        report.machine.cores,
        report.repeat
    );
    let px = |panel: usize, t: f64| {
        panel as f64 * (ml + pw + mr) + ml + (t.log10() - x0) / (x1 - x0) * pw
    };
    let py = |e: f64| mt + ph - (e.log10() - y0) / (y1 - y0) * ph;
    let many = |lo: f64, hi: f64| hi - lo <= 2.0;
    for (i, &ratio) in ratios.iter().enumerate() {
        let left = i as f64 * (ml + pw + mr) + ml;
        let faces: Vec<usize> = report
            .rows
            .iter()
            .filter(|r| r.ratio == ratio)
            .map(|r| r.target_faces)
            .fold(Vec::new(), |mut v, f| {
                if !v.contains(&f) {
                    v.push(f);
                }
                v
            });
        let title = if faces.len() == 1 {
            format!("ratio {ratio} (target {} faces)", faces[0])
        } else {
            format!("ratio {ratio}")
        };
        let _ = writeln!(
            s,
            r##"<text x="{:.1}" y="{:.1}" text-anchor="middle" font-size="14" font-weight="bold">{}</text>"##,
            left + pw / 2.0,
            mt - 10.0,
            xml(&title)
        );
        // Grid: every decade labelled; minor lines at 2..9, labelled at 2 and 5 when the axis
        // spans few decades, so that a narrow range still has numbers to read.
        for (lo, hi, vertical) in [(x0, x1, true), (y0, y1, false)] {
            let mut e = lo;
            while e <= hi {
                for m in 1..10 {
                    let v = m as f64 * 10f64.powf(e);
                    if v.log10() > hi + 1e-9 {
                        break;
                    }
                    let major = m == 1;
                    let labelled = major || (many(lo, hi) && (m == 2 || m == 5));
                    let colour = if major { "#bbb" } else { "#e6e6e6" };
                    let label = tick_label(m as f64, e);
                    if vertical {
                        let x = px(i, v);
                        let _ = writeln!(
                            s,
                            r##"<line x1="{x:.1}" y1="{mt}" x2="{x:.1}" y2="{:.1}" stroke="{colour}"/>"##,
                            mt + ph
                        );
                        if labelled {
                            let _ = writeln!(
                                s,
                                r##"<text x="{x:.1}" y="{:.1}" text-anchor="middle" fill="#333">{label}</text>"##,
                                mt + ph + 16.0
                            );
                        }
                    } else {
                        let y = py(v);
                        let _ = writeln!(
                            s,
                            r##"<line x1="{left:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="{colour}"/>"##,
                            left + pw
                        );
                        if labelled {
                            let _ = writeln!(
                                s,
                                r##"<text x="{:.1}" y="{:.1}" text-anchor="end" fill="#333">{label}</text>"##,
                                left - 6.0,
                                y + 4.0
                            );
                        }
                    }
                }
                e += 1.0;
            }
        }
        let _ = writeln!(
            s,
            r##"<rect x="{left:.1}" y="{mt}" width="{pw}" height="{ph}" fill="none" stroke="#333"/>"##
        );
        let _ = writeln!(
            s,
            r##"<text x="{:.1}" y="{:.1}" text-anchor="middle">median simplify time (s)</text>"##,
            left + pw / 2.0,
            mt + ph + 38.0
        );
        let (lx, ly) = (left - 58.0, mt + ph / 2.0);
        let _ = writeln!(
            s,
            r##"<text x="{lx:.1}" y="{ly:.1}" text-anchor="middle" transform="rotate(-90 {lx:.1} {ly:.1})">mean two-sided error / bbox diagonal</text>"##
        );
    }
    for backend in &backends {
        let (shape, colour) = style(backend);
        let _ = writeln!(s, r##"<g class="series" data-backend="{}">"##, xml(backend));
        for r in points.iter().filter(|r| r.backend == *backend) {
            let panel = ratios.iter().position(|&q| q == r.ratio).unwrap_or(0);
            let (x, y) = (px(panel, r.median_s), py(r.mean_err_rel.unwrap_or(0.0)));
            let _ = writeln!(s, "{}", marker(shape, x, y, colour));
            if meshes.len() > 1 {
                let _ = writeln!(
                    s,
                    r##"<text x="{:.1}" y="{:.1}" font-size="10" fill="#555">{}</text>"##,
                    x + 8.0,
                    y - 6.0,
                    xml(&r.mesh)
                );
            }
        }
        let _ = writeln!(s, "</g>");
    }
    let lx = n * (ml + pw + mr) + 10.0;
    let _ = writeln!(
        s,
        r##"<text x="{lx:.1}" y="{:.1}" font-weight="bold">backend</text>"##,
        mt + 4.0
    );
    for (k, backend) in backends.iter().enumerate() {
        let (shape, colour) = style(backend);
        let y = mt + 26.0 + 24.0 * k as f64;
        let _ = writeln!(s, "{}", marker(shape, lx + 8.0, y, colour));
        let _ = writeln!(
            s,
            r##"<text x="{:.1}" y="{:.1}">{}</text>"##,
            lx + 22.0,
            y + 4.0,
            xml(backend)
        );
    }
    let _ = writeln!(s, "</svg>");
    s
}

/// A global allocator that counts the heap bytes held by the whole process and their peak, so
/// that [`run`] can report the peak memory of one simplify call, threads included. The
/// `meshslim` binary installs it; elsewhere [`measure`](alloc::measure) reports `None`.
///
/// Chosen over the process's peak RSS (VmHWM after `echo 5 > /proc/self/clear_refs`): it works
/// on every platform, does not depend on when the allocator returns pages to the system, and
/// counts exactly the bytes the call asked for. Its cost is two relaxed atomic operations per
/// allocation.
pub mod alloc {
    use std::alloc::{GlobalAlloc, Layout, System};
    use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};

    static LIVE: AtomicUsize = AtomicUsize::new(0);
    static PEAK: AtomicUsize = AtomicUsize::new(0);

    /// Install with `#[global_allocator] static A: CountingAlloc = CountingAlloc;`.
    pub struct CountingAlloc;

    fn grew(by: usize) {
        let live = LIVE.fetch_add(by, Relaxed) + by;
        if live > PEAK.load(Relaxed) {
            PEAK.fetch_max(live, Relaxed);
        }
    }

    // SAFETY: every call forwards to `System` with the caller's own layout and pointer, so the
    // allocator contract is System's; the bookkeeping only touches atomics and never allocates.
    unsafe impl GlobalAlloc for CountingAlloc {
        unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
            let p = unsafe { System.alloc(layout) };
            if !p.is_null() {
                grew(layout.size());
            }
            p
        }
        unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
            let p = unsafe { System.alloc_zeroed(layout) };
            if !p.is_null() {
                grew(layout.size());
            }
            p
        }
        unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
            unsafe { System.dealloc(ptr, layout) };
            LIVE.fetch_sub(layout.size(), Relaxed);
        }
        unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
            let p = unsafe { System.realloc(ptr, layout, new_size) };
            if !p.is_null() {
                if new_size >= layout.size() {
                    grew(new_size - layout.size());
                } else {
                    LIVE.fetch_sub(layout.size() - new_size, Relaxed);
                }
            }
            p
        }
    }

    /// Whether [`CountingAlloc`] is the global allocator (it has counted something).
    pub fn installed() -> bool {
        PEAK.load(Relaxed) > 0
    }

    /// Runs `f` and returns the peak bytes held during it above what was held when it started
    /// (by any thread); `None` when the counting allocator is not installed.
    pub fn measure<T>(f: impl FnOnce() -> T) -> (T, Option<u64>) {
        if !installed() {
            return (f(), None);
        }
        let base = LIVE.load(Relaxed);
        PEAK.store(base, Relaxed);
        let out = f();
        (out, Some(PEAK.load(Relaxed).saturating_sub(base) as u64))
    }
}

/// Renders an SVG (the plot) to PNG bytes with resvg, text in the system's fonts.
pub fn svg_to_png(svg: &str) -> Result<Vec<u8>, String> {
    use resvg::{tiny_skia, usvg};
    let mut opt = usvg::Options::default();
    opt.fontdb_mut().load_system_fonts();
    let tree = usvg::Tree::from_str(svg, &opt).map_err(|e| e.to_string())?;
    let size = tree.size().to_int_size();
    let mut pixmap = tiny_skia::Pixmap::new(size.width(), size.height())
        .ok_or_else(|| format!("cannot allocate a {}x{} image", size.width(), size.height()))?;
    pixmap.fill(tiny_skia::Color::WHITE);
    resvg::render(&tree, tiny_skia::Transform::default(), &mut pixmap.as_mut());
    pixmap.encode_png().map_err(|e| e.to_string())
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

    #[test]
    fn backend_names_are_unique_and_found() {
        for (i, b) in BACKENDS.iter().enumerate() {
            assert!(std::ptr::eq(backend(b.name).unwrap(), b));
            assert!(BACKENDS[..i].iter().all(|o| o.name != b.name));
        }
        assert!(backend("nope").is_none());
    }

    #[test]
    fn median_of_odd_and_even_counts() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
    }

    #[test]
    fn sloppy_reaches_about_the_face_target() {
        let sphere = mesh::icosphere(4); // 5120 faces
        let out = meshopt_simplify_sloppy(&sphere, 512);
        assert!(out.face_count() <= 512, "{} faces", out.face_count());
        assert!(out.face_count() >= 300, "{} faces", out.face_count());
        out.validate().unwrap();
    }

    #[test]
    fn run_without_the_counting_allocator_reports_no_peak_and_plots() {
        let opts = BenchOptions {
            ratios: vec![0.5],
            repeat: 2,
            compare: CompareOptions {
                samples: Some(200),
                ..Default::default()
            },
            ..Default::default()
        };
        let inputs = [("ico".to_string(), mesh::icosphere(2))];
        let mut last = 0.0;
        let report = run(&inputs, &opts, &mut |f| last = f).unwrap();
        assert_eq!(last, 1.0);
        let backends = available_backends().len();
        assert_eq!(report.rows.len(), backends);
        for r in &report.rows {
            assert_eq!(r.times_s.len(), 2);
            assert_eq!(
                r.peak_bytes, None,
                "the test harness has no counting allocator"
            );
            assert!(r.mean_err_rel.unwrap() > 0.0);
        }
        let svg = plot_svg(&report);
        assert_eq!(svg.matches(r#"class="series""#).count(), backends);
        let mut table = Vec::new();
        write_table(&mut table, &report).unwrap();
        // Header, one row per backend, then the three lines of notes under the table.
        assert_eq!(
            String::from_utf8(table).unwrap().lines().count(),
            1 + backends + 3
        );
    }
}
