//! The DAG's cut on the device: the clusters uploaded once, then per frame one pass of
//! `dag_cut` writes every cluster's indirect draw, which a renderer draws from without reading
//! anything back.

use super::schedule::{self as sched, DagBuf, DagGrid};
use crate::compute::context::{checked_buffer, checked_buffer_write, read_ranges};
use crate::compute::gpu::{ErrorScope, Groups, Kernels, Pipelines, Runner, record};
use crate::compute::types::{CornerDraw, CutCluster, CutParams, WG};
use crate::error::{Error, Result};

/// A DAG's clusters on the device and the buffers of its cut.
pub struct GpuCut {
    device: wgpu::Device,
    queue: wgpu::Queue,
    kernels: Kernels,
    clusters: u32,
    cut: wgpu::Buffer,
    cluster_buf: wgpu::Buffer,
    /// Per cluster: its indirect draw ([`CornerDraw`]), for `multi_draw_indirect`.
    pub draws: wgpu::Buffer,
    /// Clusters in the cut, clusters drawn, triangles drawn, a spare word.
    pub counts: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    /// Seconds spent compiling the stage (none when the device's cache had it).
    pub pipeline_seconds: f64,
}

impl GpuCut {
    /// The cut of `clusters` ([`super::Dag::cut_clusters`]) on the device of `cache`.
    pub fn new(cache: &Pipelines, queue: &wgpu::Queue, clusters: &[CutCluster]) -> Result<GpuCut> {
        let device = cache.device().clone();
        let kernels = Kernels::new(cache, sched::STAGES, "the DAG cut")?;
        let n = u32::try_from(clusters.len())
            .map_err(|_| Error::InvalidOption(format!("{} clusters", clusters.len())))?;
        let scope = ErrorScope::push(&device);
        use wgpu::BufferUsages as U;
        let cut = checked_buffer(
            &device,
            "meshslim.dag_cut.params",
            std::mem::size_of::<CutParams>() as u64,
            U::UNIFORM | U::COPY_DST,
        )?;
        let cluster_buf = checked_buffer_write(
            &device,
            queue,
            "meshslim.dag_cut.clusters",
            bytemuck::cast_slice(clusters),
            U::STORAGE,
        )?;
        let draws = checked_buffer(
            &device,
            "meshslim.dag_cut.draws",
            clusters.len() as u64 * std::mem::size_of::<CornerDraw>() as u64,
            U::STORAGE | U::INDIRECT | U::COPY_SRC,
        )?;
        let counts = checked_buffer(
            &device,
            "meshslim.dag_cut.counts",
            16,
            U::STORAGE | U::COPY_SRC | U::COPY_DST,
        )?;
        let bind_group = kernels.bind_group(&device, &sched::DAG_CUT, |b| match b {
            DagBuf::Cut => &cut,
            DagBuf::Clusters => &cluster_buf,
            DagBuf::Draws => &draws,
            DagBuf::CutCounts => &counts,
        });
        scope.check("uploading the DAG's clusters")?;
        Ok(GpuCut {
            device,
            queue: queue.clone(),
            pipeline_seconds: kernels.seconds,
            kernels,
            clusters: n,
            cut,
            cluster_buf,
            draws,
            counts,
            bind_group,
        })
    }

    /// The clusters on the device.
    pub fn clusters(&self) -> u32 {
        self.clusters
    }

    /// Records the cut for `p` into `enc` (its uniform written through the queue, so before
    /// the encoder's submission): after it, [`GpuCut::draws`] holds the frame's draws.
    pub fn record(&mut self, enc: &mut wgpu::CommandEncoder, p: &CutParams) {
        let p = CutParams {
            clusters: self.clusters,
            ..*p
        };
        self.queue
            .write_buffer(&self.cut, 0, bytemuck::bytes_of(&p));
        record(self, enc, sched::CUT);
    }

    /// The cut for `p`, run and read back: every cluster's draw and the counts (what the
    /// tests compare with the twin, and what `view --json` reports).
    pub fn run(&mut self, p: &CutParams) -> Result<(Vec<CornerDraw>, [u32; 4])> {
        let scope = ErrorScope::push(&self.device);
        let mut enc = self.device.create_command_encoder(&Default::default());
        self.record(&mut enc, p);
        self.queue.submit([enc.finish()]);
        scope.check("cutting the DAG")?;
        let bytes = self.clusters as u64 * std::mem::size_of::<CornerDraw>() as u64;
        let read = read_ranges(
            &self.device,
            &self.queue,
            &[(&self.draws, 0, bytes), (&self.counts, 0, 16)],
            "reading the cut",
        )?;
        let [draws, counts]: [Vec<u8>; 2] = read.try_into().expect("one part per range");
        Ok((
            bytemuck::pod_collect_to_vec(&draws),
            bytemuck::pod_read_unaligned(&counts),
        ))
    }
}

impl Runner<DagBuf, DagGrid, (), ()> for GpuCut {
    fn buffer(&self, buf: DagBuf, _scan: Option<((), DagBuf)>) -> &wgpu::Buffer {
        match buf {
            DagBuf::Cut => &self.cut,
            DagBuf::Clusters => &self.cluster_buf,
            DagBuf::Draws => &self.draws,
            DagBuf::CutCounts => &self.counts,
        }
    }

    fn run(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        stage: &'static sched::Stage,
        _scan: Option<((), DagBuf)>,
    ) {
        let groups = match stage.grid {
            DagGrid::EachCluster => Groups::Direct(self.clusters.div_ceil(WG)),
        };
        self.kernels
            .pass_bound(enc, stage, &self.bind_group, groups, None, None);
    }

    fn own(&mut self, _enc: &mut wgpu::CommandEncoder, _step: ()) {}

    fn prefix_sum(&self) -> [&'static sched::Stage; 3] {
        // `schedule::check_schedule` asserts that the cut's parts scan nothing.
        unreachable!("the DAG cut has no prefix sum")
    }
}
