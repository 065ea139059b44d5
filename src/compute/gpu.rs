//! The GPU side every family shares: one pipeline cache per device, one way to catch the
//! device's errors (error scopes, never a handler on a device that may be borrowed), and one
//! recorder of a stage's compute pass (bind group from its description, workgroups split over y
//! beyond the device's per-dimension limit, timestamps when asked).

use super::schedule::Stage;
use crate::error::{Error, Result};
use std::collections::HashMap;
use std::sync::{Arc, Mutex, Weak};
use std::time::Instant;

/// Compute pipelines by entry point, made once per device and shared by every family on it: the
/// rounds, the clustering and a viewer's window on one device compile the prefix sum, the
/// vertex→face lists and the face planes once.
pub struct Pipelines {
    device: wgpu::Device,
    made: Mutex<HashMap<&'static str, wgpu::ComputePipeline>>,
}

impl Pipelines {
    /// The cache of `device`: the one every family on it holds, made on first use. Held by
    /// [`Arc`]s; the registry keeps only a [`Weak`], so a dropped device is not kept alive.
    pub fn of(device: &wgpu::Device) -> Arc<Pipelines> {
        static CACHES: Mutex<Vec<Weak<Pipelines>>> = Mutex::new(Vec::new());
        let mut caches = CACHES.lock().unwrap_or_else(|p| p.into_inner());
        caches.retain(|w| w.strong_count() > 0);
        if let Some(p) = caches
            .iter()
            .filter_map(Weak::upgrade)
            .find(|p| &p.device == device)
        {
            return p;
        }
        let p = Arc::new(Pipelines {
            device: device.clone(),
            made: Mutex::new(HashMap::new()),
        });
        caches.push(Arc::downgrade(&p));
        p
    }

    /// The pipelines of `stages`, compiling those this device has not made yet (each shader
    /// module once): entry point → pipeline, and the seconds spent compiling.
    pub fn get<B, G>(
        &self,
        stages: &[&'static Stage<B, G>],
    ) -> Result<(HashMap<&'static str, wgpu::ComputePipeline>, f64)> {
        let t = Instant::now();
        let mut made = self.made.lock().unwrap_or_else(|p| p.into_inner());
        let scope = ErrorScope::push(&self.device);
        let mut modules: HashMap<&str, wgpu::ShaderModule> = HashMap::new();
        let missing: Vec<&Stage<B, G>> = stages
            .iter()
            .copied()
            .filter(|s| !made.contains_key(s.entry))
            .collect();
        for stage in missing {
            let module = modules.entry(stage.shader).or_insert_with(|| {
                let src = crate::gpu::shaders::stage_source(stage.shader).unwrap_or_default();
                self.device
                    .create_shader_module(wgpu::ShaderModuleDescriptor {
                        label: Some(stage.shader),
                        source: wgpu::ShaderSource::Wgsl(crate::gpu::shaders::source(src).into()),
                    })
            });
            let label = format!("meshslim.{}", stage.entry);
            let p = self
                .device
                .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some(&label),
                    layout: None,
                    module,
                    entry_point: Some(stage.entry),
                    compilation_options: Default::default(),
                    cache: None,
                });
            made.insert(stage.entry, p);
        }
        if let Err(e) = scope.check("creating the compute pipelines") {
            // A failed pipeline is not kept: the next caller sees the error again.
            for s in stages {
                made.remove(s.entry);
            }
            return Err(e);
        }
        let out = stages
            .iter()
            .map(|s| (s.entry, made[s.entry].clone()))
            .collect();
        Ok((out, t.elapsed().as_secs_f64()))
    }
}

/// Validation and out-of-memory errors of the work between [`ErrorScope::push`] and
/// [`ErrorScope::check`], on this thread (wgpu's scopes are per thread, so a viewer's frames on
/// another thread are not caught here, nor these there).
pub struct ErrorScope {
    validation: wgpu::ErrorScopeGuard,
    memory: wgpu::ErrorScopeGuard,
}

impl ErrorScope {
    pub fn push(device: &wgpu::Device) -> ErrorScope {
        let memory = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let validation = device.push_error_scope(wgpu::ErrorFilter::Validation);
        ErrorScope { validation, memory }
    }

    /// The first error the scope caught, as an error saying what was being done.
    pub fn check(self, doing: &str) -> Result<()> {
        // Scopes pop in the reverse order of their pushes.
        let validation = pollster::block_on(self.validation.pop());
        let memory = pollster::block_on(self.memory.pop());
        match validation.or(memory) {
            Some(e) => Err(Error::Gpu(format!("{doing}: {e}"))),
            None => Ok(()),
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

/// One compute pass: `pipeline` with `buffers` bound in binding order, over `groups` (a direct
/// count beyond `max_x` is split over y; the shader folds y back into its index), with
/// `timestamps` when given; `indirect` holds the arguments of an indirect grid.
#[allow(clippy::too_many_arguments)]
pub fn pass(
    device: &wgpu::Device,
    enc: &mut wgpu::CommandEncoder,
    label: &str,
    pipeline: &wgpu::ComputePipeline,
    buffers: &[&wgpu::Buffer],
    groups: Groups,
    max_x: u32,
    indirect: Option<&wgpu::Buffer>,
    timestamps: Option<wgpu::ComputePassTimestampWrites>,
) {
    let layout = pipeline.get_bind_group_layout(0);
    let entries: Vec<wgpu::BindGroupEntry> = buffers
        .iter()
        .enumerate()
        .map(|(i, b)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource: b.as_entire_binding(),
        })
        .collect();
    let bg = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout: &layout,
        entries: &entries,
    });
    let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
        label: Some(label),
        timestamp_writes: timestamps,
    });
    pass.set_pipeline(pipeline);
    pass.set_bind_group(0, &bg, &[]);
    match (groups, indirect) {
        (Groups::Indirect(offset), Some(args)) => pass.dispatch_workgroups_indirect(args, offset),
        (Groups::Indirect(_), None) => {
            unreachable!("{label}: an indirect grid without its arguments buffer")
        }
        (Groups::Direct(groups), _) => {
            let groups = groups.max(1);
            let (x, y) = if groups <= max_x {
                (groups, 1)
            } else {
                (max_x, groups.div_ceil(max_x))
            };
            pass.dispatch_workgroups(x, y, 1);
        }
    }
}
