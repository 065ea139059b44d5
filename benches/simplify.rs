//! Every backend of `meshslim bench` this machine can run (`meshslim::bench::available_backends`:
//! meshslim's greedy `cpu`, its rounds on `cpu-parallel` and — with an adapter — `gpu`,
//! meshoptimizer's `simplify` and `simplifySloppy`) on the same meshes, through the same calls.
//!
//! Inputs: horse.ply and igea.ply from the models folder when present (see
//! `meshslim::bench::models_dir`), and the million-triangle scan
//! (`meshslim::bench::million_triangle_scan`), each at the ratios 0.1 and 0.01. Throughput is in
//! input triangles, so criterion reports triangles per second.
//!
//! Benchmark ids are `<input>-<ratio>/<backend>`, where the million-triangle input is named `1M`:
//! `cargo bench --bench simplify -- 1M` runs only that one, `-- horse-0.1` one case.

use std::time::Duration;

use criterion::{
    BenchmarkId, Criterion, SamplingMode, Throughput, criterion_group, criterion_main,
};
use meshslim::{SimplifyOptions, bench};

fn simplify(c: &mut Criterion) {
    let inputs = bench::inputs().expect("reading the benchmark inputs");
    let last = inputs.len() - 1;
    for (i, (name, mesh)) in inputs.iter().enumerate() {
        // The million-triangle scan gets a short id to filter on; its full name is printed.
        let id = if i == last {
            eprintln!(
                "1M = {name}: {} triangles, {} vertices",
                mesh.face_count(),
                mesh.vertex_count()
            );
            "1M"
        } else {
            name.as_str()
        };
        let faces = mesh.face_count();
        for ratio in bench::RATIOS {
            let opts = SimplifyOptions::with_ratio(faces, ratio).expect("valid ratio");
            let mut group = c.benchmark_group(format!("{id}-{ratio}"));
            group
                .throughput(Throughput::Elements(faces as u64))
                .sample_size(10)
                // Runs take 0.01-10 s: flat sampling, the mode criterion advises for long runs.
                .sampling_mode(SamplingMode::Flat)
                .warm_up_time(Duration::from_millis(500))
                .measurement_time(Duration::from_secs(if faces > 500_000 { 40 } else { 5 }));
            for backend in bench::available_backends() {
                group.bench_function(BenchmarkId::from_parameter(backend.name), |b| {
                    b.iter(|| (backend.simplify)(mesh, opts.target_faces).expect("simplify"))
                });
            }
            group.finish();
        }
    }
}

criterion_group!(benches, simplify);
criterion_main!(benches);
