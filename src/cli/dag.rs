//! `meshslim dag`: build a cluster DAG (.mslod), cut it at an error or for a camera, describe it.

use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Result, bail};
use clap::{Args, Subcommand};

use super::args::{AttributeArgs, Input, parse_f64, parse_input_arg};
use super::error::{UsageError, lib};
use super::files::{check_output, load};
use super::report::Progress;
use super::simplify::BackendArg;
use crate::dag::{CameraCut, Dag, DagOptions, DagReport};

pub(super) const DAG_AFTER_HELP: &str = "\
A cluster DAG holds a mesh as meshlets of at most 128 triangles at every level of detail, in
the manner of Unreal's Nanite: neighbouring clusters are grouped, each group is simplified to
half its triangles with its outer border kept, and split into clusters again, level after
level, until one cluster is left. A renderer draws, per cluster, the coarsest version whose
error is under its threshold; the cut closes up between levels.

Examples:
  meshslim dag build scan.ply scan.mslod --stats
  meshslim dag info scan.mslod
  meshslim dag cut scan.mslod far.ply --error 0.002
  meshslim dag cut scan.mslod small.ply --triangles 20000
  meshslim dag cut scan.mslod near.ply --camera 0,0,2 --pixels 1

docs/MSLOD.md describes the file.";

#[derive(Debug, Args)]
pub struct DagArgs {
    #[command(subcommand)]
    pub command: DagCommand,
}

#[derive(Debug, Subcommand)]
pub enum DagCommand {
    /// Build the cluster DAG of a mesh and write it as .mslod
    Build(BuildArgs),
    /// Write the mesh a renderer would draw at an error, or from a camera
    Cut(CutArgs),
    /// Print a DAG's levels, clusters per level, errors and sizes
    Info(DagInfoArgs),
}

#[derive(Debug, Args)]
pub struct BuildArgs {
    /// The mesh: a .obj, .ply, .stl, .gltf or .glb file, or builtin:NAME[:FACES]
    #[arg(value_name = "IN", value_parser = parse_input_arg)]
    pub input: Input,
    /// The DAG file to write (.mslod)
    #[arg(value_name = "OUT")]
    pub output: PathBuf,
    /// What simplifies the groups: cpu runs the greedy on many groups at once across the
    /// cores; cpu-parallel and gpu run the rounds once per level, each group to its own target
    #[arg(short, long, value_enum, default_value = "cpu")]
    pub backend: BackendArg,
    /// Triangles per cluster at most
    #[arg(long, value_name = "N", default_value_t = DagOptions::default().max_triangles)]
    pub cluster_triangles: usize,
    /// Vertices per cluster at most (a mesh shader's output limit)
    #[arg(long, value_name = "N", default_value_t = DagOptions::default().max_vertices)]
    pub cluster_vertices: usize,
    /// Clusters per group at most
    #[arg(long, value_name = "N", default_value_t = DagOptions::default().group_size)]
    pub group_size: usize,
    #[command(flatten)]
    pub attributes: AttributeArgs,
    /// Print one JSON object with the build's report on stdout
    #[arg(long)]
    pub json: bool,
    /// Print the build's report on stderr
    #[arg(long)]
    pub stats: bool,
}

#[derive(Debug, Args)]
pub struct CutArgs {
    /// The DAG file (.mslod)
    #[arg(value_name = "DAG")]
    pub dag: PathBuf,
    /// The mesh to write (.ply, .obj, .stl, .gltf, .glb)
    #[arg(value_name = "OUT")]
    pub output: PathBuf,
    /// Object-space error, as a fraction of the bounding-box diagonal: a cluster is drawn when
    /// its own error is at most E and its group's is over it
    #[arg(long, value_name = "E", value_parser = parse_f64, conflicts_with_all = ["camera", "triangles"], required_unless_present_any = ["camera", "triangles"])]
    pub error: Option<f64>,
    /// The finest object-space cut of at most N triangles (the root when none is that small)
    #[arg(long, value_name = "N", conflicts_with = "camera")]
    pub triangles: Option<usize>,
    /// The camera's position for a view-dependent cut, as X,Y,Z in mesh units
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_point, requires = "pixels")]
    pub camera: Option<[f64; 3]>,
    /// With --camera: the projected error allowed, in pixels
    #[arg(long, value_name = "P", value_parser = parse_f64)]
    pub pixels: Option<f64>,
    /// With --camera: the vertical field of view in degrees
    #[arg(long, value_name = "DEG", default_value_t = 60.0, value_parser = parse_f64)]
    pub fov: f64,
    /// With --camera: the viewport's height in pixels
    #[arg(long, value_name = "PX", default_value_t = 1080.0, value_parser = parse_f64)]
    pub height: f64,
    /// Print one JSON object describing the cut on stdout
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Args)]
pub struct DagInfoArgs {
    /// The DAG file (.mslod)
    #[arg(value_name = "DAG")]
    pub dag: PathBuf,
    /// Print one JSON object on stdout
    #[arg(long)]
    pub json: bool,
}

fn parse_point(s: &str) -> std::result::Result<[f64; 3], String> {
    let parts: Vec<&str> = s.split(',').collect();
    if parts.len() != 3 {
        return Err(format!("{s:?}: write the point as X,Y,Z, e.g. 0,0,2"));
    }
    let mut p = [0.0; 3];
    for (x, part) in p.iter_mut().zip(parts) {
        *x = parse_f64(part)?;
    }
    Ok(p)
}

pub(super) fn run_dag(args: DagArgs) -> Result<ExitCode> {
    match args.command {
        DagCommand::Build(a) => build(a),
        DagCommand::Cut(a) => cut(a),
        DagCommand::Info(a) => info(a),
    }
}

fn check_mslod(path: &Path) -> Result<()> {
    if path.extension().and_then(|e| e.to_str()) != Some("mslod") {
        return Err(UsageError(format!("{}: a DAG file ends in .mslod", path.display())).into());
    }
    Ok(())
}

fn build(a: BuildArgs) -> Result<ExitCode> {
    check_mslod(&a.output)?;
    let progress = Progress::new(!a.json && std::io::stderr().is_terminal());
    let mesh = load(&a.input, &progress)?;
    let opts = DagOptions {
        max_triangles: a.cluster_triangles,
        max_vertices: a.cluster_vertices,
        group_size: a.group_size,
        backend: a.backend.backend(),
        attributes: a.attributes.weights(),
        ..DagOptions::default()
    };
    let (dag, report) = progress
        .bar("building the DAG", |p| {
            crate::dag::build_with_progress(&mesh, &opts, &mut |f| p(f))
        })
        .map_err(lib)?;
    crate::dag::file::write(&a.output, &dag).map_err(lib)?;
    if a.stats {
        eprint!("{}", report_text(&report));
    }
    if a.json {
        let mut json = serde_json::to_value(&report)?;
        let o = json.as_object_mut().expect("a report is an object");
        let seconds = o.remove("seconds").unwrap_or_default();
        o.insert("seconds".into(), serde_json::json!({ "build": seconds }));
        o.insert("input".into(), a.input.display().into());
        o.insert("output".into(), a.output.display().to_string().into());
        println!("{json}");
    } else {
        println!(
            "{}: {} levels, {} clusters, {} triangles in all -> {}",
            a.input.display(),
            report.levels,
            report.clusters,
            report.dag_triangles,
            a.output.display()
        );
    }
    Ok(ExitCode::SUCCESS)
}

fn report_text(r: &DagReport) -> String {
    let per: Vec<String> = r
        .triangles_per_level
        .iter()
        .map(|t| t.to_string())
        .collect();
    format!(
        "  levels      {} (triangles {})\n  clusters    {}\n  groups      {} ({} stuck, {} at the root)\n  triangles   {} in all\n  backend     {}\n  build       {:.3} s\n",
        r.levels,
        per.join(" -> "),
        r.clusters,
        r.groups,
        r.stuck_groups,
        r.root_groups,
        r.dag_triangles,
        r.backend.name(),
        r.seconds
    )
}

fn cut(a: CutArgs) -> Result<ExitCode> {
    let dag = crate::dag::file::read(&a.dag).map_err(lib)?;
    check_output(&Input::File(a.dag.clone()), &a.output)?;
    let mut threshold = None;
    let ids = match (a.error, a.camera, a.pixels) {
        (Some(e), _, _) => {
            if e < 0.0 {
                bail!(UsageError(format!("--error must be 0 or more, got {e}")));
            }
            threshold = Some(e);
            dag.cut_at_error(e * dag.diagonal)
        }
        _ if a.triangles.is_some() => {
            let n = a.triangles.unwrap_or_default();
            let (ids, t) = dag.cut_to_triangles(n);
            threshold = Some(t / dag.diagonal.max(f64::MIN_POSITIVE));
            ids
        }
        (None, Some(eye), Some(pixels)) => {
            let cam = CameraCut {
                eye,
                pixels,
                fov_deg: a.fov,
                height: a.height,
            };
            cam.check().map_err(|e| UsageError(e.to_string()))?;
            dag.cut_from_camera(&cam)
        }
        _ => bail!(UsageError(
            "give --error E, or --camera X,Y,Z with --pixels P".into()
        )),
    };
    let mesh = dag.mesh_of(&ids);
    crate::io::write(&a.output, &mesh).map_err(lib)?;
    let depths = depth_counts(&dag, &ids);
    if a.json {
        let json = serde_json::json!({
            "dag": a.dag.display().to_string(),
            "output": a.output.display().to_string(),
            "clusters": ids.len(),
            "triangles": mesh.triangles.len(),
            "vertices": mesh.positions.len(),
            "clusters_per_depth": depths,
            "error": threshold,
        });
        println!("{json}");
    } else {
        println!(
            "{}: {} clusters, {} triangles -> {}",
            a.dag.display(),
            ids.len(),
            mesh.triangles.len(),
            a.output.display()
        );
    }
    Ok(ExitCode::SUCCESS)
}

fn depth_counts(dag: &Dag, ids: &[u32]) -> Vec<usize> {
    let mut v = vec![0; dag.levels()];
    for &i in ids {
        v[dag.clusters[i as usize].depth as usize] += 1;
    }
    v
}

fn info(a: DagInfoArgs) -> Result<ExitCode> {
    let dag = crate::dag::file::read(&a.dag).map_err(lib)?;
    let bytes = std::fs::metadata(&a.dag).map(|m| m.len()).unwrap_or(0);
    let per = dag.per_depth();
    let max_error = |d: usize| {
        dag.clusters
            .iter()
            .filter(|c| c.depth as usize == d)
            .map(|c| c.error)
            .fold(0.0f32, f32::max)
    };
    let out = std::io::stdout();
    let mut out = out.lock();
    if a.json {
        let levels: Vec<_> = per
            .iter()
            .enumerate()
            .map(|(d, &(c, t))| {
                serde_json::json!({"depth": d, "clusters": c, "triangles": t, "max_error": max_error(d)})
            })
            .collect();
        let json = serde_json::json!({
            "dag": a.dag.display().to_string(),
            "bytes": bytes,
            "vertices": dag.mesh.positions.len(),
            "triangles": dag.mesh.triangles.len(),
            "clusters": dag.clusters.len(),
            "groups": dag.groups.len(),
            "diagonal": dag.diagonal,
            "levels": levels,
        });
        writeln!(out, "{json}")?;
    } else {
        writeln!(out, "{}", a.dag.display())?;
        writeln!(
            out,
            "  {} vertices, {} triangles, {} clusters, {} groups, {} bytes",
            dag.mesh.positions.len(),
            dag.mesh.triangles.len(),
            dag.clusters.len(),
            dag.groups.len(),
            bytes
        )?;
        writeln!(
            out,
            "  depth  clusters  triangles  max error (of the diagonal)"
        )?;
        for (d, &(c, t)) in per.iter().enumerate() {
            let e = max_error(d) as f64 / dag.diagonal.max(f64::MIN_POSITIVE);
            writeln!(out, "  {d:>5}  {c:>8}  {t:>9}  {e:.3e}")?;
        }
    }
    Ok(ExitCode::SUCCESS)
}
