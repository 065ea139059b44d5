//! The clustering methods (`cluster`, `hybrid`) and their stages, on generated meshes with
//! known answers.

use meshslim::cluster::grid::CellGrid;
use meshslim::cluster::{floating, stages};
use meshslim::mesh::{grid, icosphere, topology, torus};
use meshslim::{Backend, Error, Mesh, Method, SimplifyOptions, StopReason, simplify};

fn opts(faces: usize, method: Method) -> SimplifyOptions {
    let mut o = SimplifyOptions::with_faces(faces);
    o.method = method;
    o.backend = Backend::CpuParallel;
    o
}

/// A flat sheet of `n`×`n` quads over the unit square at height `z`.
fn sheet(n: usize, z: f32) -> Mesh {
    let mut m = grid(n);
    let b = m.bounds().unwrap();
    for p in &mut m.positions {
        p[0] = (p[0] - b.min[0]) / (b.max[0] - b.min[0]);
        p[1] = (p[1] - b.min[1]) / (b.max[1] - b.min[1]);
        p[2] = z;
    }
    m
}

fn join(a: &Mesh, b: &Mesh) -> Mesh {
    let n = a.positions.len() as u32;
    let mut positions = a.positions.clone();
    positions.extend_from_slice(&b.positions);
    let mut triangles = a.triangles.clone();
    triangles.extend(b.triangles.iter().map(|t| t.map(|v| v + n)));
    Mesh::new(positions, triangles)
}

#[test]
fn the_radix_sort_is_the_stable_sort_by_key() {
    // Few keys sort in one run, many in runs on every core; both must give the stable order,
    // whatever the passes the largest key asks for (none, one, two, three; a singleton's key
    // has bit 31, so with singletons among the keys, three).
    fn scrambled(i: u32, modulo: u32) -> u32 {
        i.wrapping_mul(2_654_435_761) % modulo
    }
    type KeyOf = fn(u32) -> u32;
    let sets: [(&str, KeyOf); 6] = [
        ("26-bit", |i| scrambled(i, 70_000) | ((i % 3) << 24)),
        ("24-bit", |i| scrambled(i, 1 << 24)),
        ("20-bit", |i| scrambled(i, 1 << 20)),
        ("11-bit", |i| scrambled(i, 2048)),
        ("all zero", |_| 0),
        ("singletons among 20-bit", |i| {
            if i % 7 == 3 {
                stages::SINGLETON
            } else {
                scrambled(i, 1 << 20)
            }
        }),
    ];
    for n in [5000u32, 300_001] {
        for (name, key) in sets {
            let keys: Vec<u32> = (0..n).map(key).collect();
            let (sorted, ids) = stages::radix_sort(keys.clone());
            let mut want: Vec<u32> = (0..keys.len() as u32).collect();
            want.sort_by_key(|&i| keys[i as usize]);
            assert_eq!(ids, want, "{n} {name} keys");
            let want_keys: Vec<u32> = want.iter().map(|&i| keys[i as usize]).collect();
            assert_eq!(sorted, want_keys, "{n} {name} keys");
        }
    }
    // An empty input and all-equal keys (every key in one digit of every pass).
    assert_eq!(stages::radix_sort(vec![]), (vec![], vec![]));
    let (sorted, ids) = stages::radix_sort(vec![7u32 << 20; 100_000]);
    assert_eq!(ids, (0..100_000).collect::<Vec<u32>>());
    assert!(sorted.iter().all(|&k| k == 7 << 20));
}

#[test]
fn a_grid_of_countable_cells_keeps_the_faces_between_them() {
    // The unit square with 8×8 quads (vertices every 1/8), on cells of side 0.27 from
    // -1/16: each cell holds a 2×2 block of vertices (3 along the far walls), 4×4 cells.
    let m = sheet(8, 0.0);
    let positions: Vec<[f32; 4]> = m
        .positions
        .iter()
        .map(|p| [p[0], p[1], p[2], 1.0])
        .collect();
    // Shift the grid by half a vertex spacing so no vertex sits on a cell wall.
    let g = CellGrid::new([-1.0 / 16.0, -1.0 / 16.0, 0.0], [1.0, 1.0, 0.0], 0.27);
    let keys = stages::cell_keys(&g, &positions, &vec![false; positions.len()]);
    let (sorted, members) = stages::radix_sort(keys);
    let mut cells = stages::cell_ranges(&sorted, members);
    assert_eq!(cells.key.len(), 16, "4 x 4 occupied cells");
    let clusters = stages::Clusters::whole_cells(&mut cells);
    let faces = stages::cluster_faces(
        &m.triangles,
        &clusters.vertex_cluster,
        clusters.len(),
        false,
    );
    // A 4×4 grid of cluster vertices is a 3×3 grid of quads: 18 triangles, each from the one
    // input quad with a corner in each of four cells.
    assert_eq!(faces.len(), 18);
}

#[test]
fn cluster_lands_within_five_percent_of_the_target() {
    let m = icosphere(6); // 81,920 faces
    for target in [20_000, 5_000, 800] {
        let (out, r) = simplify(&m, &opts(target, Method::Cluster)).unwrap();
        out.validate().unwrap();
        let n = out.triangles.len() as f64;
        assert!(
            (n - target as f64).abs() <= 0.05 * target as f64,
            "{n} faces for {target}"
        );
        assert_eq!(r.stop_reason, StopReason::TargetReached);
        assert_eq!(r.output_faces, out.triangles.len());
        let c = r.clustering.expect("a clustering report");
        assert!(c.builds >= 1 && c.clusters >= out.positions.len());
        // Every output vertex lies within a cell's diagonal of the sphere (radius 1; the
        // cell size is relative to the box's diagonal, 2√3).
        let side = c.cell_size * 2.0 * 3f64.sqrt();
        for p in &out.positions {
            let r = (p[0] as f64).hypot(p[1] as f64).hypot(p[2] as f64);
            assert!(
                (r - 1.0).abs() <= 3f64.sqrt() * side,
                "vertex at radius {r}"
            );
        }
    }
}

#[test]
fn hybrid_reaches_the_exact_target_and_keeps_a_manifold_manifold() {
    let mut m = torus(1.0, 0.3, 512, 192); // 196,608 faces, genus 1
    meshslim::mesh::add_noise(&mut m, 0.002, 7);
    // The greedy queue (`cpu`) and the rounds (`cpu-parallel`) after the clusters.
    for (target, backend) in [
        (4000, Backend::Cpu),
        (600, Backend::Cpu),
        (4000, Backend::CpuParallel),
        (600, Backend::CpuParallel),
    ] {
        let mut o = opts(target, Method::Hybrid);
        o.backend = backend;
        let (out, r) = simplify(&m, &o).unwrap();
        assert_eq!(r.backend, backend, "the second phase ran where asked");
        assert_eq!(r.rounds.is_some(), backend == Backend::CpuParallel);
        out.validate().unwrap();
        assert!(
            out.triangles.len() <= target && out.triangles.len() + 2 >= target,
            "{} faces for {target}",
            out.triangles.len()
        );
        let c = r.clustering.expect("a clustering report");
        assert!(c.intermediate_faces.unwrap() >= target);
        let t = topology(&out);
        assert_eq!(t.non_manifold_edges, 0, "target {target}");
        assert_eq!(t.euler_characteristic, 0, "still a torus at {target}");
    }
}

/// On `cpu` the hybrid's second phase is the greedy queue on the clustered surface: its error
/// against the input is no higher than the rounds' from the same clusters (on the shared scans
/// 4–19% lower). With colours in the cost it runs the rounds, where the greedy's colour error
/// was higher: the same mesh as `cpu-parallel`'s.
#[test]
fn hybrid_on_cpu_is_the_greedy_queue_after_the_clusters() {
    let mut m = torus(1.0, 0.3, 512, 192);
    meshslim::mesh::add_noise(&mut m, 0.002, 7);
    let err = |o: &SimplifyOptions| {
        let (out, r) = simplify(&m, o).unwrap();
        let e = meshslim::metrics::compare(&m, &out, &Default::default()).unwrap();
        (e.distance.two_sided.mean_rel, r)
    };
    let mut greedy = opts(4000, Method::Hybrid);
    greedy.backend = Backend::Cpu;
    let (eg, rg) = err(&greedy);
    let (er, _) = err(&opts(4000, Method::Hybrid));
    assert_eq!(rg.backend, Backend::Cpu);
    assert!(eg <= er, "greedy {eg} against the rounds' {er}");
    assert!(rg.clustering.unwrap().intermediate_faces.is_some());
    // Painted: the rounds, the same mesh as cpu-parallel's.
    meshslim::mesh::paint(&mut m);
    let (a, ra) = simplify(&m, &greedy).unwrap();
    let (b, _) = simplify(&m, &opts(4000, Method::Hybrid)).unwrap();
    assert_eq!(ra.backend, Backend::CpuParallel);
    assert_eq!((a.positions, a.triangles), (b.positions, b.triangles));
}

#[test]
fn hybrid_keeps_two_sheets_closer_than_a_cell_apart() {
    // Two parallel sheets 0.005 apart (0.35% of the diagonal), 80,000 faces each; clustering
    // for 1/40 of the faces uses cells wider than that, so plain cells would merge the sheets.
    let gap = 0.005;
    let m = join(&sheet(200, 0.0), &sheet(200, gap));
    let faces = m.triangles.len();
    let (out, r) = simplify(&m, &opts(faces / 40, Method::Hybrid)).unwrap();
    let c = r.clustering.unwrap();
    assert!(
        c.cell_size > gap as f64 / 1.42,
        "cells of {} do span the gap",
        c.cell_size
    );
    assert!(c.split_clusters > 0, "cells were split by connectivity");
    let t = topology(&out);
    assert_eq!(t.connected_components, 2, "the sheets stay apart");
    assert_eq!(t.non_manifold_edges, 0);
    // And the plain grid does join them.
    let (joined, _) = simplify(&m, &opts(faces / 40, Method::Cluster)).unwrap();
    let zs: Vec<f32> = joined.positions.iter().map(|p| p[2]).collect();
    assert!(
        zs.iter().any(|&z| z > 0.1 * gap && z < 0.9 * gap),
        "cluster puts vertices between the sheets"
    );
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let mut m = icosphere(5);
    meshslim::mesh::add_noise(&mut m, 0.01, 3);
    for method in [Method::Cluster, Method::Hybrid] {
        let run = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| simplify(&m, &opts(2000, method)).unwrap().0)
        };
        let (a, b, c) = (run(1), run(2), run(3));
        assert_eq!(a.triangles, b.triangles, "{method:?}");
        assert_eq!(a.positions, b.positions, "{method:?}");
        assert_eq!(a.triangles, c.triangles, "{method:?}");
        assert_eq!(a.positions, c.positions, "{method:?}");
    }
}

/// The hybrid's greedy second phase too: its regions are cut by face count, not thread count.
#[test]
fn the_greedy_hybrid_does_not_depend_on_the_thread_count() {
    let mut m = icosphere(6); // 81,920 faces: clusters to 24,000 for 2,000
    meshslim::mesh::add_noise(&mut m, 0.01, 3);
    let mut o = opts(2000, Method::Hybrid);
    o.backend = Backend::Cpu;
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| simplify(&m, &o).unwrap())
    };
    let ((a, ra), (b, _), (c, _)) = (run(1), run(2), run(3));
    assert!(ra.clustering.unwrap().intermediate_faces.is_some());
    assert_eq!(ra.backend, Backend::Cpu);
    assert_eq!((&a.triangles, &a.positions), (&b.triangles, &b.positions));
    assert_eq!((&a.triangles, &a.positions), (&c.triangles, &c.positions));
}

/// The points' box is the input's box taken into the frame, not a pass over the points: the
/// same bits as the least and greatest normalized coordinates, on meshes off the origin, of
/// mixed signs and scales.
#[test]
fn the_points_box_is_the_least_and_greatest_point() {
    let mut shifted = torus(1.0, 0.3, 64, 32);
    meshslim::mesh::add_noise(&mut shifted, 0.01, 5);
    for p in &mut shifted.positions {
        *p = [p[0] * 1e3 + 12_345.6, p[1] * 0.37 - 7.1, p[2] * 1e-3];
    }
    for m in [icosphere(3), sheet(17, -2.5), shifted] {
        let (pts, lo, hi) = meshslim::cluster::unit_frame_points(&m);
        for i in 0..3 {
            let low = pts.iter().map(|p| p[i]).fold(f32::INFINITY, f32::min);
            let high = pts.iter().map(|p| p[i]).fold(f32::NEG_INFINITY, f32::max);
            assert_eq!(lo[i].to_bits(), low.to_bits());
            assert_eq!(hi[i].to_bits(), high.to_bits());
        }
    }
}

#[test]
fn max_error_bounds_the_cell() {
    let m = icosphere(5);
    let mut o = opts(0, Method::Cluster);
    o.max_error = Some(0.02);
    let (out, r) = simplify(&m, &o).unwrap();
    assert_eq!(r.stop_reason, StopReason::MaxError);
    let c = r.clustering.unwrap();
    assert!(c.cell_size * 3f64.sqrt() <= 0.02 + 1e-6);
    // Every output vertex within the bound (relative to the diagonal, 2√3) of the sphere.
    let diag = 2.0 * 3f64.sqrt();
    for p in &out.positions {
        let r = (p[0] as f64).hypot(p[1] as f64).hypot(p[2] as f64);
        assert!((r - 1.0).abs() <= 0.02 * diag, "vertex at radius {r}");
    }
}

/// Every clustering method takes `--backend gpu` (hybrid for its rounds): with an adapter the
/// report says gpu; without one the error is the GPU's, never a refused option.
#[test]
fn every_clustering_method_takes_the_gpu_backend() {
    let adapter = meshslim::rounds::gpu::shared().is_ok();
    for method in [Method::Cluster, Method::FloatingCell, Method::Hybrid] {
        let mut o = opts(100, method);
        o.backend = Backend::Gpu;
        match simplify(&icosphere(3), &o) {
            Ok((_, r)) => {
                assert!(adapter);
                assert_eq!(r.backend, Backend::Gpu, "{method:?}");
            }
            Err(Error::Gpu(msg)) => assert!(!adapter, "{method:?}: {msg}"),
            Err(e) => panic!("{method:?}: {e}"),
        }
    }
}

#[test]
fn a_locked_border_stays_where_it_was() {
    let m = sheet(40, 0.0);
    let mut o = opts(800, Method::Cluster);
    o.lock_border = true;
    let (out, _) = simplify(&m, &o).unwrap();
    out.validate().unwrap();
    // Every input border vertex is still an output vertex, bit for bit.
    for p in &m.positions {
        let on_border = p[0] == 0.0 || p[0] == 1.0 || p[1] == 0.0 || p[1] == 1.0;
        if on_border {
            assert!(out.positions.contains(p), "border vertex {p:?} moved");
        }
    }
}

#[test]
fn floating_cells_in_rounds_are_the_sequential_greedy() {
    // Low & Tan's sequential rule: the highest-ranked unclaimed vertex becomes a centre and
    // claims the unclaimed vertices within its radius. The parallel rounds must pick the same centres
    // and the same claims.
    let mut m = icosphere(4);
    meshslim::mesh::add_noise(&mut m, 0.02, 11);
    let positions: Vec<[f32; 4]> = m
        .positions
        .iter()
        .map(|p| [p[0], p[1], p[2], 1.0])
        .collect();
    let csr = stages::Csr::new(positions.len(), &m.triangles);
    let ranks = floating::ranks(&floating::grades(&positions, &m.triangles, &csr));
    let locked = vec![false; positions.len()];
    for r in [0.05f32, 0.15, 0.4] {
        let (centre, rounds) = floating::claim(&positions, &ranks, &locked, [-1.1; 3], [1.1; 3], r);
        let mut order: Vec<usize> = (0..positions.len()).collect();
        order.sort_by_key(|&v| std::cmp::Reverse(ranks[v]));
        let mut want = vec![u32::MAX; positions.len()];
        for &v in &order {
            if want[v] != u32::MAX {
                continue;
            }
            let rv = floating::radius(r, v as u32);
            for u in 0..positions.len() {
                let d: f32 = (0..3)
                    .map(|i| (positions[u][i] - positions[v][i]).powi(2))
                    .sum();
                if want[u] == u32::MAX && d <= rv * rv {
                    want[u] = v as u32;
                }
            }
        }
        assert_eq!(centre, want, "radius {r}, {rounds} rounds");
    }
}

#[test]
fn floating_cells_land_in_the_band_and_keep_a_cubes_corners() {
    let m = meshslim::mesh::cube(20); // 20×20 quads a side
    let faces = m.triangles.len();
    for target in [faces / 10, faces / 50] {
        let (out, r) = simplify(&m, &opts(target, Method::FloatingCell)).unwrap();
        out.validate().unwrap();
        let n = out.triangles.len() as f64;
        assert!(
            (n - target as f64).abs() <= 0.05 * target as f64,
            "{n} faces for {target}"
        );
        assert!(r.clustering.unwrap().centre_rounds.unwrap() >= 1);
        let b = m.bounds().unwrap();
        for i in 0..8 {
            let corner = [0, 1, 2].map(|k| if i >> k & 1 == 0 { b.min[k] } else { b.max[k] });
            let near = out
                .positions
                .iter()
                .any(|p| (0..3).all(|k| (p[k] - corner[k]).abs() <= 1e-4 * (b.max[k] - b.min[k])));
            assert!(near, "corner {corner:?} kept at {target} faces");
        }
    }
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| {
                simplify(&m, &opts(faces / 10, Method::FloatingCell))
                    .unwrap()
                    .0
            })
    };
    let (a, b) = (run(1), run(2));
    assert_eq!(a.triangles, b.triangles);
    assert_eq!(a.positions, b.positions);
}
