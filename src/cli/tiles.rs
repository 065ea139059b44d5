//! `meshslim tiles`: split a scan into tiles, simplify each as its own job (a Slurm array task,
//! a Kubernetes Indexed Job, or locally), merge.

use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use anyhow::{Context, Result};
use clap::{Args, Subcommand};

use super::args::{Input, parse_face_count, parse_input_arg, parse_ratio};
use super::error::{UsageError, lib};
use super::files::{check_output, load};
use super::report::Progress;
use crate::cluster::stream::Target;
use crate::tiles::{Manifest, SplitOptions, TileReport};

pub(super) const TILES_AFTER_HELP: &str = "\
A scan too big for one machine, or one job, is cut into spatial tiles by face centroid. Each
tile is simplified apart with its border vertices pinned, so neighbours still meet; the merge
welds the tiles by those vertices' global ids and simplifies the whole to the target, borders
free, so no seam survives. A tile's result depends only on its files: the output is the same
bytes however the tiles were run.

Examples:
  meshslim tiles split scan.ply work --tiles 16 --ratio 0.01
  meshslim tiles run work --jobs 2                   # every tile, here
  sbatch --array=0-15 --wait deploy/slurm/tiles.sbatch work   # or as a Slurm array
  meshslim tiles merge work scan-1pct.ply

deploy/k8s/ runs the tiles as a Kubernetes Indexed Job; docs/SCALE.md says more.";

#[derive(Debug, Args)]
pub struct TilesArgs {
    #[command(subcommand)]
    pub command: TilesCommand,
}

#[derive(Debug, Subcommand)]
pub enum TilesCommand {
    /// Cut IN (streamed: PLY or OBJ; other inputs are read whole first) into tiles in DIR,
    /// with a manifest
    Split(SplitArgs),
    /// Simplify one tile, its border pinned (the index defaults to SLURM_ARRAY_TASK_ID, then
    /// JOB_COMPLETION_INDEX)
    Simplify(TileArgs),
    /// Simplify every tile of DIR on this machine
    Run(RunArgs),
    /// Weld the simplified tiles and simplify across the former borders to the target
    Merge(MergeArgs),
}

#[derive(Debug, Args)]
pub struct SplitArgs {
    /// The mesh to split: a PLY or OBJ file (streamed), another format, or builtin:NAME[:FACES]
    #[arg(value_name = "IN", value_parser = parse_input_arg)]
    pub input: Input,
    /// The tiles folder (created if missing; an earlier split there is replaced)
    #[arg(value_name = "DIR")]
    pub dir: PathBuf,
    /// How many tiles (1 to 256): the grid over the box cuts across its longest axes
    #[arg(short, long, value_name = "N", default_value_t = 16)]
    pub tiles: usize,
    /// Fraction of the faces the merge keeps
    #[arg(short, long, value_name = "R", value_parser = parse_ratio, allow_negative_numbers = true, conflicts_with = "faces", required_unless_present = "faces")]
    pub ratio: Option<f64>,
    /// Faces the merge keeps
    #[arg(short, long, value_name = "N", value_parser = parse_face_count, allow_negative_numbers = true)]
    pub faces: Option<usize>,
}

#[derive(Debug, Args)]
pub struct TileArgs {
    /// The tiles folder `tiles split` wrote
    #[arg(value_name = "DIR")]
    pub dir: PathBuf,
    /// Which tile, from 0 [default: $SLURM_ARRAY_TASK_ID, else $JOB_COMPLETION_INDEX]
    #[arg(short, long, value_name = "I")]
    pub index: Option<usize>,
}

#[derive(Debug, Args)]
pub struct RunArgs {
    /// The tiles folder `tiles split` wrote
    #[arg(value_name = "DIR")]
    pub dir: PathBuf,
    /// Tiles simplified at once
    #[arg(short, long, value_name = "K", default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..))]
    pub jobs: u64,
}

#[derive(Debug, Args)]
pub struct MergeArgs {
    /// The tiles folder, every tile simplified
    #[arg(value_name = "DIR")]
    pub dir: PathBuf,
    /// The merged, simplified mesh (.ply, .obj, .stl, .gltf, .glb)
    #[arg(value_name = "OUT")]
    pub output: PathBuf,
    /// What the final simplification may hold, as 4G, 512M or bytes; a welded mesh that needs
    /// more is tiled again, coarser, in DIR/coarser [default: half the machine's memory]
    #[arg(long, value_name = "SIZE", value_parser = super::memory::parse_size)]
    pub memory: Option<u64>,
    /// Print one JSON object with the merge's report on stdout
    #[arg(long)]
    pub json: bool,
}

pub(super) fn run_tiles(args: TilesArgs) -> Result<ExitCode> {
    match args.command {
        TilesCommand::Split(a) => split(a),
        TilesCommand::Simplify(a) => {
            let index = tile_index(a.index)?;
            let progress = Progress::new(std::io::stderr().is_terminal());
            let r = progress
                .bar(&format!("tile {index}"), |p| {
                    crate::tiles::simplify_tile(&a.dir, index, &mut |f| p(f))
                })
                .map_err(lib)?;
            println!("{}", tile_line(&r));
            Ok(ExitCode::SUCCESS)
        }
        TilesCommand::Run(a) => run(a),
        TilesCommand::Merge(a) => merge(a),
    }
}

fn split(a: SplitArgs) -> Result<ExitCode> {
    let progress = Progress::new(std::io::stderr().is_terminal());
    let target = match (a.faces, a.ratio) {
        (Some(n), _) => Target::Faces(n),
        (None, Some(r)) => Target::Ratio(r),
        (None, None) => unreachable!("clap requires --ratio or --faces"),
    };
    let opts = SplitOptions::new(a.tiles, target);
    let streamed = matches!(&a.input, Input::File(p)
        if matches!(crate::io::Format::from_path(p), Ok(crate::io::Format::Ply | crate::io::Format::Obj)));
    // Inputs that cannot stream are read whole and split from a PLY copy in the folder.
    let copy = a.dir.join(".input.ply");
    let path = if let (true, Input::File(p)) = (streamed, &a.input) {
        p.clone()
    } else {
        std::fs::create_dir_all(&a.dir)
            .with_context(|| format!("cannot create {}", a.dir.display()))?;
        let mesh = load(&a.input, &progress)?;
        crate::io::write(&copy, &mesh).map_err(lib)?;
        copy.clone()
    };
    let result = progress.bar("splitting", |p| {
        crate::tiles::split(&path, &a.dir, &opts, &mut |f| p(f))
    });
    if !streamed {
        let _ = std::fs::remove_file(&copy);
    }
    let mut m = result.map_err(lib)?;
    if !streamed {
        m.input = a.input.display();
        m.write(&a.dir).map_err(lib)?;
    }
    let border: usize = m.tile.iter().map(|t| t.border.len()).sum();
    println!(
        "split {} ({} faces) into {} tiles ({}x{}x{}) in {}: {} border vertex entries; \
         the merge keeps {} faces",
        m.input,
        m.input_faces,
        m.tiles,
        m.grid[0],
        m.grid[1],
        m.grid[2],
        a.dir.display(),
        border,
        m.target_faces
    );
    Ok(ExitCode::SUCCESS)
}

/// `--index`, else the scheduler's array index.
fn tile_index(index: Option<usize>) -> Result<usize> {
    if let Some(i) = index {
        return Ok(i);
    }
    for var in ["SLURM_ARRAY_TASK_ID", "JOB_COMPLETION_INDEX"] {
        if let Ok(v) = std::env::var(var) {
            return v.trim().parse().map_err(|_| {
                UsageError(format!("{var}={v:?} is not a tile index (0, 1, ...)")).into()
            });
        }
    }
    Err(UsageError(
        "which tile? give --index I, or run as a Slurm array task (SLURM_ARRAY_TASK_ID) or a \
         Kubernetes Indexed Job (JOB_COMPLETION_INDEX)"
            .into(),
    )
    .into())
}

fn tile_line(r: &TileReport) -> String {
    format!(
        "tile {}: {} -> {} faces (target {}), {} border vertices pinned, {:.2} s",
        r.index, r.input_faces, r.output_faces, r.target_faces, r.border_vertices, r.seconds
    )
}

fn run(a: RunArgs) -> Result<ExitCode> {
    let m = Manifest::read(&a.dir).map_err(lib)?;
    let progress = Progress::new(std::io::stderr().is_terminal());
    let next = AtomicUsize::new(0);
    let reports: Mutex<Vec<crate::Result<TileReport>>> = Mutex::new(Vec::new());
    progress.bar(&format!("{} tiles", m.tiles), |p| {
        let (tick, ticks) = std::sync::mpsc::channel::<()>();
        std::thread::scope(|s| {
            for _ in 0..(a.jobs as usize).min(m.tiles) {
                let tick = tick.clone();
                let (next, reports, dir) = (&next, &reports, &a.dir);
                s.spawn(move || {
                    loop {
                        let i = next.fetch_add(1, Ordering::Relaxed);
                        if i >= m.tiles {
                            break;
                        }
                        let r = crate::tiles::simplify_tile(dir, i, &mut |_| {});
                        let failed = r.is_err();
                        reports.lock().expect("no panics while held").push(r);
                        let _ = tick.send(());
                        if failed {
                            // The others finish their tile; no new one starts.
                            next.store(m.tiles, Ordering::Relaxed);
                        }
                    }
                });
            }
            // The bar is drawn from here: the workers only tick.
            drop(tick);
            for (n, ()) in ticks.iter().enumerate() {
                p((n + 1) as f32 / m.tiles as f32);
            }
        })
    });
    let (mut done, failed): (Vec<_>, Vec<_>) = reports
        .into_inner()
        .expect("no panics while held")
        .into_iter()
        .partition(|r| r.is_ok());
    done.sort_by_key(|r| r.as_ref().map_or(0, |r| r.index));
    let mut out = std::io::stdout().lock();
    for r in done.into_iter().flatten() {
        writeln!(out, "{}", tile_line(&r))?;
    }
    match failed.into_iter().next() {
        Some(Err(e)) => Err(lib(e)),
        _ => Ok(ExitCode::SUCCESS),
    }
}

fn merge(a: MergeArgs) -> Result<ExitCode> {
    check_output(&Input::File(a.dir.join("manifest.json")), &a.output)?;
    let progress = Progress::new(!a.json && std::io::stderr().is_terminal());
    let (mesh, r) = progress
        .bar("merging", |p| {
            let memory = a.memory.unwrap_or_else(crate::memory::default_budget);
            crate::tiles::merge(&a.dir, memory, &mut |f| p(f))
        })
        .map_err(lib)?;
    crate::io::write(&a.output, &mesh).map_err(lib)?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&r)?);
    } else {
        let mut level = &r;
        let mut how = String::new();
        while let Some(c) = &level.coarser {
            how += &format!(
                "; needing {} of {}, tiled again coarser ({} faces welded)",
                crate::memory::mib(level.needed_bytes),
                crate::memory::mib(level.memory_budget),
                c.welded_faces
            );
            level = c;
        }
        println!(
            "merged {}: {} faces welded ({} border vertices joined){how} -> {} faces in {}",
            a.dir.display(),
            r.welded_faces,
            r.joined_vertices,
            mesh.triangles.len(),
            a.output.display()
        );
    }
    Ok(ExitCode::SUCCESS)
}
