//! How the rounds' steps become compute passes: each buffer a schedule names, each stage's
//! grid, bind group and timestamps, and dispatches kept in one pass while nothing else needs
//! the encoder.

use super::*;

impl Runner<Buf, schedule::Grid, Count, RoundStep> for GpuRounds<'_> {
    /// The buffer bound for `buf`; `scan` is the prefix sum's (count, data) when one runs.
    fn buffer(&self, buf: Buf, scan: Option<(Count, Buf)>) -> &wgpu::Buffer {
        let (h, o) = (&self.half[self.cur], &self.half[1 - self.cur]);
        match buf {
            Buf::Params => &self.params,
            Buf::ScanCount => match scan.map(|s| s.0) {
                Some(Count::Faces) => &self.scan_f,
                Some(Count::EdgeSlots) => &self.scan_e,
                // A prefix sum always names its count; vertices otherwise.
                Some(Count::Vertices) | None => &self.scan_v,
            },
            Buf::ScanData => match scan {
                Some((_, data)) if data != Buf::ScanData => self.buffer(data, None),
                _ => &self.offsets,
            },
            Buf::BlockSums => &self.block_sums,
            Buf::Positions => &h.positions,
            Buf::Quadrics => &h.quadrics,
            Buf::Flags => &h.flags,
            Buf::VertexAttr => &h.vertex_attr,
            Buf::Indices => &h.indices,
            Buf::FaceNormals => &h.face_normals,
            Buf::FaceExtra => &h.face_extra,
            Buf::PositionsOut => &o.positions,
            Buf::QuadricsOut => &o.quadrics,
            Buf::FlagsOut => &o.flags,
            Buf::VertexAttrOut => &o.vertex_attr,
            Buf::IndicesOut => &o.indices,
            Buf::FaceNormalsOut => &o.face_normals,
            Buf::FaceExtraOut => &o.face_extra,
            Buf::Offsets => &self.offsets,
            Buf::Cursor => &self.cursor,
            Buf::VertexFaces => &self.vertex_faces,
            Buf::EdgeOffsets => &self.edge_offsets,
            Buf::Neighbours => &self.neighbours,
            Buf::Remap => &self.remap,
            Buf::Edges => &self.edges,
            Buf::Candidates => &self.candidates,
            Buf::EdgeState => &self.edge_state,
            Buf::Histogram => &self.histogram,
            Buf::Live => &self.live,
            Buf::VertexLock => &self.vertex_lock,
            Buf::FaceBest => &self.face_best,
            Buf::FaceId => &self.face_id,
            Buf::Tentative => &self.tentative,
            Buf::TrimHistogram => &self.trim_histogram,
            Buf::Marks => &self.marks,
            Buf::VertexKeep => &self.vertex_keep,
            Buf::FaceKeep => &self.face_keep,
            Buf::Counters => &self.counters,
            Buf::Dispatch => &self.dispatch,
            Buf::DrawArgs => &self.draw_args,
            Buf::AttrValues => &self.attr_values,
            Buf::AttrSums => &self.attr_sums,
            Buf::Plan => &self.plan,
            Buf::Planned => &self.planned,
            Buf::FaceGroup => &self.face_group,
            Buf::GroupTarget => &self.group_target,
            Buf::GroupCount => &self.group_count,
            Buf::GroupClosed => &self.group_closed,
            Buf::GroupErr => &self.group_err,
        }
    }

    /// One compute pass of `stage` with its bindings in the shader's order, over its grid.
    fn run(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        stage: &'static Stage,
        scan: Option<(Count, Buf)>,
    ) {
        let p = &self.round_params;
        let wg = |n: u32| Groups::Direct(n.div_ceil(WG));
        let planned = match stage.grid {
            _ if !self.planned_round => None,
            grid => Self::planned_grid(grid, scan.map(|s| s.0), self.trimming),
        };
        let (groups, args) = match (planned, stage.grid) {
            (Some(at), _) => (Groups::Indirect(at), &self.planned),
            (None, schedule::Grid::Each(count)) => (wg(count.of(p)), &self.dispatch),
            (None, schedule::Grid::VerticesOrFaces) => {
                (wg(p.vertex_count.max(p.face_count)), &self.dispatch)
            }
            (None, schedule::Grid::ScanBlocks) => {
                let n = scan.map_or(p.vertex_count, |(count, _)| count.of(p));
                (Groups::Direct(n.div_ceil(SCAN_BLOCK)), &self.dispatch)
            }
            (None, schedule::Grid::One | schedule::Grid::Planner) => {
                (Groups::Direct(1), &self.dispatch)
            }
            (None, indirect) => (
                Groups::Indirect(indirect.indirect_offset().unwrap_or(0)),
                &self.dispatch,
            ),
        };
        let bound = stage.bindings.iter();
        let key: BindKey = (
            stage.entry,
            bound.map(|b| self.buffer(b.buf, scan).clone()).collect(),
        );
        if !self.bind_groups.contains_key(&key) {
            let bg = self
                .sim
                .kernels
                .bind_group(&self.sim.device, stage, |b| self.buffer(b, scan));
            Costs::add(&self.costs.bind_groups, 1);
            self.bind_groups.insert(key.clone(), bg);
        }
        let bg = &self.bind_groups[&key];
        // wgpu encodes each compute pass into command buffers of its own, so a pass per
        // dispatch made the 1M scan's ~1,800 dispatches cost 0.023 s of host time to submit.
        // They share a pass unless each must be submitted alone, or the device can only
        // stamp the bounds of a pass.
        let grouped = !self.share_queue && (self.queries.is_none() || self.sim.stamps_in_passes);
        let slot = self.next_slot;
        if grouped {
            let (pass, last) = self.pass.get_or_insert_with(|| {
                let desc = wgpu::ComputePassDescriptor {
                    label: Some("meshslim.rounds"),
                    timestamp_writes: None,
                };
                (enc.begin_compute_pass(&desc).forget_lifetime(), None)
            });
            let set = self.queries.as_ref().map(|q| &q.0);
            let mut slot = slot;
            if let Some(set) = set
                && last.is_none()
                && slot + 2 <= QUERY_CAP
            {
                pass.write_timestamp(set, slot);
                *last = Some(slot);
                slot += 1;
            }
            self.sim
                .kernels
                .dispatch_in(pass, stage, bg, groups, Some(args));
            match (set, *last) {
                (Some(set), Some(before)) if slot < QUERY_CAP => {
                    pass.write_timestamp(set, slot);
                    self.query_stages.push((stage.entry, before));
                    *last = Some(slot);
                    slot += 1;
                }
                _ => *last = None,
            }
            self.next_slot = slot;
        } else {
            let timestamps = match &self.queries {
                Some((set, _)) if slot + 2 <= QUERY_CAP => {
                    self.query_stages.push((stage.entry, slot));
                    self.next_slot += 2;
                    Some(wgpu::ComputePassTimestampWrites {
                        query_set: set,
                        beginning_of_pass_write_index: Some(slot),
                        end_of_pass_write_index: Some(slot + 1),
                    })
                }
                _ => None,
            };
            self.sim
                .kernels
                .pass_bound(enc, stage, bg, groups, Some(args), timestamps);
        }
        Costs::add(&self.costs.dispatches, 1);
        if self.share_queue {
            // Submit this pass alone and wait for it, so that work others put on the queue
            // meanwhile (the viewer's frames) runs between passes instead of after the round.
            let done = std::mem::replace(
                enc,
                self.sim
                    .device
                    .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                        label: Some("meshslim.round"),
                    }),
            );
            let index = self.submit(done);
            // A failed wait shows up at the round's own wait, which reports it.
            let t = Instant::now();
            let _ = self.sim.device.poll(wgpu::PollType::Wait {
                submission_index: Some(index),
                timeout: None,
            });
            Costs::add(&self.costs.waits, 1);
            Costs::add(&self.costs.blocked_ns, t.elapsed().as_nanos() as u64);
        }
    }

    fn own(&mut self, enc: &mut wgpu::CommandEncoder, step: RoundStep) {
        if step != RoundStep::CheckWinners {
            self.end_pass();
        }
        match step {
            RoundStep::ClearTentative => {
                enc.clear_buffer(&self.counters, TENTATIVE_OFFSET, Some(4))
            }
            // The GPU's winners are checked by the tests against the CPU twin; nothing on the
            // device writes through unchecked host memory.
            RoundStep::CheckWinners => {}
            RoundStep::ApplyPlan => self.apply_plan(enc),
        }
    }

    fn prefix_sum(&self) -> [&'static Stage; 3] {
        schedule::PREFIX_SUM
    }

    fn end_pass(&mut self) {
        // Dropping a pass ends it.
        self.pass = None;
    }
}
