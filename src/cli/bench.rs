//! `meshslim bench`: every backend on the same meshes, as a table, JSON and a plot.

use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::Args;

use super::args::{Input, parse_f64, parse_input_arg};
use super::error::{UsageError, lib};
use super::files::{check_directory, load};
use super::report::Progress;

pub(super) const BENCH_AFTER_HELP: &str = "\
Each mesh is simplified to each ratio by each backend, --repeat times, the backends taking
turns run by run (so load from elsewhere on the machine falls on all of them alike), each call
starting from a cold cache (none inherits the data the one before it read); the table
reports the median wall time of the simplify call, input triangles per second, the peak heap
held during the call (counted by the binary's allocator, output included), and the two-sided
Metro distance to the input (as 'meshslim compare'), mean and max, relative to its
bounding-box diagonal. Under the table each of our rows is held against its meshoptimizer
peer when that ran too (simplify for the edge collapses and decimate, simplifySloppy for the
clusterings): its time over ours (above 1: we are faster) and our mean error over its. Without
MESH it runs the deterministic 1M-triangle scan:
../shared/models/igea.ply subdivided once when present ($MESHSLIM_MODELS names another
folder), else a procedural displaced sphere.

Examples:
  # the benchmark: the 1M scan, every backend, ratios 0.5, 0.1 and 0.01
  meshslim bench
  meshslim bench --ratios 0.1,0.01 --json bench.json --plot bench.svg
  meshslim bench scan.ply builtin:bumpy-sphere --backends cpu,meshopt --repeat 5
  # JSON on stdout instead of the table
  meshslim bench builtin:sphere --json -";

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

    /// Backends to run, comma-separated: cpu (meshslim's greedy), cpu-parallel and gpu (its
    /// rounds), cluster, floating-cell and hybrid (--method), each also as NAME-gpu,
    /// hybrid-parallel (hybrid with the rounds, hybrid-gpu's twin), decimate, meshopt
    /// (meshoptimizer's simplify), meshopt-sloppy (its clustering simplifySloppy)
    /// [default: all of them; the *gpu ones where there is an adapter]
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

    #[command(flatten)]
    pub sampling: super::args::SamplingArgs,
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

pub(super) fn run_bench(args: BenchArgs) -> Result<ExitCode> {
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
        check_directory(file, "the output directory")?;
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
            // Asked as available_backends asks (the shared device is made once), not by
            // counting: meshoptimizer's attribute variants are left out too, when unnamed.
            if crate::rounds::gpu::shared().is_err() {
                eprintln!("note: no GPU adapter; the gpu backends are left out");
            }
            all
        } else {
            args.backends
        },
        repeat: args.repeat as usize,
        compare: super::files::compare_options(&args.sampling)?,
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
