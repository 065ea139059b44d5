//! `meshslim view`: the interactive window, or one frame to a PNG with `--screenshot`.

use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::Args;

use super::args::{Input, parse_input_arg, parse_ratio, parse_size};
use super::builtins::BUILTIN_PREFIX;
use super::error::{UsageError, lib};
use super::files::{check_directory, load};
use super::report::Progress;
use crate::lod::manifest::{self, ManifestKind};

pub(super) const VIEW_AFTER_HELP: &str = "\
In the window: left drag orbits, right or middle drag pans, the wheel zooms, G flies (W A S D),
F frames the mesh, 1-8 switch shaded / normals / heatmap / texture / quality / colour / a DAG's
clusters / its levels, X wireframe, B side by side,
Enter simplifies to the target, Esc cancels, Ctrl+O opens, Ctrl+S saves, P takes a screenshot;
F1 lists them all. Simplification runs beside the drawing: the window keeps drawing (frame time
in the side panel) and the run can be cancelled.

A manifest opens with the mesh it was made from: X.lods.json (from 'meshslim lods') puts its
levels in the LOD scene, a 21x21 grid where each instance draws the level its size on screen
calls for (L toggles LOD; the panel shows the frame time with and without). X.pareto.json (from
'meshslim pareto') plots its front in the side panel: click a point to show that member (B for
side by side with the original), Ctrl+click to choose members for the LOD scene. The panel's
Search runs the same NSGA-II on the open mesh.

A cluster DAG (X.mslod, from 'meshslim dag build') is drawn as a renderer draws it: per frame
the device picks each cluster's coarsest version whose error projects under --pixels (default 1;
in the window, a slider) and that is in view, and draws from those draws with no read-back.
--frames N draws and times N more frames from the same camera, and --json prints the median
frame time and the triangles a frame drew, for a DAG and a plain mesh alike. In the window, a
mesh of a million faces or more (--auto-dag) is drawn as its DAG once built, as a job, and whole
until then; O shows it whole.

Examples:
  meshslim view ../shared/models/horse.ply
  meshslim view horse.mslod --screenshot dag.png --pixels 1 --frames 20 --json
  meshslim view ../shared/models/spot/spot_triangulated.obj --mode texture --screenshot spot.png
  meshslim view ../shared/models/horse.ply --screenshot horse.png --ratio 0.1
  meshslim view ../shared/models/horse.ply --screenshot both.png --ratio 0.01 --side-by-side
  meshslim view lods/horse.lods.json
  meshslim view front/horse.pareto.json
  meshslim view scan.ply --screenshot err.png --ratio 0.01 --mode heatmap --size 1600x1200";

#[derive(Debug, Args)]
pub struct ViewArgs {
    /// The mesh: a file or builtin:NAME[:FACES], or a manifest of `meshslim lods` or `pareto`
    /// (X.lods.json, X.pareto.json); without one the window opens empty (Ctrl+O or drop a file
    /// on it)
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

    /// The algorithm for --ratio (and the window's starting choice): qem, cluster,
    /// floating-cell, hybrid or decimate, as `meshslim simplify --method`
    #[arg(long, value_enum, default_value_t = super::simplify::MethodArg::Qem)]
    pub method: super::simplify::MethodArg,

    /// What the surface shows [default: color for a mesh with vertex colours, else shaded]
    #[arg(long, value_enum)]
    pub mode: Option<crate::viewer::Mode>,

    /// Smooth shading (per-vertex normals) instead of flat faces
    #[arg(long)]
    pub smooth: bool,

    /// Draw the edges over the surface
    #[arg(long)]
    pub wireframe: bool,

    /// With --screenshot: the original on the left and the result on the right, each labelled,
    /// in two halves of the image (the window's B)
    #[arg(long)]
    pub side_by_side: bool,

    /// Image size for --screenshot (default 1024x768), or the window's size (default 1280x800),
    /// WIDTHxHEIGHT
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    pub size: Option<(u32, u32)>,

    /// With --screenshot of a DAG (X.mslod): the projected error each cluster may show, in
    /// pixels of the image's height
    #[arg(long, value_name = "P", value_parser = parse_pixels)]
    pub pixels: Option<f64>,

    /// With --screenshot: draw and time this many frames more from the same camera (for a
    /// DAG, each with its cut on the device)
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub frames: usize,

    /// With --screenshot: print what was drawn as JSON (frame_seconds, the median of --frames;
    /// triangles_drawn per frame) instead of a line
    #[arg(long)]
    pub json: bool,

    /// The mesh's axis drawn up: x, y, z, -x, -y, -z, or auto (the largest silhouette).
    /// Default: +Y for glTF (its specification) and generated meshes; for PLY, OBJ and STL the
    /// side the mesh rests on (horse.ply stands on +Z), else the file's convention (+Y, STL +Z)
    #[arg(long, value_enum, value_name = "AXIS", allow_hyphen_values = true)]
    pub up: Option<crate::viewer::camera::Up>,

    /// In the window: a mesh of at least this many faces is drawn as its cluster DAG, built as
    /// a job when it opens (Esc cancels it), so that it orbits like a small mesh; 0: never
    #[arg(long, value_name = "FACES", default_value_t = crate::viewer::AUTO_DAG_FACES)]
    pub auto_dag: usize,
}

/// A threshold in pixels: finite and above zero.
fn parse_pixels(s: &str) -> std::result::Result<f64, String> {
    match s.parse::<f64>() {
        Ok(p) if p.is_finite() && p > 0.0 => Ok(p),
        _ => Err(format!("{s}: the pixels must be a number above 0")),
    }
}

/// Whether `input` is a cluster DAG file.
fn is_dag(input: &Input) -> bool {
    matches!(input, Input::File(p) if p.extension().is_some_and(|e| e.eq_ignore_ascii_case("mslod")))
}

pub(super) fn run_view(args: ViewArgs) -> Result<ExitCode> {
    let progress = Progress::new(std::io::stderr().is_terminal());
    // The window picks colour mode itself for a coloured mesh (and each file opened next)
    // unless --mode says otherwise.
    let style = crate::viewer::Style {
        mode: args.mode.unwrap_or(crate::viewer::Mode::Shaded),
        smooth: args.smooth,
        wireframe: args.wireframe,
        error_scale: 0.0,
    };
    check_flags(&args)?;
    let Some(png) = args.screenshot.clone() else {
        return open_window(&args, style, &progress);
    };
    let Some(input) = &args.input else {
        return Err(UsageError("--screenshot needs a MESH to draw".into()).into());
    };
    check_screenshot(input, &png)?;
    let dag = read_dag(&args, input, &progress)?;
    let model = match &dag {
        Some(d) => {
            let mut m = crate::viewer::Model::leaves_of(d, input.display()).map_err(lib)?;
            m.up_axis = args.up.unwrap_or(m.up_axis);
            m
        }
        None => read_model(&args, &progress, input)?,
    };
    let style = crate::viewer::Style {
        // As the window opens it: a textured mesh in texture mode, a painted one in colour.
        mode: args
            .mode
            .unwrap_or(if model.mesh.uvs.is_some() && model.texture.is_some() {
                crate::viewer::Mode::Texture
            } else if model.mesh.colors.is_some() {
                crate::viewer::Mode::Color
            } else {
                crate::viewer::Mode::Shaded
            }),
        ..style
    };
    let size = args.size.unwrap_or((1024, 768));
    let frame = progress
        .spinner("simplifying and rendering on the GPU".to_string(), || {
            let shot = crate::viewer::Shot {
                ratio: args.ratio.unwrap_or(1.0),
                method: args.method.method(),
                style,
                size,
                side_by_side: args.side_by_side,
                frames: args.frames,
                dag: dag.as_ref().map(|d| (d, args.pixels.unwrap_or(1.0))),
            };
            crate::viewer::shoot(&model, shot)
        })
        .map_err(lib)?;
    crate::io::write_atomic(&png, |w| w.write_all(&frame.png))
        .map_err(lib)
        .context("cannot write the screenshot")?;
    report(&args, &png, &frame, size, style, dag.is_some())
}

/// The mesh of `input` for the window or a screenshot, its up axis and texture as given.
fn read_model(args: &ViewArgs, progress: &Progress, input: &Input) -> Result<crate::viewer::Model> {
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
            let mesh = load(input, progress)?;
            let mut m = crate::viewer::Model::from_mesh(input.display(), mesh).map_err(lib)?;
            m.up_axis = args.up.unwrap_or(m.up_axis);
            if let Some(t) = &args.texture {
                m.texture = Some(crate::viewer::scene::read_texture(t).map_err(lib)?);
            }
            Ok(m)
        }
    }
}

/// The flags that go together: --pixels with a DAG, --frames, --json and --pixels with
/// --screenshot, --frames not with --side-by-side.
fn check_flags(args: &ViewArgs) -> Result<()> {
    let dag_only = |what: &str| -> Result<()> {
        match &args.input {
            Some(i) if is_dag(i) => Ok(()),
            _ => Err(UsageError(format!("{what} is for the screenshot of a DAG (X.mslod)")).into()),
        }
    };
    if args.pixels.is_some() {
        dag_only("--pixels")?;
    }
    if args.screenshot.is_none() && (args.frames > 0 || args.json || args.pixels.is_some()) {
        return Err(UsageError(
            "--frames, --json and --pixels go with --screenshot (the window has a slider for \
             the pixels)"
                .into(),
        )
        .into());
    }
    if args.frames > 0 && args.side_by_side {
        return Err(UsageError("--frames times one view: not with --side-by-side".into()).into());
    }
    Ok(())
}

/// The window on `args.input` (blocks until it is closed).
fn open_window(
    args: &ViewArgs,
    style: crate::viewer::Style,
    progress: &Progress,
) -> Result<ExitCode> {
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
        Some(Input::File(p)) if ManifestKind::of(p).is_some() => {
            // A manifest made from a generated mesh: made again here, where the builtins
            // are; a file is read by the window.
            let input = manifest::input_of(p)
                .map_err(lib)
                .context("cannot read the manifest")?;
            if input.starts_with(BUILTIN_PREFIX) {
                let made = parse_input_arg(&input)
                    .map_err(|e| UsageError(format!("{}: its input {input}: {e}", p.display())))?;
                crate::viewer::Start::Manifest(p.clone(), read_model(args, progress, &made)?)
            } else {
                crate::viewer::Start::Open(p.clone())
            }
        }
        Some(Input::File(p)) if args.texture.is_none() => crate::viewer::Start::Open(p.clone()),
        Some(input) => crate::viewer::Start::Model(read_model(args, progress, input)?),
        None => crate::viewer::Start::Nothing,
    };
    let size = args.size.unwrap_or((1280, 800));
    crate::viewer::run_window(
        start,
        args.ratio.unwrap_or(0.1),
        args.method.method(),
        (style, args.mode),
        size,
        args.up,
        args.auto_dag,
    )
    .map_err(lib)?;
    Ok(ExitCode::SUCCESS)
}

/// A screenshot draws one mesh into a PNG whose folder exists: checked before anything is read.
fn check_screenshot(input: &Input, png: &std::path::Path) -> Result<()> {
    if let Input::File(p) = input
        && ManifestKind::of(p).is_some()
    {
        return Err(UsageError(format!(
            "{}: a manifest opens in the window (without --screenshot); a screenshot draws one \
             mesh: give one of its files",
            p.display()
        ))
        .into());
    }
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
    check_directory(png, "the screenshot's directory")?;
    Ok(())
}

/// The DAG of `input` when it is a .mslod (which --ratio and --side-by-side do not go with).
fn read_dag(
    args: &ViewArgs,
    input: &Input,
    progress: &Progress,
) -> Result<Option<crate::dag::Dag>> {
    Ok(if is_dag(input) {
        let Input::File(path) = input else {
            unreachable!("is_dag holds for files")
        };
        if args.ratio.is_some() || args.side_by_side {
            return Err(UsageError(
                "a DAG is drawn as its cut: --ratio and --side-by-side are for meshes".into(),
            )
            .into());
        }
        Some(
            progress
                .spinner(format!("reading {}", path.display()), || {
                    crate::dag::file::read(path)
                })
                .map_err(lib)
                .context("cannot read the DAG")?,
        )
    } else {
        None
    })
}

/// What the screenshot drew: JSON with --json, else a line.
fn report(
    args: &ViewArgs,
    png: &std::path::Path,
    frame: &crate::viewer::Frame,
    size: (u32, u32),
    style: crate::viewer::Style,
    is_dag: bool,
) -> Result<ExitCode> {
    if args.json {
        let mut times = frame.frame_seconds.clone();
        times.sort_by(f64::total_cmp);
        let median = (!times.is_empty()).then(|| times[times.len() / 2]);
        let json = serde_json::json!({
            "screenshot": png,
            "adapter": frame.adapter,
            "size": [size.0, size.1],
            "faces": frame.faces,
            "triangles_drawn": frame.triangles_drawn,
            "clusters_drawn": frame.clusters_drawn.map(|c| c.0),
            "clusters_in_cut": frame.clusters_drawn.map(|c| c.1),
            "pixels": is_dag.then(|| args.pixels.unwrap_or(1.0)),
            "frames": frame.frame_seconds.len(),
            "frame_seconds": median,
            "frame_seconds_each": frame.frame_seconds,
        });
        println!("{}", serde_json::to_string_pretty(&json)?);
        return Ok(ExitCode::SUCCESS);
    }
    let heat = if style.mode == crate::viewer::Mode::Heatmap {
        format!(", heatmap red at {:.3e} of the diagonal", frame.max_error)
    } else {
        String::new()
    };
    println!(
        "{}: {} faces drawn from the GPU buffers on {}, {}x{}{heat}",
        png.display(),
        frame.triangles_drawn,
        frame.adapter,
        size.0,
        size.1
    );
    Ok(ExitCode::SUCCESS)
}
