//! `meshslim remesh`: isotropic remeshing (Botsch & Kobbelt 2004) to one edge length.

use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::Args;

use super::args::{Input, parse_angle, parse_input_arg};
use super::error::{UsageError, lib};
use super::files::{check_output, load};
use super::report::{Progress, write_quality};
use crate::remesh::{EdgeTarget, RemeshOptions, RemeshReport, remesh_with_progress};

pub(super) const REMESH_AFTER_HELP: &str = "\
Each iteration splits edges longer than 4/3 L, collapses edges shorter than 4/5 L, flips edges
towards valence 6 (4 on a border), moves every vertex towards the centroid of its neighbours
within its tangent plane and projects it back onto the input. Edges whose faces meet at more than the
feature angle, and borders, stay where they are: they are split and collapsed only along
themselves. The input must be manifold and consistently oriented ('meshslim info' tells);
vertices stored twice at one place are welded first. Normals, colours and UVs are
interpolated on the input at each new vertex; UV seams are kept as lines, like creases, with
their vertices stored once per side. Materials and groups are not carried (the report says
what was left out).

With --adaptive, L is the longest edge: edges shrink where the surface bends, down to
--shortest × L, so that each chord stays within --tolerance × L of the surface.

The edge length L is, by the first that is given: --edge-length, --edge-factor times the
input's mean edge length, the length that gives about --faces equilateral faces, or the input's
mean edge length.

Examples:
  meshslim remesh scan.ply scan-remeshed.ply
  meshslim remesh scan.ply coarse.ply --edge-factor 2
  meshslim remesh part.obj part-20k.obj --faces 20000 --feature-angle 30
  meshslim remesh patch.ply patch-even.ply --lock-border --iterations 10
  meshslim remesh scan.ply adaptive.ply --edge-factor 4 --adaptive --shortest 0.25";

#[derive(Debug, Args)]
pub struct RemeshArgs {
    /// Mesh to remesh: a .obj, .ply, .stl, .gltf or .glb file, or builtin:NAME[:FACES]
    #[arg(value_name = "IN", value_parser = parse_input_arg)]
    pub input: Input,

    /// Where to write the result; the format follows the extension
    #[arg(value_name = "OUT")]
    pub output: PathBuf,

    /// Target edge length L, in the mesh's units
    #[arg(long, value_name = "L", conflicts_with_all = ["edge_factor", "faces"])]
    pub edge_length: Option<f64>,

    /// Target edge length as a multiple of the input's mean edge length
    #[arg(long, value_name = "K", conflicts_with = "faces")]
    pub edge_factor: Option<f64>,

    /// About this many faces: L from the input's area
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    pub faces: Option<u64>,

    /// Split–collapse–flip–relax iterations
    #[arg(long, value_name = "N", default_value_t = 5)]
    pub iterations: usize,

    /// Relaxation-and-projection steps in each iteration
    #[arg(long, value_name = "N", default_value_t = 3)]
    pub relax_steps: usize,

    /// Edges whose faces meet at more than this angle (degrees) stay sharp; 180 for none
    #[arg(long, value_name = "DEG", default_value_t = 45.0, value_parser = parse_angle)]
    pub feature_angle: f64,

    /// Keep borders exactly: their vertices neither move nor go
    #[arg(long)]
    pub lock_border: bool,

    /// Shorter edges where the surface bends (Dunyach et al. 2013): each edge as long as keeps
    /// its chord within --tolerance of the surface, from --shortest up to L
    #[arg(long)]
    pub adaptive: bool,

    /// --adaptive: the shortest edge, as a share of L
    #[arg(long, value_name = "S", default_value_t = 0.1, requires = "adaptive")]
    pub shortest: f64,

    /// --adaptive: how far a chord may stray from the surface, as a share of L
    #[arg(long, value_name = "T", default_value_t = 0.05, requires = "adaptive")]
    pub tolerance: f64,

    /// Print the report as one JSON object on stdout
    #[arg(long)]
    pub json: bool,

    /// Print nothing but errors (and the JSON with --json)
    #[arg(short, long)]
    pub quiet: bool,
}

pub(super) fn run_remesh(args: RemeshArgs) -> Result<ExitCode> {
    for (name, v) in [
        ("--edge-length", args.edge_length),
        ("--edge-factor", args.edge_factor),
    ] {
        if let Some(v) = v
            && !(v.is_finite() && v > 0.0)
        {
            return Err(UsageError(format!("{name} must be a positive number, got {v}")).into());
        }
    }
    check_output(&args.input, &args.output)?;
    let progress = Progress::new(!args.quiet && !args.json && std::io::stderr().is_terminal());
    let mesh = load(&args.input, &progress)?;
    let target = match (args.edge_length, args.edge_factor, args.faces) {
        (Some(l), _, _) => EdgeTarget::Length(l),
        (_, Some(k), _) => EdgeTarget::MeanEdgeTimes(k),
        (_, _, Some(n)) => EdgeTarget::Faces(n as usize),
        _ => EdgeTarget::MeanEdge,
    };
    let opts = RemeshOptions {
        target,
        iterations: args.iterations,
        relax_steps: args.relax_steps,
        feature_angle_deg: args.feature_angle,
        lock_border: args.lock_border,
        adaptive: args.adaptive.then_some(crate::remesh::Adaptive {
            shortest: args.shortest,
            tolerance: args.tolerance,
        }),
    };
    let (out, report) = progress
        .bar("remeshing", |set| remesh_with_progress(&mesh, &opts, set))
        .map_err(lib)
        .with_context(|| format!("cannot remesh {}", args.input.display()))?;
    progress
        .spinner(format!("writing {}", args.output.display()), || {
            crate::io::write(&args.output, &out)
        })
        .map_err(lib)?;
    let quality = crate::metrics::triangle_quality(&out);
    let stdout = std::io::stdout();
    let mut w = stdout.lock();
    if args.json {
        let json = serde_json::json!({
            "input": args.input.display(),
            "output": args.output.display().to_string(),
            "report": report,
            "quality": quality,
        });
        writeln!(w, "{}", serde_json::to_string_pretty(&json)?)?;
    } else if !args.quiet {
        write_report(&mut w, &args, &report)?;
        write_quality(&mut w, &quality, "  ")?;
        for what in &report.not_carried {
            writeln!(w, "  not carried        {what}")?;
        }
    }
    w.flush()?;
    Ok(ExitCode::SUCCESS)
}

fn write_report(w: &mut impl Write, args: &RemeshArgs, r: &RemeshReport) -> std::io::Result<()> {
    writeln!(w, "{} -> {}", args.input.display(), args.output.display())?;
    writeln!(
        w,
        "  faces              {} -> {}",
        r.input_faces, r.output_faces
    )?;
    writeln!(
        w,
        "  edge length        {:.6} ({} iterations)",
        r.edge_length, r.iterations
    )?;
    writeln!(
        w,
        "  features           {} edges, {} fixed corners",
        r.feature_edges, r.corners
    )?;
    writeln!(
        w,
        "  operations         {} splits, {} collapses, {} flips",
        r.splits, r.collapses, r.flips
    )?;
    let s = &r.seconds;
    writeln!(
        w,
        "  seconds            {:.3} (setup {:.3}, split {:.3}, collapse {:.3}, flip {:.3}, relax and project {:.3})",
        s.total, s.setup, s.split, s.collapse, s.flip, s.relax
    )
}
