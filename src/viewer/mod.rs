//! Looking at a simplification: the renderer draws the simplifier's own GPU buffers
//! ([`crate::rounds::gpu::GpuMesh`]) with the indirect draw arguments its rounds write, on the
//! device the simplifier ran on. `meshslim view MESH` opens the interactive window ([`app`], eframe
//! on wgpu, sharing eframe's device with the simplifier); `--screenshot` renders one frame
//! offscreen to a PNG, which needs no window system (lavapipe included).

mod actions;
pub mod app;
pub mod camera;
mod corners;
pub mod dag;
pub mod device;
mod file_browser;
pub mod front;
pub mod jobs;
pub mod lod;
pub mod panels;
pub mod render;
pub mod scene;
pub mod views;

use crate::error::{Error, Result};
use crate::options::{Backend, SimplifyOptions};
pub use app::{Start, ViewerApp};
pub use panels::AUTO_DAG_FACES;
pub use render::{Mode, Renderer, Style, encode_png};
pub use scene::{Image, Model};

/// What `screenshot` did, for the command line to report.
#[derive(Debug, Clone)]
pub struct Frame {
    pub adapter: String,
    pub faces: usize,
    /// Largest per-vertex distance to the original surface, relative to its diagonal (the top of
    /// the heatmap's colour ramp); 0 when not simplified.
    pub max_error: f64,
    pub png: Vec<u8>,
    /// Seconds of each frame drawn after the picture ([`Shot::frames`]), each submitted and
    /// waited for: a DAG's cut and the draw.
    pub frame_seconds: Vec<f64>,
    /// Triangles a frame draws: the mesh's, or the DAG cut's.
    pub triangles_drawn: usize,
    /// A DAG's clusters drawn and in its cut (none for a mesh).
    pub clusters_drawn: Option<(usize, usize)>,
}

/// Simplifies `model` to `ratio` on the GPU (1 = as is) and renders one `size` frame of the
/// result in `style`, framed to fit, straight from the simplifier's buffers; returns a PNG.
pub fn screenshot(model: &Model, ratio: f64, style: Style, size: (u32, u32)) -> Result<Frame> {
    screenshot_with(model, ratio, crate::Method::Qem, style, size)
}

/// As [`screenshot`], simplified by `method`: `qem`, `cluster` and `floating-cell` on the GPU,
/// drawn from the buffers they wrote; `hybrid` on the CPU's cores and `decimate` on one, their
/// result uploaded and drawn by the same renderer.
pub fn screenshot_with(
    model: &Model,
    ratio: f64,
    method: crate::Method,
    style: Style,
    size: (u32, u32),
) -> Result<Frame> {
    shoot(
        model,
        Shot {
            ratio,
            method,
            style,
            size,
            side_by_side: false,
            frames: 0,
            dag: None,
        },
    )
}

/// What a screenshot draws: the mesh simplified to `ratio` by `method` (1 = as is), in `style`,
/// `size` pixels; with `side_by_side`, the original and the result in two labelled halves, as
/// the window's `B` shows them.
#[derive(Debug, Clone, Copy)]
pub struct Shot<'a> {
    pub ratio: f64,
    pub method: crate::Method,
    pub style: Style,
    pub size: (u32, u32),
    pub side_by_side: bool,
    /// Frames to draw and time after the picture (`view --frames`).
    pub frames: usize,
    /// Draw this DAG's cut at this many pixels of error instead of the mesh (the model is
    /// then its first level, for the camera).
    pub dag: Option<(&'a crate::dag::Dag, f64)>,
}

/// Renders the [`Shot`] of `model`; returns a PNG and what it drew.
pub fn shoot(model: &Model, shot: Shot) -> Result<Frame> {
    let Shot {
        ratio,
        method,
        mut style,
        size,
        side_by_side,
        frames,
        dag,
    } = shot;
    check_mode(model, &style)?;
    let (ctx, sim) = crate::rounds::gpu::shared()?;
    // Every piece of device work below (uploads, the simplification, the texture, the draw) is
    // caught here and becomes an error, not a panic in wgpu's default handler.
    let scope = crate::compute::gpu::ErrorScope::push(&ctx.device);
    // The window's first view of the model, for each pane's shape.
    let pane = if side_by_side {
        ((size.0 / 2).max(1), size.1)
    } else {
        size
    };
    let cam = model.home_camera(pane);
    if let Some((dag, pixels)) = dag {
        // A DAG draws its own cut: the input mesh is not uploaded (the command line takes
        // neither --ratio nor --side-by-side with one).
        let mut renderer = shot_renderer(ctx, model, &style)?;
        let view = (&cam, size, pixels, frames);
        let frame = shoot_dag(ctx, &mut renderer, model, dag, view, &mut style)?;
        scope.check("rendering the frame")?;
        return Ok(frame);
    }
    let simplified = match ratio < 1.0 {
        true => Some(simplify_for_shot(ctx, sim, model, ratio, method)?),
        false => None,
    };
    let original = match (&simplified, side_by_side) {
        (Some(_), false) => None,
        _ => Some(model.original(&ctx.device)?),
    };
    let (scene, faces) = match &simplified {
        Some((s, faces)) => (s, *faces),
        None => (original.as_ref().expect("made above"), model.faces()),
    };
    style.error_scale = scene.max_error;
    let mut renderer = shot_renderer(ctx, model, &style)?;
    let mut draw = |mesh: &render::SceneMesh, size| {
        let items = [(mesh, cam.model)];
        render::render_rgba(
            &ctx.device,
            &ctx.queue,
            &mut renderer,
            &items,
            &cam,
            &style,
            size,
        )
    };
    let (rgba, size) = if side_by_side {
        let left = draw(original.as_ref().expect("made above"), pane)?;
        // The right pane's width takes the odd pixel.
        let right_pane = (size.0 - pane.0, size.1);
        let right = draw(scene, right_pane)?;
        views::side_by_side(
            vec![(left, pane), (right, right_pane)],
            &views::pane_labels(simplified.is_some()),
        )?
    } else {
        (draw(scene, size)?, size)
    };
    // The frames timed after the picture, as a DAG's are (side by side draws two
    // panes: not one frame of the window's).
    let frame_seconds = match frames > 0 && !side_by_side {
        true => {
            let target = render::Target::new(&ctx.device, size)?;
            let view = (&cam, &style);
            dag::time_frames(
                ctx,
                &mut renderer,
                &target,
                view,
                scene,
                frames,
                &mut |_| {},
            )?
        }
        false => Vec::new(),
    };
    let frame = Frame {
        adapter: ctx.adapter_name.clone(),
        faces,
        max_error: scene.max_error as f64,
        png: encode_png(&rgba, size)?,
        frame_seconds,
        triangles_drawn: faces,
        clusters_drawn: None,
    };
    scope.check("rendering the frame")?;
    Ok(frame)
}

/// A colour or texture mode the mesh cannot show, refused before any GPU work.
fn check_mode(model: &Model, style: &Style) -> Result<()> {
    if style.mode == Mode::Color && model.mesh.colors.is_none() {
        return Err(Error::InvalidOption(
            "--mode color: the mesh has no vertex colours".into(),
        ));
    }
    if style.mode == Mode::Texture && !(model.mesh.uvs.is_some() && model.texture.is_some()) {
        return Err(Error::InvalidOption(format!(
            "--mode texture: {}",
            model.texture_note.clone().unwrap_or_else(|| {
                "the mesh has no UVs or no texture (give one with --texture)".into()
            })
        )));
    }
    Ok(())
}

/// `model` simplified to `ratio` by `method` for the screenshot, and its faces.
fn simplify_for_shot(
    ctx: &crate::compute::context::GpuContext,
    sim: &crate::rounds::gpu::GpuSimplifier,
    model: &Model,
    ratio: f64,
    method: crate::Method,
) -> Result<(render::SceneMesh, usize)> {
    let mut opts = SimplifyOptions::with_ratio(model.up.face_count(), ratio)?;
    opts.method = method;
    // The GPU runs the rounds and the clustering; hybrid runs on the CPU as `simplify
    // --method hybrid` does by default (its clustering, then the greedy queue or the
    // rounds), decimate on one core.
    opts.backend = match method {
        crate::Method::Hybrid => Backend::Cpu,
        crate::Method::Decimate => Backend::Cpu,
        _ => Backend::Gpu,
    };
    let on = crate::simplify::OnDevice {
        rounds: Some(sim),
        cluster: Some(crate::cluster::gpu::shared()?),
        upload: None,
        share_queue: false,
    };
    let s = scene::simplify(&ctx.device, on, model, &opts, &mut |_| {}, &|_| {})?;
    Ok((s.scene, s.report.output_faces))
}

/// The screenshot's renderer, with the model's texture when the texture mode draws it (one
/// larger than the device takes is an error).
fn shot_renderer(
    ctx: &crate::compute::context::GpuContext,
    model: &Model,
    style: &Style,
) -> Result<Renderer> {
    let mut renderer = Renderer::new(&ctx.device, &ctx.queue);
    let max = ctx.device.limits().max_texture_dimension_2d;
    if let Some(t) = model
        .texture
        .as_ref()
        .filter(|_| style.mode == Mode::Texture)
    {
        if t.size.0 > max || t.size.1 > max {
            return Err(Error::InvalidOption(format!(
                "the texture is {}x{}, larger than this device's {max} pixels a side",
                t.size.0, t.size.1
            )));
        }
        renderer.set_texture(&ctx.device, &ctx.queue, Some((&t.rgba, t.size)));
    }
    Ok(renderer)
}

/// The screenshot of a DAG: its cut from `view` = (camera, size, pixels, frames timed after
/// the picture), each frame cut and drawn on the device, and the cut's counts read back.
fn shoot_dag(
    ctx: &crate::compute::context::GpuContext,
    renderer: &mut Renderer,
    model: &Model,
    dag: &crate::dag::Dag,
    (cam, size, pixels, frames): (&camera::Camera, (u32, u32), f64, usize),
    style: &mut Style,
) -> Result<Frame> {
    let frame = (model.up.center, model.up.scale);
    // The heatmap's distances cost a query a vertex: made only for it.
    let error = match style.mode {
        Mode::Heatmap => model.dag_errors(dag),
        _ => Vec::new(),
    };
    let mut d = dag::DagScene::new(&ctx.pipelines, &ctx.queue, dag, frame, error)?;
    style.error_scale = d.heat_top(cam, size, pixels);
    let p = d.cut_params(cam, size, pixels);
    let target = render::Target::new(&ctx.device, size)?;
    let (scene, cut) = (&d.scene, &mut d.cut);
    // Each frame cuts and draws; the first, which also makes what a first use makes, is
    // the picture and is not timed.
    let record = &mut |enc: &mut wgpu::CommandEncoder| cut.record(enc, &p);
    let mut seconds = dag::time_frames(
        ctx,
        renderer,
        &target,
        (cam, style),
        scene,
        frames + 1,
        record,
    )?;
    seconds.remove(0);
    let rgba = target.read_rgba(&ctx.device, &ctx.queue)?;
    let counts = crate::compute::context::read_back(
        &ctx.device,
        &ctx.queue,
        &d.cut.counts,
        16,
        "reading the cut's counts",
    )?;
    let counts: [u32; 4] = bytemuck::pod_read_unaligned(&counts);
    Ok(Frame {
        adapter: ctx.adapter_name.clone(),
        faces: dag.mesh.triangles.len(),
        max_error: style.error_scale as f64,
        png: encode_png(&rgba, size)?,
        frame_seconds: seconds,
        triangles_drawn: counts[2] as usize,
        clusters_drawn: Some((counts[1] as usize, counts[0] as usize)),
    })
}

/// Opens the interactive window with `ratio` as the starting target, drawn in `style` (in
/// `mode` when given, else as the mesh picks), of `size` points, a mesh of `auto_dag` faces or
/// more drawn as its cluster DAG (blocks until it is closed).
pub fn run_window(
    start: Start,
    ratio: f64,
    method: crate::Method,
    (style, mode): (Style, Option<Mode>),
    size: (u32, u32),
    up: Option<camera::Up>,
    auto_dag: usize,
) -> Result<()> {
    let options = eframe::NativeOptions {
        viewport: eframe::egui::ViewportBuilder::default()
            .with_title("meshslim")
            .with_inner_size([size.0 as f32, size.1 as f32])
            .with_drag_and_drop(true),
        wgpu_options: eframe::egui_wgpu::WgpuConfiguration {
            wgpu_setup: app::wgpu_setup(),
            ..Default::default()
        },
        ..Default::default()
    };
    let start = std::sync::Mutex::new(Some(start));
    eframe::run_native(
        "meshslim",
        options,
        Box::new(move |cc| {
            let start = start
                .lock()
                .ok()
                .and_then(|mut s| s.take())
                .unwrap_or(Start::Nothing);
            let mut app = ViewerApp::new(cc, start)?;
            app.set_ratio(ratio);
            app.set_method(method);
            app.set_style(style, mode);
            app.set_up(up);
            app.set_auto_dag(auto_dag);
            Ok(Box::new(app))
        }),
    )
    .map_err(|e| {
        Error::Gpu(format!(
            "cannot open the viewer window ({e}); without a display, render a frame with \
             --screenshot FILE.png"
        ))
    })
}
