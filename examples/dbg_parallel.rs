use meshslim::*;
use std::time::Instant;
fn main() {
    let (name, m) = meshslim::bench::million_triangle_scan().unwrap();
    let ratio: f64 = std::env::args()
        .nth(1)
        .map(|s| s.parse().unwrap())
        .unwrap_or(0.01);
    for backend in [Backend::CpuParallel] {
        let mut o = SimplifyOptions::with_ratio(m.triangles.len(), ratio).unwrap();
        o.backend = backend;
        let t = Instant::now();
        let (out, r) = simplify(&m, &o).unwrap();
        let secs = t.elapsed().as_secs_f64();
        let rr = r.rounds.clone().unwrap();
        println!(
            "{name} {ratio} {:?} faces {} in {secs:.3}s rounds {} {:?}",
            backend,
            out.triangles.len(),
            rr.rounds,
            rr.faces_removed_per_round
        );
        for (s, t) in &rr.stage_seconds.0 {
            println!("  {s:20} {t:.3}");
        }
        let d = meshslim::metrics::compare(&m, &out, &Default::default()).unwrap();
        println!("mean rel {:.3e}", d.distance.two_sided.mean_rel);
    }
}
