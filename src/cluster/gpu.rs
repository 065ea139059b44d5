//! `--method cluster` on the gpu backend: one clustering build at a given grid as WGSL compute
//! passes (described in `gpu_schedule.rs`, twinned in tests/cluster_twins): cell keys, a stable LSD
//! radix sort of (key, vertex), the cells, one gathered quadric and placed vertex per cell, and the
//! faces between three cells with exact repeats dropped. The mesh is uploaded once with its
//! vertex→face lists and face planes ([`GpuClusterMesh::new`]); each build then records every pass
//! in one command buffer and reads back two counts, then the result.

use crate::cluster::gpu_schedule::{
    self as sched, ClusterBuf, ClusterCount, ClusterGrid, ClusterStage, ClusterStep,
};
use crate::cluster::grid::CellGrid;
use crate::cluster::stages::{Placed, Placement};
use crate::compute::common::xyz;
use crate::compute::context::{STORAGE, UNIFORM};
use crate::compute::context::{checked_buffer, checked_buffer_init};
use crate::compute::gpu::{ErrorScope, Groups, Kernels, Pipelines, Runner};
use crate::compute::types::*;
use crate::error::{Error, Result};
use crate::rounds::gpu::GpuMesh;
use crate::rounds::gpu::simplifier::{DRAW_ARGS_USAGE, MESH_USAGE};
use std::collections::HashMap;
use std::time::Instant;

/// Radix passes at most: 32-bit keys, 8 bits a pass.
const MAX_PASSES: usize = 4;

/// The clustering stages' pipelines, made once per device.
pub struct GpuClusterer {
    pub(super) device: wgpu::Device,
    pub(super) queue: wgpu::Queue,
    kernels: Kernels,
    /// Seconds spent compiling the shaders.
    pub pipeline_seconds: f64,
}

impl GpuClusterer {
    /// Compiles every stage of [`sched::STAGES`] on `device` (borrowed: a viewer or the rounds
    /// may share it), with a cache of its own.
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue) -> Result<GpuClusterer> {
        GpuClusterer::on(&Pipelines::new(device), queue)
    }

    /// Every stage from the device's pipeline `cache`: those the rounds share with it (prefix
    /// sum, adjacency, face planes) are not compiled again.
    pub fn on(cache: &Pipelines, queue: &wgpu::Queue) -> Result<GpuClusterer> {
        let device = cache.device();
        let kernels = Kernels::new(cache, sched::STAGES, "clustering")?;
        Ok(GpuClusterer {
            device: device.clone(),
            queue: queue.clone(),
            pipeline_seconds: kernels.seconds,
            kernels,
        })
    }
}

/// The process's clustering pipelines on the shared device
/// ([`crate::rounds::gpu::shared_context`]), made on first use.
pub fn shared() -> Result<&'static GpuClusterer> {
    static CLUSTERER: std::sync::OnceLock<std::result::Result<GpuClusterer, String>> =
        std::sync::OnceLock::new();
    let ctx = crate::rounds::gpu::shared_context()?;
    CLUSTERER
        .get_or_init(|| GpuClusterer::on(&ctx.pipelines, &ctx.queue).map_err(|e| e.to_string()))
        .as_ref()
        .map_err(|e| Error::Gpu(e.trim_start_matches("GPU: ").to_string()))
}

/// A part of a build, recorded on its own (the tests read the buffers after each).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Part {
    Keys,
    /// Radix pass `n`; the halves swap after it.
    SortPass(u32),
    Cells,
    Quadrics,
    Faces,
}

/// The mesh on the GPU with its vertex→face lists and face planes, and every working buffer of
/// a build.
pub struct GpuClusterMesh<'a> {
    pub(super) sim: &'a GpuClusterer,
    pub(super) nv: usize,
    nf: usize,
    any_locked: bool,
    pub(super) cluster: ClusterParams,
    /// The half holding the sort's current keys and values.
    cur: usize,
    /// The radix pass a [`ClusterBuf::Radix`] binding takes.
    pass: usize,
    halves: [[wgpu::Buffer; 2]; 2],
    radix: Vec<wgpu::Buffer>,
    scans: [wgpu::Buffer; 3],
    /// The build's buffers; the floating cells' are added on their first build
    /// (`floating_gpu.rs`).
    pub(super) bufs: HashMap<ClusterBuf, wgpu::Buffer>,
    /// The floating cells' uniforms, one per round slot ([`ClusterBuf::Floating`]), empty until their
    /// first build.
    pub(super) floats: Vec<wgpu::Buffer>,
    /// The round slot a [`ClusterBuf::Floating`] binding takes.
    pub(super) slot: usize,
    /// Whether the floating cells' rank order has been sorted (once per mesh).
    pub(super) ranked: bool,
    /// The last build's cells and kept faces, and its grid.
    built: Option<(u32, u32)>,
    grid: Option<CellGrid>,
    /// Upload, vertex→face lists and face planes: seconds.
    pub setup_seconds: f64,
}

impl<'a> GpuClusterMesh<'a> {
    /// Uploads the mesh, allocates the build's buffers (checked against the device's limits)
    /// and builds the vertex→face lists and face planes.
    pub fn new(
        sim: &'a GpuClusterer,
        positions: &[[f32; 4]],
        faces: &[[u32; 3]],
        locked: &[bool],
    ) -> Result<GpuClusterMesh<'a>> {
        assert_eq!(positions.len(), locked.len(), "a locked flag per vertex");
        let t = Instant::now();
        let dev = &sim.device;
        let scope = ErrorScope::push(dev);
        let (nv, nf) = (positions.len(), faces.len());
        let (v, f) = (nv as u64, nf as u64);
        let blocks = (nv as u32).div_ceil(SORT_BLOCK) as u64;
        let mk = |label: &str, size: u64, usage| {
            checked_buffer(dev, &format!("meshslim.{label}"), size, usage)
        };
        let init = |label: &str, data: &[u8]| {
            checked_buffer_init(dev, &format!("meshslim.{label}"), data, data.len(), STORAGE)
        };
        let locked_u32: Vec<u32> = locked.iter().map(|&l| l as u32).collect();
        let mut bufs = HashMap::new();
        for (buf, label, size, usage) in buffer_sizes(v, f, blocks) {
            bufs.insert(buf, mk(label, size, usage)?);
        }
        bufs.insert(
            ClusterBuf::Positions,
            init("positions", bytemuck::cast_slice(positions))?,
        );
        bufs.insert(
            ClusterBuf::Indices,
            init("indices", bytemuck::cast_slice(faces))?,
        );
        bufs.insert(
            ClusterBuf::Locked,
            init("locked", bytemuck::cast_slice(&locked_u32))?,
        );
        let half = |s: &str| -> Result<[wgpu::Buffer; 2]> {
            Ok([
                mk(&format!("sort_keys{s}"), 4 * v, STORAGE)?,
                mk(&format!("sort_vals{s}"), 4 * v, STORAGE)?,
            ])
        };
        let halves = [half("")?, half("_out")?];
        let radix = (0..MAX_PASSES)
            .map(|p| mk(&format!("radix{p}"), 16, UNIFORM))
            .collect::<Result<Vec<_>>>()?;
        let scans = [
            mk("scan_v", 16, UNIFORM)?,
            mk("scan_f", 16, UNIFORM)?,
            mk("scan_d", 16, UNIFORM)?,
        ];
        write_params(
            &sim.queue,
            &scans,
            &bufs[&ClusterBuf::Params],
            &radix,
            (nv, nf),
        );
        let mut m = GpuClusterMesh {
            sim,
            nv,
            nf,
            any_locked: locked.contains(&true),
            cluster: ClusterParams::default(),
            cur: 0,
            pass: 0,
            halves,
            radix,
            scans,
            bufs,
            built: None,
            grid: None,
            floats: Vec::new(),
            slot: 0,
            ranked: false,
            setup_seconds: 0.0,
        };
        let mut enc = dev.create_command_encoder(&Default::default());
        m.record(&mut enc, sched::ADJACENCY);
        m.record(&mut enc, sched::PLANES);
        sim.queue.submit([enc.finish()]);
        scope.check("uploading the mesh for clustering")?;
        m.setup_seconds = t.elapsed().as_secs_f64();
        Ok(m)
    }

    /// Sets the grid of the next build (and rewinds the sort to `cell_keys`' half).
    pub fn set_grid(&mut self, grid: &CellGrid) {
        self.cluster = sched::cluster_params(grid, self.nv, self.nf);
        self.cur = 0;
        let c = &self.bufs[&ClusterBuf::Cluster];
        self.sim
            .queue
            .write_buffer(c, 0, bytemuck::bytes_of(&self.cluster));
    }

    /// The uniform of the current grid (the twins take it).
    pub fn cluster_params(&self) -> ClusterParams {
        self.cluster
    }

    /// Radix passes the current grid's keys need.
    pub fn passes(&self) -> u32 {
        sched::radix_passes(&self.cluster, self.any_locked)
    }

    /// Records `part` into `enc`.
    pub(super) fn record_part(&mut self, enc: &mut wgpu::CommandEncoder, part: Part) {
        match part {
            Part::Keys => self.record(enc, sched::KEYS),
            Part::SortPass(p) => {
                self.pass = p as usize;
                self.record(enc, sched::SORT_PASS);
                self.cur = 1 - self.cur;
            }
            Part::Cells => self.record(enc, sched::CELLS),
            Part::Quadrics => self.record(enc, sched::QUADRICS),
            Part::Faces => self.record(enc, sched::FACES),
        }
    }

    /// Runs one part alone and waits for it (after [`Self::set_grid`]).
    pub fn run_part(&mut self, part: Part) -> Result<()> {
        let scope = ErrorScope::push(&self.sim.device);
        let mut enc = self.sim.device.create_command_encoder(&Default::default());
        self.record_part(&mut enc, part);
        self.sim.queue.submit([enc.finish()]);
        scope.check_with("running a clustering stage", self.wait())
    }

    /// Runs `steps` alone and waits for them (after [`Self::set_grid`] and the parts they
    /// read): what examples/cluster_gpu_stages.rs times stage by stage.
    pub fn run_steps(&mut self, steps: &[ClusterStep]) -> Result<()> {
        let scope = ErrorScope::push(&self.sim.device);
        let mut enc = self.sim.device.create_command_encoder(&Default::default());
        self.record(&mut enc, steps);
        self.sim.queue.submit([enc.finish()]);
        scope.check_with("running clustering steps", self.wait())
    }

    pub(super) fn wait(&self) -> Result<()> {
        self.sim
            .device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(|e| Error::Gpu(format!("waiting for the device: {e}")))
    }

    /// One clustering at `grid`: every pass in one command buffer, then the result read back.
    pub fn build(&mut self, grid: &CellGrid) -> Result<ClusterBuild> {
        let scope = ErrorScope::push(&self.sim.device);
        self.set_grid(grid);
        let mut enc = self
            .sim
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("meshslim.cluster_build"),
            });
        self.record_part(&mut enc, Part::Keys);
        for p in 0..self.passes() {
            self.record_part(&mut enc, Part::SortPass(p));
        }
        for part in [Part::Cells, Part::Quadrics, Part::Faces] {
            self.record_part(&mut enc, part);
        }
        self.sim.queue.submit([enc.finish()]);
        let b = scope.check_with("clustering on the GPU", self.read_build())?;
        self.grid = Some(*grid);
        Ok(b)
    }

    /// The result of the build just submitted: the counts, then the clusters, the faces and
    /// each vertex's cluster.
    pub(super) fn read_build(&mut self) -> Result<ClusterBuild> {
        let (nv, nf) = (self.nv as u64, self.nf as u64);
        let counts = self.read_many(&[
            (ClusterBuf::CellHead, 4 * nv, 4),
            (ClusterBuf::FaceKeep, 4 * nf, 4),
        ])?;
        let cells = u32::from_le_bytes(counts[0][..4].try_into().unwrap_or_default()) as u64;
        let kept = u32::from_le_bytes(counts[1][..4].try_into().unwrap_or_default()) as u64;
        assert!(cells <= nv && kept <= nf, "counts within their buffers");
        // The grid is the uniform build's to set (a floating build has none).
        self.built = Some((cells as u32, kept as u32));
        self.grid = None;
        let data = self.read_many(&[
            (ClusterBuf::ClusterPlaced, 0, 32 * cells),
            (ClusterBuf::ClusterQuadric, 0, 48 * cells),
            (ClusterBuf::ClusterFaces, 0, 12 * kept),
            (ClusterBuf::FaceOrigin, 0, 4 * kept),
            (ClusterBuf::VertexCell, 0, 4 * nv),
        ])?;
        let pod = |i: usize| -> &[u8] { &data[i] };
        Ok(ClusterBuild::from_buffers(
            &bytemuck::pod_collect_to_vec::<u8, ClusterPlaced>(pod(0)),
            &bytemuck::pod_collect_to_vec::<u8, Quadric>(pod(1)),
            &bytemuck::pod_collect_to_vec::<u8, u32>(pod(2)),
            &bytemuck::pod_collect_to_vec::<u8, u32>(pod(3)),
            bytemuck::pod_collect_to_vec::<u8, u32>(pod(4)),
        ))
    }

    /// The grid of the last build.
    pub fn last_grid(&self) -> Option<CellGrid> {
        self.grid
    }

    /// The last build's result as a mesh a renderer draws, made on the device (`cluster_mesh`
    /// writes the clusters' vertices; the compacted faces are the index buffer): it shares this
    /// mesh's buffers, so the next build rewrites it. `center` and `scale` are the frame.
    pub fn drawable(&mut self, center: [f64; 3], scale: f64) -> Result<GpuMesh> {
        let (_, kept) = self
            .built
            .ok_or_else(|| Error::Internal("a drawable clustering before any build".into()))?;
        let scope = ErrorScope::push(&self.sim.device);
        let mut enc = self.sim.device.create_command_encoder(&Default::default());
        self.record(&mut enc, sched::DRAWABLE);
        self.sim.queue.submit([enc.finish()]);
        let args = DrawArgs {
            index_count: 3 * kept,
            instance_count: 1,
            ..Default::default()
        };
        let draw_args = checked_buffer_init(
            &self.sim.device,
            "meshslim.cluster.draw_args",
            bytemuck::bytes_of(&args),
            std::mem::size_of::<DrawArgs>(),
            DRAW_ARGS_USAGE,
        )?;
        scope.check("making the clustering drawable")?;
        Ok(GpuMesh {
            positions: self.bufs[&ClusterBuf::MeshPositions].clone(),
            indices: self.bufs[&ClusterBuf::ClusterFaces].clone(),
            draw_args,
            center,
            scale,
        })
    }

    pub(super) fn record(&mut self, enc: &mut wgpu::CommandEncoder, steps: &[ClusterStep]) {
        crate::compute::gpu::record(self, enc, steps)
    }

    fn count(&self, c: ClusterCount) -> u32 {
        match c {
            ClusterCount::Vertices => self.nv as u32,
            ClusterCount::Faces => self.nf as u32,
            ClusterCount::Digits => 256 * (self.nv as u32).div_ceil(SORT_BLOCK),
        }
    }

    /// The first `bytes` of a working buffer as the schedule names it (the sort's names as the
    /// halves stand now): what the tests diff against the twins.
    pub fn read_buffer(&self, buf: ClusterBuf, bytes: u64) -> Result<Vec<u8>> {
        Ok(self.read_many(&[(buf, 0, bytes)])?.remove(0))
    }

    /// `(buffer, byte offset, bytes)` ranges read back through one staging buffer, one wait.
    pub(super) fn read_many(&self, ranges: &[(ClusterBuf, u64, u64)]) -> Result<Vec<Vec<u8>>> {
        let ranges: Vec<(&wgpu::Buffer, u64, u64)> = ranges
            .iter()
            .map(|&(buf, offset, bytes)| (self.buffer(buf, None), offset, bytes))
            .collect();
        crate::compute::context::read_ranges(
            &self.sim.device,
            &self.sim.queue,
            &ranges,
            "reading back the clustering",
        )
    }
}

/// The build's working buffers, each with its label, size in bytes and usage, for `v`
/// vertices, `f` faces and `blocks` radix-sort blocks.
fn buffer_sizes(
    v: u64,
    f: u64,
    blocks: u64,
) -> Vec<(ClusterBuf, &'static str, u64, wgpu::BufferUsages)> {
    let longest_scan = (256 * blocks + 1).max(v + 1).max(f + 1);
    vec![
        (ClusterBuf::Cluster, "cluster", 48, UNIFORM),
        (
            ClusterBuf::Params,
            "params",
            std::mem::size_of::<Params>() as u64,
            UNIFORM,
        ),
        (
            ClusterBuf::BlockSums,
            "block_sums",
            4 * (longest_scan.div_ceil(1024) + 1),
            STORAGE,
        ),
        (
            ClusterBuf::DigitCounts,
            "digit_counts",
            4 * (256 * blocks + 1),
            STORAGE,
        ),
        (ClusterBuf::CellHead, "cell_head", 4 * (v + 1), STORAGE),
        (ClusterBuf::CellStart, "cell_start", 4 * (v + 1), STORAGE),
        (ClusterBuf::VertexCell, "vertex_cell", 4 * v, STORAGE),
        (ClusterBuf::CellKey, "cell_key", 4 * v, STORAGE),
        (ClusterBuf::Offsets, "offsets", 4 * (v + 1), STORAGE),
        (ClusterBuf::Cursor, "cursor", 4 * v, STORAGE),
        (ClusterBuf::VertexFaces, "vertex_faces", 12 * f, STORAGE),
        (ClusterBuf::FaceNormals, "face_normals", 16 * f, STORAGE),
        (ClusterBuf::ClusterPlaced, "cluster_placed", 32 * v, STORAGE),
        (
            ClusterBuf::ClusterQuadric,
            "cluster_quadric",
            48 * v,
            STORAGE,
        ),
        (ClusterBuf::FaceKey, "face_key", 12 * f, STORAGE),
        (ClusterBuf::FaceKeep, "face_keep", 4 * (f + 1), STORAGE),
        (
            ClusterBuf::BucketOffsets,
            "bucket_offsets",
            4 * (v + 1),
            STORAGE,
        ),
        (ClusterBuf::BucketCursor, "bucket_cursor", 4 * v, STORAGE),
        (ClusterBuf::BucketFaces, "bucket_faces", 4 * f, STORAGE),
        (
            ClusterBuf::ClusterFaces,
            "cluster_faces",
            12 * f,
            MESH_USAGE,
        ),
        (
            ClusterBuf::MeshPositions,
            "mesh_positions",
            16 * v,
            MESH_USAGE,
        ),
        (ClusterBuf::FaceOrigin, "face_origin", 4 * f, STORAGE),
    ]
}

/// The prefix sums' counts, the mesh's counts and each radix pass's parameters, written once.
fn write_params(
    q: &wgpu::Queue,
    scans: &[wgpu::Buffer; 3],
    params_buf: &wgpu::Buffer,
    radix: &[wgpu::Buffer],
    (nv, nf): (usize, usize),
) {
    let (v, f) = (nv as u64, nf as u64);
    let blocks = (nv as u32).div_ceil(SORT_BLOCK) as u64;
    let sp = |n: u64| ScanParams {
        n: n as u32,
        _pad: [0; 3],
    };
    q.write_buffer(&scans[0], 0, bytemuck::bytes_of(&sp(v)));
    q.write_buffer(&scans[1], 0, bytemuck::bytes_of(&sp(f)));
    q.write_buffer(&scans[2], 0, bytemuck::bytes_of(&sp(256 * blocks)));
    let params = Params {
        vertex_count: nv as u32,
        face_count: nf as u32,
        ..Default::default()
    };
    q.write_buffer(params_buf, 0, bytemuck::bytes_of(&params));
    for (p, b) in radix.iter().enumerate() {
        q.write_buffer(b, 0, bytemuck::bytes_of(&sched::radix_params(nv, p as u32)));
    }
}

impl crate::compute::gpu::Runner<ClusterBuf, ClusterGrid, ClusterCount, std::convert::Infallible>
    for GpuClusterMesh<'_>
{
    /// The buffer bound for `buf`; `scan` is the prefix sum's (count, data) when one runs.
    fn buffer(&self, buf: ClusterBuf, scan: Option<(ClusterCount, ClusterBuf)>) -> &wgpu::Buffer {
        match buf {
            ClusterBuf::SortKeys => &self.halves[self.cur][0],
            ClusterBuf::SortVals => &self.halves[self.cur][1],
            ClusterBuf::SortKeysOut => &self.halves[1 - self.cur][0],
            ClusterBuf::SortValsOut => &self.halves[1 - self.cur][1],
            ClusterBuf::Radix => &self.radix[self.pass],
            ClusterBuf::Floating => &self.floats[self.slot],
            ClusterBuf::ScanCount => match scan.map(|s| s.0) {
                Some(ClusterCount::Faces) => &self.scans[1],
                Some(ClusterCount::Digits) => &self.scans[2],
                _ => &self.scans[0],
            },
            ClusterBuf::ScanData => {
                let data = scan.map_or(ClusterBuf::CellHead, |s| s.1);
                &self.bufs[&data]
            }
            other => &self.bufs[&other],
        }
    }

    /// One compute pass of `stage` over its grid.
    fn run(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        stage: &'static ClusterStage,
        scan: Option<(ClusterCount, ClusterBuf)>,
    ) {
        let groups = match stage.grid {
            ClusterGrid::Each(c) => self.count(c).div_ceil(WG),
            ClusterGrid::SortBlocks => (self.nv as u32).div_ceil(SORT_BLOCK),
            ClusterGrid::ScanBlocks => scan.map_or(0, |s| self.count(s.0)).div_ceil(SCAN_BLOCK),
            ClusterGrid::One => 1,
        };
        self.sim.kernels.pass(
            &self.sim.device,
            enc,
            stage,
            |b| self.buffer(b, scan),
            Groups::Direct(groups),
            None,
            None,
        );
    }

    fn own(&mut self, _: &mut wgpu::CommandEncoder, step: std::convert::Infallible) {
        match step {}
    }

    fn prefix_sum(&self) -> [&'static ClusterStage; 3] {
        sched::PREFIX_SUM
    }
}

/// One clustering, as the CPU driver's build returns it: per cluster its vertex, the kept faces
/// (input face id, clusters) in face order, each vertex's cluster, the counts.
pub struct ClusterBuild {
    pub placed: Vec<Placed>,
    pub faces: Vec<(u32, [u32; 3])>,
    pub vertex_cluster: Vec<u32>,
    pub clusters: usize,
    /// Cells: clusters are whole cells here, so the same as `clusters`.
    pub cells: usize,
}

impl ClusterBuild {
    /// From the buffers `cluster_quadrics` and `cluster_faces_compact` write.
    pub fn from_buffers(
        placed: &[ClusterPlaced],
        quadrics: &[Quadric],
        cluster_faces: &[u32],
        face_origin: &[u32],
        vertex_cell: Vec<u32>,
    ) -> ClusterBuild {
        assert_eq!(placed.len(), quadrics.len(), "a quadric per cluster");
        assert_eq!(
            cluster_faces.len(),
            3 * face_origin.len(),
            "three clusters a face"
        );
        let placed: Vec<Placed> = placed
            .iter()
            .zip(quadrics)
            .map(|(p, q)| Placed {
                pos: xyz(p.pos),
                quadric: *q,
                attr: p.attr,
                how: match p.how {
                    place::SINGLE => Placement::Single,
                    place::SOLVE => Placement::Solve,
                    place::MEMBER => Placement::Member,
                    _ => Placement::Centroid,
                },
            })
            .collect();
        let faces = face_origin
            .iter()
            .zip(cluster_faces.chunks_exact(3))
            .map(|(&f, t)| (f, [t[0], t[1], t[2]]))
            .collect();
        ClusterBuild {
            clusters: placed.len(),
            cells: placed.len(),
            placed,
            faces,
            vertex_cluster: vertex_cell,
        }
    }
}
