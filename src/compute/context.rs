//! The device: adapter and device through pollster, with the adapter's own limits so that
//! million-triangle meshes fit, and every buffer checked against them before it is allocated.

use crate::error::{Error, Result};

/// The usage of a working buffer of the stages: read and written by shaders, filled and read
/// back by copies.
pub const STORAGE: wgpu::BufferUsages = wgpu::BufferUsages::STORAGE
    .union(wgpu::BufferUsages::COPY_DST)
    .union(wgpu::BufferUsages::COPY_SRC);

/// The usage of a stage's uniform parameters, written by the host.
pub const UNIFORM: wgpu::BufferUsages =
    wgpu::BufferUsages::UNIFORM.union(wgpu::BufferUsages::COPY_DST);

/// A device and queue the simplifier (and a viewer) use.
pub struct GpuContext {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub adapter_name: String,
    /// The adapter is a software rasterizer (llvmpipe, WARP, SwiftShader): it runs the WGSL on
    /// the CPU's cores, several times slower than the CPU backends (measured on the 1M scan on
    /// lavapipe at 1%: 9.5 s against 3.2 s for cpu-parallel and 1.1 s for cpu), so `auto` passes
    /// it over.
    pub software: bool,
    /// What wgpu says of the adapter (its pipeline cache is keyed by it).
    pub adapter_info: wgpu::AdapterInfo,
    /// The device's pipeline cache, which every family simplifying on it shares.
    pub pipelines: std::sync::Arc<crate::compute::gpu::Pipelines>,
}

impl GpuContext {
    /// The first hardware or software adapter wgpu finds (lavapipe counts), with its limits and,
    /// when it has them, timestamp queries.
    pub fn new() -> Result<GpuContext> {
        // Vulkan, Metal, DX12 (WGPU_BACKEND overrides): GL's compute is limited, and probing it
        // without a display only prints EGL noise.
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
        desc.backends = wgpu::Backends::PRIMARY;
        let instance = wgpu::Instance::new(desc.with_env());
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            ..Default::default()
        }))
        .map_err(|e| {
            Error::Gpu(format!(
                "no GPU adapter found ({e}); install a Vulkan driver (on Debian without a GPU: \
                 apt-get install mesa-vulkan-drivers libvulkan1) or use --backend cpu-parallel"
            ))
        })?;
        let info = adapter.get_info();
        let (device, queue) =
            pollster::block_on(adapter.request_device(&device_descriptor(&adapter)))
                .map_err(|e| Error::Gpu(format!("adapter {} refused a device: {e}", info.name)))?;
        Ok(GpuContext {
            pipelines: crate::compute::gpu::Pipelines::with_disk_cache(&device, &info),
            device,
            queue,
            adapter_name: info.name.clone(),
            software: info.device_type == wgpu::DeviceType::Cpu,
            adapter_info: info,
        })
    }
}

/// The runtime directory that keeps Mesa's device-select layer quiet, when one is needed.
///
/// Mesa 22.3's implicit `VK_LAYER_MESA_device_select` connects to Wayland whenever an application
/// enables `VK_KHR_wayland_surface` (wgpu does), and libwayland prints `error: XDG_RUNTIME_DIR is
/// invalid or not set in the environment.` when there is no runtime directory: twice per device
/// on every headless machine, though nothing failed. With neither `WAYLAND_DISPLAY` nor
/// `WAYLAND_SOCKET` set and no valid `XDG_RUNTIME_DIR`, no compositor can be found either way, so
/// pointing the probe at an empty private directory changes nothing but that line; with any of
/// them set, nothing is touched and every message gets through. Returns the directory (removed
/// when dropped) and the value to give `XDG_RUNTIME_DIR`, or `None` when nothing is needed.
pub fn quiet_wayland_probe() -> Option<(tempfile::TempDir, std::ffi::OsString)> {
    let set = |k: &str| std::env::var_os(k).is_some_and(|v| !v.is_empty());
    let valid_runtime_dir =
        std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| std::path::Path::new(&d).is_absolute());
    if set("WAYLAND_DISPLAY") || set("WAYLAND_SOCKET") || valid_runtime_dir {
        return None;
    }
    // tempfile makes the directory 0700, as the XDG spec asks of a runtime directory.
    let dir = tempfile::Builder::new()
        .prefix("meshslim-runtime-")
        .tempdir()
        .ok()?;
    let value = dir.path().as_os_str().to_owned();
    Some((dir, value))
}

/// A buffer of `size` bytes (at least 16 and a multiple of 4: wgpu refuses empty buffers),
/// checked against the device's limits before it is allocated.
pub fn checked_buffer(
    device: &wgpu::Device,
    label: &str,
    size: u64,
    usage: wgpu::BufferUsages,
) -> Result<wgpu::Buffer> {
    check_buffer(&device.limits(), label, size)?;
    Ok(device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size.max(16).next_multiple_of(4),
        usage,
        mapped_at_creation: false,
    }))
}

/// A buffer holding `data` (zero-padded to at least 16 bytes and a multiple of 4), written
/// through `queue` before its next submission: one copy into a staging buffer, where
/// [`checked_buffer_init`] makes three (the padded copy, wgpu zeroing the mapping, the copy in),
/// which took 0.028 s of the 1M scan's 19 MB upload on a 2-core host.
pub fn checked_buffer_write(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    label: &str,
    data: &[u8],
    usage: wgpu::BufferUsages,
) -> Result<wgpu::Buffer> {
    let buf = checked_buffer(
        device,
        label,
        data.len() as u64,
        usage | wgpu::BufferUsages::COPY_DST,
    )?;
    // The queue copies whole words; a short tail goes in as one zero-padded word.
    let whole = data.len() / 4 * 4;
    // A refused write gives no view and leaves its error in the caller's scope.
    if let Some(mut view) =
        std::num::NonZeroU64::new(whole as u64).and_then(|n| queue.write_buffer_with(&buf, 0, n))
    {
        copy_on_every_core(view.slice(..), &data[..whole]);
    }
    if whole < data.len() {
        let mut tail = [0u8; 4];
        tail[..data.len() - whole].copy_from_slice(&data[whole..]);
        queue.write_buffer(&buf, whole as u64, &tail);
    }
    Ok(buf)
}

/// `src` into the staging memory `dst`, a slice per core: the copy's time is the kernel's,
/// faulting in the fresh pages one by one, and on the 1M scan's 19 MB upload one core spent
/// 0.019 s of the call there.
fn copy_on_every_core(dst: wgpu::WriteOnly<[u8]>, src: &[u8]) {
    use rayon::prelude::*;
    const SLICE: usize = 1 << 20;
    // Whole slices as arrays, which (unlike a view of a slice) may go to another thread.
    let (slices, mut tail) = dst.into_chunks::<SLICE>();
    let slices: Vec<wgpu::WriteOnly<[u8; SLICE]>> = slices.into_iter().collect();
    let from = src.chunks_exact(SLICE);
    tail.copy_from_slice(from.remainder());
    slices
        .into_par_iter()
        .zip(from.collect::<Vec<_>>())
        .for_each(|(dst, src)| wgpu::WriteOnly::<[u8]>::from(dst).copy_from_slice(src));
}

/// A buffer holding `data` zero-padded to `len` bytes (at least 16), checked against the
/// device's limits before it is allocated.
pub fn checked_buffer_init(
    device: &wgpu::Device,
    label: &str,
    data: &[u8],
    len: usize,
    usage: wgpu::BufferUsages,
) -> Result<wgpu::Buffer> {
    use wgpu::util::DeviceExt;
    let len = len.max(data.len());
    check_buffer(&device.limits(), label, len as u64)?;
    let mut bytes = data.to_vec();
    bytes.resize(len.max(16), 0);
    Ok(
        device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents: &bytes,
            usage,
        }),
    )
}

/// What meshslim asks of a device, whoever creates it (the simplifier here, eframe for the
/// viewer's window, the viewer's tests): the adapter's own limits, so that million-triangle
/// meshes fit; timestamp queries for the per-stage table (inside passes too, so that the
/// rounds time each dispatch of a pass), line polygons for the viewer's
/// wireframe, f64 in shaders for the preparation on the device, and indirect first instances
/// for a DAG's cluster colours, each only when the adapter has it.
pub fn device_descriptor(adapter: &wgpu::Adapter) -> wgpu::DeviceDescriptor<'static> {
    wgpu::DeviceDescriptor {
        label: Some("meshslim"),
        required_features: adapter.features()
            & (wgpu::Features::TIMESTAMP_QUERY
                | wgpu::Features::TIMESTAMP_QUERY_INSIDE_PASSES
                | wgpu::Features::POLYGON_MODE_LINE
                | wgpu::Features::PIPELINE_CACHE
                | wgpu::Features::SHADER_F64
                | wgpu::Features::INDIRECT_FIRST_INSTANCE),
        required_limits: adapter.limits(),
        ..Default::default()
    }
}

/// Checks a storage buffer of `size` bytes against the device limits.
pub fn check_buffer(limits: &wgpu::Limits, label: &str, size: u64) -> Result<()> {
    let too_big = |limit: u64, which| Error::BufferTooLarge {
        label: label.to_string(),
        size,
        limit,
        which,
    };
    if size > limits.max_buffer_size {
        return Err(too_big(limits.max_buffer_size, "max_buffer_size"));
    }
    if size > limits.max_storage_buffer_binding_size {
        return Err(too_big(
            limits.max_storage_buffer_binding_size,
            "max_storage_buffer_binding_size",
        ));
    }
    Ok(())
}

/// Maps `buf` for reading and waits for the device until it is: the one round trip every
/// read-back makes. Gives the outcome (what failed, in words) and the seconds spent blocked.
pub fn map_and_wait(
    device: &wgpu::Device,
    buf: &wgpu::Buffer,
) -> (std::result::Result<(), String>, f64) {
    let t = std::time::Instant::now();
    let (tx, rx) = std::sync::mpsc::channel();
    buf.map_async(wgpu::MapMode::Read, .., move |r| {
        let _ = tx.send(r);
    });
    let polled = device.poll(wgpu::PollType::wait_indefinitely());
    let waited = t.elapsed().as_secs_f64();
    let outcome = polled
        .map_err(|e| format!("waiting for the device: {e}"))
        .and_then(|_| {
            rx.recv()
                .map_err(|_| "the device dropped a read-back".to_string())?
                .map_err(|e| format!("mapping a read-back buffer: {e}"))
        });
    (outcome, waited)
}

/// The first `bytes` of `buf` (`COPY_SRC`), copied to a staging buffer after the work already
/// submitted and read with one wait; `doing` says what for in an error.
pub fn read_back(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    buf: &wgpu::Buffer,
    bytes: u64,
    doing: &str,
) -> Result<Vec<u8>> {
    Ok(read_ranges(device, queue, &[(buf, 0, bytes)], doing)?.remove(0))
}

/// `(buffer, byte offset, bytes)` ranges (`COPY_SRC`), copied side by side into one staging
/// buffer after the work already submitted and read with one wait: each range's bytes, in order.
/// Each copy is rounded up to 4 bytes, as copies must be; `doing` says what for in an error.
pub fn read_ranges(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    ranges: &[(&wgpu::Buffer, u64, u64)],
    doing: &str,
) -> Result<Vec<Vec<u8>>> {
    let scope = crate::compute::gpu::ErrorScope::push(device);
    let total: u64 = ranges.iter().map(|r| r.2.next_multiple_of(4)).sum();
    let staging = checked_buffer(
        device,
        "meshslim.read_back",
        total.max(4),
        wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
    )?;
    let mut enc = device.create_command_encoder(&Default::default());
    let mut at = 0;
    for &(buf, offset, bytes) in ranges {
        let size = bytes.next_multiple_of(4);
        if size > 0 {
            enc.copy_buffer_to_buffer(buf, offset, &staging, at, size);
        }
        at += size;
    }
    queue.submit([enc.finish()]);
    let read = map_and_wait(device, &staging)
        .0
        .map_err(|e| Error::Gpu(format!("{doing}: {e}")))
        .and_then(|()| {
            let view = staging
                .get_mapped_range(..)
                .map_err(|e| Error::Gpu(format!("{doing}: {e}")))?;
            let mut at = 0usize;
            Ok(ranges
                .iter()
                .map(|&(_, _, bytes)| {
                    let part = view[at..at + bytes as usize].to_vec();
                    at += bytes.next_multiple_of(4) as usize;
                    part
                })
                .collect())
        });
    scope.check_with(doing, read)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn oversized_buffer_names_itself_and_the_limit() {
        let limits = wgpu::Limits::default();
        let err = check_buffer(&limits, "meshslim.candidates", 1 << 40).unwrap_err();
        let msg = err.to_string();
        assert!(
            msg.contains("meshslim.candidates") && msg.contains("max_buffer_size"),
            "{msg}"
        );
        assert!(check_buffer(&limits, "meshslim.small", 1024).is_ok());
    }
}
