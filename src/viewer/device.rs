//! The device the window draws with — eframe's — and the simplifier's pipelines made on it, so
//! that a `gpu` result is drawn from the buffers it was written to.

use crate::cluster::gpu::GpuClusterer;
use crate::options::Backend;
use crate::rounds::gpu::GpuSimplifier;
use eframe::egui;
use eframe::egui_wgpu;
use std::sync::Arc;

pub struct Device {
    pub(super) device: wgpu::Device,
    pub(super) queue: wgpu::Queue,
    pub(super) egui_renderer: Arc<egui::mutex::RwLock<egui_wgpu::Renderer>>,
    pub(super) sim: Option<Arc<GpuSimplifier>>,
    /// `--method cluster`'s pipelines on the same device, so its result is drawn from the
    /// buffers the build wrote.
    pub(super) clusterer: Option<Arc<GpuClusterer>>,
    /// The device's pipelines, for the stages made after the window starts (a DAG's cut).
    pub(super) pipelines: Arc<crate::compute::gpu::Pipelines>,
    pub(super) adapter: String,
}

impl Device {
    /// The pipelines of one cache on eframe's device (the rounds and the clustering share it),
    /// and the backend the window starts on with why: the library's `auto` choice on this
    /// adapter. The pipelines' error, if any, is given for the status line.
    pub(super) fn new(rs: &egui_wgpu::RenderState) -> (Device, (Backend, String), String) {
        let cache = crate::compute::gpu::Pipelines::new(&rs.device);
        let (sim, status) = match GpuSimplifier::on(&cache, &rs.queue) {
            Ok(s) => (Some(Arc::new(s)), String::new()),
            Err(e) => (
                None,
                format!("gpu backend unavailable on this device ({e}); cpu backends work"),
            ),
        };
        // The library's `auto` on the window's own adapter; gpu stays one click away.
        let info = rs.adapter.get_info();
        let start = match &sim {
            Some(_) => {
                crate::simplify::auto_on(&info.name, info.device_type == wgpu::DeviceType::Cpu)
            }
            None => (
                Backend::CpuParallel,
                "cpu-parallel: the gpu backend is unavailable on this device".into(),
            ),
        };
        let clusterer = sim
            .as_ref()
            .and_then(|_| GpuClusterer::on(&cache, &rs.queue).ok().map(Arc::new));
        let device = Device {
            device: rs.device.clone(),
            queue: rs.queue.clone(),
            egui_renderer: rs.renderer.clone(),
            adapter: info.name,
            sim,
            clusterer,
            pipelines: cache,
        };
        (device, start, status)
    }

    /// The gpu backend runs `method` on this device and leaves its result there: the rounds
    /// (`qem`), `cluster` and `floating-cell`; `hybrid` runs on the CPU's cores here.
    pub fn draws(&self, method: crate::Method) -> bool {
        match method {
            crate::Method::Qem => self.sim.is_some(),
            crate::Method::Cluster | crate::Method::FloatingCell => self.clusterer.is_some(),
            _ => false,
        }
    }
}
