//! The rounds on the GPU: pipelines made once per device ([`GpuSimplifier`]), buffers and their
//! bind groups made once per mesh ([`GpuMesh`] plus the working buffers), and one command
//! buffer per batch of rounds the device plans itself, whose only read-back is the planner's
//! state and each round's counters (and the stage timestamps when the device has them); the
//! submissions and read-backs are in [`batch`].

use super::BindKey;
use crate::compute::context::{STORAGE, UNIFORM};
use crate::compute::context::{checked_buffer, checked_buffer_init, checked_buffer_write};
use crate::compute::gpu::{ErrorScope, Groups, Kernels, Pipelines, Runner};
use crate::compute::types::*;
use crate::error::{Error, Result};
use crate::rounds::schedule::{self, Buf, Count, RoundStep, Stage, Step, When};
use crate::rounds::{Download, RoundRunner, Selection, StageTimes, Upload};
use std::collections::HashMap;
use std::time::Instant;

mod batch;
mod passes;
pub use super::costs::Costs;

/// Timestamp slots per submission (a round, or a batch of them): one per dispatch and one per
/// compute pass (two per dispatch where stamps only bracket passes), up to the 4096 queries a
/// WebGPU query set may hold.
const QUERY_CAP: u32 = 4096;

/// Selection passes recorded between two read-backs in an exhaustive round: a pass with nothing
/// left to select costs a few empty dispatches, a read-back a round trip.
const EXHAUSTIVE_CHUNK: u32 = 8;

/// Bytes of the counters block, a round's read-back.
const COUNTERS_BYTES: u64 = std::mem::size_of::<Counters>() as u64;
/// `Counters::tentative`, cleared before each selection pass.
const TENTATIVE_OFFSET: u64 = std::mem::offset_of!(Counters, tentative) as u64;

/// Compute pipelines of every stage, made once for a device and reused for every mesh.
pub struct GpuSimplifier {
    device: wgpu::Device,
    queue: wgpu::Queue,
    kernels: Kernels,
    /// The preparation's stages, where the device has f64 in shaders (`None` elsewhere: the
    /// host prepares).
    prep: Option<Kernels>,
    /// Seconds spent compiling shaders and creating pipelines.
    pub pipeline_seconds: f64,
    /// How they were found: `hit`, `miss` or `unsupported` ([`crate::compute::disk_cache`]),
    /// or `shared` when another family on the device had made them all.
    pub pipeline_cache: &'static str,
    timestamps: bool,
    /// Timestamps can be written between the dispatches of a pass: the rounds then record
    /// their dispatches in few passes and still time each.
    stamps_in_passes: bool,
}

impl GpuSimplifier {
    /// Compiles every stage on `device`, with a cache of its own. Borrows the device: a viewer
    /// can share it (and its cache, with [`GpuSimplifier::on`]).
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue) -> Result<GpuSimplifier> {
        GpuSimplifier::on(&Pipelines::new(device), queue)
    }

    /// Every stage from the device's pipeline `cache`, compiling those no other family on it
    /// made yet.
    pub fn on(cache: &Pipelines, queue: &wgpu::Queue) -> Result<GpuSimplifier> {
        let device = cache.device();
        let before = cache.compiled().len();
        let kernels = Kernels::new(cache, schedule::STAGES, "the simplifier")?;
        let prep = super::prepare::kernels(cache)?;
        let pipeline_cache = match cache.cache_status() {
            _ if cache.compiled().len() == before => "shared",
            crate::compute::disk_cache::CacheStatus::Hit => "hit",
            crate::compute::disk_cache::CacheStatus::Miss => "miss",
            crate::compute::disk_cache::CacheStatus::Unsupported => "unsupported",
        };
        Ok(GpuSimplifier {
            pipeline_cache,
            device: device.clone(),
            queue: queue.clone(),
            pipeline_seconds: kernels.seconds + prep.as_ref().map_or(0.0, |k| k.seconds),
            kernels,
            prep,
            timestamps: device.features().contains(wgpu::Features::TIMESTAMP_QUERY),
            stamps_in_passes: device
                .features()
                .contains(wgpu::Features::TIMESTAMP_QUERY_INSIDE_PASSES),
        })
    }

    pub fn has_timestamps(&self) -> bool {
        self.timestamps
    }

    /// The preparation's stages, where the device runs them.
    pub fn prepare_kernels(&self) -> Option<&Kernels> {
        self.prep.as_ref()
    }
}

/// The mesh on the GPU as a renderer draws it: positions (vec4, normalized frame) and u32
/// indices, usable as STORAGE, VERTEX and INDEX buffers, and indexed indirect draw arguments the
/// rounds keep current. Positions are in the unit-diagonal frame: world = p / scale + center.
/// A clone shares the buffers (wgpu handles).
#[derive(Clone)]
pub struct GpuMesh {
    pub positions: wgpu::Buffer,
    pub indices: wgpu::Buffer,
    pub draw_args: wgpu::Buffer,
    pub center: [f64; 3],
    pub scale: f64,
}

/// Usages of a [`GpuMesh`]'s positions and indices: the rounds' storage, a renderer's vertex and
/// index buffers, copies.
pub(crate) const MESH_USAGE: wgpu::BufferUsages = STORAGE
    .union(wgpu::BufferUsages::VERTEX)
    .union(wgpu::BufferUsages::INDEX);
pub(crate) const DRAW_ARGS_USAGE: wgpu::BufferUsages = STORAGE.union(wgpu::BufferUsages::INDIRECT);

impl GpuMesh {
    /// A mesh made on the host — the input as loaded, or a CPU backend's result — with the
    /// simplifier's usages and draw arguments, so that one renderer draws every backend's output
    /// the same way. `positions` are in the frame of `center` and `scale`.
    pub fn from_arrays(
        device: &wgpu::Device,
        positions: &[[f32; 4]],
        indices: &[u32],
        center: [f64; 3],
        scale: f64,
    ) -> Result<GpuMesh> {
        let scope = ErrorScope::push(device);
        let init = |label: &str, data: &[u8], usage| {
            checked_buffer_init(device, label, data, data.len(), usage)
        };
        let args = DrawArgs {
            index_count: indices.len() as u32,
            instance_count: 1,
            ..Default::default()
        };
        let mesh = GpuMesh {
            positions: init(
                "meshslim.mesh.positions",
                bytemuck::cast_slice(positions),
                MESH_USAGE,
            )?,
            indices: init(
                "meshslim.mesh.indices",
                bytemuck::cast_slice(indices),
                MESH_USAGE,
            )?,
            draw_args: init(
                "meshslim.mesh.draw_args",
                bytemuck::bytes_of(&args),
                DRAW_ARGS_USAGE,
            )?,
            center,
            scale,
        };
        scope.check("uploading a mesh to draw")?;
        Ok(mesh)
    }
}

/// One ping-pong half of the per-vertex and per-face buffers.
struct Half {
    positions: wgpu::Buffer,
    quadrics: wgpu::Buffer,
    flags: wgpu::Buffer,
    vertex_attr: wgpu::Buffer,
    indices: wgpu::Buffer,
    face_normals: wgpu::Buffer,
    face_extra: wgpu::Buffer,
}

/// Makes the rounds' buffers, counting the bytes uploaded.
struct Alloc<'d> {
    dev: &'d wgpu::Device,
    queue: &'d wgpu::Queue,
    uploaded: std::cell::Cell<u64>,
}

impl Alloc<'_> {
    /// A buffer of `size` bytes, zeroed.
    fn empty(&self, label: &str, size: u64, usage: wgpu::BufferUsages) -> Result<wgpu::Buffer> {
        checked_buffer(self.dev, &format!("meshslim.{label}"), size, usage)
    }

    /// A buffer holding `data`.
    fn init(&self, label: &str, data: &[u8], usage: wgpu::BufferUsages) -> Result<wgpu::Buffer> {
        self.uploaded.set(self.uploaded.get() + data.len() as u64);
        checked_buffer_write(
            self.dev,
            self.queue,
            &format!("meshslim.{label}"),
            data,
            usage,
        )
    }

    /// A storage buffer holding `data`, or of one word when there is none (a binding the
    /// stages never read without it).
    fn init_or(&self, label: &str, data: Option<&[u8]>) -> Result<wgpu::Buffer> {
        match data {
            Some(d) => self.init(label, d, STORAGE),
            None => self.empty(label, 4, STORAGE),
        }
    }
}

impl Half {
    /// The first round's input: the device's own preparation, or the host's arrays uploaded.
    fn input(
        a: &Alloc,
        up: &Upload,
        prepared: Option<super::prepare::DevicePrepared>,
    ) -> Result<Half> {
        let nv = up.vertex_count().max(1) as u64;
        let nf = up.face_count().max(1) as u64;
        let qsize = std::mem::size_of::<Quadric>() as u64;
        Ok(match prepared {
            Some(d) => Half {
                positions: d.positions,
                quadrics: a.empty("quadrics", nv * qsize, STORAGE)?,
                flags: d.flags,
                vertex_attr: d.vertex_attr,
                indices: d.indices,
                face_normals: a.empty("face_normals", nf * 16, STORAGE)?,
                face_extra: d.face_extra,
            },
            None => Half {
                positions: a.init("positions", bytemuck::cast_slice(&up.positions), MESH_USAGE)?,
                // Quadrics carried in (`hybrid`'s clusters) are the first round's; otherwise the
                // first round's `vertex_quadrics` writes them.
                quadrics: match &up.quadrics {
                    Some(q) => a.init("quadrics", bytemuck::cast_slice(q), STORAGE)?,
                    None => a.empty("quadrics", nv * qsize, STORAGE)?,
                },
                flags: a.init("flags", bytemuck::cast_slice(&up.flags), STORAGE)?,
                vertex_attr: a.init(
                    "vertex_attr",
                    bytemuck::cast_slice(&up.vertex_attr),
                    STORAGE,
                )?,
                indices: a.init("indices", bytemuck::cast_slice(&up.indices), MESH_USAGE)?,
                face_normals: match &up.face_planes {
                    Some(p) => a.init("face_normals", bytemuck::cast_slice(p), STORAGE)?,
                    None => a.empty("face_normals", nf * 16, STORAGE)?,
                },
                face_extra: a.init("face_extra", bytemuck::cast_slice(&up.face_extra), STORAGE)?,
            },
        })
    }

    /// The other half the rounds ping-pong into, sized for `nv` vertices and `nf` faces.
    fn output(a: &Alloc, nv: u64, nf: u64) -> Result<Half> {
        let qsize = std::mem::size_of::<Quadric>() as u64;
        Ok(Half {
            positions: a.empty("positions_out", nv * 16, MESH_USAGE)?,
            quadrics: a.empty("quadrics_out", nv * qsize, STORAGE)?,
            flags: a.empty("flags_out", nv * 4, STORAGE)?,
            vertex_attr: a.empty("vertex_attr_out", nv * 4, STORAGE)?,
            indices: a.empty("indices_out", nf * 12, MESH_USAGE)?,
            face_normals: a.empty("face_normals_out", nf * 16, STORAGE)?,
            face_extra: a.empty("face_extra_out", nf * 16, STORAGE)?,
        })
    }
}

/// The query set the stages' timestamps are written to, and the buffer it resolves into.
fn timestamp_queries(dev: &wgpu::Device) -> (wgpu::QuerySet, wgpu::Buffer) {
    let set = dev.create_query_set(&wgpu::QuerySetDescriptor {
        label: Some("meshslim.timestamps"),
        ty: wgpu::QueryType::Timestamp,
        count: QUERY_CAP,
    });
    let resolve = dev.create_buffer(&wgpu::BufferDescriptor {
        label: Some("meshslim.timestamps_resolve"),
        size: QUERY_CAP as u64 * 8,
        usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    (set, resolve)
}

/// The working state of one simplification on the GPU.
pub struct GpuRounds<'a> {
    sim: &'a GpuSimplifier,
    half: [Half; 2],
    cur: usize,
    /// Vertices and faces of the mesh in the current half: the upload's until a round has run,
    /// then that round's counters. Download reads these, not the counters buffer, which holds
    /// nothing before the first round (a target at or above the input ran none).
    live_counts: (u32, u32),
    draw_args: wgpu::Buffer,
    params: wgpu::Buffer,
    scan_v: wgpu::Buffer,
    scan_f: wgpu::Buffer,
    scan_e: wgpu::Buffer,
    offsets: wgpu::Buffer,
    cursor: wgpu::Buffer,
    vertex_faces: wgpu::Buffer,
    edge_offsets: wgpu::Buffer,
    edges: wgpu::Buffer,
    candidates: wgpu::Buffer,
    edge_state: wgpu::Buffer,
    /// The edge errors' histogram, kept through the round (tests read it).
    histogram: wgpu::Buffer,
    trim_histogram: wgpu::Buffer,
    /// Candidates under the ceiling (`live_list`), in an order that depends on timing.
    live: wgpu::Buffer,
    face_best: wgpu::Buffer,
    face_id: wgpu::Buffer,
    vertex_lock: wgpu::Buffer,
    remap: wgpu::Buffer,
    vertex_keep: wgpu::Buffer,
    face_keep: wgpu::Buffer,
    marks: wgpu::Buffer,
    tentative: wgpu::Buffer,
    dispatch: wgpu::Buffer,
    neighbours: wgpu::Buffer,
    block_sums: wgpu::Buffer,
    counters: wgpu::Buffer,
    /// The planner's state and its next round (`plan_round`), between the rounds of a batch.
    plan: wgpu::Buffer,
    planned: wgpu::Buffer,
    /// Recording a round the device planned: grids from `planned`...
    planned_round: bool,
    /// ...and its trim: the planner's trim grids.
    trimming: bool,
    /// Every bind group made so far: the buffers never change, so each stage binds each set
    /// of them (a half's, a scan's) once.
    bind_groups: HashMap<BindKey, wgpu::BindGroup>,
    /// What the simplification cost on the device's side.
    pub costs: Costs,
    /// The output needs the faces' extras ([`Upload::output_needs_face_extra`]): the download
    /// reads them back.
    face_extra_out: bool,
    /// Per attribute vertex: weighted appearance values and attribute sums (a word each when
    /// the rounds carry none: bound, never read).
    attr_values: wgpu::Buffer,
    attr_sums: wgpu::Buffer,
    /// Numbers in `attr_values`, for the read-back.
    attr_len: u64,
    /// Grouped rounds ([`crate::rounds::UploadGroups`]; a word each without, bound and never
    /// read): per input face its group, per group its target, faces, closed flag and largest
    /// squared error's bits.
    face_group: wgpu::Buffer,
    group_target: wgpu::Buffer,
    group_count: wgpu::Buffer,
    group_closed: wgpu::Buffer,
    group_err: wgpu::Buffer,
    /// Groups (0 without), for the read-back.
    groups: u64,
    readback: wgpu::Buffer,
    queries: Option<(wgpu::QuerySet, wgpu::Buffer)>,
    /// Stage of each dispatch timed this submission, with the slot of the stamp before it
    /// (the one after it is the next slot).
    query_stages: Vec<(&'static str, u32)>,
    /// The first timestamp slot not written yet this submission.
    next_slot: u32,
    /// The compute pass the dispatches are going into, left open across consecutive
    /// dispatches ([`Runner::end_pass`] ends it), and the slot of its last stamp.
    pass: Option<(wgpu::ComputePass<'static>, Option<u32>)>,
    times: StageTimes,
    selection_passes: u32,
    /// The upload brought the face planes and quadrics: the first round skips
    /// `SETUP_QUADRICS`.
    carried_quadrics: bool,
    /// Upload and download seconds.
    pub transfer_seconds: f64,
    /// Seconds from each submission of rounds to their counters read back.
    pub wait_seconds: f64,
    /// The round being recorded's parameters (the grids are counted from them).
    round_params: Params,
    /// Submit each pass on its own and wait for it: set when the device also draws a window,
    /// whose frames then come between passes (a round on a 1M-face mesh keeps lavapipe busy
    /// for over a second, which would otherwise be one frame's wait). Off for the command line.
    pub share_queue: bool,
}

impl<'a> GpuRounds<'a> {
    /// Uploads `up` and allocates every working buffer for its size (they only shrink).
    pub fn new(
        sim: &'a GpuSimplifier,
        up: &Upload,
        selection_passes: u32,
    ) -> Result<GpuRounds<'a>> {
        GpuRounds::build(sim, up, selection_passes, None, Costs::default())
    }

    /// Prepares the plain `mesh` on the device (`p` from [`crate::rounds::prepare::eligible`],
    /// the device's preparation `kernels`) and allocates the rounds around what it wrote: the
    /// rounds and the upload that describes them, whose arrays stay on the device.
    pub fn prepared(
        sim: &'a GpuSimplifier,
        kernels: &Kernels,
        mesh: &crate::mesh::Mesh,
        p: &PrepParams,
        selection_passes: u32,
    ) -> Result<(GpuRounds<'a>, Upload)> {
        // The costs begin with the preparation's on the device.
        let costs = Costs::default();
        let device = (&sim.device, &sim.queue);
        let d = super::prepare::prepare(device, kernels, mesh, p, &costs, MESH_USAGE)?;
        super::prepare::check_counts(&d, mesh)?;
        let frame = ([p.frame[0], p.frame[1], p.frame[2]], p.frame[3]);
        let up = Upload::on_device(mesh, d.vertices, d.faces, frame);
        let r = GpuRounds::build(sim, &up, selection_passes, Some(d), costs)?;
        Ok((r, up))
    }

    /// The rounds' buffers for `up`: the first half uploaded from it, or the one the device
    /// `prepared`.
    fn build(
        sim: &'a GpuSimplifier,
        up: &Upload,
        selection_passes: u32,
        prepared: Option<super::prepare::DevicePrepared>,
        costs: Costs,
    ) -> Result<GpuRounds<'a>> {
        let t = Instant::now();
        let dev = &sim.device;
        let scope = ErrorScope::push(dev);
        let nv = up.vertex_count().max(1) as u64;
        let nf = up.face_count().max(1) as u64;
        let cap = 3 * nf;
        let a = Alloc {
            dev,
            queue: &sim.queue,
            uploaded: std::cell::Cell::new(0),
        };
        let groups = up.groups.as_ref().map_or(0, |g| g.targets.len() as u64);
        let blocks = (cap + 1)
            .div_ceil(SCAN_BLOCK as u64)
            .max(nv.div_ceil(SCAN_BLOCK as u64))
            + 1;
        let r = GpuRounds {
            sim,
            half: [Half::input(&a, up, prepared)?, Half::output(&a, nv, nf)?],
            cur: 0,
            live_counts: (up.vertex_count() as u32, up.face_count() as u32),
            draw_args: a.empty(
                "draw_args",
                std::mem::size_of::<DrawArgs>() as u64,
                DRAW_ARGS_USAGE,
            )?,
            params: a.empty(
                "params",
                std::mem::size_of::<Params>() as u64,
                UNIFORM | wgpu::BufferUsages::COPY_SRC,
            )?,
            scan_v: a.empty("scan_v", 16, UNIFORM)?,
            scan_f: a.empty("scan_f", 16, UNIFORM)?,
            scan_e: a.empty("scan_e", 16, UNIFORM)?,
            offsets: a.empty("offsets", (nv + 1) * 4, STORAGE)?,
            cursor: a.empty("cursor", nv * 4, STORAGE)?,
            vertex_faces: a.empty("vertex_faces", nf * 12, STORAGE)?,
            edge_offsets: a.empty("edge_offsets", (nv + 1) * 4, STORAGE)?,
            edges: a.empty("edges", cap * 8, STORAGE)?,
            candidates: a.empty(
                "candidates",
                cap * std::mem::size_of::<EdgeCandidate>() as u64,
                STORAGE,
            )?,
            edge_state: a.empty("edge_state", cap * 4, STORAGE)?,
            histogram: a.empty("histogram", HIST_BINS as u64 * 4, STORAGE)?,
            trim_histogram: a.empty("trim_histogram", HIST_BINS as u64 * 4, STORAGE)?,
            face_best: a.empty("face_best", nf * 4, STORAGE)?,
            face_id: a.empty("face_id", nf * 4, STORAGE)?,
            vertex_lock: a.empty("vertex_lock", nv * 4, STORAGE)?,
            remap: a.empty("remap", nv * 4, STORAGE)?,
            vertex_keep: a.empty("vertex_keep", (nv + 1) * 4, STORAGE)?,
            face_keep: a.empty("face_keep", (nf + 1) * 4, STORAGE)?,
            marks: a.empty("marks", (cap + 1) * 4, STORAGE)?,
            tentative: a.empty("tentative", cap * 4, STORAGE)?,
            dispatch: a.empty("dispatch", 64, STORAGE | wgpu::BufferUsages::INDIRECT)?,
            live: a.empty("live", cap * 4, STORAGE)?,
            neighbours: a.empty("neighbours", nf * 24, STORAGE)?,
            block_sums: a.empty("block_sums", blocks * 4, STORAGE)?,
            counters: a.empty("counters", COUNTERS_BYTES, STORAGE)?,
            plan: a.empty(
                "plan",
                std::mem::size_of::<crate::compute::types::PlanState>() as u64,
                STORAGE,
            )?,
            planned: a.empty(
                "planned",
                std::mem::size_of::<crate::compute::types::Planned>() as u64,
                STORAGE | wgpu::BufferUsages::INDIRECT,
            )?,
            planned_round: false,
            trimming: false,
            bind_groups: HashMap::new(),
            costs,
            face_extra_out: up.output_needs_face_extra(),
            attr_values: a.init_or(
                "attr_values",
                up.attrs.as_ref().map(|x| bytemuck::cast_slice(&x.values)),
            )?,
            attr_sums: a.empty("attr_sums", (up.attr_sums_len().max(1) * 4) as u64, STORAGE)?,
            attr_len: up.attrs.as_ref().map_or(0, |a| a.values.len() as u64),
            face_group: a.init_or(
                "face_group",
                up.groups
                    .as_ref()
                    .map(|g| bytemuck::cast_slice(&g.face_group)),
            )?,
            group_target: a.init_or(
                "group_target",
                up.groups.as_ref().map(|g| bytemuck::cast_slice(&g.targets)),
            )?,
            group_closed: a.init_or(
                "group_closed",
                up.groups.as_ref().map(|g| bytemuck::cast_slice(&g.closed)),
            )?,
            group_count: a.empty("group_count", groups.max(1) * 4, STORAGE)?,
            group_err: a.empty("group_err", groups.max(1) * 4, STORAGE)?,
            groups,
            readback: a.empty(
                "readback",
                batch::READBACK_BYTES,
                wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            )?,
            queries: sim.timestamps.then(|| timestamp_queries(dev)),
            query_stages: Vec::new(),
            next_slot: 0,
            pass: None,
            times: StageTimes::default(),
            selection_passes,
            carried_quadrics: up.quadrics.is_some(),
            transfer_seconds: 0.0,
            wait_seconds: 0.0,
            round_params: Params::default(),
            share_queue: false,
        };
        // Draw arguments for the mesh as uploaded: a renderer can draw it before any round.
        let args = DrawArgs {
            index_count: 3 * up.face_count() as u32,
            instance_count: 1,
            ..Default::default()
        };
        Costs::add(&r.costs.uploaded, a.uploaded.get());
        r.write(&r.draw_args, 0, bytemuck::bytes_of(&args));
        scope.check("uploading the mesh")?;
        let mut r = r;
        r.transfer_seconds += t.elapsed().as_secs_f64();
        Ok(r)
    }

    /// Frees the rounds' buffers on a thread of their own, so that the call returns without
    /// waiting for it: on lavapipe, whose device memory is the process's, unmapping the 1M
    /// scan's buffers took 0.03-0.04 s, more than the rest of the host's part of the call.
    pub fn retire(self) {
        // Moved out field by field (the rounds borrow their simplifier, which stays).
        let buffers = [
            self.draw_args,
            self.params,
            self.scan_v,
            self.scan_f,
            self.scan_e,
            self.offsets,
            self.cursor,
            self.vertex_faces,
            self.edge_offsets,
            self.edges,
            self.candidates,
            self.edge_state,
            self.histogram,
            self.trim_histogram,
            self.live,
            self.face_best,
            self.face_id,
            self.vertex_lock,
            self.remap,
            self.vertex_keep,
            self.face_keep,
            self.marks,
            self.tentative,
            self.dispatch,
            self.neighbours,
            self.block_sums,
            self.counters,
            self.plan,
            self.planned,
            self.attr_values,
            self.attr_sums,
            self.face_group,
            self.group_target,
            self.group_count,
            self.group_closed,
            self.group_err,
            self.readback,
        ];
        let resources = (self.half, buffers, self.bind_groups, self.queries);
        // A thread that cannot start leaves the freeing to this one.
        let _ = std::thread::Builder::new()
            .name("meshslim-free".into())
            .spawn(move || drop(resources));
    }

    /// Records the steps in `steps` with the round's parameters `p`.
    fn record(&mut self, enc: &mut wgpu::CommandEncoder, p: &Params, steps: &[Step]) {
        self.round_params = *p;
        crate::compute::gpu::record(self, enc, steps)
    }

    /// The mesh as it stands (after the last round), for a renderer.
    pub fn into_mesh(self, up: &Upload) -> Result<GpuMesh> {
        let scope = ErrorScope::push(&self.sim.device);
        let h = &self.half[self.cur];
        let (positions, indices) = if self.cur == 0 {
            (h.positions.clone(), h.indices.clone())
        } else {
            // The result lives in the second half: copy it into the first, the GpuMesh's own.
            let mut enc = self.sim.device.create_command_encoder(&Default::default());
            let h0 = &self.half[0];
            enc.copy_buffer_to_buffer(
                &h.positions,
                0,
                &h0.positions,
                0,
                h.positions.size().min(h0.positions.size()),
            );
            enc.copy_buffer_to_buffer(
                &h.indices,
                0,
                &h0.indices,
                0,
                h.indices.size().min(h0.indices.size()),
            );
            self.submit(enc);
            (h0.positions.clone(), h0.indices.clone())
        };
        scope.check("keeping the result on the device")?;
        Ok(GpuMesh {
            positions,
            indices,
            draw_args: self.draw_args.clone(),
            center: up.center,
            scale: up.scale,
        })
    }

    /// A copy of the mesh as it stands, made on the GPU (nothing goes through the host), while
    /// the rounds go on: a level of detail. `vertices` and `faces` are the counts after the last
    /// round ([`crate::rounds::Driver`] knows them).
    pub fn snapshot(&self, up: &Upload, vertices: usize, faces: usize) -> Result<GpuMesh> {
        let dev = &self.sim.device;
        let scope = ErrorScope::push(dev);
        let h = &self.half[self.cur];
        let mk = |label: &str, size: u64, usage| checked_buffer(dev, label, size, usage);
        let (pb, ib) = (vertices as u64 * 16, faces as u64 * 12);
        let mesh = GpuMesh {
            positions: mk("meshslim.lod.positions", pb, MESH_USAGE)?,
            indices: mk("meshslim.lod.indices", ib, MESH_USAGE)?,
            draw_args: mk(
                "meshslim.lod.draw_args",
                std::mem::size_of::<DrawArgs>() as u64,
                DRAW_ARGS_USAGE,
            )?,
            center: up.center,
            scale: up.scale,
        };
        let mut enc = dev.create_command_encoder(&Default::default());
        enc.copy_buffer_to_buffer(&h.positions, 0, &mesh.positions, 0, pb);
        enc.copy_buffer_to_buffer(&h.indices, 0, &mesh.indices, 0, ib);
        enc.copy_buffer_to_buffer(
            &self.draw_args,
            0,
            &mesh.draw_args,
            0,
            std::mem::size_of::<DrawArgs>() as u64,
        );
        self.submit(enc);
        scope.check("copying a level of detail")?;
        Ok(mesh)
    }

    /// The first `bytes` of a working buffer, as the schedule names it: what tests diff against
    /// the CPU twin. After a round the plain per-vertex and per-face names are its result and
    /// the `*Out` ones the half it compacted from.
    pub fn read_buffer(&self, buf: Buf, bytes: u64) -> Result<Vec<u8>> {
        self.read(self.buffer(buf, None), bytes)
    }

    fn read(&self, src: &wgpu::Buffer, bytes: u64) -> Result<Vec<u8>> {
        if bytes == 0 {
            return Ok(Vec::new());
        }
        let dev = &self.sim.device;
        let scope = ErrorScope::push(dev);
        let size = bytes.max(4).next_multiple_of(4);
        let staging = dev.create_buffer(&wgpu::BufferDescriptor {
            label: Some("meshslim.download"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut enc = dev.create_command_encoder(&Default::default());
        enc.copy_buffer_to_buffer(src, 0, &staging, 0, size);
        self.submit(enc);
        if let Err(e) = self.map_wait(&staging) {
            return scope.check_with("reading back", Err(e));
        }
        let data = staging
            .get_mapped_range(..)
            .map_err(|e| Error::Gpu(format!("reading back: {e}")))?[..bytes as usize]
            .to_vec();
        staging.unmap();
        scope.check("reading back")?;
        Costs::add(&self.costs.read_back, bytes);
        Ok(data)
    }
}
