//! The GPU side every family shares: one pipeline cache per device, one way to catch the
//! device's errors (error scopes, never a handler on a device that may be borrowed), and one
//! recorder of a stage's compute pass (bind group from its description, workgroups split over y
//! beyond the device's per-dimension limit, timestamps when asked).

use super::schedule::{Stage, Step};
use crate::error::{Error, Result};
use std::collections::HashMap;
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// Compute pipelines by entry point, made once per device and shared by every family on it: the
/// rounds, the clustering and a viewer's window on one device compile the prefix sum, the
/// vertex→face lists and the face planes once. Whoever owns the device makes its cache (the
/// process's shared [`crate::compute::context::GpuContext`] holds one; the viewer's window makes
/// one for both families when it opens) and hands it to each family; there is no process-wide
/// registry, since a `wgpu::Device` compares by an id that devices of two instances can share.
pub struct Pipelines {
    device: wgpu::Device,
    made: Mutex<HashMap<&'static str, wgpu::ComputePipeline>>,
    /// The driver's compiled pipelines kept on disk between processes, where the adapter can.
    disk: Option<super::disk_cache::DiskCache>,
}

impl Pipelines {
    /// An empty cache for `device`, kept in memory only.
    pub fn new(device: &wgpu::Device) -> Arc<Pipelines> {
        Arc::new(Pipelines {
            device: device.clone(),
            made: Mutex::new(HashMap::new()),
            disk: None,
        })
    }

    /// An empty cache for `device` (made on the adapter `info`), its pipelines compiled
    /// through the on-disk cache of that adapter in the user's cache folder when the device
    /// keeps one ([`super::disk_cache`]).
    pub fn with_disk_cache(device: &wgpu::Device, info: &wgpu::AdapterInfo) -> Arc<Pipelines> {
        match super::disk_cache::cache_dir() {
            Some(dir) => Pipelines::with_disk_cache_in(device, info, &dir),
            None => Pipelines::new(device),
        }
    }

    /// As [`Pipelines::with_disk_cache`], the cache file in the folder `dir`.
    pub fn with_disk_cache_in(
        device: &wgpu::Device,
        info: &wgpu::AdapterInfo,
        dir: &std::path::Path,
    ) -> Arc<Pipelines> {
        Arc::new(Pipelines {
            device: device.clone(),
            made: Mutex::new(HashMap::new()),
            disk: super::disk_cache::DiskCache::open(device, info, dir),
        })
    }

    /// The file the device's pipelines are kept in between processes, if any.
    pub fn cache_file(&self) -> Option<&std::path::Path> {
        self.disk.as_ref().map(|d| d.path())
    }

    /// How this device's pipelines are found: from the file on disk, compiled into it, or
    /// without one.
    pub fn cache_status(&self) -> super::disk_cache::CacheStatus {
        self.disk
            .as_ref()
            .map_or(super::disk_cache::CacheStatus::Unsupported, |d| d.status)
    }

    /// The device the pipelines are made on.
    pub fn device(&self) -> &wgpu::Device {
        &self.device
    }

    /// The entry points compiled so far.
    pub fn compiled(&self) -> Vec<&'static str> {
        let made = self.made.lock().unwrap_or_else(|p| p.into_inner());
        let mut entries: Vec<&'static str> = made.keys().copied().collect();
        entries.sort_unstable();
        entries
    }

    /// The pipelines of `stages`, compiling those this device has not made yet: entry point →
    /// pipeline, and the seconds spent compiling. Each shader's module and pipelines are made
    /// on a core of their own (a driver compiles them one by one otherwise), each under its
    /// own error scope, since wgpu's scopes are per thread.
    pub fn get<B, G>(
        &self,
        stages: &[&'static Stage<B, G>],
    ) -> Result<(HashMap<&'static str, wgpu::ComputePipeline>, f64)> {
        use rayon::prelude::*;
        let t = Instant::now();
        let mut made = self.made.lock().unwrap_or_else(|p| p.into_inner());
        let mut shaders: Vec<(&'static str, Vec<&'static str>)> = Vec::new();
        for s in stages.iter().filter(|s| !made.contains_key(s.entry)) {
            match shaders.iter_mut().find(|(sh, _)| *sh == s.shader) {
                Some((_, entries)) if !entries.contains(&s.entry) => entries.push(s.entry),
                Some(_) => {}
                None => shaders.push((s.shader, vec![s.entry])),
            }
        }
        let cache = self.disk.as_ref().map(|d| &d.cache);
        let compiled: Vec<Result<Vec<(&'static str, wgpu::ComputePipeline)>>> = shaders
            .par_iter()
            .map(|(shader, entries)| {
                let scope = ErrorScope::push(&self.device);
                // Every described stage's shader is in SOURCES (the schedules' tests check it).
                let src = super::shaders::stage_source(shader).unwrap_or_default();
                let module = self
                    .device
                    .create_shader_module(wgpu::ShaderModuleDescriptor {
                        label: Some(shader),
                        source: wgpu::ShaderSource::Wgsl(src.into()),
                    });
                let pipelines = entries
                    .iter()
                    .map(|&entry| {
                        let label = format!("meshslim.{entry}");
                        let p =
                            self.device
                                .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                                    label: Some(&label),
                                    layout: None,
                                    module: &module,
                                    entry_point: Some(entry),
                                    compilation_options: Default::default(),
                                    cache,
                                });
                        (entry, p)
                    })
                    .collect();
                scope.check(&format!(
                    "creating the compute pipelines of shaders/{shader}.wgsl"
                ))?;
                Ok(pipelines)
            })
            .collect();
        // The pipelines of a shader that failed are not kept: the next caller sees the error
        // again.
        let mut first_error = None;
        let mut new = 0;
        for r in compiled {
            match r {
                Ok(pipelines) => {
                    new += pipelines.len();
                    made.extend(pipelines)
                }
                Err(e) => first_error = first_error.or(Some(e)),
            }
        }
        if let Some(e) = first_error {
            return Err(e);
        }
        if new > 0
            && let Some(disk) = &self.disk
        {
            disk.save();
        }
        let out = stages
            .iter()
            .map(|s| (s.entry, made[s.entry].clone()))
            .collect();
        Ok((out, t.elapsed().as_secs_f64()))
    }
}

/// A family's compiled stages on one device: what its runner needs to record a pass.
pub struct Kernels {
    pipelines: HashMap<&'static str, wgpu::ComputePipeline>,
    /// The device's `max_compute_workgroups_per_dimension`, read once.
    max_workgroups: u32,
    /// Seconds spent compiling the shaders and creating the pipelines this family did not
    /// find in the device's cache.
    pub seconds: f64,
}

impl Kernels {
    /// The pipelines of the family's stage `lists` from the device's `cache`, after checking
    /// that the device binds as many storage buffers per stage as the family's widest stage;
    /// `family` names it in the error.
    pub fn new<B, G>(
        cache: &Pipelines,
        lists: &[&[&'static Stage<B, G>]],
        family: &str,
    ) -> Result<Kernels> {
        let device = cache.device();
        let stages: Vec<&'static Stage<B, G>> =
            lists.iter().flat_map(|l| l.iter().copied()).collect();
        let stages = &stages[..];
        let limits = device.limits();
        let most = stages
            .iter()
            .map(|s| s.storage_buffers())
            .max()
            .unwrap_or(0) as u32;
        if limits.max_storage_buffers_per_shader_stage < most {
            return Err(Error::Gpu(format!(
                "the device binds at most {} storage buffers per stage; {family} needs {most}",
                limits.max_storage_buffers_per_shader_stage
            )));
        }
        let (pipelines, seconds) = cache.get(stages)?;
        Ok(Kernels {
            pipelines,
            max_workgroups: limits.max_compute_workgroups_per_dimension,
            seconds,
        })
    }

    /// The device's workgroups per dimension: a grid past it is split over y.
    pub fn max_workgroups(&self) -> u32 {
        self.max_workgroups
    }

    /// The bind group of `stage` on the buffers `bind` gives (each binding's buffer, in binding
    /// order, on the layout of its pipeline), to record passes with ([`Kernels::pass_bound`]) as
    /// long as those buffers live: a family that keeps its buffers makes each once, not once a
    /// pass.
    pub fn bind_group<'b, B: Copy, G>(
        &self,
        device: &wgpu::Device,
        stage: &Stage<B, G>,
        bind: impl Fn(B) -> &'b wgpu::Buffer,
    ) -> wgpu::BindGroup {
        let layout = self.pipelines[stage.entry].get_bind_group_layout(0);
        let entries: Vec<wgpu::BindGroupEntry> = stage
            .bindings
            .iter()
            .enumerate()
            .map(|(i, b)| wgpu::BindGroupEntry {
                binding: i as u32,
                resource: bind(b.buf).as_entire_binding(),
            })
            .collect();
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(stage.entry),
            layout: &layout,
            entries: &entries,
        })
    }

    /// One compute pass of `stage` with a bind group made by [`Kernels::bind_group`].
    pub fn pass_bound<B, G>(
        &self,
        enc: &mut wgpu::CommandEncoder,
        stage: &Stage<B, G>,
        bg: &wgpu::BindGroup,
        groups: Groups,
        indirect: Option<&wgpu::Buffer>,
        timestamps: Option<wgpu::ComputePassTimestampWrites>,
    ) {
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(stage.entry),
            timestamp_writes: timestamps,
        });
        self.dispatch_in(&mut pass, stage, bg, groups, indirect)
    }

    /// One dispatch of `stage` into an open compute pass, with a bind group made by
    /// [`Kernels::bind_group`], over `groups` (a direct count beyond the device's
    /// `max_compute_workgroups_per_dimension` is split over y; the shader folds y back into
    /// its index); `indirect` holds the arguments of an indirect grid. A family that records
    /// many dispatches back to back puts them in one pass, since wgpu encodes each pass into
    /// command buffers of its own.
    pub fn dispatch_in<B, G>(
        &self,
        pass: &mut wgpu::ComputePass,
        stage: &Stage<B, G>,
        bg: &wgpu::BindGroup,
        groups: Groups,
        indirect: Option<&wgpu::Buffer>,
    ) {
        let (label, pipeline) = (stage.entry, &self.pipelines[stage.entry]);
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, bg, &[]);
        match (groups, indirect) {
            (Groups::Indirect(offset), Some(args)) => {
                pass.dispatch_workgroups_indirect(args, offset)
            }
            (Groups::Indirect(_), None) => {
                unreachable!("{label}: an indirect grid without its arguments buffer")
            }
            (Groups::Direct(groups), _) => {
                let (groups, max_x) = (groups.max(1), self.max_workgroups);
                let (x, y) = if groups <= max_x {
                    (groups, 1)
                } else {
                    (max_x, groups.div_ceil(max_x))
                };
                pass.dispatch_workgroups(x, y, 1);
            }
        }
    }

    /// One compute pass of `stage` into `enc` on a bind group made for it from `bind` (see
    /// [`Kernels::bind_group`] and [`Kernels::dispatch_in`]), with `timestamps` when given.
    #[allow(clippy::too_many_arguments)]
    pub fn pass<'b, B: Copy, G>(
        &self,
        device: &wgpu::Device,
        enc: &mut wgpu::CommandEncoder,
        stage: &Stage<B, G>,
        bind: impl Fn(B) -> &'b wgpu::Buffer,
        groups: Groups,
        indirect: Option<&wgpu::Buffer>,
        timestamps: Option<wgpu::ComputePassTimestampWrites>,
    ) {
        let bg = self.bind_group(device, stage, bind);
        self.pass_bound(enc, stage, &bg, groups, indirect, timestamps)
    }
}

/// Validation, out-of-memory and internal (a driver's failed compile) errors of the work
/// between [`ErrorScope::push`] and [`ErrorScope::check`], on this thread (wgpu's scopes are per
/// thread, so a viewer's frames on another thread are not caught here, nor these there).
pub struct ErrorScope {
    // Declared innermost first: a scope dropped on an early return pops its guards in field
    // order, which must be the reverse of their pushes (wgpu panics on a mismatched pop).
    validation: wgpu::ErrorScopeGuard,
    memory: wgpu::ErrorScopeGuard,
    internal: wgpu::ErrorScopeGuard,
}

impl ErrorScope {
    pub fn push(device: &wgpu::Device) -> ErrorScope {
        let internal = device.push_error_scope(wgpu::ErrorFilter::Internal);
        let memory = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let validation = device.push_error_scope(wgpu::ErrorFilter::Validation);
        ErrorScope {
            validation,
            memory,
            internal,
        }
    }

    /// The first error the scope caught, as an error saying what was being done.
    pub fn check(self, doing: &str) -> Result<()> {
        // Scopes pop in the reverse order of their pushes.
        let validation = pollster::block_on(self.validation.pop());
        let memory = pollster::block_on(self.memory.pop());
        let internal = pollster::block_on(self.internal.pop());
        match validation.or(memory).or(internal) {
            Some(e) => Err(Error::Gpu(format!("{doing}: {e}"))),
            None => Ok(()),
        }
    }

    /// `result`, unless the scope caught the error behind it (a failed read-back after a
    /// refused pass): then that error, which says what went wrong first.
    pub fn check_with<T>(self, doing: &str, result: Result<T>) -> Result<T> {
        match result {
            Ok(v) => self.check(doing).map(|()| v),
            Err(e) => Err(self.check(doing).err().unwrap_or(e)),
        }
    }
}

/// How many workgroups a pass runs.
#[derive(Debug, Clone, Copy)]
pub enum Groups {
    Direct(u32),
    /// From an indirect-arguments buffer at this byte offset.
    Indirect(u64),
}

/// What a family's GPU runner gives the step interpreter ([`record`]): its buffers, its passes
/// and its own steps.
pub trait Runner<B: Copy + 'static, G: 'static, C: Copy, X: Copy> {
    /// The buffer bound for `buf`; `scan` is the prefix sum's (count, data) when one runs.
    fn buffer(&self, buf: B, scan: Option<(C, B)>) -> &wgpu::Buffer;
    /// One compute pass of `stage` (`scan` as for [`Runner::buffer`]).
    fn run(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        stage: &'static Stage<B, G>,
        scan: Option<(C, B)>,
    );
    /// The family's own step.
    fn own(&mut self, enc: &mut wgpu::CommandEncoder, step: X);
    /// The three passes of the family's prefix sum (`shared_stages!`'s `PREFIX_SUM`).
    fn prefix_sum(&self) -> [&'static Stage<B, G>; 3];
    /// Ends the compute pass [`Runner::run`] left open, if it keeps one: a clear or a copy
    /// records on the encoder itself, which an open pass locks. A runner that keeps passes
    /// open ends them before its own steps and its own uses of the encoder too.
    fn end_pass(&mut self) {}
}

/// Records a family's `steps` into `enc`: the one interpreter of the steps on the GPU. A pass
/// the runner keeps open stays open after the last step ([`Runner::end_pass`]).
pub fn record<B: Copy + 'static, G: 'static, C: Copy, X: Copy>(
    runner: &mut impl Runner<B, G, C, X>,
    enc: &mut wgpu::CommandEncoder,
    steps: &[Step<B, G, C, X>],
) {
    for step in steps {
        if matches!(step, Step::Clear(_) | Step::CopyBuffer(..)) {
            runner.end_pass();
        }
        match *step {
            Step::Clear(buf) => enc.clear_buffer(runner.buffer(buf, None), 0, None),
            Step::CopyBuffer(from, to) => {
                let (from, to) = (runner.buffer(from, None), runner.buffer(to, None));
                enc.copy_buffer_to_buffer(from, 0, to, 0, from.size().min(to.size()));
            }
            Step::Run(stage) => runner.run(enc, stage, None),
            Step::PrefixSum { count, data } => {
                for stage in runner.prefix_sum() {
                    runner.run(enc, stage, Some((count, data)));
                }
            }
            Step::Own(x) => runner.own(enc, x),
        }
    }
}
