//! `meshslim lods` (the LOD chain in one run) and `meshslim pareto` (NSGA-II Pareto sets of
//! vertex-removal LODs): their arguments, help and runners.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{Context, Result};
use clap::{Args, ValueEnum};

use super::args::{Input, parse_angle, parse_input_arg};
use super::error::lib;
use super::files::load;
use super::report::Progress;
use super::simplify::{BackendArg, MethodArg, RemovalArg};
use crate::io::Format;
use crate::lod::{self, ErrorMeasure, Initialisation, ParetoOptions, Variation, manifest};
use crate::metrics::{CompareOptions, compare};
use crate::{Mesh, SimplifyOptions};

pub(super) const LODS_AFTER_HELP: &str = "\
Each level goes on from the one before (its quadrics, positions and history kept), so five levels
cost about what the smallest alone does. Writes OUTDIR/<name>.lod<k>.<ext> (k = 1 for the first
ratio) and OUTDIR/<name>.lods.json: per level the faces, vertices, time and the error against the
original (two-sided Metro mean and Hausdorff distance, as 'meshslim compare' measures them).

Examples:
  meshslim lods builtin:bumpy-sphere lods
  meshslim lods scan.ply lods --ratios 0.5,0.25,0.1,0.05,0.01 --method decimate
  meshslim lods scan.ply lods --backend gpu --no-measure";

pub(super) const PARETO_AFTER_HELP: &str = "\
NSGA-II (Deb et al. 2002) over vertex-removal levels of detail (Campomanes-Alvarez et al. 2012): a
candidate keeps or removes each removable vertex; the decimation engine removes the masked vertices
in its own greedy order, a removal it refuses keeps its vertex (and the candidate's bit says so).
The objectives are the vertices kept and the error against the original, both minimized.

Writes OUTDIR/<name>.pareto-<V>v.<ext> for every member of the final front (V vertices),
OUTDIR/<name>.pareto.json (the front of every generation and its hypervolume; the final front and
the greedy decimation chain at the same vertex counts, both measured with the Metro mean) and
OUTDIR/<name>.pareto.svg (the fronts as a plot).

The result depends on --seed only, not on --threads.

Examples:
  meshslim pareto builtin:bumpy-sphere:20000 front
  meshslim pareto scan.ply front --population 100 --generations 20 --offspring 10 --threads 2
  meshslim pareto scan.ply front --error metro --seed 7";

/// `meshslim lods`.
#[derive(Debug, Args)]
pub struct LodsArgs {
    /// The mesh: a file, or a generated mesh builtin:NAME[:FACES]
    #[arg(value_name = "IN", value_parser = parse_input_arg)]
    pub input: Input,
    /// The folder the levels go into (made if missing)
    #[arg(value_name = "OUTDIR")]
    pub outdir: PathBuf,
    /// The levels' fractions of the input's faces, falling
    #[arg(
        long,
        value_name = "R,R,...",
        value_delimiter = ',',
        default_value = "0.5,0.25,0.1,0.05,0.01"
    )]
    pub ratios: Vec<f64>,
    /// qem, decimate or hybrid (the methods with a state to go on from)
    #[arg(long, value_enum, default_value_t = MethodArg::Qem)]
    pub method: MethodArg,
    #[arg(long, value_enum, default_value_t = BackendArg::Cpu)]
    pub backend: BackendArg,
    /// decimate: the dihedral angle over which an edge is a crease
    #[arg(long = "feature-angle", value_name = "DEG", default_value_t = 60.0, value_parser = parse_angle)]
    pub feature_angle: f64,
    /// decimate: how a removed vertex's hole is filled
    #[arg(long, value_enum, default_value_t = RemovalArg::HalfEdge)]
    pub removal: RemovalArg,
    /// Keep border vertices where they are
    #[arg(long)]
    pub lock_border: bool,
    #[command(flatten)]
    pub attributes: super::args::AttributeArgs,
    /// The levels' file format (default: the input's; ply for a generated mesh)
    #[arg(long, value_name = "EXT")]
    pub format: Option<String>,
    /// Skip measuring each level against the original
    #[arg(long)]
    pub no_measure: bool,
    /// Print the manifest on stdout too
    #[arg(long)]
    pub json: bool,
    #[arg(short, long)]
    pub quiet: bool,
}

/// `--error` of `meshslim pareto`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ErrorArg {
    /// The engine's vertex-to-plane error: how far the kept vertices are from the planes of the
    /// original faces they took over (fast)
    VertexPlane,
    /// The two-sided Metro mean, as 'meshslim compare' measures it (about 0.2 s a candidate on
    /// a 100k-face mesh)
    Metro,
}

/// `--init` of `meshslim pareto`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum InitArg {
    /// Half the first population the engine's greedy masks at spread vertex counts
    Greedy,
    /// Every candidate random
    Random,
}

/// `--crossover` of `meshslim pareto`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum CrossoverArg {
    /// A span of the Morton order (a region of the surface) from one parent, the rest from the
    /// other
    Regions,
    /// Each bit from either parent
    Uniform,
}

/// `--mutation-at` of `meshslim pareto`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum MutationArg {
    /// Around the candidate's removal threshold in the greedy order (as many flips in
    /// expectation as uniform)
    Threshold,
    /// Every bit alike
    Uniform,
}

/// `meshslim pareto`.
#[derive(Debug, Args)]
pub struct ParetoArgs {
    /// The mesh: a file, or a generated mesh builtin:NAME[:FACES]
    #[arg(value_name = "IN", value_parser = parse_input_arg)]
    pub input: Input,
    /// The folder the front goes into (made if missing)
    #[arg(value_name = "OUTDIR")]
    pub outdir: PathBuf,
    #[arg(long, default_value_t = 100)]
    pub population: usize,
    #[arg(long, default_value_t = 20)]
    pub generations: usize,
    /// New candidates per generation
    #[arg(long, default_value_t = 10)]
    pub offspring: usize,
    /// Per-bit flip probability
    #[arg(long, value_name = "P", default_value_t = 1e-3)]
    pub mutation: f64,
    /// Tournament size
    #[arg(long, default_value_t = 5)]
    pub tournament: usize,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Worker threads (default: one per core); the result is the same for any count
    #[arg(long)]
    pub threads: Option<usize>,
    #[arg(long, value_enum, default_value_t = ErrorArg::VertexPlane)]
    pub error: ErrorArg,
    #[arg(long, value_enum, default_value_t = InitArg::Greedy)]
    pub init: InitArg,
    #[arg(long, value_enum, default_value_t = CrossoverArg::Regions)]
    pub crossover: CrossoverArg,
    #[arg(long = "mutation-at", value_enum, default_value_t = MutationArg::Threshold)]
    pub mutation_at: MutationArg,
    /// The hypervolume's reference error (relative to the bounding-box diagonal); the
    /// reference point is (all vertices, this error)
    #[arg(long, value_name = "E", default_value_t = 0.01)]
    pub reference_error: f64,
    /// Don't add the greedy's mask at each child's vertex count to the population (then the
    /// front may keep members worse than the greedy at their counts)
    #[arg(long)]
    pub no_anchor: bool,
    /// Face samples per direction of the Metro mean during the search (--error metro;
    /// default: as 'meshslim compare'); the final front is measured as 'meshslim compare' does
    #[arg(long, value_name = "N")]
    pub search_samples: Option<usize>,
    /// Skip the Metro measure of the final front and of the greedy chain
    #[arg(long)]
    pub no_measure: bool,
    /// Also write the greedy chain's meshes at the front's vertex counts
    /// (OUTDIR/<name>.greedy-<V>v.<ext>)
    #[arg(long)]
    pub write_baseline: bool,
    /// decimate: the dihedral angle over which an edge is a crease
    #[arg(long = "feature-angle", value_name = "DEG", default_value_t = 60.0, value_parser = parse_angle)]
    pub feature_angle: f64,
    /// How a removed vertex's hole is filled
    #[arg(long, value_enum, default_value_t = RemovalArg::HalfEdge)]
    pub removal: RemovalArg,
    /// Print the JSON on stdout too
    #[arg(long)]
    pub json: bool,
    #[arg(short, long)]
    pub quiet: bool,
}

/// The stem and extension the outputs take: the input file's, or `builtin-NAME` and ply.
fn naming(input: &Input, format: Option<&str>) -> Result<(String, String)> {
    let (stem, ext) = match input {
        Input::File(p) => (
            p.file_stem()
                .map_or("mesh".into(), |s| s.to_string_lossy().into_owned()),
            p.extension()
                .map_or("ply".into(), |e| e.to_string_lossy().to_lowercase()),
        ),
        Input::Builtin { kind, .. } => (format!("builtin-{}", kind.name), "ply".into()),
    };
    let ext = format.map_or(ext, |f| f.trim_start_matches('.').to_lowercase());
    Format::from_path(Path::new(&format!("x.{ext}"))).map_err(lib)?;
    Ok((stem, ext))
}

fn make_outdir(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot make the output folder {}", dir.display()))
}

fn write_mesh(path: &Path, m: &Mesh) -> Result<()> {
    crate::io::write(path, m)
        .map_err(lib)
        .with_context(|| format!("cannot write {}", path.display()))
}

fn write_json<T: serde::Serialize>(path: &Path, v: &T) -> Result<()> {
    manifest::write(path, v)
        .map_err(lib)
        .with_context(|| format!("cannot write {}", path.display()))
}

pub(super) fn run_lods(args: LodsArgs) -> Result<ExitCode> {
    let (stem, ext) = naming(&args.input, args.format.as_deref())?;
    lod::check_ratios(&args.ratios).map_err(lib)?;
    make_outdir(&args.outdir)?;
    let progress = Progress::new(!(args.quiet || args.json) && std::io::stderr().is_terminal());
    let t = Instant::now();
    let mesh = load(&args.input, &progress)?;
    let load_s = t.elapsed().as_secs_f64();

    let mut opts = SimplifyOptions::with_faces(0);
    opts.method = args.method.method();
    opts.backend = args.backend.backend();
    opts.feature_angle_deg = args.feature_angle;
    opts.removal = args.removal.removal();
    opts.lock_border = args.lock_border;
    opts.attributes = args.attributes.weights();
    let t = Instant::now();
    let (levels, backend) = progress
        .bar("making the levels", |set| {
            lod::lod_chain(&mesh, &opts, &args.ratios, &mut |f| set(f))
        })
        .map_err(lib)
        .context("cannot make the levels of detail")?;
    let simplify_s = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let measured: Vec<Option<crate::metrics::Comparison>> = if args.no_measure {
        vec![None; levels.len()]
    } else {
        progress
            .spinner("measuring the levels".into(), || {
                levels
                    .iter()
                    .map(|l| compare(&mesh, &l.mesh, &CompareOptions::default()).map(Some))
                    .collect::<crate::Result<_>>()
            })
            .map_err(lib)?
    };
    let measure_s = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let mut rows = Vec::new();
    for (k, (l, c)) in levels.iter().zip(&measured).enumerate() {
        let file = args.outdir.join(format!("{stem}.lod{}.{ext}", k + 1));
        write_mesh(&file, &l.mesh)?;
        let error = c.as_ref().map(|c| manifest::LevelError {
            mean_rel: c.distance.two_sided.mean_rel,
            rms_rel: c.distance.two_sided.rms_rel,
            hausdorff_rel: c.distance.two_sided.max_rel,
        });
        rows.push(manifest::LodsEntry {
            level: k + 1,
            file: file.display().to_string(),
            ratio: l.ratio,
            target_faces: l.target_faces,
            faces: l.mesh.face_count(),
            vertices: l.mesh.positions.len(),
            stop_reason: format!("{:?}", l.stop_reason),
            max_collapse_error: Some(l.max_error).filter(|e| e.is_finite()),
            error,
            ready_after_seconds: l.seconds,
        });
    }
    let save_s = t.elapsed().as_secs_f64();
    let manifest = manifest::LodsManifest {
        input: args.input.display(),
        input_from_manifest: input_from(&args.input, &args.outdir),
        faces: mesh.face_count(),
        vertices: mesh.positions.len(),
        method: opts.method.name().into(),
        backend: backend.name().into(),
        levels: rows,
        seconds: manifest::LodsSeconds {
            load: load_s,
            simplify: simplify_s,
            measure: measure_s,
            save: save_s,
        },
    };
    let manifest_path = args.outdir.join(format!("{stem}.lods.json"));
    write_json(&manifest_path, &manifest)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&manifest)?);
    }
    if !args.quiet {
        eprintln!(
            "{}: {} faces, {} vertices; {} levels by {} on {}",
            args.input.display(),
            mesh.face_count(),
            mesh.positions.len(),
            levels.len(),
            opts.method.name(),
            backend.name()
        );
        for (k, (l, c)) in levels.iter().zip(&measured).enumerate() {
            let err = c.as_ref().map_or(String::new(), |c| {
                format!(
                    ", error mean {:.3e} max {:.3e}",
                    c.distance.two_sided.mean_rel, c.distance.two_sided.max_rel
                )
            });
            eprintln!(
                "  lod{} {:>9} faces {:>9} vertices ({:.1}% of the faces{err})",
                k + 1,
                l.mesh.face_count(),
                l.mesh.positions.len(),
                100.0 * l.mesh.face_count() as f64 / mesh.face_count().max(1) as f64
            );
        }
        eprintln!("manifest {}", manifest_path.display());
        eprintln!(
            "time     load {load_s:.3} s, levels {simplify_s:.3} s, measure {measure_s:.3} s, \
             save {save_s:.3} s"
        );
    }
    Ok(ExitCode::SUCCESS)
}

pub(super) fn run_pareto(args: ParetoArgs) -> Result<ExitCode> {
    let (stem, ext) = naming(&args.input, None)?;
    make_outdir(&args.outdir)?;
    let progress = Progress::new(!(args.quiet || args.json) && std::io::stderr().is_terminal());
    let mesh = load(&args.input, &progress)?;
    let opts = pareto_options(&args);
    let t = Instant::now();
    let run = progress
        .bar("searching", |set| {
            lod::pareto_front(&mesh, &opts, &mut |f| set(f))
        })
        .map_err(lib)
        .context("cannot search the Pareto front")?;
    let search_s = t.elapsed().as_secs_f64();
    let members = write_members(&args, &run, (&stem, &ext))?;
    let out = pareto_manifest(&args, &opts, &run, members, search_s);
    let json_path = args.outdir.join(format!("{stem}.pareto.json"));
    write_json(&json_path, &out)?;
    let svg_path = write_fronts_svg(&args, &run, &stem)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&out)?);
    }
    if !args.quiet {
        print_pareto_summary(&args, &run, search_s, (&json_path, &svg_path));
    }
    Ok(ExitCode::SUCCESS)
}

/// The search's options from the command line.
fn pareto_options(args: &ParetoArgs) -> ParetoOptions {
    let mut engine = SimplifyOptions::with_faces(0);
    engine.feature_angle_deg = args.feature_angle;
    engine.removal = args.removal.removal();
    ParetoOptions {
        population: args.population,
        generations: args.generations,
        offspring: args.offspring,
        mutation: args.mutation,
        tournament: args.tournament,
        seed: args.seed,
        threads: args.threads,
        error: match args.error {
            ErrorArg::VertexPlane => ErrorMeasure::VertexPlane,
            ErrorArg::Metro => ErrorMeasure::Metro,
        },
        init: match args.init {
            InitArg::Greedy => Initialisation::Greedy,
            InitArg::Random => Initialisation::Random,
        },
        variation: Variation {
            region_crossover: args.crossover == CrossoverArg::Regions,
            threshold_mutation: args.mutation_at == MutationArg::Threshold,
        },
        reference_error: args.reference_error,
        anchor: !args.no_anchor,
        search_samples: args.search_samples,
        measure: !args.no_measure,
        engine,
    }
}

/// Each member of the front written beside the input's name (and the greedy chain's mesh at its
/// vertex count with --write-baseline), as the manifest lists them.
fn write_members(
    args: &ParetoArgs,
    run: &lod::ParetoRun,
    (stem, ext): (&str, &str),
) -> Result<Vec<manifest::MemberEntry>> {
    let mut members = Vec::new();
    for (k, (c, m)) in run.front.iter().zip(&run.front_measured).enumerate() {
        let file = args
            .outdir
            .join(format!("{stem}.pareto-{}v.{ext}", c.vertices));
        write_mesh(&file, &run.front_meshes[k])?;
        let greedy = run.baseline.get(k).map(|b| manifest::GreedyEntry {
            vertices: b.vertices,
            faces: b.faces,
            objective: b.objective,
            metro_mean: finite(b.metro_mean),
        });
        if args.write_baseline {
            let file = args
                .outdir
                .join(format!("{stem}.greedy-{}v.{ext}", c.vertices));
            write_mesh(&file, &run.baseline_meshes[k])?;
        }
        members.push(manifest::MemberEntry {
            file: file.display().to_string(),
            vertices: c.vertices,
            faces: c.faces,
            objective: c.error,
            metro_mean: finite(m.metro_mean),
            greedy_at_same_vertices: greedy,
        });
    }
    Ok(members)
}

/// The manifest of the run: options, every generation's front and hypervolume, the members.
fn pareto_manifest(
    args: &ParetoArgs,
    opts: &ParetoOptions,
    run: &lod::ParetoRun,
    members: Vec<manifest::MemberEntry>,
    search_s: f64,
) -> manifest::ParetoManifest {
    let measured = !run.baseline.is_empty();
    let hv = |of: &[crate::lod::Measured]| measured.then(|| run.metro_hypervolume(of));
    let generations = run
        .generations
        .iter()
        .enumerate()
        .map(|(g, gen_)| manifest::GenerationEntry {
            generation: g,
            hypervolume: gen_.hypervolume,
            front: gen_.front.clone(),
        })
        .collect();
    manifest::ParetoManifest {
        input: args.input.display(),
        input_from_manifest: input_from(&args.input, &args.outdir),
        vertices: run.input_vertices,
        removable: run.removable,
        options: manifest::ParetoManifestOptions {
            population: opts.population,
            generations: opts.generations,
            offspring: opts.offspring,
            mutation: opts.mutation,
            tournament: opts.tournament,
            seed: opts.seed,
            error: format!("{:?}", args.error),
            init: format!("{:?}", args.init),
            crossover: format!("{:?}", args.crossover),
            mutation_at: format!("{:?}", args.mutation_at),
            anchor: opts.anchor,
            search_samples: opts.search_samples,
        },
        reference_point: run.reference,
        objective_axes: vec![
            "share of the vertices kept".into(),
            "error relative to the diagonal".into(),
        ],
        evaluations: run.evaluations,
        generations,
        front: members,
        metro_hypervolume: manifest::MetroHypervolume {
            front: hv(&run.front_measured),
            greedy_chain: hv(&run.baseline),
        },
        seconds: search_s,
    }
}

/// The SVG of every generation's front beside the greedy chain; its path.
fn write_fronts_svg(args: &ParetoArgs, run: &lod::ParetoRun, stem: &str) -> Result<PathBuf> {
    let fronts: Vec<Vec<crate::lod::nsga::Point>> =
        run.generations.iter().map(|g| g.front.clone()).collect();
    let n = run.input_vertices as f64;
    let baseline: Vec<crate::lod::nsga::Point> = run
        .baseline
        .iter()
        .map(|b| [b.vertices as f64 / n, b.objective])
        .collect();
    let svg_path = args.outdir.join(format!("{stem}.pareto.svg"));
    let title = format!(
        "{}: Pareto fronts, {} generations",
        args.input.display(),
        run.generations.len() - 1
    );
    std::fs::write(&svg_path, lod::svg::fronts_svg(&title, &fronts, &baseline))
        .with_context(|| format!("cannot write {}", svg_path.display()))?;
    Ok(svg_path)
}

/// What the search found, on stderr.
fn print_pareto_summary(
    args: &ParetoArgs,
    run: &lod::ParetoRun,
    search_s: f64,
    (json_path, svg_path): (&Path, &Path),
) {
    let last = run
        .generations
        .last()
        .expect("the first population at least");
    eprintln!(
        "{}: {} vertices, {} removable; {} evaluations in {search_s:.2} s",
        args.input.display(),
        run.input_vertices,
        run.removable,
        run.evaluations
    );
    eprintln!(
        "front    {} members, hypervolume {:.6e} (first population {:.6e})",
        run.front.len(),
        last.hypervolume,
        run.generations[0].hypervolume
    );
    let measured = !run.baseline.is_empty();
    let hv = |of: &[crate::lod::Measured]| measured.then(|| run.metro_hypervolume(of));
    if let (Some(f), Some(b)) = (hv(&run.front_measured), hv(&run.baseline)) {
        eprintln!(
            "metro    hypervolume of the front {f:.6e}, of the greedy chain at the same \
             vertex counts {b:.6e} ({:+.3}%)",
            100.0 * (f - b) / b
        );
    }
    eprintln!(
        "wrote    {} and {}",
        json_path.display(),
        svg_path.display()
    );
}

/// The input file's path from the output folder (where the manifest goes).
fn input_from(input: &Input, outdir: &Path) -> Option<String> {
    match input {
        Input::File(p) => manifest::path_from(outdir, p),
        Input::Builtin { .. } => None,
    }
}

/// NaN (not measured) as JSON null.
fn finite(x: f64) -> Option<f64> {
    x.is_finite().then_some(x)
}
