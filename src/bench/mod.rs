//! Inputs and the meshoptimizer baseline for benchmarks: shared by `benches/simplify.rs` and the
//! `meshslim bench` command, so that both measure the same meshes the same way.
//!
//! The reference meshes live outside the crate (`../shared/models`, see its README); without
//! them every function here falls back to a procedural mesh so that benches still run.
//!
//! [`run`] is the benchmark itself: every mesh × ratio × backend of [`BACKENDS`], timed
//! (median over repeats), its peak heap measured ([`alloc`]) and its two-sided Metro distance
//! to the input measured with [`crate::metrics::compare`]. [`write_table`] and [`plot_svg`]
//! present the [`Report`]; it serializes to the JSON of `meshslim bench --json`.
//!
//! The parts: `models` (the reference meshes and the 1M-triangle scan), `peers` (meshoptimizer's
//! simplifiers), `backends` (what runs and on which device), `report` (what a run measured),
//! `present` (the table, the SVG plot and its PNG), [`alloc`] (the counting allocator).

pub mod alloc;
mod backends;
mod models;
mod peers;
mod present;
mod report;

use std::time::Instant;

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::metrics::{self, CompareOptions};
use crate::options::SimplifyOptions;

pub use backends::{BACKENDS, BenchBackend, available_backends, backend, cpu_name, gpu_name};
pub use models::{
    BENCH_MODELS, MODELS_ENV, RATIOS, inputs, load_model, million_triangle_scan, models_dir,
};
pub use peers::{meshopt_simplify, meshopt_simplify_sloppy};
pub use present::{plot_svg, svg_to_png, write_table};
pub use report::{Machine, Report, Row};

/// Ratios `meshslim bench` runs at when none are given.
pub const DEFAULT_RATIOS: [f64; 3] = [0.5, 0.1, 0.01];

/// What to run.
#[derive(Debug, Clone)]
pub struct BenchOptions {
    /// Fractions of the input faces to keep, each in (0, 1].
    pub ratios: Vec<f64>,
    pub backends: Vec<&'static BenchBackend>,
    /// Timed runs per case; the median is reported.
    pub repeat: usize,
    /// How the error is measured.
    pub compare: CompareOptions,
}

impl Default for BenchOptions {
    fn default() -> Self {
        BenchOptions {
            ratios: DEFAULT_RATIOS.to_vec(),
            backends: available_backends(),
            repeat: 3,
            compare: CompareOptions::default(),
        }
    }
}

/// Runs every mesh × ratio × backend of `opts`, in that nesting order. `progress` gets the
/// fraction done (0..=1) after every timed run and every measurement.
pub fn run(
    inputs: &[(String, Mesh)],
    opts: &BenchOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<Report> {
    if opts.repeat == 0 {
        return Err(Error::InvalidOption("repeat must be at least 1".into()));
    }
    if opts.backends.is_empty() || opts.ratios.is_empty() {
        return Err(Error::InvalidOption(
            "at least one backend and one ratio are needed".into(),
        ));
    }
    let targets = opts
        .ratios
        .iter()
        .map(|&r| SimplifyOptions::with_ratio(1, r).map(|_| r))
        .collect::<Result<Vec<f64>>>()?;
    let steps = inputs.len() * targets.len() * opts.backends.len() * (opts.repeat + 1);
    let mut done = 0;
    let mut step = || {
        done += 1;
        progress(done as f32 / steps.max(1) as f32)
    };
    let mut rows = Vec::new();
    let mut cold = Cold::new();
    for (name, mesh) in inputs {
        mesh.validate()
            .map_err(|e| Error::InvalidMesh(format!("{name}: {e}")))?;
        let faces = mesh.face_count();
        let diagonal = mesh.bounds().map_or(0.0, |b| b.diagonal());
        for &ratio in &targets {
            let target = SimplifyOptions::with_ratio(faces, ratio)?.target_faces;
            // The repeats take turns across the backends (each backend's first run, then each
            // one's second, ...): a burst of load from elsewhere on the machine, or the page
            // faults a call pays after another has freed its memory, then lands on every
            // backend alike instead of on whichever ran during it, and the ratios between them
            // hold from run to run.
            let mut runs: Vec<Timed> = opts.backends.iter().map(|_| Timed::default()).collect();
            for _ in 0..opts.repeat {
                for (backend, run) in opts.backends.iter().zip(&mut runs) {
                    drop(run.out.take()); // the previous output is not part of this run's baseline
                    cold.evict();
                    let (result, bytes) = alloc::measure(|| {
                        let t = Instant::now();
                        let r = (backend.simplify)(mesh, target);
                        (r, t.elapsed().as_secs_f64())
                    });
                    let (simplified, seconds) = result;
                    run.out = Some(simplified?);
                    run.times.push(seconds);
                    run.peak = bytes.map(|b| run.peak.map_or(b, |p| p.max(b)));
                    step();
                }
            }
            for (backend, run) in opts.backends.iter().zip(runs) {
                let Timed { times, peak, out } = run;
                let out = out.expect("repeat is at least 1");
                let c = if out.face_count() == 0 {
                    None
                } else {
                    Some(metrics::compare(mesh, &out, &opts.compare)?)
                };
                let color_err = c
                    .as_ref()
                    .and_then(|c| c.appearance.as_ref()?.color.as_ref())
                    .map(|s| s.mean);
                let texture_err = c
                    .as_ref()
                    .and_then(|c| c.appearance.as_ref()?.texture.as_ref())
                    .map(|s| s.mean);
                let d = c.map(|c| c.distance.two_sided);
                step();
                let median_s = median(&times);
                rows.push(Row {
                    mesh: name.clone(),
                    input_faces: faces,
                    ratio,
                    target_faces: target,
                    backend: backend.name.to_string(),
                    device: (backend.device)(),
                    output_faces: out.face_count(),
                    missed_target: out.face_count() as f64 > target as f64 * (1.0 + backend.band),
                    median_s,
                    times_s: times,
                    mtri_per_s: faces as f64 / median_s.max(1e-9) / 1e6,
                    peak_bytes: peak,
                    peak_mib: peak.map(|b| b as f64 / (1024.0 * 1024.0)),
                    diagonal,
                    mean_err: d.as_ref().map(|d| d.mean),
                    max_err: d.as_ref().map(|d| d.max),
                    mean_err_rel: d.as_ref().map(|d| d.mean_rel),
                    max_err_rel: d.as_ref().map(|d| d.max_rel),
                    color_err,
                    texture_err,
                });
            }
        }
    }
    Ok(Report {
        machine: Machine::this(),
        repeat: opts.repeat,
        samples: opts.compare.samples,
        rows,
    })
}

/// What starts every timed call from a cold cache: a buffer twice the last-level cache, one
/// byte of each line written before the call. Without it a call inherits what the one before
/// left, and the fixed turn order favours whoever follows a call that read the same mesh
/// (`simplifySloppy` ran right after `cluster`). Both 1M meshes at 10% and 1%, two runs of five
/// repeats each way: `cluster`'s speed against `simplifySloppy`'s ranged over 0.72–1.14 warm,
/// 0.75–0.93 cold, as a user's single call runs.
struct Cold(Vec<u8>);

impl Cold {
    fn new() -> Cold {
        Cold(vec![0; 2 * last_level_cache()])
    }

    fn evict(&mut self) {
        for (i, b) in self.0.iter_mut().enumerate().step_by(64) {
            *b = b.wrapping_add(i as u8 | 1);
        }
        std::hint::black_box(&self.0);
    }
}

/// The largest cache's size, from Linux's sysfs (64 MiB where it says nothing), at most 1 GiB.
fn last_level_cache() -> usize {
    let size = |dir: std::fs::DirEntry| {
        let s = std::fs::read_to_string(dir.path().join("size")).ok()?;
        let s = s.trim();
        let (n, unit) = s.split_at(s.find(|c: char| !c.is_ascii_digit()).unwrap_or(s.len()));
        let scale = match unit {
            "K" => 1 << 10,
            "M" => 1 << 20,
            "G" => 1 << 30,
            _ => 1,
        };
        n.parse::<usize>().ok().map(|n| n * scale)
    };
    std::fs::read_dir("/sys/devices/system/cpu/cpu0/cache")
        .into_iter()
        .flatten()
        .flatten()
        .filter_map(size)
        .max()
        .unwrap_or(64 << 20)
        .min(1 << 30)
}

/// One backend's timed runs of one case: their seconds, the largest peak, the last output.
#[derive(Default)]
struct Timed {
    times: Vec<f64>,
    peak: Option<u64>,
    out: Option<Mesh>,
}

fn median(xs: &[f64]) -> f64 {
    let mut v = xs.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh;

    /// The cold-cache buffer is twice a real cache's size (this machine's sysfs names one), and
    /// a pass over it changes its bytes (it cannot be optimised away).
    #[test]
    fn the_cold_cache_buffer_spans_the_last_level_cache() {
        let llc = last_level_cache();
        assert!((1 << 20..=1 << 30).contains(&llc), "{llc} bytes");
        let mut cold = Cold::new();
        assert_eq!(cold.0.len(), 2 * llc);
        cold.evict();
        assert_ne!(cold.0[64], 0);
    }

    #[test]
    fn median_of_odd_and_even_counts() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
    }

    /// Two backends that write down when they run, and the order a run of three repeats
    /// calls them in: taking turns, each row still with its own three times.
    #[test]
    fn repeats_take_turns_across_the_backends() {
        use std::sync::Mutex;
        static CALLS: Mutex<Vec<&str>> = Mutex::new(Vec::new());
        fn called(name: &'static str, m: &Mesh, faces: usize) -> Result<Mesh> {
            CALLS.lock().unwrap().push(name);
            Ok(crate::bench::meshopt_simplify(m, faces))
        }
        let backend = |name, simplify| BenchBackend {
            name,
            about: "",
            simplify,
            device: cpu_name,
            band: 0.0,
            peer: None,
        };
        let a: &'static BenchBackend = Box::leak(Box::new(backend("a", |m, f| called("a", m, f))));
        let b: &'static BenchBackend = Box::leak(Box::new(backend("b", |m, f| called("b", m, f))));
        let opts = BenchOptions {
            ratios: vec![0.5],
            backends: vec![a, b],
            repeat: 3,
            compare: CompareOptions {
                samples: Some(100),
                ..Default::default()
            },
        };
        let report = run(
            &[("ico".to_string(), mesh::icosphere(2))],
            &opts,
            &mut |_| {},
        )
        .unwrap();
        assert_eq!(*CALLS.lock().unwrap(), ["a", "b", "a", "b", "a", "b"]);
        let rows: Vec<(&str, usize)> = report
            .rows
            .iter()
            .map(|r| (r.backend.as_str(), r.times_s.len()))
            .collect();
        assert_eq!(rows, [("a", 3), ("b", 3)]);
    }

    #[test]
    fn run_without_the_counting_allocator_reports_no_peak_plots_and_holds_rows_to_peers() {
        let opts = BenchOptions {
            ratios: vec![0.5],
            repeat: 2,
            compare: CompareOptions {
                samples: Some(200),
                ..Default::default()
            },
            ..Default::default()
        };
        let inputs = [("ico".to_string(), mesh::icosphere(2))];
        let mut last = 0.0;
        let report = run(&inputs, &opts, &mut |f| last = f).unwrap();
        assert_eq!(last, 1.0);
        let backends = available_backends().len();
        assert_eq!(report.rows.len(), backends);
        for r in &report.rows {
            assert_eq!(r.times_s.len(), 2);
            assert_eq!(
                r.peak_bytes, None,
                "the test harness has no counting allocator"
            );
            assert!(r.mean_err_rel.unwrap() > 0.0);
        }
        let svg = plot_svg(&report);
        assert_eq!(svg.matches(r#"class="series""#).count(), backends);
        let mut table = Vec::new();
        write_table(&mut table, &report).unwrap();
        let text = String::from_utf8(table).unwrap();
        // Header, one row per backend, the three lines of notes under the table; then the rows
        // against their peers: a blank line, a heading, a header and every backend but
        // meshoptimizer's two.
        assert_eq!(text.lines().count(), 1 + backends + 3 + 3 + backends - 2);
        let row = |b: &str| report.rows.iter().find(|r| r.backend == b).unwrap();
        let against = |b: &str| -> Vec<String> {
            let line = text
                .lines()
                .find(|l| l.split_whitespace().nth(2) == Some(b))
                .unwrap_or_else(|| panic!("no row of {b} against its peer:\n{text}"));
            line.split_whitespace().map(str::to_string).collect()
        };
        for (ours, peer) in [("cpu", "meshopt"), ("cluster", "meshopt-sloppy")] {
            let (r, p) = (row(ours), row(peer));
            let fields = against(ours);
            assert_eq!(fields[3], peer);
            assert_eq!(fields[4], format!("{:.2}", p.median_s / r.median_s));
            let error = r.mean_err_rel.unwrap() / p.mean_err_rel.unwrap();
            assert_eq!(fields[5], format!("{error:.2}"));
        }
    }
}
