//! `meshslim simplify`: its arguments, help, and the runner that reads, simplifies (choosing the
//! backend for `auto`) and writes.

use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{Context, Result};
use clap::{Args, ValueEnum};

use super::args::{
    Input, parse_angle, parse_face_count, parse_input_arg, parse_non_negative, parse_ratio,
    parse_unit,
};
use super::error::{UsageError, lib};
use super::files::{check_output, load};
use super::report::{Progress, Times, simplify_json, write_summary};
use crate::{Backend, SimplifyOptions};

pub(super) const SIMPLIFY_AFTER_HELP: &str = "\
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
  # keep a subset of the scan's own vertices (no moved points), topology and borders kept
  meshslim simplify scan.ply scan-kept.ply --ratio 0.1 --method decimate
  # a PLY larger than memory: vertex clustering with the faces streamed from the file
  meshslim simplify huge.ply huge-1m.ply --faces 1000000 --method cluster --stream
  # machine-readable report
  meshslim simplify builtin:torus torus-half.glb --ratio 0.5 --json";

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

    #[command(flatten)]
    pub attributes: super::args::AttributeArgs,

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

    /// Which algorithm: qem for the best surface, cluster for speed, hybrid for near-qem
    /// quality at clustering speed on big scans, decimate to keep the input's own vertices
    /// (see the choices below)
    #[arg(long, value_enum, default_value_t = MethodArg::Qem)]
    pub method: MethodArg,

    /// --method decimate: faces meeting at a dihedral angle over DEG degrees make a feature
    /// edge; a vertex on exactly two is removed along the feature line, a vertex on one or on
    /// three and more (a corner) is kept
    #[arg(long = "feature-angle", value_name = "DEG", default_value_t = 60.0, value_parser = parse_angle, allow_negative_numbers = true)]
    pub feature_angle: f64,

    /// --method decimate: how the hole a removed vertex leaves is filled
    #[arg(long, value_enum, default_value_t = RemovalArg::HalfEdge)]
    pub removal: RemovalArg,

    /// Stream the input (a PLY or OBJ file, --method cluster or hybrid): hold its vertices and read
    /// its faces again in blocks at each clustering pass, so memory follows the vertices and
    /// the output, not the faces (hybrid's rounds then run on the clustered mesh). Chosen by
    /// itself when reading the file whole would take more than --memory. Vertex colours are
    /// carried (each cluster its nearest member's); normals and UVs are not
    #[arg(long)]
    pub stream: bool,

    /// What reading the input whole may take before cluster or hybrid streams it instead, as
    /// 4G, 512M or bytes [default: half the machine's memory]
    #[arg(long, value_name = "SIZE", value_parser = super::memory::parse_size)]
    pub memory: Option<u64>,

    /// Then remesh the result with K isotropic remeshing iterations (as 'meshslim remesh',
    /// features over 45 degrees kept) at the edge length that keeps its face count (aiming at
    /// 3%), projecting onto the input: well-shaped triangles for simulation or printing, at
    /// some cost in distance. Normals, colours and UVs are interpolated on the input (UV
    /// seams kept). A result remeshing refuses (clustering's may be non-manifold)
    /// is written as simplified, with a warning
    #[arg(long, value_name = "K", default_value_t = 0)]
    pub remesh: usize,

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

/// The `--method` choices.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum MethodArg {
    /// Quadric edge collapse: the best surface for the face count, exactly on target, topology
    /// and UV seams kept; every backend
    Qem,
    /// Uniform-grid vertex clustering: the fastest, within 5% of the target; may join nearby
    /// sheets and change topology, and closes UV seams; for previews and far LODs (cpu-parallel
    /// or gpu)
    Cluster,
    /// Low & Tan's floating cells: clusters centred on the most important vertices (tips,
    /// creases), so features survive where a uniform grid cuts them; within 5% of the target,
    /// slower than cluster, topology and UV seams as cluster
    FloatingCell,
    /// Clustering to twice the target plus 20,000 faces, then qem to the exact target: near-qem
    /// error in a fraction of the time on large scans; closes UV seams (cpu or auto: qem's
    /// greedy queue on the clustered surface; cpu-parallel or gpu: qem's rounds from the
    /// clusters' quadrics)
    Hybrid,
    /// Schroeder's vertex decimation: removes vertices and fills their holes, so the output's
    /// vertices are a subset of the input's, unmoved, with their normals, UVs and colours;
    /// topology and borders kept; exactly on target; creases (--feature-angle), seams and
    /// corners respected (cpu)
    Decimate,
}

/// The `--removal` choices.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum RemovalArg {
    /// Remove the vertex and triangulate its hole by recursive loop splitting (Schroeder 1992)
    LoopSplit,
    /// Collapse the vertex into the allowed neighbour of least error (a half-edge collapse,
    /// Schroeder 1997): lower error than loop-split on the scans
    HalfEdge,
}

impl RemovalArg {
    pub fn removal(self) -> crate::decimate::Removal {
        match self {
            RemovalArg::LoopSplit => crate::decimate::Removal::LoopSplit,
            RemovalArg::HalfEdge => crate::decimate::Removal::HalfEdge,
        }
    }
}

impl MethodArg {
    pub fn method(self) -> crate::Method {
        match self {
            MethodArg::Qem => crate::Method::Qem,
            MethodArg::Cluster => crate::Method::Cluster,
            MethodArg::FloatingCell => crate::Method::FloatingCell,
            MethodArg::Hybrid => crate::Method::Hybrid,
            MethodArg::Decimate => crate::Method::Decimate,
        }
    }
}

impl BackendArg {
    /// The library backend.
    pub fn backend(self) -> Backend {
        match self {
            BackendArg::Cpu => Backend::Cpu,
            BackendArg::CpuParallel => Backend::CpuParallel,
            BackendArg::Gpu => Backend::Gpu,
            BackendArg::Auto => Backend::Auto,
        }
    }
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

/// The face target as given: a ratio of the input's faces or a face count.
#[derive(Clone, Copy)]
enum Target {
    Ratio(f64),
    Faces(usize),
}

/// A simplification done, streamed or in memory, with what the report needs of how it went.
struct Simplified {
    mesh: crate::Mesh,
    report: crate::SimplifyReport,
    load_s: f64,
    simplify_s: f64,
    /// How clustering changed the topology (in memory only).
    topology: Option<super::report::TopologyChange>,
    /// Why the input was streamed, when it was.
    streamed: Option<String>,
    /// The input mesh, when it was read whole.
    original: Option<crate::Mesh>,
}

/// Runs `meshslim simplify`: reads (or streams) the input, simplifies it, remeshes it when asked,
/// writes it and prints the report.
pub(super) fn run_simplify(mut args: SimplifyArgs) -> Result<ExitCode> {
    let Some(input) = args.input.take() else {
        eprintln!("{GETTING_STARTED}");
        return Ok(ExitCode::from(2));
    };
    let Some(output) = args.output.take() else {
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
    let opts = simplify_options(&args, target);
    let done = match stream_choice(&input, &args, &opts)? {
        Some((path, why)) => simplify_streamed(&args, &progress, path, why, target, &opts)?,
        None => simplify_in_memory(&args, &progress, &input, target, opts)?,
    };
    let (done, remeshed) = remesh_if_asked(&args, &progress, done);
    note_what_the_format_loses(&args, &output, &done.mesh);
    let save_s = write_output(&progress, &input, &output, &done.mesh)?;
    let times = Times {
        load: done.load_s,
        simplify: done.simplify_s,
        save: save_s,
    };
    print_report(&args, &input, &output, &done, &times, remeshed.as_ref())?;
    Ok(ExitCode::SUCCESS)
}

impl SimplifyArgs {
    /// Prints a message on stderr unless `--quiet`.
    fn say(&self, msg: String) {
        if !self.quiet {
            eprintln!("{msg}");
        }
    }
}

/// The library's options from the arguments; a ratio target is turned into a face count once
/// the input's faces are known.
fn simplify_options(args: &SimplifyArgs, target: Target) -> SimplifyOptions {
    let mut opts = SimplifyOptions::with_faces(match target {
        Target::Faces(n) => n,
        Target::Ratio(_) => 0,
    });
    opts.max_error = args.max_error;
    opts.lock_border = args.lock_border;
    opts.border_weight = args.border_weight;
    opts.attributes = args.attributes.weights();
    opts.max_normal_angle_deg = args.max_normal_angle;
    opts.quality_threshold = args.quality_threshold;
    opts.backend = args.backend.backend();
    opts.method = args.method.method();
    opts.feature_angle_deg = args.feature_angle;
    opts.removal = args.removal.removal();
    opts
}

/// Whether to stream the input, and why: `--stream` (a file only), or the library's policy for
/// a cluster or hybrid input that would not fit in memory.
fn stream_choice(
    input: &Input,
    args: &SimplifyArgs,
    opts: &SimplifyOptions,
) -> Result<Option<(PathBuf, String)>> {
    Ok(match input {
        Input::Builtin { .. } if args.stream => {
            return Err(UsageError(
                "--stream reads a file; a builtin mesh is made in memory".into(),
            )
            .into());
        }
        Input::File(path) if args.stream => Some((path.clone(), "--stream".to_string())),
        // The library's policy: stream a cluster or hybrid input that would not fit in memory.
        Input::File(path) => {
            crate::simplify::stream_reason(path, opts, args.memory).map(|why| (path.clone(), why))
        }
        _ => None,
    })
}

/// Simplifies the file at `path` by streaming its faces (`why` says why), timed as one step.
fn simplify_streamed(
    args: &SimplifyArgs,
    progress: &Progress,
    path: PathBuf,
    why: String,
    target: Target,
    opts: &SimplifyOptions,
) -> Result<Simplified> {
    args.say(format!("streaming {}: {why}", path.display()));
    let t = Instant::now();
    let target = match target {
        Target::Faces(n) => crate::cluster::stream::Target::Faces(n),
        Target::Ratio(r) => crate::cluster::stream::Target::Ratio(r),
    };
    let (mesh, report) = progress
        .bar("simplifying (streamed)", |set| {
            crate::cluster::stream::simplify_file(&path, target, opts, &mut |f| set(f))
        })
        .map_err(lib)
        .with_context(|| format!("cannot simplify {}", path.display()))?;
    Ok(Simplified {
        mesh,
        report,
        load_s: 0.0,
        simplify_s: t.elapsed().as_secs_f64(),
        topology: None,
        streamed: Some(why),
        original: None,
    })
}

/// Loads the input whole and simplifies it, saying which backend `auto` chose, and how
/// clustering changed the topology.
fn simplify_in_memory(
    args: &SimplifyArgs,
    progress: &Progress,
    input: &Input,
    target: Target,
    mut opts: SimplifyOptions,
) -> Result<Simplified> {
    let t = Instant::now();
    let mesh = load(input, progress)?;
    let load_s = t.elapsed().as_secs_f64();
    if let Target::Ratio(r) = target {
        opts.target_faces = SimplifyOptions::with_ratio(mesh.face_count(), r)
            .map_err(lib)?
            .target_faces;
    }
    // Said before the long part; the library makes the same choice (the process's one
    // shared device), and its report says so again only if the GPU then failed.
    let early = (opts.backend == Backend::Auto).then(|| {
        let (_, why) = crate::simplify::auto_backend();
        args.say(format!("backend auto: {why}"));
        why
    });

    let t = Instant::now();
    let result = progress.bar("simplifying", |set| {
        crate::simplify_with_progress(&mesh, &opts, &mut |f| set(f))
    });
    if let Ok((_, report)) = &result
        && let Some(note) = &report.auto
        && Some(note) != early.as_ref()
    {
        args.say(format!("backend auto: {note}"));
    }
    let (simplified, report) = result
        .map_err(lib)
        .with_context(|| format!("cannot simplify {}", input.display()))?;
    let simplify_s = t.elapsed().as_secs_f64();
    // Clustering may change the topology: say how (outside the timed call).
    let topology = report
        .clustering
        .is_some()
        .then(|| super::report::TopologyChange::of(&mesh, &simplified));
    Ok(Simplified {
        mesh: simplified,
        report,
        load_s,
        simplify_s,
        topology,
        streamed: None,
        original: Some(mesh),
    })
}

/// With `--remesh K`, remeshes the simplified mesh (its time counted in simplify's, the report
/// describing the remeshed mesh); a failure is a warning and keeps the simplified mesh.
fn remesh_if_asked(
    args: &SimplifyArgs,
    progress: &Progress,
    done: Simplified,
) -> (Simplified, Option<crate::remesh::RemeshReport>) {
    if args.remesh == 0 {
        return (done, None);
    }
    let remeshed = progress.bar("remeshing", |set| {
        // Onto the original where it is in memory (not when streamed): nearer it.
        crate::remesh::remesh_simplified(
            &done.mesh,
            done.original.as_ref(),
            args.remesh,
            args.lock_border,
            set,
        )
    });
    match remeshed {
        Ok((out, r)) => {
            let simplify_s = done.simplify_s + r.seconds.total;
            // The report describes the file written: the remeshed mesh's counts.
            let report = done.report.describing(&out);
            let done = Simplified {
                mesh: out,
                report,
                simplify_s,
                ..done
            };
            (done, Some(r))
        }
        // The simplification is done and good: keep it rather than lose it.
        Err(e) => {
            eprintln!("warning: cannot remesh the simplified mesh ({e}); writing it as simplified");
            (done, None)
        }
    }
}

/// Notes each attribute of the mesh the output's format does not keep.
fn note_what_the_format_loses(args: &SimplifyArgs, output: &Path, mesh: &crate::Mesh) {
    if let Ok(format) = crate::io::Format::from_path(output) {
        for lost in crate::io::not_kept(mesh, format) {
            args.say(format!(
                "note: {} ({}) does not keep {lost}",
                output.display(),
                format.extension()
            ));
        }
    }
}

/// Writes the mesh to `output` (carrying what the input file had beside it); returns the
/// seconds it took.
fn write_output(
    progress: &Progress,
    input: &Input,
    output: &Path,
    mesh: &crate::Mesh,
) -> Result<f64> {
    let t = Instant::now();
    progress
        .spinner(format!("writing {}", output.display()), || match input {
            Input::File(from) => crate::io::write_from(output, mesh, from),
            Input::Builtin { .. } => crate::io::write(output, mesh),
        })
        .map_err(lib)
        .context("cannot write the output")?;
    Ok(t.elapsed().as_secs_f64())
}

/// Prints the report on stdout: the JSON object with `--json`, else the summary (with the
/// remesh and stream lines) unless `--quiet`.
fn print_report(
    args: &SimplifyArgs,
    input: &Input,
    output: &Path,
    done: &Simplified,
    times: &Times,
    remeshed: Option<&crate::remesh::RemeshReport>,
) -> Result<()> {
    let out = std::io::stdout();
    let mut out = out.lock();
    if args.json {
        let mut json = simplify_json(input, output, &done.report, times, done.topology.as_ref());
        json["streamed"] = serde_json::json!(done.streamed);
        json["remesh"] = serde_json::json!(remeshed);
        json["peak_resident_bytes"] = serde_json::json!(crate::memory::peak_resident_bytes());
        writeln!(out, "{}", serde_json::to_string_pretty(&json)?)?;
    } else if !args.quiet {
        write_summary(
            &mut out,
            input,
            output,
            &done.report,
            times,
            args.stats,
            done.topology.as_ref(),
        )?;
        if let Some(r) = remeshed {
            writeln!(
                out,
                "remesh   {} iterations at edge length {:.6}: {} simplified faces -> {} in {:.3} s (in simplify)",
                r.iterations, r.edge_length, r.input_faces, r.output_faces, r.seconds.total
            )?;
        }
        if let Some(why) = &done.streamed {
            let peak =
                crate::memory::peak_resident_bytes().map_or("unknown".into(), crate::memory::mib);
            writeln!(
                out,
                "stream   {why}: faces read in blocks (load is in simplify); peak resident {peak}"
            )?;
        }
    }
    out.flush()?;
    Ok(())
}
