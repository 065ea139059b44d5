//! Reading speed of the PLY reader on the reference scans (bytes per second):
//! `cargo bench --bench io`. Skipped, with a note, when ../shared/models is absent.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use meshslim::{bench, io};

fn read_ply(c: &mut Criterion) {
    let Some(dir) = bench::models_dir() else {
        eprintln!("note: no models folder (see meshslim::bench::models_dir); nothing to measure");
        return;
    };
    let mut group = c.benchmark_group("read-ply");
    for name in ["horse.ply", "igea.ply"] {
        let path = dir.join(name);
        let Ok(meta) = std::fs::metadata(&path) else {
            continue;
        };
        group.throughput(Throughput::Bytes(meta.len()));
        group.bench_function(name, |b| {
            b.iter(|| io::read(&path).expect("reading a reference scan"))
        });
    }
    group.finish();
}

criterion_group!(benches, read_ply);
criterion_main!(benches);
