//! Levels of detail: NSGA-II's parts on hand-made point sets, the Pareto search's decoding,
//! determinism and an exhaustively known front, and the LOD chain's continuation.

use meshslim::decimate::Decimator;
use meshslim::lod::nsga::{
    Point, crowding_distance, hypervolume, non_dominated_sort, select_survivors,
};
use meshslim::lod::{
    ErrorMeasure, Initialisation, Pareto, ParetoOptions, Variation, lod_chain, pareto_front,
};
use meshslim::mesh::{add_noise, grid, noisy_sphere};
use meshslim::{Backend, Mesh, Method, SimplifyOptions, simplify};

#[test]
fn non_dominated_sorting_finds_the_known_ranks() {
    // Front 0: (1,5) (2,3) (4,1); front 1: (3,4) (5,2); front 2: (6,6); (2,3) repeated is
    // dominated by nobody and so in front 0 too.
    let pts: Vec<Point> = vec![
        [3.0, 4.0],
        [1.0, 5.0],
        [6.0, 6.0],
        [2.0, 3.0],
        [5.0, 2.0],
        [4.0, 1.0],
        [2.0, 3.0],
    ];
    let fronts = non_dominated_sort(&pts);
    assert_eq!(fronts, vec![vec![1, 3, 5, 6], vec![0, 4], vec![2]]);
}

#[test]
fn crowding_distance_matches_the_hand_computed_values() {
    // One front, both objectives ranging over 4: the extremes are infinite.
    let pts: Vec<Point> = vec![[1.0, 5.0], [2.0, 3.0], [4.0, 1.5], [5.0, 1.0]];
    let d = crowding_distance(&pts, &[0, 1, 2, 3]);
    assert!(d[0].is_infinite() && d[3].is_infinite());
    // (2,3): x neighbours 1 and 4 → 3/4; y neighbours 1.5 and 5 → 3.5/4. Sum 1.625.
    assert!((d[1] - 1.625).abs() < 1e-12, "{d:?}");
    // (4,1.5): x neighbours 2 and 5 → 3/4; y neighbours 1 and 3 → 2/4. Sum 1.25.
    assert!((d[2] - 1.25).abs() < 1e-12, "{d:?}");
    // Survivors: front 0 whole, then the most crowded-apart of the next front.
    let more: Vec<Point> = vec![
        [1.0, 5.0],
        [2.0, 3.0],
        [3.0, 2.0],
        [5.0, 1.0],
        [2.0, 6.0],
        [3.5, 3.5],
        [6.0, 2.0],
    ];
    // Front 1 is (2,6) (3.5,3.5) (6,2): its extremes go first.
    assert_eq!(select_survivors(&more, 6), vec![0, 1, 2, 3, 4, 6]);
}

#[test]
fn hypervolume_of_a_known_front() {
    // Against (10, 10): the staircase of (2,8) (4,4) (8,2) covers
    // 2·2 + 4·6 + ... = (4-2)·2 + (8-4)·6 + (10-8)·8 = 4 + 24 + 16 = 44;
    // a dominated point and one outside the box change nothing.
    let front: Vec<Point> = vec![[2.0, 8.0], [4.0, 4.0], [8.0, 2.0]];
    assert_eq!(hypervolume(&front, [10.0, 10.0]), 44.0);
    let mut more = front.clone();
    more.push([5.0, 5.0]);
    more.push([11.0, 0.5]);
    assert_eq!(hypervolume(&more, [10.0, 10.0]), 44.0);
    assert_eq!(hypervolume(&[], [1.0, 1.0]), 0.0);
}

fn small_options() -> ParetoOptions {
    ParetoOptions {
        population: 16,
        generations: 6,
        offspring: 6,
        mutation: 0.02,
        measure: false,
        ..ParetoOptions::default()
    }
}

fn bumpy_sphere() -> Mesh {
    noisy_sphere(2, 0.02, 3)
}

#[test]
fn a_decoded_candidate_keeps_exactly_what_its_repaired_genome_says() {
    let mesh = bumpy_sphere();
    let engine = SimplifyOptions::with_faces(0);
    let pr = Pareto::new(&mesh, &engine).unwrap();
    let m = pr.order().len();
    assert!(m > 100, "most of the sphere is removable: {m}");
    let fixed = pr.live_vertices() - m;
    // A mask that removes every other vertex of the order, and one that removes all.
    for mut keep in [
        (0..m).map(|k| k % 2 == 0).collect::<Vec<_>>(),
        vec![false; m],
    ] {
        let before = keep.clone();
        let d = pr.decode(&mut keep);
        let kept = keep.iter().filter(|&&k| k).count();
        // Repair only ever keeps more.
        assert!(before.iter().zip(&keep).all(|(b, k)| !*b || *k));
        assert_eq!(d.live_vertices(), fixed + kept);
        let out = d.mesh();
        assert_eq!(
            out.positions.len(),
            fixed + kept,
            "the mesh has the genome's vertices"
        );
        // Decoding the repaired genome again refuses nothing and gives the same mesh.
        let mut again = keep.clone();
        let d2 = pr.decode(&mut again);
        assert_eq!(again, keep);
        assert_eq!(d2.mesh(), out);
    }
    // The greedy's mask at a count is the greedy run itself.
    let removed = m / 2;
    let mut keep = pr.greedy_mask(removed);
    let d = pr.decode(&mut keep);
    assert_eq!(
        keep,
        pr.greedy_mask(removed),
        "the greedy's own removals are never refused"
    );
    let mut greedy = Decimator::new(&mesh, &engine);
    let order = pr.order();
    for &v in &order[..removed] {
        assert!(matches!(
            greedy.remove(v),
            meshslim::decimate::Outcome::Removed { .. }
        ));
    }
    assert_eq!(greedy.mesh(), d.mesh());
}

#[test]
fn the_front_is_the_same_for_any_thread_count() {
    let mesh = bumpy_sphere();
    let run = |threads| {
        let opts = ParetoOptions {
            threads: Some(threads),
            ..small_options()
        };
        pareto_front(&mesh, &opts, &mut |_| {}).unwrap()
    };
    let (one, two) = (run(1), run(2));
    assert_eq!(one.generations, two.generations);
    assert_eq!(one.front, two.front);
    assert_eq!(one.front_meshes, two.front_meshes);
    assert!(
        one.evaluations >= 16 + 6 * 6,
        "children and their greedy twins"
    );
    assert_eq!(
        one.generations.len(),
        7,
        "the first population and six generations"
    );
    // Another seed searches differently.
    let other = pareto_front(
        &mesh,
        &ParetoOptions {
            seed: 2,
            ..small_options()
        },
        &mut |_| {},
    )
    .unwrap();
    assert_ne!(other.generations, one.generations);
}

/// A bumpy 4×4 grid: few enough removable vertices to try every mask.
fn tiny() -> Mesh {
    let mut m = grid(3);
    add_noise(&mut m, 0.05, 11);
    m
}

#[test]
fn nsga_finds_the_exhaustive_front_of_a_tiny_mesh() {
    let mesh = tiny();
    let engine = SimplifyOptions::with_faces(0);
    let pr = Pareto::new(&mesh, &engine).unwrap();
    let m = pr.order().len();
    assert!((4..=14).contains(&m), "{m} removable vertices");
    let n = pr.live_vertices() as f64;
    // Every mask, decoded: the points and their non-dominated set.
    let mut all: Vec<Point> = (0..1u32 << m)
        .map(|bits| {
            let mut keep: Vec<bool> = (0..m).map(|k| bits >> k & 1 == 1).collect();
            let d = pr.decode(&mut keep);
            [d.live_vertices() as f64 / n, d.vertex_plane_error()]
        })
        .collect();
    all.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    all.dedup();
    let mut exhaustive: Vec<Point> = non_dominated_sort(&all)[0]
        .iter()
        .map(|&i| all[i])
        .collect();
    exhaustive.sort_by(|a, b| a[0].total_cmp(&b[0]));
    assert!(exhaustive.len() >= 3, "{exhaustive:?}");

    let opts = ParetoOptions {
        population: 24,
        generations: 40,
        offspring: 8,
        mutation: 0.1,
        init: Initialisation::Random,
        variation: Variation {
            region_crossover: false,
            threshold_mutation: false,
        },
        error: ErrorMeasure::VertexPlane,
        measure: false,
        ..ParetoOptions::default()
    };
    let run = pareto_front(&mesh, &opts, &mut |_| {}).unwrap();
    let found: Vec<Point> = run
        .front
        .iter()
        .map(|c| [c.vertices as f64 / n, c.error])
        .collect();
    assert_eq!(found, exhaustive);
}

#[test]
fn the_decimation_chain_continues_each_level_from_the_one_before() {
    let mesh = bumpy_sphere();
    let mut opts = SimplifyOptions::with_faces(0);
    opts.method = Method::Decimate;
    let ratios = [0.5, 0.2, 0.05];
    let (levels, backend) = lod_chain(&mesh, &opts, &ratios, &mut |_| {}).unwrap();
    assert_eq!(backend, Backend::Cpu);
    assert_eq!(levels.len(), 3);
    let mut prev = mesh.positions.clone();
    for l in &levels {
        assert!(l.mesh.face_count() <= l.target_faces, "on target");
        assert!(l.mesh.face_count() + 2 >= l.target_faces);
        // Decimation keeps vertices where they were: each level's are a subset of the last's.
        assert!(l.mesh.positions.iter().all(|p| prev.contains(p)));
        prev = l.mesh.positions.clone();
    }
    // The first level is a separate run to its ratio.
    opts.target_faces = levels[0].target_faces;
    let (alone, _) = simplify(&mesh, &opts).unwrap();
    assert_eq!(alone, levels[0].mesh);
}

#[test]
fn qem_chains_go_on_from_their_state_on_every_backend() {
    let mesh = bumpy_sphere();
    let ratios = [0.5, 0.25, 0.1];
    for backend in [Backend::Cpu, Backend::CpuParallel] {
        let mut opts = SimplifyOptions::with_faces(0);
        opts.backend = backend;
        let (levels, used) = lod_chain(&mesh, &opts, &ratios, &mut |_| {}).unwrap();
        assert_eq!(used, backend);
        let faces: Vec<usize> = levels.iter().map(|l| l.mesh.face_count()).collect();
        assert!(faces.windows(2).all(|w| w[1] < w[0]), "{faces:?}");
        for l in &levels {
            assert!(
                l.mesh.face_count() <= l.target_faces,
                "{backend:?}: on target"
            );
            l.mesh.validate().unwrap();
        }
        // The first level is the separate run; the later ones start from it (their error
        // bound never falls).
        opts.target_faces = levels[0].target_faces;
        let (alone, _) = simplify(&mesh, &opts).unwrap();
        assert_eq!(alone, levels[0].mesh, "{backend:?}");
        assert!(levels.windows(2).all(|w| w[1].max_error >= w[0].max_error));
    }
}

#[test]
fn bad_ratios_and_clustering_chains_are_refused() {
    let mesh = bumpy_sphere();
    let opts = SimplifyOptions::with_faces(0);
    for bad in [&[][..], &[0.5, 0.5], &[0.1, 0.2], &[1.5], &[0.0]] {
        assert!(
            lod_chain(&mesh, &opts, bad, &mut |_| {}).is_err(),
            "{bad:?}"
        );
    }
    let cluster = SimplifyOptions {
        method: Method::Cluster,
        ..opts
    };
    let e = lod_chain(&mesh, &cluster, &[0.5], &mut |_| {}).unwrap_err();
    assert!(e.to_string().contains("no state"), "{e}");
}
