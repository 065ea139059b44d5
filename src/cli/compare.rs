//! `meshslim compare`: the Metro distance between two meshes both ways, and the change in area,
//! volume, triangle quality and topology.

use std::io::{IsTerminal, Write};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{Context, Result};
use clap::Args;

use super::args::{Input, parse_input_arg};
use super::error::lib;
use super::files::load;
use super::report::{Progress, write_comparison, write_json_with};

pub(super) const COMPARE_AFTER_HELP: &str = "\
Distances are Metro's (as MeshLab's Hausdorff Distance filter): points sampled uniformly by
area on the faces of each mesh, plus every vertex and points along every edge for the maximum, each
measured to the closest point of the other mesh. Relative figures are fractions of A's
bounding-box diagonal; the two-sided mean is the average of the two directions' means.

Examples:
  meshslim compare scan.ply scan-5k.obj
  meshslim compare scan.ply scan-5k.obj --samples 1000000 --seed 7
  meshslim compare builtin:sphere builtin:sphere:500 --json";

#[derive(Debug, Args)]
pub struct CompareArgs {
    /// The reference mesh (the original): a file or builtin:NAME[:FACES]
    #[arg(value_name = "A", value_parser = parse_input_arg)]
    pub a: Input,

    /// The mesh to measure against A (the simplified one)
    #[arg(value_name = "B", value_parser = parse_input_arg)]
    pub b: Input,

    #[command(flatten)]
    pub sampling: super::args::SamplingArgs,

    /// Print one JSON object with every figure on stdout
    #[arg(long)]
    pub json: bool,
}

pub(super) fn run_compare(args: CompareArgs) -> Result<ExitCode> {
    let progress = Progress::new(!args.json && std::io::stderr().is_terminal());
    let t = Instant::now();
    let a = load(&args.a, &progress)?;
    let b = load(&args.b, &progress)?;
    let load_s = t.elapsed().as_secs_f64();
    let opts = super::files::compare_options(&args.sampling)?;
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
        let extra = serde_json::json!({
            "a": args.a.display(),
            "b": args.b.display(),
            "seconds": { "load": load_s, "compare": compare_s },
        });
        write_json_with(&mut out, &c, extra)?;
    } else {
        write_comparison(&mut out, &args.a, &args.b, &c, load_s, compare_s)?;
    }
    out.flush()?;
    Ok(ExitCode::SUCCESS)
}
