//! What the benchmark can run: every backend with its help line, the call that is timed, and the
//! device that runs it (the CPU's model or the GPU adapter).

use super::peers::{meshopt_simplify, meshopt_simplify_sloppy, meshopt_simplify_with_attributes};
use crate::error::Result;
use crate::mesh::Mesh;
use crate::options::{Backend, Method, SimplifyOptions};

/// One implementation the benchmark can run. A new backend (cpu-parallel, gpu) is one entry in
/// [`BACKENDS`]: its name, a line of help, the simplify call that is timed, and the device
/// that runs it (a GPU backend names its adapter there).
#[derive(Debug)]
pub struct BenchBackend {
    /// The `--backends` name, also the `backend` field of each row.
    pub name: &'static str,
    /// One line for `meshslim bench --help`.
    pub about: &'static str,
    /// Simplifies the mesh to about this many faces: the call that is timed and measured.
    pub simplify: fn(&Mesh, usize) -> Result<Mesh>,
    /// The device that runs it, named in every row.
    pub device: fn() -> String,
    /// How far above the target a result may land and still count as on target (clustering
    /// lands within 5% of it, either side).
    pub band: f64,
    /// The meshoptimizer call it is held against under the table: `simplify` for the edge
    /// collapses (and decimation, which also keeps the topology and the exact count),
    /// `simplifySloppy` for the clusterings; `None` for meshoptimizer's own rows.
    pub peer: Option<&'static str>,
}

/// Every backend `meshslim bench` knows, in the order of the table and the plot legend.
pub static BACKENDS: &[BenchBackend] = &[
    BenchBackend {
        name: "cpu",
        about: "meshslim's greedy quadric edge collapse (the quality reference)",
        simplify: |m, faces| ours(m, faces, Method::Qem, Backend::Cpu),
        device: cpu_name,
        band: 0.0,
        peer: Some("meshopt"),
    },
    BenchBackend {
        name: "cpu-parallel",
        about: "meshslim's GPU rounds run on the CPU's cores (rayon)",
        simplify: |m, faces| ours(m, faces, Method::Qem, Backend::CpuParallel),
        device: cpu_name,
        band: 0.0,
        peer: Some("meshopt"),
    },
    BenchBackend {
        name: "gpu",
        about: "meshslim's rounds as WGSL compute passes (wgpu)",
        simplify: |m, faces| ours(m, faces, Method::Qem, Backend::Gpu),
        device: gpu_name,
        band: 0.0,
        peer: Some("meshopt"),
    },
    BenchBackend {
        name: "cluster",
        about: "meshslim's uniform-grid vertex clustering (cpu-parallel; topology not kept)",
        simplify: |m, faces| ours(m, faces, Method::Cluster, Backend::CpuParallel),
        device: cpu_name,
        band: crate::cluster::BAND,
        peer: Some("meshopt-sloppy"),
    },
    BenchBackend {
        name: "cluster-gpu",
        about: "meshslim's uniform-grid vertex clustering as WGSL compute passes (wgpu)",
        simplify: |m, faces| ours(m, faces, Method::Cluster, Backend::Gpu),
        device: gpu_name,
        band: crate::cluster::BAND,
        peer: Some("meshopt-sloppy"),
    },
    BenchBackend {
        name: "floating-cell",
        about: "meshslim's floating-cell vertex clustering, Low & Tan (cpu-parallel)",
        simplify: |m, faces| ours(m, faces, Method::FloatingCell, Backend::CpuParallel),
        device: cpu_name,
        band: crate::cluster::BAND,
        peer: Some("meshopt-sloppy"),
    },
    BenchBackend {
        name: "floating-cell-gpu",
        about: "meshslim's floating-cell vertex clustering as WGSL compute passes (wgpu)",
        simplify: |m, faces| ours(m, faces, Method::FloatingCell, Backend::Gpu),
        device: gpu_name,
        band: crate::cluster::BAND,
        peer: Some("meshopt-sloppy"),
    },
    BenchBackend {
        name: "decimate",
        about: "meshslim's vertex decimation, Schroeder (cpu; keeps a subset of the vertices)",
        simplify: |m, faces| ours(m, faces, Method::Decimate, Backend::Cpu),
        device: cpu_name,
        band: 0.0,
        peer: Some("meshopt"),
    },
    BenchBackend {
        name: "hybrid",
        about: "meshslim's clustering to 2x the target + 20k faces, then the greedy queue (cpu)",
        simplify: |m, faces| ours(m, faces, Method::Hybrid, Backend::Cpu),
        device: cpu_name,
        band: 0.0,
        peer: Some("meshopt"),
    },
    BenchBackend {
        name: "hybrid-parallel",
        about: "meshslim's hybrid with the rounds (cpu-parallel), the CPU twin of hybrid-gpu",
        simplify: |m, faces| ours(m, faces, Method::Hybrid, Backend::CpuParallel),
        device: cpu_name,
        band: 0.0,
        peer: Some("meshopt"),
    },
    BenchBackend {
        name: "hybrid-gpu",
        about: "meshslim's hybrid with the rounds as WGSL compute passes (wgpu)",
        simplify: |m, faces| ours(m, faces, Method::Hybrid, Backend::Gpu),
        device: gpu_name,
        band: 0.0,
        peer: Some("meshopt"),
    },
    BenchBackend {
        name: "meshopt",
        about: "meshoptimizer's simplify (quadric edge collapse)",
        simplify: |m, faces| Ok(meshopt_simplify(m, faces)),
        device: cpu_name,
        band: 0.0,
        peer: None,
    },
    BenchBackend {
        name: "meshopt-attr-0.1",
        about: "meshoptimizer's simplifyWithAttributes, colours and UVs weighted 0.1",
        simplify: |m, faces| Ok(meshopt_simplify_with_attributes(m, faces, 0.1)),
        device: cpu_name,
        band: 0.0,
        peer: None,
    },
    BenchBackend {
        name: "meshopt-attr-0.3",
        about: "meshoptimizer's simplifyWithAttributes, colours and UVs weighted 0.3",
        simplify: |m, faces| Ok(meshopt_simplify_with_attributes(m, faces, 0.3)),
        device: cpu_name,
        band: 0.0,
        peer: None,
    },
    BenchBackend {
        name: "meshopt-attr-1",
        about: "meshoptimizer's simplifyWithAttributes, colours and UVs weighted 1",
        simplify: |m, faces| Ok(meshopt_simplify_with_attributes(m, faces, 1.0)),
        device: cpu_name,
        band: 0.0,
        peer: None,
    },
    BenchBackend {
        name: "meshopt-sloppy",
        about: "meshoptimizer's simplifySloppy (vertex clustering, topology not kept)",
        simplify: |m, faces| Ok(meshopt_simplify_sloppy(m, faces)),
        device: cpu_name,
        band: 0.0,
        peer: None,
    },
];

/// meshslim's `method` on `backend`, the other options at their defaults for `faces` faces.
fn ours(m: &Mesh, faces: usize, method: Method, backend: Backend) -> Result<Mesh> {
    let mut o = SimplifyOptions::with_faces(faces);
    o.method = method;
    o.backend = backend;
    Ok(crate::simplify(m, &o)?.0)
}

/// The GPU adapter's name, or why there is none.
pub fn gpu_name() -> String {
    static NAME: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    NAME.get_or_init(|| match crate::rounds::gpu::shared() {
        Ok((c, _)) => c.adapter_name.clone(),
        Err(e) => format!("no GPU ({e})"),
    })
    .clone()
}

/// Every backend this machine can run: all of [`BACKENDS`] but the `meshopt-attr-*` ones, less the GPU ones (`gpu`,
/// `cluster-gpu`) without an adapter.
pub fn available_backends() -> Vec<&'static BenchBackend> {
    let gpu = crate::rounds::gpu::shared().is_ok();
    BACKENDS
        .iter()
        .filter(|b| gpu || !b.name.ends_with("gpu"))
        // meshoptimizer with attribute weights runs when named: on most inputs (no colours,
        // no UVs) it is plain `meshopt` again.
        .filter(|b| !b.name.starts_with("meshopt-attr"))
        .collect()
}

/// The backend called `name` in [`BACKENDS`].
pub fn backend(name: &str) -> Option<&'static BenchBackend> {
    BACKENDS.iter().find(|b| b.name == name)
}

/// The CPU's model name (`model name` in /proc/cpuinfo, else the architecture).
pub fn cpu_name() -> String {
    static NAME: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    NAME.get_or_init(|| {
        std::fs::read_to_string("/proc/cpuinfo")
            .ok()
            .and_then(|info| {
                info.lines()
                    .filter_map(|l| l.split_once(':'))
                    .find(|(k, _)| matches!(k.trim(), "model name" | "Model" | "Hardware"))
                    .map(|(_, v)| v.split_whitespace().collect::<Vec<_>>().join(" "))
            })
            .filter(|n| !n.is_empty())
            .unwrap_or_else(|| format!("unknown {} CPU", std::env::consts::ARCH))
    })
    .clone()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn backend_names_are_unique_and_found() {
        for (i, b) in BACKENDS.iter().enumerate() {
            assert!(std::ptr::eq(backend(b.name).unwrap(), b));
            assert!(BACKENDS[..i].iter().all(|o| o.name != b.name));
        }
        assert!(backend("nope").is_none());
    }
}
