//! What a benchmark run measured: the machine, and one row per mesh × ratio × backend; it
//! serializes to the JSON of `meshslim bench --json`.

use serde::Serialize;

use super::backends::cpu_name;

/// The machine a report was measured on.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Machine {
    /// CPU model name.
    pub cpu: String,
    /// Hardware threads available to the process.
    pub cores: usize,
}

impl Machine {
    pub fn this() -> Machine {
        Machine {
            cpu: cpu_name(),
            cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
        }
    }
}

/// One mesh × ratio × backend.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Row {
    pub mesh: String,
    pub input_faces: usize,
    pub ratio: f64,
    pub target_faces: usize,
    pub backend: String,
    /// What ran it: the CPU model for CPU backends, the adapter for GPU ones.
    pub device: String,
    pub output_faces: usize,
    /// The run stopped above its target (beyond its backend's band: 5% for clustering; the
    /// error columns then compare a larger mesh);
    /// the table marks it with `*`.
    pub missed_target: bool,
    /// Median wall time of the simplify call over the repeats, seconds.
    pub median_s: f64,
    /// Every repeat's wall time, seconds, in run order.
    pub times_s: Vec<f64>,
    /// Input triangles per second at the median time, millions.
    pub mtri_per_s: f64,
    /// Peak heap bytes held during the simplify call above what was held before it (the output
    /// included; largest over the repeats); `None` when the counting allocator
    /// ([`alloc::CountingAlloc`](super::alloc::CountingAlloc)) is not the global allocator.
    /// Rust heap only: the scratch memory meshoptimizer's C++ takes from `malloc` is not seen
    /// (the meshopt crate does not expose `meshopt_setAllocator`), so its rows count little more
    /// than the output.
    pub peak_bytes: Option<u64>,
    /// `peak_bytes` in MiB.
    pub peak_mib: Option<f64>,
    /// Bounding-box diagonal of the input, the unit of the `*_rel` errors.
    pub diagonal: f64,
    /// Two-sided Metro distances (see [`crate::metrics::Distance::two_sided`]); `None` when the
    /// output has no faces left to measure.
    pub mean_err: Option<f64>,
    pub max_err: Option<f64>,
    pub mean_err_rel: Option<f64>,
    pub max_err_rel: Option<f64>,
    /// Mean colour deviation (`meshslim compare`'s, RGB distance in 0..1 units) when the input
    /// and the output both have vertex colours; absent from the JSON otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub color_err: Option<f64>,
    /// Mean texture-colour deviation at the UVs (`meshslim compare --texture`) when a texture
    /// was given and the input and the output have UVs; absent from the JSON otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub texture_err: Option<f64>,
}

/// Everything `meshslim bench` measured; serializes to its JSON.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Report {
    pub machine: Machine,
    pub repeat: usize,
    /// Face samples per direction when set; `null`: the metrics' default.
    pub samples: Option<usize>,
    pub rows: Vec<Row>,
}
