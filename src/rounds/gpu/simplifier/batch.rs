//! The rounds' submissions and read-backs: a round with the host's parameters, a batch of
//! rounds planned on the device between two waits, the one read-back of the result, and the
//! count of what each costs on the device's side.

use super::*;
use crate::compute::types::{PlanState, Planned, grid_slot};

/// Bytes of the planner's state, read back after a batch.
const PLAN_BYTES: u64 = std::mem::size_of::<PlanState>() as u64;
/// Bytes of a batch's log entry: a round's counters, then its parameters.
const LOG_BYTES: u64 = COUNTERS_BYTES + std::mem::size_of::<Params>() as u64;
/// Where `Planned`'s parts sit, for the copies into the uniforms and the indirect grids.
const PLANNED_SCANS: u64 = std::mem::offset_of!(Planned, scans) as u64;
const PLANNED_GRIDS: u64 = std::mem::offset_of!(Planned, grids) as u64;

/// Bytes of the read-back buffer: a round's counters or a batch's plan and log, then the
/// timestamps.
pub(super) const READBACK_BYTES: u64 =
    PLAN_BYTES + crate::rounds::BATCH_ROUNDS as u64 * LOG_BYTES + QUERY_CAP as u64 * 8;

impl GpuRounds<'_> {
    /// Submits `enc`, counted.
    pub(super) fn submit(&self, enc: wgpu::CommandEncoder) -> wgpu::SubmissionIndex {
        Costs::add(&self.costs.submits, 1);
        self.sim.queue.submit([enc.finish()])
    }

    /// `data` into `buf` at `offset` through the queue, counted.
    pub(super) fn write(&self, buf: &wgpu::Buffer, offset: u64, data: &[u8]) {
        Costs::add(&self.costs.uploaded, data.len() as u64);
        self.sim.queue.write_buffer(buf, offset, data);
    }

    /// Maps `buf` for reading and waits for it: one round trip, counted with its seconds.
    pub(super) fn map_wait(&self, buf: &wgpu::Buffer) -> Result<f64> {
        let (outcome, waited) = crate::compute::context::map_and_wait(&self.sim.device, buf);
        Costs::add(&self.costs.waits, 1);
        Costs::add(&self.costs.blocked_ns, (waited * 1e9) as u64);
        outcome.map_err(Error::Gpu)?;
        Ok(waited)
    }

    /// The round's parameters and prefix-sum counts into the uniforms.
    fn write_params(&self, p: &Params) {
        let sp = |n: u32| ScanParams { n, _pad: [0; 3] };
        self.write(&self.params, 0, bytemuck::bytes_of(p));
        self.write(&self.scan_v, 0, bytemuck::bytes_of(&sp(p.vertex_count)));
        self.write(&self.scan_f, 0, bytemuck::bytes_of(&sp(p.face_count)));
        self.write(&self.scan_e, 0, bytemuck::bytes_of(&sp(p.edge_capacity)));
    }

    /// The planner's round into the uniforms its stages bind ([`RoundStep::ApplyPlan`]).
    pub(super) fn apply_plan(&self, enc: &mut wgpu::CommandEncoder) {
        let params = std::mem::size_of::<Params>() as u64;
        enc.copy_buffer_to_buffer(&self.planned, 0, &self.params, 0, params);
        for (i, scan) in [&self.scan_v, &self.scan_f, &self.scan_e]
            .iter()
            .enumerate()
        {
            enc.copy_buffer_to_buffer(&self.planned, PLANNED_SCANS + 16 * i as u64, scan, 0, 16);
        }
    }

    /// The grid of a stage over `grid` in a planned round: the planner's slot for it (its trim
    /// slots while `trimming`).
    pub(super) fn planned_grid(
        grid: schedule::Grid,
        scan: Option<Count>,
        trimming: bool,
    ) -> Option<u64> {
        let count = |c: Count| match c {
            Count::Vertices => 0,
            Count::Faces => 1,
            Count::EdgeSlots => 2,
        };
        let slot = match grid {
            schedule::Grid::Each(Count::EdgeSlots) if trimming => grid_slot::TRIM_EDGE_SLOTS,
            schedule::Grid::ScanBlocks if trimming => grid_slot::TRIM_SCAN,
            schedule::Grid::One if trimming => grid_slot::TRIM_ONE,
            schedule::Grid::Each(c) => grid_slot::VERTICES + count(c),
            schedule::Grid::VerticesOrFaces => grid_slot::VERTICES_OR_FACES,
            schedule::Grid::ScanBlocks => {
                grid_slot::SCAN_VERTICES + count(scan.unwrap_or(Count::Vertices))
            }
            schedule::Grid::One => grid_slot::ONE,
            _ => return None,
        };
        Some(PLANNED_GRIDS + 16 * slot as u64)
    }

    /// Records one round's steps after the counters are cleared; `first` runs the set-up,
    /// `planned` records it as planned on the device (every part, the trim included, over the
    /// planner's grids). Exhaustive selection submits `enc` every few passes to look at the
    /// last pass's count.
    fn record_round(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        p: &Params,
        first: bool,
        planned: bool,
        selection: Selection,
    ) -> Result<()> {
        self.planned_round = planned;
        for &(when, steps) in schedule::ROUND {
            match when {
                When::Planned => {}
                When::EachSelectionPass => {
                    for pass in 0u32.. {
                        match selection {
                            Selection::Ordinary if pass == self.selection_passes => break,
                            // Exhaustive: every EXHAUSTIVE_CHUNK passes, submit what is
                            // recorded and read the last pass's tentative count; none means
                            // no candidate is left to settle.
                            Selection::Exhaustive if pass > 0 && pass % EXHAUSTIVE_CHUNK == 0 => {
                                self.end_pass();
                                let done = std::mem::replace(enc, self.encoder());
                                self.submit(done);
                                let now: Counters = *bytemuck::from_bytes(
                                    &self.read(&self.counters, COUNTERS_BYTES)?,
                                );
                                if now.tentative == 0 {
                                    break;
                                }
                            }
                            _ => {}
                        }
                        self.record(enc, p, steps);
                    }
                }
                When::Trimming if planned => {
                    self.trimming = true;
                    self.record(enc, p, steps);
                    self.trimming = false;
                }
                w if w.runs_once(first, self.carried_quadrics, p) => self.record(enc, p, steps),
                _ => {}
            }
        }
        self.planned_round = false;
        self.end_pass();
        Ok(())
    }

    pub(super) fn encoder(&self) -> wgpu::CommandEncoder {
        self.sim
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("meshslim.round"),
            })
    }

    /// The stamps before and after each timed dispatch into the stage times, or the wall
    /// time when the device has none.
    fn add_times(&mut self, stamps: &[u64], wall: f64) {
        if self.queries.is_some() && !stamps.is_empty() {
            let period = self.sim.queue.get_timestamp_period() as f64 * 1e-9;
            for &(stage, at) in &self.query_stages {
                let at = at as usize;
                let d = stamps[at + 1].saturating_sub(stamps[at]);
                self.times.add(stage, d as f64 * period);
            }
        } else {
            self.times.add("round (wall, no timestamps)", wall);
        }
    }

    /// Resolves the pass timestamps recorded so far into the read-back at `at`; the slots used.
    fn resolve_times(&self, enc: &mut wgpu::CommandEncoder, at: u64) -> u32 {
        let used = self.next_slot;
        if let Some((set, resolve)) = &self.queries
            && used > 0
        {
            enc.resolve_query_set(set, 0..used, resolve, 0);
            enc.copy_buffer_to_buffer(resolve, 0, &self.readback, at, used as u64 * 8);
        }
        used
    }

    /// Submits `enc`, waits for the read-back and hands its first `bytes` and the `used`
    /// timestamp slots after `at` to `f`.
    fn finish_read<T>(
        &mut self,
        enc: wgpu::CommandEncoder,
        bytes: u64,
        at: u64,
        used: u32,
        doing: &str,
        f: impl FnOnce(&[u8]) -> T,
    ) -> Result<(T, Vec<u64>, f64)> {
        self.submit(enc);
        let wall = self.map_wait(&self.readback)?;
        let view = self
            .readback
            .get_mapped_range(..)
            .map_err(|e| Error::Gpu(format!("{doing}: {e}")))?;
        let out = f(&view[..bytes as usize]);
        let stamps: Vec<u64> =
            bytemuck::pod_collect_to_vec(&view[at as usize..at as usize + used as usize * 8]);
        drop(view);
        self.readback.unmap();
        Costs::add(&self.costs.read_back, bytes + used as u64 * 8);
        Ok((out, stamps, wall))
    }
}

impl RoundRunner for GpuRounds<'_> {
    fn round(&mut self, p: &Params, first: bool, selection: Selection) -> Result<Counters> {
        let scope = ErrorScope::push(&self.sim.device);
        self.write_params(p);
        self.query_stages.clear();
        self.next_slot = 0;
        let mut enc = self.encoder();
        enc.clear_buffer(&self.counters, 0, None);
        if let Err(e) = self.record_round(&mut enc, p, first, false, selection) {
            return scope.check_with("running a round", Err(e));
        }
        enc.copy_buffer_to_buffer(&self.counters, 0, &self.readback, 0, COUNTERS_BYTES);
        let used = self.resolve_times(&mut enc, COUNTERS_BYTES);
        let read = self.finish_read(
            enc,
            COUNTERS_BYTES,
            COUNTERS_BYTES,
            used,
            "running a round",
            |b| *bytemuck::from_bytes::<Counters>(b),
        );
        let (c, stamps, wall) = match read {
            Ok(r) => r,
            Err(e) => return scope.check_with("running a round", Err(e)),
        };
        scope.check("running a round")?;
        self.wait_seconds += wall;
        self.add_times(&stamps, wall);
        self.cur = 1 - self.cur;
        self.live_counts = (c.vertices_out, c.faces_out);
        Ok(c)
    }

    /// Up to `most` rounds in one submission: the first with the host's `p`, each later one
    /// planned on the device (`plan_round`) from the last one's counters, every grid zero once
    /// the batch stops; one wait reads back the planner's state and each round's counters and
    /// parameters.
    fn rounds(&mut self, p: &Params, first: bool, most: usize) -> Result<Vec<(Params, Counters)>> {
        let most = most.clamp(1, crate::rounds::BATCH_ROUNDS);
        let scope = ErrorScope::push(&self.sim.device);
        self.write_params(p);
        let plan = PlanState {
            vertices: p.vertex_count,
            faces: p.face_count,
            target_faces: p.target_faces,
            executed: 1,
            max_groups: self.sim.kernels.max_workgroups(),
            ..Default::default()
        };
        self.write(&self.plan, 0, bytemuck::bytes_of(&plan));
        self.query_stages.clear();
        self.next_slot = 0;
        let cur = self.cur;
        let mut enc = self.encoder();
        for j in 0..most {
            if j > 0 {
                self.record(&mut enc, p, schedule::PLAN);
                self.end_pass();
            }
            enc.clear_buffer(&self.counters, 0, None);
            if let Err(e) =
                self.record_round(&mut enc, p, first && j == 0, j > 0, Selection::Ordinary)
            {
                return scope.check_with("running a batch of rounds", Err(e));
            }
            let at = PLAN_BYTES + j as u64 * LOG_BYTES;
            enc.copy_buffer_to_buffer(&self.counters, 0, &self.readback, at, COUNTERS_BYTES);
            let pb = std::mem::size_of::<Params>() as u64;
            enc.copy_buffer_to_buffer(&self.params, 0, &self.readback, at + COUNTERS_BYTES, pb);
            self.cur = 1 - self.cur;
        }
        enc.copy_buffer_to_buffer(&self.plan, 0, &self.readback, 0, PLAN_BYTES);
        let bytes = PLAN_BYTES + most as u64 * LOG_BYTES;
        let used = self.resolve_times(&mut enc, bytes);
        let read = self.finish_read(enc, bytes, bytes, used, "running a batch of rounds", |b| {
            let plan: PlanState = bytemuck::pod_read_unaligned(&b[..PLAN_BYTES as usize]);
            let log: Vec<(Params, Counters)> = (0..most)
                .map(|j| {
                    let at = (PLAN_BYTES + j as u64 * LOG_BYTES) as usize;
                    let c = bytemuck::pod_read_unaligned(&b[at..at + COUNTERS_BYTES as usize]);
                    let p = bytemuck::pod_read_unaligned(
                        &b[at + COUNTERS_BYTES as usize..at + LOG_BYTES as usize],
                    );
                    (p, c)
                })
                .collect();
            (plan, log)
        });
        let ((plan, mut log), stamps, wall) = match read {
            Ok(r) => r,
            Err(e) => return scope.check_with("running a batch of rounds", Err(e)),
        };
        scope.check("running a batch of rounds")?;
        let ran = plan.executed as usize;
        if ran == 0 || ran > most {
            return Err(Error::Internal(format!(
                "the planner says {ran} of a batch's {most} rounds ran"
            )));
        }
        self.wait_seconds += wall;
        self.add_times(&stamps, wall);
        // Rounds past the stop dispatched nothing: the mesh is where the last one that ran
        // compacted it.
        self.cur = (cur + ran) % 2;
        log.truncate(ran);
        let last = log[ran - 1].1;
        self.live_counts = (last.vertices_out, last.faces_out);
        Ok(log)
    }

    fn batch(&self) -> usize {
        if self.share_queue {
            // A window's frames come between passes anyway; the batch changes nothing there.
            1
        } else {
            crate::rounds::BATCH_ROUNDS
        }
    }

    /// The current mesh in one copy: every buffer the output needs, side by side in one
    /// staging buffer, one submission and one wait.
    fn download(&mut self) -> Result<Download> {
        let t = Instant::now();
        let (nv, nf) = (self.live_counts.0 as u64, self.live_counts.1 as u64);
        let h = &self.half[self.cur];
        let parts: [(&wgpu::Buffer, u64); 7] = [
            (&h.positions, nv * 16),
            (&h.flags, nv * 4),
            (&h.vertex_attr, nv * 4),
            (&h.indices, nf * 12),
            (&h.face_extra, if self.face_extra_out { nf * 16 } else { 0 }),
            (&self.attr_values, self.attr_len * 4),
            (&self.group_err, self.groups * 4),
        ];
        let total: u64 = parts.iter().map(|p| p.1).sum();
        let dev = &self.sim.device;
        let scope = ErrorScope::push(dev);
        let staging = checked_buffer(
            dev,
            "meshslim.download",
            total,
            wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        )?;
        let mut enc = dev.create_command_encoder(&Default::default());
        let mut at = 0;
        for &(buf, bytes) in &parts {
            if bytes > 0 {
                enc.copy_buffer_to_buffer(buf, 0, &staging, at, bytes);
            }
            at += bytes;
        }
        self.submit(enc);
        if let Err(e) = self.map_wait(&staging) {
            return scope.check_with("reading back the result", Err(e));
        }
        let d = {
            let view = staging
                .get_mapped_range(..)
                .map_err(|e| Error::Gpu(format!("reading back the result: {e}")))?;
            let mut at = 0usize;
            let mut next = |bytes: u64| {
                let s = &view[at..at + bytes as usize];
                at += bytes as usize;
                s
            };
            Download {
                positions: bytemuck::pod_collect_to_vec(next(parts[0].1)),
                flags: bytemuck::pod_collect_to_vec(next(parts[1].1)),
                vertex_attr: bytemuck::pod_collect_to_vec(next(parts[2].1)),
                indices: bytemuck::pod_collect_to_vec(next(parts[3].1)),
                face_extra: bytemuck::pod_collect_to_vec(next(parts[4].1)),
                attr_values: bytemuck::pod_collect_to_vec(next(parts[5].1)),
                group_err: bytemuck::pod_collect_to_vec(next(parts[6].1)),
            }
        };
        staging.unmap();
        scope.check("reading back the result")?;
        Costs::add(&self.costs.read_back, total);
        self.transfer_seconds += t.elapsed().as_secs_f64();
        Ok(d)
    }

    fn stage_times(&self) -> &StageTimes {
        &self.times
    }
}
