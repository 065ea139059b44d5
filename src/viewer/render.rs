//! Draws [`GpuMesh`]es — the simplifier's own position and index buffers, with the indirect draw
//! arguments its rounds wrote — into a texture: the mesh never goes through the CPU between
//! simplification and the screen. The window shows that texture through egui; a screenshot reads
//! the same texture back, so the PNG is what the window showed.

use super::camera::Camera;
use crate::error::{Error, Result};
use crate::rounds::gpu::GpuMesh;
use glam::Mat4;
use wgpu::util::DeviceExt;

/// What the fragments show.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum Mode {
    /// Lit from the camera (flat, or smooth with per-vertex normals).
    Shaded,
    /// Surface normals as colours.
    Normals,
    /// Per-vertex distance to the original surface, blue (0) to red (the largest).
    Heatmap,
    /// The mesh's texture through its UVs (OBJ with a material's map_Kd).
    Texture,
    /// Each face's smallest angle, red (0 degrees) to blue (60, equilateral): where a mesh
    /// has slivers, before and after remeshing.
    Quality,
    /// The mesh's vertex colours (a painted or photographed scan), lit like `shaded`.
    Color,
    /// A DAG's cut: each cluster in a colour of its own.
    Clusters,
    /// A DAG's cut: each cluster by its level, blue (the input's) to red (the coarsest).
    Levels,
}

impl Mode {
    pub const ALL: [Mode; 8] = [
        Mode::Shaded,
        Mode::Normals,
        Mode::Heatmap,
        Mode::Texture,
        Mode::Quality,
        Mode::Color,
        Mode::Clusters,
        Mode::Levels,
    ];
    pub fn label(self) -> &'static str {
        match self {
            Mode::Shaded => "shaded",
            Mode::Normals => "normals",
            Mode::Heatmap => "error heatmap",
            Mode::Texture => "texture",
            Mode::Quality => "triangle quality",
            Mode::Color => "vertex colour",
            Mode::Clusters => "clusters",
            Mode::Levels => "levels",
        }
    }
}

/// How a frame is drawn, apart from the camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Style {
    pub mode: Mode,
    /// Per-vertex normals instead of flat faces.
    pub smooth: bool,
    /// Edges drawn over the surface (needs the device's line polygons).
    pub wireframe: bool,
    /// The error at the top of the heatmap's ramp (relative to the diagonal).
    pub error_scale: f32,
}

impl Default for Style {
    fn default() -> Self {
        Style {
            mode: Mode::Shaded,
            smooth: false,
            wireframe: false,
            error_scale: 0.0,
        }
    }
}

/// A drawable mesh: the [`GpuMesh`] as the simplifier left it, and extras beside it: one entry
/// per vertex of the GpuMesh, in its order, or per corner for the UVs. A clone shares the
/// GPU buffers (wgpu handles): it uploads and copies nothing.
#[derive(Clone)]
pub struct SceneMesh {
    pub gpu: GpuMesh,
    /// f32 per vertex: distance to the original surface, relative to its diagonal.
    pub error: wgpu::Buffer,
    /// [f32; 3] per vertex: area-weighted normal (zero where unknown: flat shading there).
    pub normals: wgpu::Buffer,
    /// [f32; 2] per corner (3 per face), so that a seam vertex shows each side's own.
    pub uvs: wgpu::Buffer,
    /// RGBA8 (packed in a u32) per corner, as the UVs.
    pub colors: wgpu::Buffer,
    pub vertices: usize,
    pub faces: usize,
    pub has_uvs: bool,
    pub has_colors: bool,
    /// Largest value in `error`.
    pub max_error: f32,
    /// The buffers the vertex shader reads, bound once, on first draw.
    group: std::sync::OnceLock<wgpu::BindGroup>,
    /// A DAG's clusters: per cluster its draw, written by the cut on the device
    /// ([`crate::dag::gpu::GpuCut::draws`]), and how many; the mesh is drawn from these
    /// instead of its own arguments.
    pub cluster_draws: Option<(wgpu::Buffer, u32)>,
    /// A DAG's levels (0 for a mesh): the top of the levels mode's ramp.
    pub levels: u32,
}

/// Extras made on the host: per vertex, except the UVs and colours (per corner).
#[derive(Debug, Clone, Default)]
pub struct Extras {
    pub error: Vec<f32>,
    pub normals: Vec<[f32; 3]>,
    /// Per corner (3 per face).
    pub uvs: Option<Vec<[f32; 2]>>,
    /// Per corner, RGBA8 packed as WGSL's `unpack4x8unorm` reads it ([`pack_color`]).
    pub colors: Option<Vec<u32>>,
}

/// A linear RGBA colour in 0..1 as four bytes in a u32, red in the lowest.
pub fn pack_color(c: [f32; 4]) -> u32 {
    let b = c.map(|x| (x.clamp(0.0, 1.0) * 255.0).round() as u32);
    b[0] | (b[1] << 8) | (b[2] << 16) | (b[3] << 24)
}

impl SceneMesh {
    /// `gpu` with `extras` uploaded beside it; missing extras are zeros.
    pub fn new(
        device: &wgpu::Device,
        gpu: GpuMesh,
        vertices: usize,
        faces: usize,
        extras: &Extras,
    ) -> Result<SceneMesh> {
        // Zeros where the extra is missing.
        let buf = |label: &str, data: &[u8], len: usize| {
            crate::compute::context::checked_buffer_init(
                device,
                label,
                data,
                len,
                wgpu::BufferUsages::STORAGE,
            )
        };
        let max_error = extras.error.iter().fold(0f32, |m, &e| m.max(e));
        let uvs = extras.uvs.as_deref().unwrap_or(&[]);
        let colors = extras.colors.as_deref().unwrap_or(&[]);
        Ok(SceneMesh {
            error: buf(
                "meshslim.viewer.vertex_error",
                bytemuck::cast_slice(&extras.error),
                vertices * 4,
            )?,
            normals: buf(
                "meshslim.viewer.vertex_normals",
                bytemuck::cast_slice(&extras.normals),
                vertices * 12,
            )?,
            // Per corner, the largest extra: only when there are UVs (without, the shader's
            // reads land past the end, which wgpu's bounds checks keep safe, and only the
            // texture mode, unavailable then, would show them).
            uvs: buf(
                "meshslim.viewer.corner_uvs",
                bytemuck::cast_slice(uvs),
                if extras.uvs.is_some() {
                    faces * 3 * 8
                } else {
                    0
                },
            )?,
            colors: buf(
                "meshslim.viewer.corner_colors",
                bytemuck::cast_slice(colors),
                if extras.colors.is_some() {
                    faces * 3 * 4
                } else {
                    0
                },
            )?,
            has_uvs: extras.uvs.is_some(),
            has_colors: extras.colors.is_some(),
            gpu,
            vertices,
            faces,
            max_error,
            group: std::sync::OnceLock::new(),
            cluster_draws: None,
            levels: 0,
        })
    }
}

/// Area-weighted vertex normals of an indexed triangle list (smooth shading).
pub fn vertex_normals(positions: &[[f32; 4]], indices: &[u32]) -> Vec<[f32; 3]> {
    let mut n = vec![glam::Vec3::ZERO; positions.len()];
    let p = |i: u32| glam::Vec4::from(positions[i as usize]).truncate();
    for t in indices.chunks_exact(3) {
        let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
        // The cross product's length is twice the area: the weight comes with it.
        let f = (b - a).cross(c - a);
        for &v in t {
            n[v as usize] += f;
        }
    }
    n.into_iter()
        .map(|v| v.normalize_or_zero().to_array())
        .collect()
}

/// Keep in sync with `View` in shaders/viewer/mesh.wgsl.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ViewUniform {
    view_proj: [[f32; 4]; 4],
    eye: [f32; 4],
    mode: [f32; 4],
}

/// Each instance's uniform sits at a multiple of this (the dynamic-offset alignment wgpu
/// guarantees on every device).
const SLOT: u64 = 256;

pub const SHADER: &str = include_str!("../../shaders/viewer/mesh.wgsl");
pub const DEPTH: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// The colour of the frames: stored as the shader writes it, which is also how egui 0.37 reads
/// a texture (gamma-encoded), so the window and a PNG show the same values.
pub const COLOR: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// A colour and a depth texture to draw into.
pub struct Target {
    pub color: wgpu::Texture,
    pub color_view: wgpu::TextureView,
    depth_view: wgpu::TextureView,
    pub size: (u32, u32),
}

impl Target {
    pub fn new(device: &wgpu::Device, (width, height): (u32, u32)) -> Result<Target> {
        let max = device.limits().max_texture_dimension_2d;
        if width == 0 || height == 0 || width > max || height > max {
            return Err(Error::InvalidOption(format!(
                "image size {width}x{height}: each side must be 1..={max} on this device"
            )));
        }
        let scope = crate::compute::gpu::ErrorScope::push(device);
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
            COLOR,
            wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::COPY_SRC
                | wgpu::TextureUsages::TEXTURE_BINDING,
        );
        let depth = texture(
            "meshslim.viewer.depth",
            DEPTH,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        );
        let target = Target {
            color_view: color.create_view(&Default::default()),
            depth_view: depth.create_view(&Default::default()),
            color,
            size: (width, height),
        };
        scope.check("making a view's image")?;
        Ok(target)
    }

    /// The pixels as RGBA8 rows (waits for the GPU); the device's errors on the way are this
    /// call's error.
    pub fn read_rgba(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<Vec<u8>> {
        let scope = crate::compute::gpu::ErrorScope::push(device);
        let rgba = self.copy_rgba(device, queue);
        scope.check_with("reading the frame", rgba)
    }

    fn copy_rgba(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<Vec<u8>> {
        let (width, height) = self.size;
        // Rows of a texture copy are padded to 256 bytes.
        let row = (width * 4).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("meshslim.viewer.readback"),
            size: row as u64 * height as u64,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut enc = device.create_command_encoder(&Default::default());
        enc.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture: &self.color,
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
            wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
        );
        queue.submit([enc.finish()]);
        crate::compute::context::map_and_wait(device, &readback)
            .0
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
}

/// Storage buffers of one mesh the vertex shader reads (group 2 of shaders/viewer/mesh.wgsl).
const MESH_BINDINGS: u32 = 6;

/// The mesh pipelines (fill, and wireframe where the device draws line polygons) and the
/// per-instance uniforms.
pub struct Renderer {
    fill: wgpu::RenderPipeline,
    wire: Option<wgpu::RenderPipeline>,
    view_layout: wgpu::BindGroupLayout,
    texture_layout: wgpu::BindGroupLayout,
    mesh_layout: wgpu::BindGroupLayout,
    slots: wgpu::Buffer,
    slot_count: u64,
    view_group: wgpu::BindGroup,
    texture_group: wgpu::BindGroup,
    has_texture: bool,
}

impl Renderer {
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue) -> Renderer {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("meshslim.viewer.mesh"),
            source: wgpu::ShaderSource::Wgsl(SHADER.into()),
        });
        let view_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("meshslim.viewer.view"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: true,
                    min_binding_size: wgpu::BufferSize::new(
                        std::mem::size_of::<ViewUniform>() as u64
                    ),
                },
                count: None,
            }],
        });
        let texture_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("meshslim.viewer.albedo"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
            ],
        });
        // The GpuMesh's indices and positions as the simplifier wrote them, then the extras:
        // read by the vertex shader, one invocation per corner.
        let mesh_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("meshslim.viewer.mesh_buffers"),
            entries: &(0..MESH_BINDINGS)
                .map(|binding| wgpu::BindGroupLayoutEntry {
                    binding,
                    visibility: wgpu::ShaderStages::VERTEX,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Storage { read_only: true },
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                })
                .collect::<Vec<_>>(),
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("meshslim.viewer.mesh"),
            bind_group_layouts: &[
                Some(&view_layout),
                Some(&texture_layout),
                Some(&mesh_layout),
            ],
            immediate_size: 0,
        });
        let pipeline = |label: &str, fs: &str, line: bool| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(&layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs_main"),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: wgpu::PrimitiveState {
                    polygon_mode: if line {
                        wgpu::PolygonMode::Line
                    } else {
                        wgpu::PolygonMode::Fill
                    },
                    ..Default::default()
                },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: DEPTH,
                    depth_write_enabled: Some(!line),
                    depth_compare: Some(wgpu::CompareFunction::LessEqual),
                    stencil: Default::default(),
                    // The surface is pushed back a little so that the wireframe's lines, drawn
                    // at the true depth, are not hidden by the faces they bound.
                    bias: if line {
                        Default::default()
                    } else {
                        wgpu::DepthBiasState {
                            constant: 2,
                            slope_scale: 1.0,
                            clamp: 0.0,
                        }
                    },
                }),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(fs),
                    compilation_options: Default::default(),
                    targets: &[Some(COLOR.into())],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let fill = pipeline("meshslim.viewer.mesh", "fs_main", false);
        let wire = device
            .features()
            .contains(wgpu::Features::POLYGON_MODE_LINE)
            .then(|| pipeline("meshslim.viewer.wireframe", "fs_wire", true));
        let slot_count = 4;
        let slots = Self::slot_buffer(device, slot_count);
        let view_group = Self::view_group(device, &view_layout, &slots);
        let white = Self::texture_group_for(device, queue, &texture_layout, None);
        Renderer {
            fill,
            wire,
            view_layout,
            texture_layout,
            mesh_layout,
            view_group,
            slots,
            slot_count,
            texture_group: white,
            has_texture: false,
        }
    }

    /// Whether the device draws the wireframe overlay (line polygons).
    pub fn has_wireframe(&self) -> bool {
        self.wire.is_some()
    }

    pub fn has_texture(&self) -> bool {
        self.has_texture
    }

    /// The texture for [`Mode::Texture`]: RGBA8 rows of `size`, or none (white).
    pub fn set_texture(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        image: Option<(&[u8], (u32, u32))>,
    ) {
        self.has_texture = image.is_some();
        self.texture_group = Self::texture_group_for(device, queue, &self.texture_layout, image);
    }

    fn texture_group_for(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        layout: &wgpu::BindGroupLayout,
        image: Option<(&[u8], (u32, u32))>,
    ) -> wgpu::BindGroup {
        let white = [255u8; 4];
        let (rgba, (w, h)) = image.unwrap_or((&white[..], (1, 1)));
        let size = wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        };
        let desc = wgpu::TextureDescriptor {
            label: Some("meshslim.viewer.albedo"),
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            // The image's bytes are sRGB: sampled as such they light in linear terms, and are
            // written out as the shader returns them.
            format: wgpu::TextureFormat::Rgba8Unorm,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        };
        let texture = device.create_texture_with_data(
            queue,
            &desc,
            wgpu::util::TextureDataOrder::LayerMajor,
            rgba,
        );
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("meshslim.viewer.albedo"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::Repeat,
            ..Default::default()
        });
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("meshslim.viewer.albedo"),
            layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(
                        &texture.create_view(&Default::default()),
                    ),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::Sampler(&sampler),
                },
            ],
        })
    }

    fn slot_buffer(device: &wgpu::Device, count: u64) -> wgpu::Buffer {
        device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("meshslim.viewer.view"),
            size: count * SLOT,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        })
    }

    fn view_group(
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        slots: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("meshslim.viewer.view"),
            layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: slots,
                    offset: 0,
                    size: wgpu::BufferSize::new(std::mem::size_of::<ViewUniform>() as u64),
                }),
            }],
        })
    }

    /// Records one pass into `target`: clears it, then draws each `(mesh, placement)` with the
    /// mesh's indirect arguments — the counts the simplifier's last round wrote.
    #[allow(clippy::too_many_arguments)]
    pub fn draw(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        enc: &mut wgpu::CommandEncoder,
        target: &Target,
        camera: &Camera,
        style: &Style,
        items: &[(&SceneMesh, Mat4)],
    ) {
        let n = items.len().max(1) as u64;
        if n > self.slot_count {
            self.slot_count = n.next_power_of_two();
            self.slots = Self::slot_buffer(device, self.slot_count);
            self.view_group = Self::view_group(device, &self.view_layout, &self.slots);
        }
        let aspect = target.size.0 as f32 / target.size.1 as f32;
        // Each item's matrix places it in the world (the camera's model turn included).
        let view_proj = camera.proj_view(aspect);
        let eye = camera.eye();
        let mut bytes = vec![0u8; (n * SLOT) as usize];
        for (i, (mesh, model)) in items.iter().enumerate() {
            let u = ViewUniform {
                view_proj: (view_proj * *model).to_cols_array_2d(),
                eye: model.inverse().transform_point3(eye).extend(1.0).to_array(),
                mode: [
                    style.mode as u32 as f32,
                    style.error_scale,
                    style.smooth as u32 as f32,
                    mesh.levels.saturating_sub(1) as f32,
                ],
            };
            let at = i * SLOT as usize;
            bytes[at..at + std::mem::size_of::<ViewUniform>()]
                .copy_from_slice(bytemuck::bytes_of(&u));
        }
        queue.write_buffer(&self.slots, 0, &bytes);
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("meshslim.viewer.mesh"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &target.color_view,
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
                view: &target.depth_view,
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
        pass.set_bind_group(1, &self.texture_group, &[]);
        let wire = self.wire.as_ref().filter(|_| style.wireframe);
        for pipeline in std::iter::once(&self.fill).chain(wire) {
            pass.set_pipeline(pipeline);
            for (i, (mesh, _)) in items.iter().enumerate() {
                pass.set_bind_group(0, &self.view_group, &[(i as u64 * SLOT) as u32]);
                let group = mesh.group.get_or_init(|| {
                    let buffers = [
                        &mesh.gpu.indices,
                        &mesh.gpu.positions,
                        &mesh.error,
                        &mesh.normals,
                        &mesh.uvs,
                        &mesh.colors,
                    ];
                    device.create_bind_group(&wgpu::BindGroupDescriptor {
                        label: Some("meshslim.viewer.mesh_buffers"),
                        layout: &self.mesh_layout,
                        entries: &buffers
                            .iter()
                            .enumerate()
                            .map(|(i, b)| wgpu::BindGroupEntry {
                                binding: i as u32,
                                resource: b.as_entire_binding(),
                            })
                            .collect::<Vec<_>>(),
                    })
                });
                pass.set_bind_group(2, group, &[]);
                // Not indexed: the vertex shader reads the index buffer itself, one invocation
                // per corner. The simplifier's indexed arguments serve as they are: their first
                // four words (index count, instances, first index 0, base vertex 0) read as
                // (vertex count, instances, first vertex, first instance).
                match &mesh.cluster_draws {
                    // A DAG: one draw per cluster, those out of the cut with no instance.
                    Some((draws, n)) => pass.multi_draw_indirect(draws, 0, *n),
                    None => pass.draw_indirect(&mesh.gpu.draw_args, 0),
                }
            }
        }
    }
}

/// Renders one frame of `size` offscreen and returns it as RGBA8 rows.
pub fn render_rgba(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    renderer: &mut Renderer,
    items: &[(&SceneMesh, Mat4)],
    camera: &Camera,
    style: &Style,
    size: (u32, u32),
) -> Result<Vec<u8>> {
    let target = Target::new(device, size)?;
    let mut enc = device.create_command_encoder(&Default::default());
    renderer.draw(device, queue, &mut enc, &target, camera, style, items);
    queue.submit([enc.finish()]);
    target.read_rgba(device, queue)
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

    #[test]
    fn vertex_normals_of_a_flat_square_point_up() {
        let p = [
            [0.0, 0.0, 0.0, 1.0],
            [1.0, 0.0, 0.0, 1.0],
            [1.0, 1.0, 0.0, 1.0],
            [0.0, 1.0, 0.0, 1.0],
        ];
        let n = super::vertex_normals(&p, &[0, 1, 2, 0, 2, 3]);
        for v in n {
            assert!((glam::Vec3::from(v) - glam::Vec3::Z).length() < 1e-6);
        }
    }
}
