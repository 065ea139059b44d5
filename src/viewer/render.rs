//! Draws a [`GpuMesh`] — the simplifier's own position and index buffers, with the indirect draw
//! arguments its last round wrote — into a texture: the mesh never goes through the CPU between
//! simplification and the screen.

use super::camera::Camera;
use crate::error::{Error, Result};
use crate::gpu::GpuMesh;

/// What the fragments show.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Mode {
    /// Flat shading, lit from the camera.
    Shaded,
    /// Face normals as colours.
    Normals,
    /// Per-vertex distance to the original surface, blue (0) to red (the largest).
    Heatmap,
}

/// Keep in sync with `View` in shaders/viewer/mesh.wgsl.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ViewUniform {
    view_proj: [[f32; 4]; 4],
    eye: [f32; 4],
    mode: [f32; 4],
}

pub const SHADER: &str = include_str!("../../shaders/viewer/mesh.wgsl");
pub const DEPTH: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// The mesh pipeline for one colour format.
pub struct Renderer {
    pipeline: wgpu::RenderPipeline,
    uniform: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
}

impl Renderer {
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> Renderer {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("meshslim.viewer.mesh"),
            source: wgpu::ShaderSource::Wgsl(SHADER.into()),
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("meshslim.viewer.mesh"),
            layout: None,
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[
                    // GpuMesh positions: vec4 per vertex, as the simplifier writes them.
                    Some(wgpu::VertexBufferLayout {
                        array_stride: 16,
                        step_mode: wgpu::VertexStepMode::Vertex,
                        attributes: &wgpu::vertex_attr_array![0 => Float32x4],
                    }),
                    Some(wgpu::VertexBufferLayout {
                        array_stride: 4,
                        step_mode: wgpu::VertexStepMode::Vertex,
                        attributes: &wgpu::vertex_attr_array![1 => Float32],
                    }),
                ],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(format.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        let uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("meshslim.viewer.view"),
            size: std::mem::size_of::<ViewUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("meshslim.viewer.view"),
            layout: &pipeline.get_bind_group_layout(0),
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: uniform.as_entire_binding(),
            }],
        });
        Renderer {
            pipeline,
            uniform,
            bind_group,
        }
    }

    /// Records the draw: clears `color` and `depth`, draws `mesh` with its indirect arguments.
    /// `vertex_error` holds one f32 per vertex (the heatmap), at least as long as the mesh.
    #[allow(clippy::too_many_arguments)]
    pub fn draw(
        &self,
        queue: &wgpu::Queue,
        enc: &mut wgpu::CommandEncoder,
        color: &wgpu::TextureView,
        depth: &wgpu::TextureView,
        mesh: &GpuMesh,
        vertex_error: &wgpu::Buffer,
        camera: &Camera,
        aspect: f32,
        mode: Mode,
        error_scale: f32,
    ) {
        let u = ViewUniform {
            view_proj: camera.view_proj(aspect).to_cols_array_2d(),
            eye: camera.eye().extend(1.0).to_array(),
            mode: [mode as u32 as f32, error_scale, 0.0, 0.0],
        };
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&u));
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("meshslim.viewer.mesh"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: color,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color {
                        r: 0.11,
                        g: 0.12,
                        b: 0.14,
                        a: 1.0,
                    }),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.bind_group, &[]);
        pass.set_vertex_buffer(0, mesh.positions.slice(..));
        pass.set_vertex_buffer(1, vertex_error.slice(..));
        pass.set_index_buffer(mesh.indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed_indirect(&mesh.draw_args, 0);
    }
}

/// Renders one frame of `width` × `height` offscreen and returns it as RGBA8 rows.
#[allow(clippy::too_many_arguments)]
pub fn render_rgba(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    mesh: &GpuMesh,
    vertex_error: &wgpu::Buffer,
    camera: &Camera,
    mode: Mode,
    error_scale: f32,
    (width, height): (u32, u32),
) -> Result<Vec<u8>> {
    let max = device.limits().max_texture_dimension_2d;
    if width == 0 || height == 0 || width > max || height > max {
        return Err(Error::InvalidOption(format!(
            "image size {width}x{height}: each side must be 1..={max} on this device"
        )));
    }
    let format = wgpu::TextureFormat::Rgba8Unorm;
    let size = wgpu::Extent3d {
        width,
        height,
        depth_or_array_layers: 1,
    };
    let texture = |label, format, usage| {
        device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        })
    };
    let color = texture(
        "meshslim.viewer.color",
        format,
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
    );
    let depth = texture(
        "meshslim.viewer.depth",
        DEPTH,
        wgpu::TextureUsages::RENDER_ATTACHMENT,
    );
    let renderer = Renderer::new(device, format);
    // Rows of a texture copy are padded to 256 bytes.
    let row = (width * 4).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("meshslim.viewer.readback"),
        size: row as u64 * height as u64,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut enc = device.create_command_encoder(&Default::default());
    let cv = color.create_view(&Default::default());
    let dv = depth.create_view(&Default::default());
    let aspect = width as f32 / height as f32;
    renderer.draw(
        queue,
        &mut enc,
        &cv,
        &dv,
        mesh,
        vertex_error,
        camera,
        aspect,
        mode,
        error_scale,
    );
    enc.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo {
            texture: &color,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        wgpu::TexelCopyBufferInfo {
            buffer: &readback,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row),
                rows_per_image: Some(height),
            },
        },
        size,
    );
    queue.submit([enc.finish()]);
    let (tx, rx) = std::sync::mpsc::channel();
    readback.map_async(wgpu::MapMode::Read, .., move |r| {
        let _ = tx.send(r);
    });
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| Error::Gpu(format!("waiting for the frame: {e}")))?;
    rx.recv()
        .map_err(|_| Error::Gpu("the device dropped the frame".into()))?
        .map_err(|e| Error::Gpu(format!("reading the frame: {e}")))?;
    let view = readback
        .get_mapped_range(..)
        .map_err(|e| Error::Gpu(format!("reading the frame: {e}")))?;
    let mut rgba = Vec::with_capacity((width * height * 4) as usize);
    for y in 0..height as usize {
        let start = y * row as usize;
        rgba.extend_from_slice(&view[start..start + width as usize * 4]);
    }
    drop(view);
    readback.unmap();
    Ok(rgba)
}

#[cfg(test)]
mod tests {
    #[test]
    fn mesh_shader_parses_and_validates() {
        let module = naga::front::wgsl::parse_str(super::SHADER)
            .unwrap_or_else(|e| panic!("{}", e.emit_to_string(super::SHADER)));
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::empty(),
        )
        .validate(&module)
        .expect("shaders/viewer/mesh.wgsl validates");
        let (_, view) = module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some("View"))
            .expect("struct View");
        assert_eq!(
            view.inner.size(module.to_ctx()) as usize,
            std::mem::size_of::<super::ViewUniform>()
        );
    }
}
