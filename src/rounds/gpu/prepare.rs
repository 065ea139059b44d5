//! The preparation on the device ([`crate::rounds::prepare`]): the input's arrays go up as the
//! host parsed them, the stages weld, order and number them into the rounds' first half, and
//! one read-back brings the counts the rounds' uniforms need. Recorded in one command buffer,
//! the sorts' passes included (a uniform per pass, as the clustering's).

use super::costs::Costs;
use crate::compute::context::STORAGE;
use crate::compute::context::{checked_buffer, checked_buffer_write};
use crate::compute::gpu::{ErrorScope, Groups, Kernels};
use crate::compute::types::{
    FaceExtra, PrepCounts, PrepParams, RadixParams, SCAN_BLOCK, ScanParams, WG,
};
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::rounds::prepare::{
    CLASSES, FACE_SORT_PASS, OUTPUT, PBuf, PCount, PGrid, PStage, PStep, VERTEX_SORT_PASS,
    VERTEX_SORT_PASSES, WELD, face_sort_passes, sort_blocks,
};
use std::collections::HashMap;

/// The rounds' first half as the preparation wrote it, and its counts.
pub struct DevicePrepared {
    pub positions: wgpu::Buffer,
    pub flags: wgpu::Buffer,
    pub vertex_attr: wgpu::Buffer,
    pub indices: wgpu::Buffer,
    pub face_extra: wgpu::Buffer,
    /// Welded vertices, used classes (the rounds' vertices) and kept faces.
    pub welded: u32,
    pub vertices: u32,
    pub faces: u32,
}

/// The runner: the preparation's buffers by name, the sort's halves and pass.
struct GpuPrepare<'a> {
    device: &'a wgpu::Device,
    kernels: &'a Kernels,
    costs: &'a Costs,
    bufs: HashMap<PBuf, wgpu::Buffer>,
    /// The sort's (keys, values) halves; `cur` is the one a pass reads.
    halves: [[wgpu::Buffer; 2]; 2],
    cur: usize,
    /// The radix pass's uniform, copied in before each pass from `radix_all` (every pass's,
    /// the Morton sort's then the faces'): one uniform, so the sort's stages bind one group a
    /// half rather than one a pass.
    radix: wgpu::Buffer,
    radix_all: wgpu::Buffer,
    pass: usize,
    /// Prefix sums' counts: the vertices, and the digit counts of the sort under way (copied
    /// in from `digit_scans`, the two sorts', before each sort).
    scans: [wgpu::Buffer; 2],
    digit_scans: wgpu::Buffer,
    n: usize,
    m: usize,
    /// Bind groups made so far, by stage and the buffers bound.
    bind_groups: HashMap<super::BindKey, wgpu::BindGroup>,
}

impl GpuPrepare<'_> {
    fn count(&self, c: PCount) -> u32 {
        match c {
            PCount::Vertices => self.n as u32,
            PCount::Faces => self.m as u32,
            PCount::VertexDigits => 256 * sort_blocks(self.n),
            PCount::FaceDigits => 256 * sort_blocks(self.m),
        }
    }

    /// Keys the sort under way orders: the vertices' for the first passes, then the faces'.
    fn sorted(&self) -> usize {
        if self.pass < VERTEX_SORT_PASSES as usize {
            self.n
        } else {
            self.m
        }
    }

    fn record(&mut self, enc: &mut wgpu::CommandEncoder, steps: &[PStep]) {
        crate::compute::gpu::record(self, enc, steps)
    }

    /// `passes` radix passes of `steps`, the halves swapping after each.
    fn sort(&mut self, enc: &mut wgpu::CommandEncoder, steps: &[PStep], passes: u32) {
        let which = u64::from(self.pass >= VERTEX_SORT_PASSES as usize);
        enc.copy_buffer_to_buffer(&self.digit_scans, 16 * which, &self.scans[1], 0, 16);
        for _ in 0..passes {
            enc.copy_buffer_to_buffer(&self.radix_all, 16 * self.pass as u64, &self.radix, 0, 16);
            self.record(enc, steps);
            self.cur = 1 - self.cur;
            self.pass += 1;
        }
    }
}

impl crate::compute::gpu::Runner<PBuf, PGrid, PCount, std::convert::Infallible> for GpuPrepare<'_> {
    fn buffer(&self, buf: PBuf, scan: Option<(PCount, PBuf)>) -> &wgpu::Buffer {
        match buf {
            PBuf::SortKeys => &self.halves[self.cur][0],
            PBuf::SortVals => &self.halves[self.cur][1],
            PBuf::SortKeysOut => &self.halves[1 - self.cur][0],
            PBuf::SortValsOut => &self.halves[1 - self.cur][1],
            PBuf::Radix => &self.radix,
            PBuf::ScanCount => match scan.map(|s| s.0) {
                Some(PCount::VertexDigits | PCount::FaceDigits) => &self.scans[1],
                _ => &self.scans[0],
            },
            PBuf::ScanData => &self.bufs[&scan.map_or(PBuf::WeldedId, |s| s.1)],
            // Every buffer a stage of the preparation binds is made in `prepare`.
            other => &self.bufs[&other],
        }
    }

    fn run(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        stage: &'static PStage,
        scan: Option<(PCount, PBuf)>,
    ) {
        let groups = match stage.grid {
            PGrid::Each(c) => self.count(c).div_ceil(WG),
            PGrid::SortBlocks => sort_blocks(self.sorted()),
            PGrid::ScanBlocks => scan.map_or(0, |s| self.count(s.0)).div_ceil(SCAN_BLOCK),
            PGrid::One => 1,
        };
        Costs::add(&self.costs.dispatches, 1);
        let bound = stage
            .bindings
            .iter()
            .map(|b| self.buffer(b.buf, scan).clone())
            .collect();
        let key = (stage.entry, bound);
        if !self.bind_groups.contains_key(&key) {
            Costs::add(&self.costs.bind_groups, 1);
            let bg = self
                .kernels
                .bind_group(self.device, stage, |b| self.buffer(b, scan));
            self.bind_groups.insert(key.clone(), bg);
        }
        let bg = &self.bind_groups[&key];
        self.kernels
            .pass_bound(enc, stage, bg, Groups::Direct(groups), None, None);
    }

    fn own(&mut self, _: &mut wgpu::CommandEncoder, step: std::convert::Infallible) {
        match step {}
    }

    fn prefix_sum(&self) -> [&'static PStage; 3] {
        use crate::rounds::prepare::{PREFIX_SUM_APPLY, PREFIX_SUM_REDUCE, PREFIX_SUM_SPINE};
        [&PREFIX_SUM_REDUCE, &PREFIX_SUM_SPINE, &PREFIX_SUM_APPLY]
    }
}

/// Prepares `mesh` (a plain one: [`crate::rounds::prepare::eligible`] gave `p`) on `device`
/// with its preparation `kernels`, the costs counted into `costs`; the positions and indices
/// get `mesh_usage` (the rounds' mesh buffers are a renderer's too).
pub fn prepare(
    (dev, queue): (&wgpu::Device, &wgpu::Queue),
    kernels: &Kernels,
    mesh: &Mesh,
    p: &PrepParams,
    costs: &Costs,
    mesh_usage: wgpu::BufferUsages,
) -> Result<DevicePrepared> {
    let scope = ErrorScope::push(dev);
    let (n, m) = (mesh.positions.len(), mesh.triangles.len());
    let (n1, m1) = (n.max(1) as u64, m.max(1) as u64);
    let mk = |label: &str, size: u64, usage: wgpu::BufferUsages| {
        checked_buffer(dev, &format!("meshslim.prep.{label}"), size, usage)
    };
    let init = |label: &str, data: &[u8], usage: wgpu::BufferUsages| {
        Costs::add(&costs.uploaded, data.len() as u64);
        let label = format!("meshslim.prep.{label}");
        checked_buffer_write(dev, queue, &label, data, usage)
    };
    let uniform = wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST;
    let sorted = n1.max(m1);
    let digits = 256 * sort_blocks(n.max(m)) as u64 + 1;
    let blocks = (digits.max(n1 + 1)).div_ceil(SCAN_BLOCK as u64) + 1;
    let mut bufs = HashMap::new();
    for (buf, size) in [
        (PBuf::WeldTable, (p.table_mask as u64 + 1) * 4),
        (PBuf::WeldSlot, n1 * 4),
        (PBuf::WeldFirst, n1 * 4),
        (PBuf::WeldedId, (n1 + 1) * 4),
        (PBuf::WeldedInput, n1 * 4),
        (PBuf::DigitCounts, digits * 4),
        (PBuf::ClassOf, n1 * 4),
        (PBuf::ClassWelded, n1 * 4),
        (PBuf::ClassUsed, (n1 + 1) * 4),
        (PBuf::PrepCounts, std::mem::size_of::<PrepCounts>() as u64),
        (PBuf::BlockSums, blocks * 4),
        (PBuf::Flags, n1 * 4),
        (PBuf::VertexAttr, n1 * 4),
        (
            PBuf::FaceExtra,
            m1 * std::mem::size_of::<FaceExtra>() as u64,
        ),
    ] {
        bufs.insert(buf, mk(&format!("{buf:?}"), size, STORAGE)?);
    }
    bufs.insert(PBuf::Positions, mk("positions", n1 * 16, mesh_usage)?);
    bufs.insert(PBuf::Indices, mk("indices", m1 * 12, mesh_usage)?);
    bufs.insert(
        PBuf::InPositions,
        init(
            "in_positions",
            bytemuck::cast_slice(&mesh.positions),
            STORAGE,
        )?,
    );
    bufs.insert(
        PBuf::InIndices,
        init("in_indices", bytemuck::cast_slice(&mesh.triangles), STORAGE)?,
    );
    bufs.insert(PBuf::Prep, init("params", bytemuck::bytes_of(p), uniform)?);
    let face_passes = face_sort_passes(n);
    let passes: Vec<RadixParams> = (0..VERTEX_SORT_PASSES + face_passes)
        .map(|pass| {
            let (keys, shift) = if pass < VERTEX_SORT_PASSES {
                (n, pass)
            } else {
                (m, pass - VERTEX_SORT_PASSES)
            };
            RadixParams {
                n: keys as u32,
                blocks: sort_blocks(keys),
                shift: 8 * shift,
                _pad: 0,
            }
        })
        .collect();
    let copied = wgpu::BufferUsages::COPY_SRC;
    let scan = |count: u32| ScanParams {
        n: count,
        _pad: [0; 3],
    };
    let digit_counts = [scan(256 * sort_blocks(n)), scan(256 * sort_blocks(m))];
    let half = |label: &str| -> Result<[wgpu::Buffer; 2]> {
        Ok([
            mk(&format!("sort_keys{label}"), sorted * 4, STORAGE)?,
            mk(&format!("sort_vals{label}"), sorted * 4, STORAGE)?,
        ])
    };
    let mut run = GpuPrepare {
        device: dev,
        kernels,
        costs,
        scans: [
            init("scan", bytemuck::bytes_of(&scan(n as u32)), uniform)?,
            mk("scan_digits", 16, uniform)?,
        ],
        digit_scans: init("digit_scans", bytemuck::cast_slice(&digit_counts), copied)?,
        halves: [half("")?, half("_out")?],
        cur: 0,
        radix: mk("radix", 16, uniform)?,
        radix_all: init("radix_all", bytemuck::cast_slice(&passes), copied)?,
        pass: 0,
        bufs,
        n,
        m,
        bind_groups: HashMap::new(),
    };
    let readback = mk(
        "readback",
        16,
        wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
    )?;
    let mut enc = dev.create_command_encoder(&Default::default());
    run.record(&mut enc, WELD);
    run.sort(&mut enc, VERTEX_SORT_PASS, VERTEX_SORT_PASSES);
    run.record(&mut enc, CLASSES);
    run.sort(&mut enc, FACE_SORT_PASS, face_passes);
    run.record(&mut enc, OUTPUT);
    let at_n = 4 * n as u64;
    enc.copy_buffer_to_buffer(&run.bufs[&PBuf::WeldedId], at_n, &readback, 0, 4);
    enc.copy_buffer_to_buffer(&run.bufs[&PBuf::ClassUsed], at_n, &readback, 4, 4);
    enc.copy_buffer_to_buffer(&run.bufs[&PBuf::PrepCounts], 0, &readback, 8, 4);
    Costs::add(&costs.submits, 1);
    queue.submit([enc.finish()]);
    scope.check("preparing the mesh on the device")?;
    let words = read_mapped(dev, &readback, costs)?;
    let mut bufs = run.bufs;
    let mut take = |b: PBuf| bufs.remove(&b).expect("made above");
    Ok(DevicePrepared {
        positions: take(PBuf::Positions),
        flags: take(PBuf::Flags),
        vertex_attr: take(PBuf::VertexAttr),
        indices: take(PBuf::Indices),
        face_extra: take(PBuf::FaceExtra),
        welded: words[0],
        vertices: words[1],
        faces: words[2],
    })
}

/// Maps `buf` (submitted work copies into it) and reads its words: one round trip, counted
/// with the time blocked and the bytes.
fn read_mapped(device: &wgpu::Device, buf: &wgpu::Buffer, costs: &Costs) -> Result<Vec<u32>> {
    let (outcome, waited) = crate::compute::context::map_and_wait(device, buf);
    Costs::add(&costs.waits, 1);
    Costs::add(&costs.blocked_ns, (waited * 1e9) as u64);
    Costs::add(&costs.read_back, buf.size());
    outcome.map_err(Error::Gpu)?;
    let view = buf
        .get_mapped_range(..)
        .map_err(|e| Error::Gpu(format!("reading back: {e}")))?;
    let words = bytemuck::cast_slice(&view).to_vec();
    drop(view);
    buf.unmap();
    Ok(words)
}

/// A device without f64 in shaders cannot run the preparation's stages.
pub fn kernels(sim_cache: &crate::compute::gpu::Pipelines) -> Result<Option<Kernels>> {
    let device = sim_cache.device();
    if !device.features().contains(wgpu::Features::SHADER_F64) {
        return Ok(None);
    }
    Kernels::new(sim_cache, crate::rounds::prepare::STAGES, "the preparation").map(Some)
}

/// An error from the counts read back: never more than the input.
pub(crate) fn check_counts(d: &DevicePrepared, mesh: &Mesh) -> Result<()> {
    if d.welded as usize > mesh.positions.len()
        || d.vertices > d.welded
        || d.faces as usize > mesh.triangles.len()
    {
        return Err(Error::Gpu(format!(
            "the preparation on the device counted {} welded and {} used vertices and {} faces \
             of a mesh of {} vertices and {} faces",
            d.welded,
            d.vertices,
            d.faces,
            mesh.positions.len(),
            mesh.triangles.len()
        )));
    }
    Ok(())
}
