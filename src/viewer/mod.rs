//! Looking at a simplification: the renderer draws the simplifier's own GPU buffers
//! ([`crate::gpu::GpuMesh`]) with the indirect draw arguments its rounds write, on the device the
//! simplifier ran on. Today: one offscreen frame to a PNG (`meshslim view MESH --screenshot`),
//! which works without a window system (lavapipe included); the interactive window is not
//! built yet.

pub mod camera;
pub mod render;

use crate::error::{Error, Result};
use crate::gpu::GpuRounds;
use crate::mesh::Mesh;
use crate::metrics::TriangleBvh;
use crate::parallel::{SELECTION_PASSES, Upload, drive};
use crate::simplify::{Backend, SimplifyOptions};
use camera::Camera;
pub use render::Mode;
use wgpu::util::DeviceExt;

/// What `screenshot` did, for the command line to report.
#[derive(Debug, Clone)]
pub struct Frame {
    pub adapter: String,
    pub faces: usize,
    /// Largest per-vertex distance to the original surface, relative to its diagonal (the top of
    /// the heatmap's colour ramp); 0 when not measured.
    pub max_error: f64,
    pub png: Vec<u8>,
}

/// Simplifies `mesh` to `ratio` on the GPU (1 = as is) and renders one `size` frame of the
/// result in `mode`, framed to fit, straight from the simplifier's buffers; returns a PNG.
pub fn screenshot(mesh: &Mesh, ratio: f64, mode: Mode, size: (u32, u32)) -> Result<Frame> {
    let (ctx, sim) = crate::gpu::shared()?;
    let up = Upload::new(mesh);
    if up.face_count() == 0 {
        return Err(Error::InvalidMesh(
            "nothing to draw: the mesh has no faces".into(),
        ));
    }
    let mut rounds = GpuRounds::new(sim, &up, SELECTION_PASSES)?;
    let mut opts = SimplifyOptions::with_ratio(up.face_count(), ratio)?;
    opts.backend = Backend::Gpu;
    let faces = if ratio < 1.0 {
        let d = drive(&mut rounds, &up, &opts, &mut |_| {})?;
        up.face_count() - d.removed.iter().sum::<usize>()
    } else {
        up.face_count()
    };
    // The heatmap needs each vertex's distance to the original surface: the positions come back
    // to be measured (the BVH is on the CPU), the mesh that is drawn does not.
    let (errors, max_error) = if mode == Mode::Heatmap {
        let d = crate::parallel::RoundRunner::download(&mut rounds)?;
        let bvh = TriangleBvh::new(mesh);
        let diag = mesh
            .bounds()
            .map_or(1.0, |b| b.diagonal())
            .max(f64::MIN_POSITIVE);
        let errors: Vec<f32> = d
            .positions
            .iter()
            .map(|p| {
                let w = [0, 1, 2].map(|i| p[i] as f64 / up.scale + up.center[i]);
                bvh.closest(w, None)
                    .map_or(0.0, |h| (h.dist2.sqrt() / diag) as f32)
            })
            .collect();
        let max = errors.iter().fold(0f32, |m, &e| m.max(e));
        (errors, max as f64)
    } else {
        (vec![0f32; up.positions.len()], 0.0)
    };
    let error_buf = ctx
        .device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("meshslim.viewer.vertex_error"),
            contents: bytemuck::cast_slice(&errors),
            usage: wgpu::BufferUsages::VERTEX,
        });
    let gpu_mesh = rounds.into_mesh(&up)?;
    let (lo, hi) = up.positions.iter().fold(
        (glam::Vec3::splat(f32::MAX), glam::Vec3::splat(f32::MIN)),
        |(lo, hi), p| {
            let v = glam::Vec3::new(p[0], p[1], p[2]);
            (lo.min(v), hi.max(v))
        },
    );
    let mut cam = Camera {
        model: Camera::upright(hi - lo),
        yaw: 0.35,
        pitch: 0.2,
        ..Camera::default()
    };
    // The normalized frame: centred, bounding-box diagonal 1, so a sphere of radius 0.5 holds it.
    cam.fit(glam::Vec3::ZERO, 0.5, size.0 as f32 / size.1 as f32);
    let rgba = render::render_rgba(
        &ctx.device,
        &ctx.queue,
        &gpu_mesh,
        &error_buf,
        &cam,
        mode,
        max_error as f32,
        size,
    )?;
    Ok(Frame {
        adapter: ctx.adapter_name.clone(),
        faces,
        max_error,
        png: encode_png(&rgba, size)?,
    })
}

/// RGBA8 rows (opaque) to PNG bytes.
pub fn encode_png(rgba: &[u8], (w, h): (u32, u32)) -> Result<Vec<u8>> {
    use resvg::tiny_skia;
    let size = tiny_skia::IntSize::from_wh(w, h)
        .ok_or_else(|| Error::InvalidOption(format!("image size {w}x{h}")))?;
    let pixmap = tiny_skia::Pixmap::from_vec(rgba.to_vec(), size)
        .ok_or_else(|| Error::Internal("frame size does not match its pixels".into()))?;
    pixmap
        .encode_png()
        .map_err(|e| Error::Internal(format!("encoding the PNG: {e}")))
}
