//! `--method floating-cell` on the gpu backend: one floating-cell build at a nominal radius as
//! WGSL compute passes on a [`GpuClusterMesh`] (stages in `gpu_schedule.rs`, twins in
//! tests/cluster_twins/floating.rs). Once per mesh the grades and ranks, and the vertices sorted
//! by rank;
//! per build the hash grid's cells (by cell, then rank), rounds of `fc_decide` and `fc_claim`
//! recorded [`ROUND_SLOTS`] at a time with one counter per round read back per batch, then the
//! clusters numbered, sorted, placed and their faces found by the uniform grid's stages.

use super::floating::hash_grid;
use super::gpu::{ClusterBuild, GpuClusterMesh, Part};
use super::gpu_schedule::{
    self as sched, ClusterBuf, RANK_PASSES, ROUND_SLOTS, cluster_passes, float_params,
};
use crate::compute::common::V3;
use crate::compute::context::checked_buffer;
use crate::compute::context::{STORAGE, UNIFORM};
use crate::compute::gpu::ErrorScope;
use crate::error::{Error, Result};

/// A part of a floating-cell build recorded on its own (the tests read the buffers after each);
/// the sort passes, cells and faces are [`Part`]s.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FcPart {
    /// `fc_grades` and `fc_ranks`; then [`RANK_PASSES`] sort passes and [`FcPart::Order`].
    Ranks,
    Order,
    /// `fc_keys` and `fc_init` (after [`GpuClusterMesh::set_radius`]); then the hash grid's
    /// sort passes and [`Part::Cells`].
    Keys,
    /// The counters of a batch cleared.
    Batch,
    /// One round in the given slot.
    Round(u32),
    /// The centres numbered and the vertices keyed by cluster; then [`cluster_passes`] sort
    /// passes, [`Part::Cells`], [`FcPart::Quadrics`] and [`Part::Faces`].
    Clusters,
    Quadrics,
}

impl GpuClusterMesh<'_> {
    /// The floating cells' buffers, made on the first floating build of this mesh (a `cluster`
    /// run never pays for them).
    fn floating_buffers(&mut self) -> Result<()> {
        if !self.floats.is_empty() {
            return Ok(());
        }
        let dev = &self.sim.device;
        let v = self.nv as u64;
        let mk = |label: &str, size: u64, usage| {
            checked_buffer(dev, &format!("meshslim.{label}"), size, usage)
        };
        for (buf, label, size) in [
            (ClusterBuf::FcGrade, "fc_grade", 4 * v),
            (ClusterBuf::FcRank, "fc_rank", 4 * v),
            (ClusterBuf::FcOrder, "fc_order", 4 * v),
            (ClusterBuf::FcCentre, "fc_centre", 4 * v),
            (ClusterBuf::FcDecided, "fc_decided", 4 * v),
            (ClusterBuf::FcHead, "fc_head", 4 * (v + 1)),
            (ClusterBuf::FcLive, "fc_live", 4 * ROUND_SLOTS as u64),
        ] {
            let b = mk(label, size, STORAGE)?;
            self.bufs.insert(buf, b);
        }
        self.floats = (0..ROUND_SLOTS)
            .map(|j| mk(&format!("floating{j}"), 16, UNIFORM))
            .collect::<Result<Vec<_>>>()?;
        Ok(())
    }

    /// Sets the nominal radius of the next floating build: the hash grid (cells twice the
    /// largest radius wide over the box `[lo, hi]`) and every slot's uniform.
    pub fn set_radius(&mut self, lo: V3, hi: V3, r: f32) -> Result<()> {
        self.floating_buffers()?;
        self.set_grid(&hash_grid(lo, hi, r));
        for (j, b) in self.floats.iter().enumerate() {
            let f = float_params(r, j as u32);
            self.sim.queue.write_buffer(b, 0, bytemuck::bytes_of(&f));
        }
        Ok(())
    }

    /// Radix passes of the hash grid's keys (after [`Self::set_radius`]): locked vertices are
    /// keyed like the others, so no SINGLETON pass.
    pub fn hash_passes(&self) -> u32 {
        sched::radix_passes(&self.cluster, false)
    }

    fn record_fc(&mut self, enc: &mut wgpu::CommandEncoder, part: FcPart) {
        match part {
            FcPart::Ranks => self.record(enc, sched::FLOATING_RANKS),
            FcPart::Order => self.record(enc, sched::FLOATING_ORDER),
            FcPart::Keys => self.record(enc, sched::FLOATING_KEYS),
            FcPart::Batch => self.record(enc, sched::FLOATING_BATCH),
            FcPart::Round(slot) => {
                self.slot = slot as usize;
                self.record(enc, sched::FLOATING_ROUND);
            }
            FcPart::Clusters => self.record(enc, sched::FLOATING_CLUSTERS),
            FcPart::Quadrics => {
                self.slot = 0;
                self.record(enc, sched::FLOATING_QUADRICS);
            }
        }
    }

    /// Runs one floating part alone and waits for it.
    pub fn run_fc_part(&mut self, part: FcPart) -> Result<()> {
        let scope = ErrorScope::push(&self.sim.device);
        self.floating_buffers()?;
        let mut enc = self.sim.device.create_command_encoder(&Default::default());
        self.record_fc(&mut enc, part);
        self.sim.queue.submit([enc.finish()]);
        scope.check_with("running a floating-cell stage", self.wait())
    }

    /// The ranks and the rank order, once per mesh.
    fn rank(&mut self, enc: &mut wgpu::CommandEncoder) {
        if self.ranked {
            return;
        }
        self.record_fc(enc, FcPart::Ranks);
        for p in 0..RANK_PASSES {
            self.record_part(enc, Part::SortPass(p));
        }
        self.record_fc(enc, FcPart::Order);
        self.ranked = true;
    }

    /// One floating-cell clustering at nominal radius `r` in the box `[lo, hi]` (the points'
    /// bounds), and the rounds its centres took. Every vertex is claimed after at most as many
    /// rounds as vertices (each round the highest-ranked unclaimed vertex becomes a centre); more
    /// is a device fault and an error.
    pub fn build_floating(&mut self, lo: V3, hi: V3, r: f32) -> Result<(ClusterBuild, usize)> {
        let dev = self.sim.device.clone();
        let scope = ErrorScope::push(&dev);
        self.set_radius(lo, hi, r)?;
        let encoder = || {
            dev.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("meshslim.floating_build"),
            })
        };
        let mut enc = encoder();
        self.rank(&mut enc);
        self.record_fc(&mut enc, FcPart::Keys);
        for p in 0..self.hash_passes() {
            self.record_part(&mut enc, Part::SortPass(p));
        }
        self.record_part(&mut enc, Part::Cells);
        let mut rounds = 0usize;
        loop {
            self.record_fc(&mut enc, FcPart::Batch);
            for slot in 0..ROUND_SLOTS as u32 {
                self.record_fc(&mut enc, FcPart::Round(slot));
            }
            self.sim.queue.submit([enc.finish()]);
            let live = self.read_many(&[(ClusterBuf::FcLive, 0, 4 * ROUND_SLOTS as u64)])?;
            let live: Vec<u32> = bytemuck::pod_collect_to_vec(&live[0]);
            let busy = live.iter().take_while(|&&n| n > 0).count();
            rounds += busy;
            if busy < ROUND_SLOTS {
                break;
            }
            if rounds > self.nv {
                return Err(Error::Gpu(format!(
                    "floating cells: vertices still unclaimed after {rounds} rounds"
                )));
            }
            enc = encoder();
        }
        let mut enc = encoder();
        self.record_fc(&mut enc, FcPart::Clusters);
        for p in 0..cluster_passes(self.nv) {
            self.record_part(&mut enc, Part::SortPass(p));
        }
        self.record_part(&mut enc, Part::Cells);
        self.record_fc(&mut enc, FcPart::Quadrics);
        self.record_part(&mut enc, Part::Faces);
        self.sim.queue.submit([enc.finish()]);
        let b = scope.check_with("floating cells on the GPU", self.read_build())?;
        Ok((b, rounds))
    }
}
