//! The `meshslim` command line: clap argument types and the runners behind each subcommand.
//!
//! `main.rs` only parses and hands the result to [`run`]; this module converts the arguments to
//! library options once, calls the library, and prints the result. It is the one place besides
//! `main.rs` that uses `anyhow`: errors of the library arrive as [`meshslim::Error`] and leave
//! as messages for the user.

use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::mpsc;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use clap::{Args, Parser, Subcommand, ValueEnum};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use crate::io::Format;
use crate::mesh::{self, Mesh};
use crate::{Backend, SimplifyOptions, SimplifyReport};

// ---------------------------------------------------------------------------------------------
// Arguments
// ---------------------------------------------------------------------------------------------

const TOP_AFTER_HELP: &str = "\
Examples:
  meshslim simplify builtin:bumpy-sphere bumpy-10.ply --ratio 0.1
  meshslim simplify scan.ply scan-5k.obj --faces 5000 --stats
  meshslim info scan.ply
  meshslim info builtin:torus --json
  meshslim compare scan.ply scan-5k.obj
  meshslim bench --json bench.json --plot bench.svg

Run 'meshslim <COMMAND> --help' for every option of a command.";

const SIMPLIFY_AFTER_HELP: &str = "\
Built-in meshes (IN = builtin:NAME or builtin:NAME:FACES, FACES a minimum face count):
  sphere        icosphere, 20480 faces
  uv-sphere     latitude-longitude sphere with poles, 16128 faces
  torus         torus, 16384 faces
  double-torus  genus-2 slab with two square holes, sharp edges, 22528 faces
  cube          cube with flat faces and sharp edges, 19200 faces
  grid          flat open square grid with a border, 20000 faces
  noisy-sphere  icosphere with 1% radial noise, 20480 faces
  bumpy-sphere  smooth bumpy sphere with fine noise, a stand-in for a scan, 327680 faces

Examples:
  # 10% of a generated 330k-face scan stand-in
  meshslim simplify builtin:bumpy-sphere bumpy-10.ply --ratio 0.1
  # a real file to 5000 faces, with the collapse statistics
  meshslim simplify scan.ply scan-5k.obj --faces 5000 --stats
  # on the GPU when there is one (else the same rounds on the CPU's cores), with the
  # rounds and per-stage times
  meshslim simplify scan.ply scan-1.ply --ratio 0.01 --backend auto --stats
  # keep the outline of an open mesh exactly
  meshslim simplify terrain.obj terrain-small.obj --ratio 0.05 --lock-border
  # simplify as far as an error of 0.1% of the bounding-box diagonal allows
  meshslim simplify scan.ply scan-err.ply --faces 0 --max-error 0.001
  # machine-readable report
  meshslim simplify builtin:torus torus-half.glb --ratio 0.5 --json";

const INFO_AFTER_HELP: &str = "\
Examples:
  meshslim info scan.ply
  meshslim info simplified.obj --json
  meshslim info builtin:double-torus";

const COMPARE_AFTER_HELP: &str = "\
Distances are Metro's (as MeshLab's Hausdorff Distance filter): points sampled uniformly by
area on the faces of each mesh, plus every vertex and points along every edge for the maximum, each
measured to the closest point of the other mesh. Relative figures are fractions of A's
bounding-box diagonal; the two-sided mean is the average of the two directions' means.

Examples:
  meshslim compare scan.ply scan-5k.obj
  meshslim compare scan.ply scan-5k.obj --samples 1000000 --seed 7
  meshslim compare builtin:sphere builtin:sphere:500 --json";

const BENCH_AFTER_HELP: &str = "\
Each mesh is simplified to each ratio by each backend, --repeat times; the table reports the
median wall time of the simplify call, input triangles per second, the peak heap held during
the call (counted by the binary's allocator, output included), and the two-sided Metro
distance to the input (as 'meshslim compare'), mean and max, relative to its bounding-box
diagonal. Without MESH it runs the deterministic 1M-triangle scan: ../shared/models/igea.ply
subdivided once when present ($MESHSLIM_MODELS names another folder), else a procedural
displaced sphere.

Examples:
  # the benchmark: the 1M scan, every backend, ratios 0.5, 0.1 and 0.01
  meshslim bench
  meshslim bench --ratios 0.1,0.01 --json bench.json --plot bench.svg
  meshslim bench scan.ply builtin:bumpy-sphere --backends cpu,meshopt --repeat 5
  # JSON on stdout instead of the table
  meshslim bench builtin:sphere --json -";

/// Triangle-mesh simplification by quadric error metrics.
#[derive(Debug, Parser)]
#[command(name = "meshslim", version, after_help = TOP_AFTER_HELP)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Simplify a mesh to a face count or a fraction of its faces
    #[command(after_help = SIMPLIFY_AFTER_HELP)]
    Simplify(SimplifyArgs),
    /// Print a mesh's topology report: counts, borders, manifoldness, genus, area, volume
    #[command(after_help = INFO_AFTER_HELP)]
    Info(InfoArgs),
    /// Measure how far mesh B is from mesh A (Metro/Hausdorff distance both ways), and the
    /// change in area, volume, triangle quality and topology
    #[command(after_help = COMPARE_AFTER_HELP)]
    Compare(CompareArgs),
    /// Time every backend on the same meshes and measure their error: a table, JSON and a plot
    #[command(after_help = BENCH_AFTER_HELP)]
    Bench(BenchArgs),
    /// Look at a mesh and its simplification in a window (orbit, modes, side by side, LOD
    /// scene), drawn from the simplifier's own GPU buffers; or one frame to a PNG with
    /// --screenshot, which needs no window system
    #[command(after_help = VIEW_AFTER_HELP)]
    View(ViewArgs),
}

const VIEW_AFTER_HELP: &str = "\
In the window: left drag orbits, right or middle drag pans, the wheel zooms, G flies (W A S D),
F frames the mesh, 1-4 switch shaded / normals / heatmap / texture, X wireframe, B side by side,
Enter simplifies to the target, Esc cancels, Ctrl+O opens, Ctrl+S saves, P takes a screenshot;
F1 lists them all. Simplification runs beside the drawing: the window keeps drawing (frame time
in the side panel) and the run can be cancelled.

Examples:
  meshslim view ../shared/models/horse.ply
  meshslim view ../shared/models/spot/spot_triangulated.obj --mode texture --screenshot spot.png
  meshslim view ../shared/models/horse.ply --screenshot horse.png --ratio 0.1
  meshslim view scan.ply --screenshot err.png --ratio 0.01 --mode heatmap --size 1600x1200";

#[derive(Debug, Args)]
pub struct ViewArgs {
    /// The mesh: a file or builtin:NAME[:FACES]; without one the window opens empty (Ctrl+O or
    /// drop a file on it)
    #[arg(value_name = "MESH", value_parser = parse_input_arg)]
    pub input: Option<Input>,

    /// Render one frame to this PNG file and exit, without a window
    #[arg(long, value_name = "FILE.png")]
    pub screenshot: Option<PathBuf>,

    /// A PNG or JPEG texture for the texture mode (default: the OBJ material's map_Kd, else the
    /// only PNG or JPEG beside a mesh that has UVs)
    #[arg(long, value_name = "FILE.png|jpg")]
    pub texture: Option<PathBuf>,

    /// With --screenshot: simplify to this fraction of the faces on the GPU first, in (0, 1]
    /// (default 1: the mesh as is). In the window: the starting target (default 0.1)
    #[arg(long, value_name = "R", value_parser = parse_ratio, allow_negative_numbers = true)]
    pub ratio: Option<f64>,

    /// What the surface shows
    #[arg(long, value_enum, default_value_t = crate::viewer::Mode::Shaded)]
    pub mode: crate::viewer::Mode,

    /// Smooth shading (per-vertex normals) instead of flat faces
    #[arg(long)]
    pub smooth: bool,

    /// Draw the edges over the surface
    #[arg(long)]
    pub wireframe: bool,

    /// Image size for --screenshot (default 1024x768), or the window's size (default 1280x800),
    /// WIDTHxHEIGHT
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    pub size: Option<(u32, u32)>,

    /// The mesh's axis drawn up: x, y, z, -x, -y, -z, or auto (the largest silhouette).
    /// Default: the file's convention, +Y (OBJ, PLY, glTF, generated meshes) or +Z (STL)
    #[arg(long, value_enum, value_name = "AXIS", allow_hyphen_values = true)]
    pub up: Option<crate::viewer::camera::Up>,
}

fn parse_size(s: &str) -> std::result::Result<(u32, u32), String> {
    let bad = || format!("{s:?}: write the size as WIDTHxHEIGHT, e.g. 1024x768");
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let (w, h) = (w.trim().parse::<u32>(), h.trim().parse::<u32>());
    match (w, h) {
        (Ok(w), Ok(h)) if (1..=16384).contains(&w) && (1..=16384).contains(&h) => Ok((w, h)),
        (Ok(w), Ok(h)) => Err(format!("{w}x{h}: each side must be 1 to 16384 pixels")),
        _ => Err(bad()),
    }
}

fn run_view(args: ViewArgs) -> Result<ExitCode> {
    let progress = Progress::new(std::io::stderr().is_terminal());
    let style = crate::viewer::Style {
        mode: args.mode,
        smooth: args.smooth,
        wireframe: args.wireframe,
        error_scale: 0.0,
    };
    let model = |input: &Input| -> Result<crate::viewer::Model> {
        match input {
            Input::File(path) => progress
                .spinner(format!("reading {}", path.display()), || {
                    crate::viewer::Model::open(path, args.texture.as_deref())
                })
                .map(|mut m| {
                    m.up_axis = args.up.unwrap_or(m.up_axis);
                    m
                })
                .map_err(lib)
                .context("cannot read the input"),
            Input::Builtin { .. } => {
                let mesh = load(input, &progress)?;
                let mut m = crate::viewer::Model::from_mesh(input.display(), mesh).map_err(lib)?;
                m.up_axis = args.up.unwrap_or(m.up_axis);
                if let Some(t) = &args.texture {
                    m.texture = Some(crate::viewer::scene::read_texture(t).map_err(lib)?);
                }
                Ok(m)
            }
        }
    };
    let Some(png) = args.screenshot.clone() else {
        // A file that cannot be opened fails here, not in a window that opens to say so.
        if let Some(Input::File(p)) = &args.input {
            std::fs::File::open(p)
                .map_err(|e| {
                    lib(crate::Error::Io {
                        path: p.clone(),
                        source: e,
                    })
                })
                .context("cannot read the input")?;
        }
        let start = match &args.input {
            Some(Input::File(p)) if args.texture.is_none() => crate::viewer::Start::Open(p.clone()),
            Some(input) => crate::viewer::Start::Model(model(input)?),
            None => crate::viewer::Start::Nothing,
        };
        let size = args.size.unwrap_or((1280, 800));
        crate::viewer::run_window(start, args.ratio.unwrap_or(0.1), style, size, args.up)
            .map_err(lib)?;
        return Ok(ExitCode::SUCCESS);
    };
    let Some(input) = &args.input else {
        return Err(UsageError("--screenshot needs a MESH to draw".into()).into());
    };
    if !png
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"))
    {
        return Err(UsageError(format!(
            "{}: the screenshot is a PNG; name it FILE.png",
            png.display()
        ))
        .into());
    }
    // Before any reading or rendering: a screenshot with nowhere to go fails at once.
    check_directory(&png, "the screenshot's directory")?;
    let model = model(input)?;
    let size = args.size.unwrap_or((1024, 768));
    let frame = progress
        .spinner("simplifying and rendering on the GPU".to_string(), || {
            crate::viewer::screenshot(&model, args.ratio.unwrap_or(1.0), style, size)
        })
        .map_err(lib)?;
    crate::io::write_atomic(&png, |w| w.write_all(&frame.png))
        .map_err(lib)
        .context("cannot write the screenshot")?;
    let heat = if args.mode == crate::viewer::Mode::Heatmap {
        format!(", heatmap red at {:.3e} of the diagonal", frame.max_error)
    } else {
        String::new()
    };
    println!(
        "{}: {} faces drawn from the GPU buffers on {}, {}x{}{heat}",
        png.display(),
        frame.faces,
        frame.adapter,
        size.0,
        size.1
    );
    Ok(ExitCode::SUCCESS)
}

/// A mesh to read: a file, or a generated mesh `builtin:NAME[:FACES]`.
#[derive(Debug, Clone)]
pub enum Input {
    File(PathBuf),
    /// The spec as written (`builtin:torus:5000`) and what it names.
    Builtin {
        spec: String,
        kind: &'static BuiltinMesh,
        min_faces: Option<usize>,
    },
}

impl Input {
    /// How the user named it, for messages and the JSON report.
    pub fn display(&self) -> String {
        match self {
            Input::File(p) => p.display().to_string(),
            Input::Builtin { spec, .. } => spec.clone(),
        }
    }
}

impl std::str::FromStr for Input {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s.strip_prefix(BUILTIN_PREFIX) {
            Some(rest) => {
                let (kind, min_faces) = parse_builtin(rest)?;
                Ok(Input::Builtin {
                    spec: s.to_string(),
                    kind,
                    min_faces,
                })
            }
            None if s.is_empty() => Err("the input path is empty".into()),
            None => Ok(Input::File(PathBuf::from(s))),
        }
    }
}

#[derive(Debug, Args)]
pub struct SimplifyArgs {
    /// Input mesh: a .obj, .ply, .stl, .gltf or .glb file, or a generated mesh written
    /// builtin:NAME or builtin:NAME:FACES (names below)
    #[arg(value_name = "IN", value_parser = parse_input_arg)]
    pub input: Option<Input>,

    /// Output file; the format follows its extension (.obj, .ply, .stl, .gltf, .glb). Written
    /// atomically, and never over the input
    #[arg(value_name = "OUT")]
    pub output: Option<PathBuf>,

    /// Keep this fraction of the faces, in (0, 1] [default: 0.1 unless --faces is given]
    #[arg(short, long, value_name = "R", value_parser = parse_ratio, allow_negative_numbers = true, conflicts_with = "faces")]
    pub ratio: Option<f64>,

    /// Keep this many faces (reached exactly or one below: an interior collapse removes two).
    /// 0 simplifies until --max-error or the constraints stop it
    #[arg(short, long, value_name = "N", value_parser = parse_face_count, allow_negative_numbers = true)]
    pub faces: Option<usize>,

    /// Stop before a collapse whose error exceeds E, relative to the bounding-box diagonal
    /// (0.001 = 0.1% of the diagonal), even if the face target is not reached [default: no limit]
    #[arg(short = 'e', long, value_name = "E", value_parser = parse_non_negative, allow_negative_numbers = true)]
    pub max_error: Option<f64>,

    /// Keep the border (the outline of an open mesh) exactly: border vertices never move, and one
    /// is removed only where it lies on the straight line between its border neighbours
    #[arg(long)]
    pub lock_border: bool,

    /// Weight of the border and attribute-seam constraint planes relative to the face planes
    /// (Hoppe's boundary quadrics); larger keeps open borders and seams closer to where they were
    #[arg(long, value_name = "W", default_value_t = 1.0, value_parser = parse_non_negative, allow_negative_numbers = true)]
    pub border_weight: f64,

    /// Refuse a collapse that turns any surrounding face's normal by more than DEG degrees,
    /// in (0, 180]
    #[arg(long = "max-normal-angle", value_name = "DEG", default_value_t = 90.0, value_parser = parse_angle, allow_negative_numbers = true)]
    pub max_normal_angle: f64,

    /// Collapses creating faces of quality below Q cost proportionally more (MeshLab's
    /// QualityThr; quality is 0.866 for an equilateral triangle, 0 for a sliver), in [0, 1].
    /// 0 turns the term off, giving textbook QEM order
    #[arg(long, value_name = "Q", default_value_t = 0.3, value_parser = parse_unit, allow_negative_numbers = true)]
    pub quality_threshold: f64,

    /// Which implementation simplifies
    #[arg(long, value_enum, default_value_t = BackendArg::Cpu)]
    pub backend: BackendArg,

    /// Print exactly one JSON object with the report on stdout, and nothing else there
    #[arg(long)]
    pub json: bool,

    /// Also print the collapse statistics: collapses, pinned vertices, dropped degenerate faces,
    /// largest collapse error (the JSON report always has them)
    #[arg(long)]
    pub stats: bool,

    /// Print nothing but errors (and the JSON report with --json); no progress bars
    #[arg(short, long)]
    pub quiet: bool,
}

#[derive(Debug, Args)]
pub struct InfoArgs {
    /// Mesh to describe: a .obj, .ply, .stl, .gltf or .glb file, or builtin:NAME[:FACES]
    /// (names in 'meshslim simplify --help')
    #[arg(value_name = "IN", value_parser = parse_input_arg)]
    pub input: Input,

    /// Print the report as one JSON object on stdout
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Args)]
pub struct CompareArgs {
    /// The reference mesh (the original): a file or builtin:NAME[:FACES]
    #[arg(value_name = "A", value_parser = parse_input_arg)]
    pub a: Input,

    /// The mesh to measure against A (the simplified one)
    #[arg(value_name = "B", value_parser = parse_input_arg)]
    pub b: Input,

    /// Points sampled on the faces in each direction [default: at least one per face of the
    /// denser mesh and ten per face of the coarser one]
    #[arg(short = 'n', long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    pub samples: Option<u64>,

    /// Seed of the sample positions: the same seed gives the same figures
    #[arg(long, value_name = "S", default_value_t = 1)]
    pub seed: u64,

    /// Print one JSON object with every figure on stdout
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Args)]
pub struct BenchArgs {
    /// Meshes to benchmark: files or builtin:NAME[:FACES] [default: the deterministic
    /// 1M-triangle scan]
    #[arg(value_name = "MESH", value_parser = parse_input_arg)]
    pub meshes: Vec<Input>,

    /// Fractions of the faces to keep, comma-separated, each in (0, 1]
    #[arg(long, value_name = "R,...", value_delimiter = ',', value_parser = parse_bench_ratio, allow_negative_numbers = true,
          default_values_t = crate::bench::DEFAULT_RATIOS)]
    pub ratios: Vec<f64>,

    /// Backends to run, comma-separated: cpu (meshslim's greedy), meshopt (meshoptimizer's
    /// simplify), meshopt-sloppy (its clustering simplifySloppy) [default: all of them]
    #[arg(long, value_name = "B,...", value_delimiter = ',', value_parser = parse_bench_backend)]
    pub backends: Vec<&'static crate::bench::BenchBackend>,

    /// Timed runs of each simplify call; the table reports their median
    #[arg(long, value_name = "N", default_value_t = 3, value_parser = clap::value_parser!(u64).range(1..))]
    pub repeat: u64,

    /// Also write the report as one JSON object to FILE ('-': to stdout, instead of the table)
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,

    /// Draw the mean error against the time (log-log, one panel per ratio) to FILE.svg or
    /// FILE.png
    #[arg(long, value_name = "FILE.svg|FILE.png")]
    pub plot: Option<PathBuf>,

    /// Points sampled on the faces in each direction for the error [default: as 'meshslim
    /// compare']
    #[arg(short = 'n', long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    pub samples: Option<u64>,

    /// Seed of the error's sample positions
    #[arg(long, value_name = "S", default_value_t = 1)]
    pub seed: u64,
}

fn parse_bench_ratio(s: &str) -> std::result::Result<f64, String> {
    let v = parse_f64(s)?;
    if v > 0.0 && v <= 1.0 {
        Ok(v)
    } else {
        Err(format!("each ratio must be in (0, 1], got {v}"))
    }
}

fn parse_bench_backend(
    s: &str,
) -> std::result::Result<&'static crate::bench::BenchBackend, String> {
    crate::bench::backend(s.trim()).ok_or_else(|| {
        let names: Vec<&str> = crate::bench::BACKENDS.iter().map(|b| b.name).collect();
        format!(
            "unknown backend {s:?}; the backends are {}",
            names.join(", ")
        )
    })
}

/// The `--backend` choices.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum BackendArg {
    /// Greedy quadric edge collapse with a priority queue, in f64: the quality reference
    Cpu,
    /// The GPU's rounds of parallel collapses, on the CPU's cores (rayon)
    CpuParallel,
    /// Rounds of parallel collapses as WGSL compute passes (wgpu: Vulkan, Metal, DX12)
    Gpu,
    /// gpu when a GPU adapter is found, else cpu-parallel (says which on stderr); a software
    /// rasterizer (llvmpipe, WARP) counts as none, being slower than the CPU's cores; falls back
    /// to cpu-parallel when the GPU fails (a lost device, a mesh too big for it)
    Auto,
}

impl BackendArg {
    /// The library backend, `None` for `auto` (decided when the mesh is there).
    fn fixed(self) -> Option<Backend> {
        match self {
            BackendArg::Cpu => Some(Backend::Cpu),
            BackendArg::CpuParallel => Some(Backend::CpuParallel),
            BackendArg::Gpu => Some(Backend::Gpu),
            BackendArg::Auto => None,
        }
    }
}

fn parse_input_arg(s: &str) -> std::result::Result<Input, String> {
    s.parse()
}

fn parse_f64(s: &str) -> std::result::Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("{s:?} is not a number"))?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!("{s:?} is not a finite number"))
    }
}

fn parse_face_count(s: &str) -> std::result::Result<usize, String> {
    s.trim()
        .parse::<usize>()
        .map_err(|_| format!("{s:?}: the face count is a whole number, 0 or more"))
}

fn parse_ratio(s: &str) -> std::result::Result<f64, String> {
    let v = parse_f64(s)?;
    if v > 0.0 && v <= 1.0 {
        Ok(v)
    } else {
        Err(format!(
            "the ratio must be in (0, 1], got {v} (use --faces N for a face count)"
        ))
    }
}

fn parse_non_negative(s: &str) -> std::result::Result<f64, String> {
    let v = parse_f64(s)?;
    if v >= 0.0 {
        Ok(v)
    } else {
        Err(format!("must be >= 0, got {v}"))
    }
}

fn parse_angle(s: &str) -> std::result::Result<f64, String> {
    let v = parse_f64(s)?;
    if v > 0.0 && v <= 180.0 {
        Ok(v)
    } else {
        Err(format!("the angle must be in (0, 180] degrees, got {v}"))
    }
}

fn parse_unit(s: &str) -> std::result::Result<f64, String> {
    let v = parse_f64(s)?;
    if (0.0..=1.0).contains(&v) {
        Ok(v)
    } else {
        Err(format!("must be in [0, 1], got {v}"))
    }
}

// ---------------------------------------------------------------------------------------------
// Built-in meshes
// ---------------------------------------------------------------------------------------------

const BUILTIN_PREFIX: &str = "builtin:";

/// Largest FACES accepted in `builtin:NAME:FACES` (a typo should not allocate gigabytes).
pub const MAX_BUILTIN_FACES: usize = 20_000_000;

/// A generated mesh the command line can use as input.
#[derive(Debug)]
pub struct BuiltinMesh {
    pub name: &'static str,
    /// Builds the mesh with at least the given number of faces, or its default size.
    make: fn(Option<usize>) -> Mesh,
}

/// Smallest `k >= start` with `faces(k) >= min`.
fn smallest(start: usize, min: usize, faces: impl Fn(usize) -> usize) -> usize {
    let mut k = start;
    while faces(k) < min {
        k += 1;
    }
    k
}

fn icosphere_level(min: Option<usize>) -> u32 {
    match min {
        None => 5,
        Some(n) => smallest(0, n, |l| 20 << (2 * l)) as u32,
    }
}

/// The generated meshes, by name. `simplify --help` lists them (a unit test keeps the two in
/// step).
pub static BUILTINS: &[BuiltinMesh] = &[
    BuiltinMesh {
        name: "sphere",
        make: |n| mesh::icosphere(icosphere_level(n)),
    },
    BuiltinMesh {
        name: "uv-sphere",
        // 2·segments·(rings − 1) faces with rings = segments / 2.
        make: |n| {
            let half = n.map_or(64, |n| smallest(2, n, |h| 4 * h * (h - 1)));
            mesh::uv_sphere(2 * half, half)
        },
    },
    BuiltinMesh {
        name: "torus",
        // 2·nu·nv faces with nu = 2·nv.
        make: |n| {
            let k = n.map_or(64, |n| smallest(3, n, |k| 4 * k * k));
            mesh::torus(1.0, 0.35, 2 * k, k)
        },
    },
    BuiltinMesh {
        name: "double-torus",
        // 176·s² voxel faces, two triangles each.
        make: |n| mesh::double_torus(n.map_or(8, |n| smallest(1, n, |s| 352 * s * s))),
    },
    BuiltinMesh {
        name: "cube",
        make: |n| mesh::cube(n.map_or(40, |n| smallest(1, n, |k| 12 * k * k))),
    },
    BuiltinMesh {
        name: "grid",
        make: |n| mesh::grid(n.map_or(100, |n| smallest(1, n, |k| 2 * k * k))),
    },
    BuiltinMesh {
        name: "noisy-sphere",
        make: |n| mesh::noisy_sphere(icosphere_level(n), 0.01, 1),
    },
    BuiltinMesh {
        name: "bumpy-sphere",
        make: |n| mesh::displaced_sphere(n.unwrap_or(200_000), 1),
    },
];

/// Parses `NAME` or `NAME:FACES` (without the `builtin:` prefix).
fn parse_builtin(spec: &str) -> std::result::Result<(&'static BuiltinMesh, Option<usize>), String> {
    let (name, faces) = match spec.split_once(':') {
        Some((name, faces)) => (name, Some(faces)),
        None => (spec, None),
    };
    let names = || {
        BUILTINS
            .iter()
            .map(|b| b.name)
            .collect::<Vec<_>>()
            .join(", ")
    };
    let kind = BUILTINS.iter().find(|b| b.name == name).ok_or_else(|| {
        format!(
            "unknown built-in mesh {name:?}; the built-in meshes are {}",
            names()
        )
    })?;
    let min_faces = match faces {
        None => None,
        Some(f) => match f.parse::<usize>() {
            Ok(n) if (1..=MAX_BUILTIN_FACES).contains(&n) => Some(n),
            _ => {
                return Err(format!(
                    "the face count in builtin:{name}:{f} must be a whole number from 1 to \
                     {MAX_BUILTIN_FACES}"
                ));
            }
        },
    };
    Ok((kind, min_faces))
}

/// The generated mesh a spec names: `builtin:NAME`, `builtin:NAME:FACES` (at least FACES faces),
/// or the same without the `builtin:` prefix.
pub fn builtin(spec: &str) -> Result<Mesh> {
    let rest = spec.strip_prefix(BUILTIN_PREFIX).unwrap_or(spec);
    let (kind, min_faces) = parse_builtin(rest).map_err(UsageError)?;
    Ok((kind.make)(min_faces))
}

// ---------------------------------------------------------------------------------------------
// Running
// ---------------------------------------------------------------------------------------------

/// A mistake in how the command was called: reported like clap's own, with exit code 2.
#[derive(Debug)]
pub struct UsageError(pub String);

impl std::fmt::Display for UsageError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for UsageError {}

/// The exit code for an error [`run`] returned: 2 for bad usage, 1 for everything else.
pub fn exit_code(err: &anyhow::Error) -> ExitCode {
    if err.downcast_ref::<UsageError>().is_some() {
        ExitCode::from(2)
    } else {
        ExitCode::FAILURE
    }
}

/// The library's errors carry the file and the cause in their message already; passing them on
/// as messages keeps `{:#}` from printing the cause a second time.
fn lib(e: crate::Error) -> anyhow::Error {
    anyhow::Error::msg(e.to_string())
}

/// What a user who typed `meshslim` or `meshslim simplify` alone needs to get going.
pub const GETTING_STARTED: &str = "\
meshslim simplifies triangle meshes.

Try it on a generated mesh (a bumpy 330k-face sphere standing in for a scan):
  meshslim simplify builtin:bumpy-sphere bumpy-10.ply --ratio 0.1

On your own file, down to 5000 faces (.obj, .ply, .stl, .gltf and .glb are read and written):
  meshslim simplify scan.ply scan-5k.obj --faces 5000

Look at a mesh (faces, borders, manifoldness, genus, area, volume):
  meshslim info scan.ply

Learn more:
  meshslim simplify --help
  meshslim --help";

/// Runs a parsed command line. Returns the exit code for success or for an input-less call;
/// an error goes back to `main`, which prints it and exits with [`exit_code`].
pub fn run(cli: Cli) -> Result<ExitCode> {
    match cli.command {
        None => {
            eprintln!("{GETTING_STARTED}");
            Ok(ExitCode::from(2))
        }
        Some(Command::Simplify(args)) => run_simplify(args),
        Some(Command::Info(args)) => run_info(args),
        Some(Command::Compare(args)) => run_compare(args),
        Some(Command::Bench(args)) => run_bench(args),
        Some(Command::View(args)) => run_view(args),
    }
}

fn load(input: &Input, progress: &Progress) -> Result<Mesh> {
    match input {
        Input::File(path) => progress
            .spinner(format!("reading {}", path.display()), || {
                crate::io::read(path)
            })
            .map_err(lib)
            .context("cannot read the input"),
        Input::Builtin {
            spec,
            kind,
            min_faces,
        } => Ok(progress.spinner(format!("generating {spec}"), || (kind.make)(*min_faces))),
    }
}

/// Fails when the folder `file` is to be written into does not exist (`what` names it).
fn check_directory(file: &Path, what: &str) -> Result<()> {
    if let Some(dir) = file.parent().filter(|d| !d.as_os_str().is_empty())
        && !dir.is_dir()
    {
        anyhow::bail!(
            "{}: {what} {} does not exist",
            file.display(),
            dir.display()
        );
    }
    Ok(())
}

/// The checks that need no mesh, so that a wrong output path fails before any work.
fn check_output(input: &Input, output: &Path) -> Result<()> {
    Format::from_path(output).map_err(lib)?;
    check_directory(output, "the output directory")?;
    if let Input::File(input) = input
        && output.exists()
        && same_file(input, output)
    {
        return Err(lib(crate::Error::WouldOverwriteInput(input.clone())));
    }
    Ok(())
}

/// Whether two existing paths name one file: the same canonical path, or (on Unix) the same
/// inode, which also catches hard links.
fn same_file(a: &Path, b: &Path) -> bool {
    if let (Ok(ca), Ok(cb)) = (a.canonicalize(), b.canonicalize())
        && ca == cb
    {
        return true;
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if let (Ok(ma), Ok(mb)) = (std::fs::metadata(a), std::fs::metadata(b)) {
            return ma.dev() == mb.dev() && ma.ino() == mb.ino();
        }
    }
    false
}

enum Target {
    Ratio(f64),
    Faces(usize),
}

fn run_simplify(args: SimplifyArgs) -> Result<ExitCode> {
    let Some(input) = args.input else {
        eprintln!("{GETTING_STARTED}");
        return Ok(ExitCode::from(2));
    };
    let Some(output) = args.output else {
        return Err(UsageError(format!(
            "no output file: write it after the input, as in\n  meshslim simplify {} OUT.ply \
             [OPTIONS]\n\nFor more information, try 'meshslim simplify --help'.",
            input.display()
        ))
        .into());
    };
    check_output(&input, &output)?;

    let target = match (args.ratio, args.faces) {
        (_, Some(n)) => Target::Faces(n),
        (Some(r), None) => Target::Ratio(r),
        (None, None) => Target::Ratio(0.1),
    };
    let progress = Progress::new(!(args.quiet || args.json) && std::io::stderr().is_terminal());

    let t = Instant::now();
    let mesh = load(&input, &progress)?;
    let load_s = t.elapsed().as_secs_f64();

    let mut opts = match target {
        Target::Ratio(r) => SimplifyOptions::with_ratio(mesh.face_count(), r).map_err(lib)?,
        Target::Faces(n) => SimplifyOptions::with_faces(n),
    };
    opts.max_error = args.max_error;
    opts.lock_border = args.lock_border;
    opts.border_weight = args.border_weight;
    opts.max_normal_angle_deg = args.max_normal_angle;
    opts.quality_threshold = args.quality_threshold;
    let say = |msg: String| {
        if !args.quiet {
            eprintln!("{msg}");
        }
    };
    opts.backend = match args.backend.fixed() {
        Some(b) => b,
        // The process's shared device: the adapter found here is the one that simplifies.
        None => match crate::gpu::shared_context() {
            Ok(ctx) if ctx.software => {
                say(format!(
                    "backend auto: cpu-parallel (the only GPU adapter, {}, is a software \
                     rasterizer, slower than the CPU's cores; --backend gpu runs on it anyway)",
                    ctx.adapter_name
                ));
                Backend::CpuParallel
            }
            Ok(_) => match crate::gpu::shared() {
                Ok((ctx, _)) => {
                    say(format!("backend auto: gpu on {}", ctx.adapter_name));
                    Backend::Gpu
                }
                Err(e) => {
                    say(format!("backend auto: cpu-parallel ({e})"));
                    Backend::CpuParallel
                }
            },
            Err(e) => {
                say(format!("backend auto: cpu-parallel ({e})"));
                Backend::CpuParallel
            }
        },
    };

    let t = Instant::now();
    let mut result = progress.bar("simplifying", |set| {
        crate::simplify_with_progress(&mesh, &opts, &mut |f| set(f))
    });
    if args.backend == BackendArg::Auto
        && opts.backend == Backend::Gpu
        && matches!(
            result,
            Err(crate::Error::Gpu(_) | crate::Error::BufferTooLarge { .. })
        )
    {
        if let Err(e) = &result {
            say(format!(
                "backend auto: the GPU failed ({e}); falling back to cpu-parallel"
            ));
        }
        opts.backend = Backend::CpuParallel;
        result = progress.bar("simplifying", |set| {
            crate::simplify_with_progress(&mesh, &opts, &mut |f| set(f))
        });
    }
    let (simplified, report) = result
        .map_err(lib)
        .with_context(|| format!("cannot simplify {}", input.display()))?;
    let simplify_s = t.elapsed().as_secs_f64();
    drop(mesh);

    if let Ok(format) = crate::io::Format::from_path(&output) {
        for lost in crate::io::not_kept(&simplified, format) {
            say(format!(
                "note: {} ({}) does not keep {lost}",
                output.display(),
                format.extension()
            ));
        }
    }
    let t = Instant::now();
    progress
        .spinner(format!("writing {}", output.display()), || match &input {
            Input::File(from) => crate::io::write_from(&output, &simplified, from),
            Input::Builtin { .. } => crate::io::write(&output, &simplified),
        })
        .map_err(lib)
        .context("cannot write the output")?;
    let save_s = t.elapsed().as_secs_f64();

    let times = Times {
        load: load_s,
        simplify: simplify_s,
        save: save_s,
    };
    let out = std::io::stdout();
    let mut out = out.lock();
    if args.json {
        let json = simplify_json(&input, &output, &report, &times);
        writeln!(out, "{}", serde_json::to_string_pretty(&json)?)?;
    } else if !args.quiet {
        write_summary(&mut out, &input, &output, &report, &times, args.stats)?;
    }
    out.flush()?;
    Ok(ExitCode::SUCCESS)
}

struct Times {
    load: f64,
    simplify: f64,
    save: f64,
}

fn simplify_json(input: &Input, output: &Path, r: &SimplifyReport, t: &Times) -> serde_json::Value {
    serde_json::json!({
        "input": input.display(),
        "output": output.display().to_string(),
        "backend": r.backend,
        "input_faces": r.input_faces,
        "input_vertices": r.input_vertices,
        "target_faces": r.target_faces,
        "output_faces": r.output_faces,
        "output_vertices": r.output_vertices,
        "stop_reason": r.stop_reason,
        "stop_reason_explained": r.stop_reason.explain(),
        "collapses": r.collapses,
        "max_collapse_error": r.max_collapse_error,
        "pinned_vertices": r.pinned_vertices,
        "dropped_degenerate_faces": r.dropped_degenerate_faces,
        "seconds": { "load": t.load, "simplify": t.simplify, "save": t.save },
        "rounds": r.rounds,
    })
}

fn write_summary(
    out: &mut impl Write,
    input: &Input,
    output: &Path,
    r: &SimplifyReport,
    t: &Times,
    stats: bool,
) -> std::io::Result<()> {
    let pct = |n: usize| {
        if r.input_faces == 0 {
            100.0
        } else {
            100.0 * n as f64 / r.input_faces as f64
        }
    };
    writeln!(
        out,
        "input    {}: {} faces, {} vertices",
        input.display(),
        r.input_faces,
        r.input_vertices
    )?;
    writeln!(
        out,
        "output   {}: {} faces, {} vertices ({:.1}% of the faces; target {})",
        output.display(),
        r.output_faces,
        r.output_vertices,
        pct(r.output_faces),
        r.target_faces
    )?;
    match r.stop_reason {
        crate::StopReason::TargetReached => writeln!(out, "result   {}", r.stop_reason.explain())?,
        reason => writeln!(
            out,
            "result   target of {} faces not reached: {}",
            r.target_faces,
            reason.explain()
        )?,
    }
    if let Some(b) = &r.blocked {
        writeln!(out, "why      {}", b.explain())?;
    }
    writeln!(
        out,
        "time     load {:.3} s, simplify {:.3} s, save {:.3} s (backend {})",
        t.load,
        t.simplify,
        t.save,
        r.backend.name()
    )?;
    if stats {
        writeln!(out, "collapses           {}", r.collapses)?;
        writeln!(
            out,
            "pinned vertices     {} (kept in place: non-manifold points, seams on a locked border)",
            r.pinned_vertices
        )?;
        writeln!(
            out,
            "dropped degenerate  {} faces with a repeated vertex, removed before simplifying",
            r.dropped_degenerate_faces
        )?;
        writeln!(
            out,
            "max collapse error  {:.3e} of the bounding-box diagonal",
            r.max_collapse_error
        )?;
        if let Some(rr) = &r.rounds {
            write_rounds(out, rr)?;
        }
    }
    Ok(())
}

/// The round-based backends' statistics: adapter, rounds, removals, time per stage.
fn write_rounds(out: &mut impl Write, rr: &crate::parallel::RoundsReport) -> std::io::Result<()> {
    if let Some(a) = &rr.adapter {
        writeln!(out, "adapter             {a}")?;
        writeln!(
            out,
            "pipelines           {:.3} s to compile shaders and create pipelines (not in the \
             stage times); upload + download {:.3} s",
            rr.pipeline_seconds, rr.transfer_seconds
        )?;
    }
    let removed = &rr.faces_removed_per_round;
    writeln!(out, "rounds              {}", rr.rounds)?;
    let list: Vec<String> = removed.iter().map(|n| n.to_string()).collect();
    writeln!(out, "faces removed/round {}", list.join(" "))?;
    let kind = if rr.adapter.is_none() {
        "CPU time"
    } else if rr.gpu_timestamps {
        "GPU time (timestamp queries)"
    } else {
        "wall time per round (the device has no timestamp queries)"
    };
    let total = rr.stage_seconds.total();
    writeln!(out, "stage times         {kind}, {total:.3} s in all")?;
    let mut stages = rr.stage_seconds.0.clone();
    stages.sort_by(|a, b| b.1.total_cmp(&a.1));
    for (s, t) in &stages {
        let share = if total > 0.0 { 100.0 * t / total } else { 0.0 };
        writeln!(out, "  {s:<20} {t:>9.4} s {share:>5.1}%")?;
    }
    if let Some((s, _)) = rr.stage_seconds.slowest() {
        writeln!(out, "slowest stage       {s}")?;
    }
    Ok(())
}

fn run_info(args: InfoArgs) -> Result<ExitCode> {
    let progress = Progress::new(!args.json && std::io::stderr().is_terminal());
    let mesh = load(&args.input, &progress)?;
    let topo = progress.spinner("measuring".to_string(), || mesh::topology(&mesh));
    let diagonal = mesh.bounds().map_or(0.0, |b| b.diagonal());
    let out = std::io::stdout();
    let mut out = out.lock();
    if args.json {
        let mut json = serde_json::to_value(&topo)?;
        let obj = json
            .as_object_mut()
            .expect("the topology report serializes as an object");
        let extra = serde_json::json!({
            "input": args.input.display(),
            "diagonal": diagonal,
            "manifold": topo.is_manifold(),
            "closed": topo.is_closed(),
            "consistently_oriented": topo.is_consistently_oriented(),
            "normals": mesh.normals.is_some(),
            "uvs": mesh.uvs.is_some(),
            "colors": mesh.colors.is_some(),
            "uv_origin": mesh.uvs.as_ref().map(|_| mesh.uv_origin.name()),
            "materials": mesh.materials.len(),
            "texture_images": mesh.textures.images.len(),
            "groups": mesh.groups.len(),
        });
        obj.extend(extra.as_object().cloned().unwrap_or_default());
        writeln!(out, "{}", serde_json::to_string_pretty(&json)?)?;
    } else {
        let t = &topo;
        let yes_no = |b: bool, yes: &'static str, no: &'static str| if b { yes } else { no };
        writeln!(out, "{}", args.input.display())?;
        writeln!(
            out,
            "  vertices           {} ({} welded by position)",
            t.vertices, t.welded_vertices
        )?;
        writeln!(out, "  faces              {}", t.faces)?;
        writeln!(out, "  edges              {}", t.edges)?;
        writeln!(
            out,
            "  boundary           {} edges in {} loops ({})",
            t.boundary_edges,
            t.boundary_loops,
            yes_no(t.is_closed(), "closed", "open")
        )?;
        writeln!(
            out,
            "  non-manifold       {} edges, {} vertices ({})",
            t.non_manifold_edges,
            t.non_manifold_vertices,
            yes_no(t.is_manifold(), "manifold", "not manifold")
        )?;
        writeln!(out, "  components         {}", t.connected_components)?;
        let genus = t
            .genus
            .map_or("undefined (not manifold)".to_string(), |g| g.to_string());
        writeln!(
            out,
            "  euler / genus      {} / {}",
            t.euler_characteristic, genus
        )?;
        if t.is_consistently_oriented() {
            writeln!(out, "  orientation        consistent")?;
        } else {
            writeln!(
                out,
                "  orientation        inconsistent: {} edges traversed the same way by both faces",
                t.inconsistently_oriented_edges
            )?;
        }
        writeln!(out, "  degenerate faces   {}", t.degenerate_faces)?;
        writeln!(out, "  duplicate faces    {}", t.duplicate_faces)?;
        writeln!(out, "  area               {:.6}", t.surface_area)?;
        writeln!(out, "  volume             {:.6} (signed)", t.signed_volume)?;
        writeln!(
            out,
            "  bounding box       {:?} .. {:?}, diagonal {:.6}",
            t.bounds_min, t.bounds_max, diagonal
        )?;
        let attrs: Vec<&str> = [
            (mesh.normals.is_some(), "normals"),
            (mesh.uvs.is_some(), "uvs"),
            (mesh.colors.is_some(), "colors"),
        ]
        .into_iter()
        .filter_map(|(has, name)| has.then_some(name))
        .collect();
        writeln!(
            out,
            "  attributes         {}",
            if attrs.is_empty() {
                "none".to_string()
            } else {
                attrs.join(", ")
            }
        )?;
        if mesh.uvs.is_some() {
            writeln!(
                out,
                "  uv origin          {} of the texture image",
                mesh.uv_origin.name()
            )?;
        }
        writeln!(out, "  materials          {}", mesh.materials.len())?;
        let images = &mesh.textures.images;
        if !images.is_empty() {
            let bytes: usize = images
                .iter()
                .filter_map(|i| i.data.as_ref())
                .map(|d| d.len())
                .sum();
            let unread = images.iter().filter(|i| i.data.is_none()).count();
            writeln!(
                out,
                "  texture images     {} ({:.1} MiB{})",
                images.len(),
                bytes as f64 / (1024.0 * 1024.0),
                if unread > 0 {
                    format!(", {unread} could not be read")
                } else {
                    String::new()
                }
            )?;
        }
        writeln!(out, "  groups             {}", mesh.groups.len())?;
    }
    out.flush()?;
    Ok(ExitCode::SUCCESS)
}

fn run_compare(args: CompareArgs) -> Result<ExitCode> {
    let progress = Progress::new(!args.json && std::io::stderr().is_terminal());
    let t = Instant::now();
    let a = load(&args.a, &progress)?;
    let b = load(&args.b, &progress)?;
    let load_s = t.elapsed().as_secs_f64();
    let opts = crate::metrics::CompareOptions {
        samples: args.samples.map(|n| n as usize),
        seed: args.seed,
        ..Default::default()
    };
    let t = Instant::now();
    let c = progress
        .spinner("measuring".to_string(), || {
            crate::metrics::compare(&a, &b, &opts)
        })
        .map_err(lib)
        .with_context(|| {
            format!(
                "cannot compare {} with {}",
                args.a.display(),
                args.b.display()
            )
        })?;
    let compare_s = t.elapsed().as_secs_f64();
    let out = std::io::stdout();
    let mut out = out.lock();
    if args.json {
        let mut json = serde_json::to_value(&c)?;
        let obj = json
            .as_object_mut()
            .expect("the comparison serializes as an object");
        let extra = serde_json::json!({
            "a": args.a.display(),
            "b": args.b.display(),
            "seconds": { "load": load_s, "compare": compare_s },
        });
        obj.extend(extra.as_object().cloned().unwrap_or_default());
        writeln!(out, "{}", serde_json::to_string_pretty(&json)?)?;
    } else {
        write_comparison(&mut out, &args.a, &args.b, &c, load_s, compare_s)?;
    }
    out.flush()?;
    Ok(ExitCode::SUCCESS)
}

fn run_bench(args: BenchArgs) -> Result<ExitCode> {
    let json_stdout = args.json.as_deref() == Some(Path::new("-"));
    // Wrong output paths fail before the minutes of work.
    if let Some(plot) = &args.plot
        && !plot
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("svg") || e.eq_ignore_ascii_case("png"))
    {
        return Err(UsageError(format!(
            "{}: the plot is written as SVG or PNG; name it FILE.svg or FILE.png",
            plot.display()
        ))
        .into());
    }
    for file in args.json.iter().filter(|_| !json_stdout).chain(&args.plot) {
        if let Some(dir) = file.parent().filter(|d| !d.as_os_str().is_empty())
            && !dir.is_dir()
        {
            anyhow::bail!(
                "{}: the output directory {} does not exist",
                file.display(),
                dir.display()
            );
        }
    }
    let progress = Progress::new(std::io::stderr().is_terminal());
    let mut inputs = Vec::new();
    for input in &args.meshes {
        inputs.push((input.display(), load(input, &progress)?));
    }
    if inputs.is_empty() {
        inputs.push(
            progress
                .spinner("building the 1M-triangle scan".to_string(), || {
                    crate::bench::million_triangle_scan()
                })
                .map_err(lib)
                .context("cannot build the 1M-triangle scan")?,
        );
    }
    let opts = crate::bench::BenchOptions {
        ratios: args.ratios,
        backends: if args.backends.is_empty() {
            // Every backend; gpu only where there is an adapter (named with --backends gpu, a
            // missing adapter is an error instead).
            let all = crate::bench::available_backends();
            if all.len() < crate::bench::BACKENDS.len() {
                eprintln!("note: no GPU adapter; the gpu backend is left out");
            }
            all
        } else {
            args.backends
        },
        repeat: args.repeat as usize,
        compare: crate::metrics::CompareOptions {
            samples: args.samples.map(|n| n as usize),
            seed: args.seed,
            ..Default::default()
        },
    };
    let report = progress
        .bar("benchmarking", |set| {
            crate::bench::run(&inputs, &opts, &mut |f| set(f))
        })
        .map_err(lib)?;
    drop(inputs);

    let json = serde_json::to_string_pretty(&report)?;
    let out = std::io::stdout();
    let mut out = out.lock();
    if json_stdout {
        writeln!(out, "{json}")?;
    } else {
        crate::bench::write_table(&mut out, &report)?;
        if let Some(file) = &args.json {
            std::fs::write(file, json + "\n")
                .with_context(|| format!("cannot write {}", file.display()))?;
        }
    }
    if let Some(file) = &args.plot {
        let svg = crate::bench::plot_svg(&report);
        let bytes = if file
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("png"))
        {
            crate::bench::svg_to_png(&svg)
                .map_err(|e| anyhow::anyhow!("cannot render the plot as PNG: {e}"))?
        } else {
            svg.into_bytes()
        };
        std::fs::write(file, bytes).with_context(|| format!("cannot write {}", file.display()))?;
    }
    out.flush()?;
    Ok(ExitCode::SUCCESS)
}

fn write_comparison(
    out: &mut impl Write,
    a: &Input,
    b: &Input,
    c: &crate::metrics::Comparison,
    load_s: f64,
    compare_s: f64,
) -> std::io::Result<()> {
    let d = &c.distance;
    writeln!(
        out,
        "A  {}: {} faces, {} vertices",
        a.display(),
        c.faces_a,
        c.vertices_a
    )?;
    writeln!(
        out,
        "B  {}: {} faces, {} vertices",
        b.display(),
        c.faces_b,
        c.vertices_b
    )?;
    writeln!(
        out,
        "\ndistance (absolute, and relative to A's bounding-box diagonal {:.6})",
        d.diagonal
    )?;
    writeln!(
        out,
        "  {:<10} {:>22} {:>22} {:>22}  samples (faces + vertices + edges)",
        "", "max (Hausdorff)", "mean", "RMS"
    )?;
    let cell = |abs: f64, rel: f64| format!("{abs:.4e} ({rel:.3e})");
    for (name, s) in [("A -> B", &d.a_to_b), ("B -> A", &d.b_to_a)] {
        writeln!(
            out,
            "  {:<10} {:>22} {:>22} {:>22}  {} + {} + {}",
            name,
            cell(s.max, s.max_rel),
            cell(s.mean, s.mean_rel),
            cell(s.rms, s.rms_rel),
            s.face_samples,
            s.vertex_samples,
            s.edge_samples
        )?;
    }
    let t = &d.two_sided;
    writeln!(
        out,
        "  {:<10} {:>22} {:>22} {:>22}  (max of both; mean of the two means)",
        "both",
        cell(t.max, t.max_rel),
        cell(t.mean, t.mean_rel),
        cell(t.rms, t.rms_rel)
    )?;
    let pct = |r: Option<f64>| r.map_or("n/a".to_string(), |r| format!("{:+.4}%", 100.0 * r));
    writeln!(out)?;
    writeln!(
        out,
        "area     {:.6} -> {:.6} ({})",
        c.area.a,
        c.area.b,
        pct(c.area.relative)
    )?;
    writeln!(
        out,
        "volume   {:.6} -> {:.6} ({}, signed)",
        c.volume.a,
        c.volume.b,
        pct(c.volume.relative)
    )?;
    let q = &c.quality_b;
    writeln!(
        out,
        "\ntriangle quality of B: min angle {:.2} deg, mean smallest angle {:.2} deg, {} degenerate",
        q.min_angle_deg, q.mean_min_angle_deg, q.degenerate_faces
    )?;
    writeln!(
        out,
        "  aspect ratio (circumradius / 2 inradius, 1 = equilateral):"
    )?;
    let mut lower = 1.0;
    for bin in &q.aspect_ratio_histogram {
        let range = match bin.upper {
            Some(u) => format!("[{lower}, {u})"),
            None => format!(">= {lower}"),
        };
        writeln!(out, "    {range:<12} {}", bin.count)?;
        lower = bin.upper.unwrap_or(lower);
    }
    let tp = &c.topology;
    writeln!(
        out,
        "\ntopology           {:>8} {:>8} {:>8}",
        "A", "B", "B - A"
    )?;
    let rows = [
        (
            "euler",
            tp.a.euler_characteristic,
            tp.b.euler_characteristic,
            tp.difference.euler_characteristic,
        ),
        (
            "boundary loops",
            tp.a.boundary_loops,
            tp.b.boundary_loops,
            tp.difference.boundary_loops,
        ),
        (
            "non-manifold edges",
            tp.a.non_manifold_edges,
            tp.b.non_manifold_edges,
            tp.difference.non_manifold_edges,
        ),
        (
            "non-manifold verts",
            tp.a.non_manifold_vertices,
            tp.b.non_manifold_vertices,
            tp.difference.non_manifold_vertices,
        ),
        (
            "components",
            tp.a.connected_components,
            tp.b.connected_components,
            tp.difference.connected_components,
        ),
    ];
    for (name, x, y, dxy) in rows {
        writeln!(out, "  {name:<18} {x:>6} {y:>8} {dxy:>+8}")?;
    }
    writeln!(
        out,
        "\ntime     load {load_s:.3} s, compare {compare_s:.3} s (seed {})",
        c.seed
    )?;
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// Progress
// ---------------------------------------------------------------------------------------------

/// Progress bars on stderr for steps that take long enough to wonder about. A bar starts hidden
/// and is revealed only once its step has run for [`Progress::DELAY`], so quick steps print
/// nothing; with `enabled` false (not a terminal, `--quiet`, `--json`) nothing is ever drawn.
struct Progress {
    enabled: bool,
}

impl Progress {
    const DELAY: Duration = Duration::from_millis(500);

    fn new(enabled: bool) -> Self {
        Progress { enabled }
    }

    /// Runs `f` with a spinner (for steps that report no progress of their own).
    fn spinner<T>(&self, msg: String, f: impl FnOnce() -> T) -> T {
        let style = ProgressStyle::with_template("{spinner} {msg} {elapsed}")
            .expect("valid progress template");
        self.run(None, style, msg, |_| f())
    }

    /// Runs `f` with a bar; `f` gets a setter for the fraction done (0..=1).
    fn bar<T>(&self, msg: &str, f: impl FnOnce(&dyn Fn(f32)) -> T) -> T {
        let style = ProgressStyle::with_template("{msg} [{bar:40}] {percent:>3}% {elapsed}")
            .expect("valid progress template")
            .progress_chars("=> ");
        self.run(Some(1000), style, msg.to_string(), |pb| {
            f(&|frac: f32| pb.set_position((frac.clamp(0.0, 1.0) * 1000.0) as u64))
        })
    }

    fn run<T>(
        &self,
        len: Option<u64>,
        style: ProgressStyle,
        msg: String,
        f: impl FnOnce(&ProgressBar) -> T,
    ) -> T {
        let pb = ProgressBar::with_draw_target(len, ProgressDrawTarget::hidden())
            .with_style(style)
            .with_message(msg);
        if !self.enabled {
            return f(&pb);
        }
        let (done, wait) = mpsc::channel::<()>();
        let result = std::thread::scope(|s| {
            let reveal = pb.clone();
            s.spawn(move || {
                // Dropping `done` ends the wait early: the step finished in time, draw nothing.
                if let Err(mpsc::RecvTimeoutError::Timeout) = wait.recv_timeout(Self::DELAY) {
                    reveal.set_draw_target(ProgressDrawTarget::stderr());
                    reveal.enable_steady_tick(Duration::from_millis(100));
                }
            });
            let r = f(&pb);
            drop(done);
            r
        });
        pb.finish_and_clear();
        result
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    #[test]
    fn cli_definition_is_consistent() {
        Cli::command().debug_assert();
    }

    #[test]
    fn every_builtin_is_listed_in_the_help() {
        for b in BUILTINS {
            assert!(
                SIMPLIFY_AFTER_HELP.contains(&format!("\n  {:<14}", b.name)),
                "{} missing from the simplify help",
                b.name
            );
        }
    }

    #[test]
    fn builtin_defaults_match_the_help() {
        for b in BUILTINS {
            let faces = builtin(b.name).unwrap().face_count().to_string();
            let line = SIMPLIFY_AFTER_HELP
                .lines()
                .find(|l| l.starts_with(&format!("  {:<14}", b.name)))
                .unwrap();
            assert!(
                line.ends_with(&format!(" {faces} faces")),
                "{line}: {faces}"
            );
        }
    }

    #[test]
    fn builtin_face_count_is_a_minimum() {
        for b in BUILTINS {
            for n in [1, 500, 3001] {
                let m = builtin(&format!("builtin:{}:{n}", b.name)).unwrap();
                assert!(
                    m.face_count() >= n,
                    "{}:{n} gave {}",
                    b.name,
                    m.face_count()
                );
                m.validate().unwrap();
            }
        }
        assert!(builtin("builtin:nope").is_err());
        assert!(builtin("builtin:sphere:0").is_err());
        assert!(builtin("builtin:sphere:x").is_err());
        assert!(builtin("sphere:99999999999").is_err());
    }
}
