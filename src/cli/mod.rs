//! The `meshslim` command line: clap argument types and the runners behind each subcommand.
//!
//! `main.rs` only parses and hands the result to [`run`]; this module converts the arguments to
//! library options once, calls the library, and prints the result. It is the one place besides
//! `main.rs` that uses `anyhow`: errors of the library arrive as [`meshslim::Error`] and leave
//! as messages for the user.
//!
//! One file per command (`simplify`, `info`, `compare`, `bench`, `view`, `tiles`, `lods` with `pareto`, `remesh`) holds its arguments, its
//! help text and its runner; `args` the argument types and parsers they share, `builtins` the
//! generated meshes, `files` reading inputs and checking output paths, `report` what the
//! commands print and the progress bars, `error` the usage error and the library's errors.

mod args;
mod bench;
mod builtins;
mod compare;
mod dag;
mod error;
mod files;
mod info;
mod lods;
mod memory;
mod remesh;
mod report;
mod simplify;
mod tiles;
mod view;

use std::process::ExitCode;

use anyhow::Result;
use clap::{Parser, Subcommand};

pub use args::Input;
pub use bench::BenchArgs;
use bench::{BENCH_AFTER_HELP, run_bench};
pub use builtins::{BUILTINS, BuiltinMesh, MAX_BUILTIN_FACES, builtin};
pub use compare::CompareArgs;
use compare::{COMPARE_AFTER_HELP, run_compare};
pub use dag::DagArgs;
use dag::{DAG_AFTER_HELP, run_dag};
pub use error::UsageError;
pub use info::InfoArgs;
use info::{INFO_AFTER_HELP, run_info};
use lods::{LODS_AFTER_HELP, PARETO_AFTER_HELP, run_lods, run_pareto};
pub use lods::{LodsArgs, ParetoArgs};
pub use remesh::RemeshArgs;
use remesh::{REMESH_AFTER_HELP, run_remesh};
pub use simplify::{BackendArg, GETTING_STARTED, SimplifyArgs};
use simplify::{SIMPLIFY_AFTER_HELP, run_simplify};
pub use tiles::TilesArgs;
use tiles::{TILES_AFTER_HELP, run_tiles};
pub use view::ViewArgs;
use view::{VIEW_AFTER_HELP, run_view};

const TOP_AFTER_HELP: &str = "\
Examples:
  meshslim simplify builtin:bumpy-sphere bumpy-10.ply --ratio 0.1
  meshslim simplify scan.ply scan-5k.obj --faces 5000 --stats
  meshslim info scan.ply
  meshslim info builtin:torus --json
  meshslim compare scan.ply scan-5k.obj
  meshslim bench --json bench.json --plot bench.svg
  meshslim tiles split scan.ply work --tiles 16 --ratio 0.01
  meshslim lods scan.ply lods --ratios 0.5,0.25,0.1,0.05,0.01
  meshslim pareto scan.ply front --population 100 --generations 20
  meshslim remesh scan.ply even.ply --edge-factor 2

Run 'meshslim <COMMAND> --help' for every option of a command.";

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
    /// Split a scan into tiles, simplify each as its own job (a Slurm array task, a Kubernetes
    /// Indexed Job, or here), and merge them across the former borders
    #[command(after_help = TILES_AFTER_HELP)]
    Tiles(TilesArgs),
    /// Levels of detail in one run, each going on from the one before: files and a manifest
    /// with each level's error against the original
    #[command(after_help = LODS_AFTER_HELP)]
    Lods(LodsArgs),
    /// Pareto sets of vertex-removal levels of detail by NSGA-II (vertices against error):
    /// the front's meshes, its hypervolume per generation, a plot
    #[command(after_help = PARETO_AFTER_HELP)]
    Pareto(ParetoArgs),
    /// Remesh to one edge length with well-shaped triangles (split, collapse, flip, relax,
    /// project), keeping sharp features and borders
    #[command(after_help = REMESH_AFTER_HELP)]
    Remesh(RemeshArgs),
    /// Cluster levels of detail (a Nanite-style DAG of meshlets): build one from a mesh, cut it
    /// at an error or for a camera, describe it
    #[command(after_help = DAG_AFTER_HELP)]
    Dag(DagArgs),
}

/// The exit code for an error [`run`] returned: 2 for bad usage, 1 for everything else.
pub fn exit_code(err: &anyhow::Error) -> ExitCode {
    if err.downcast_ref::<UsageError>().is_some() {
        ExitCode::from(2)
    } else {
        ExitCode::FAILURE
    }
}

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
        Some(Command::Tiles(args)) => run_tiles(args),
        Some(Command::Lods(args)) => run_lods(args),
        Some(Command::Pareto(args)) => run_pareto(args),
        Some(Command::Remesh(args)) => run_remesh(args),
        Some(Command::Dag(args)) => run_dag(args),
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
