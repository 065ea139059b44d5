use meshslim::*;
use std::time::Instant;
fn main() {
    for (name, m) in [
        ("noisy", mesh::noisy_sphere(4, 0.01, 42)),
        ("grid", mesh::grid(40)),
    ] {
        for ratio in [0.5, 0.01] {
            for backend in [Backend::CpuParallel, Backend::Gpu] {
                let mut o = SimplifyOptions::with_ratio(m.triangles.len(), ratio).unwrap();
                o.backend = backend;
                let t = Instant::now();
                match simplify(&m, &o) {
                    Ok((out, r)) => {
                        let d = meshslim::metrics::compare(&m, &out, &Default::default()).unwrap();
                        let rr = r.rounds.unwrap();
                        println!(
                            "{name} {ratio} {backend:?} faces {} rounds {} {:?} err {:.4e} {:.3}s",
                            out.triangles.len(),
                            rr.rounds,
                            rr.faces_removed_per_round,
                            d.distance.two_sided.mean_rel,
                            t.elapsed().as_secs_f64()
                        );
                    }
                    Err(e) => println!("{name} {ratio} {backend:?} error {e}"),
                }
            }
        }
    }
}
