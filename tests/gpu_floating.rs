//! `--method floating-cell` on the gpu backend (lavapipe in CI): every floating stage's buffers
//! against its CPU twin (tests/cluster_twins/floating.rs) fed the GPU's own inputs, so integers
//! must match exactly stage by stage and floats within 1e-4; the whole GPU build against the
//! twins' chain; and `simplify` on the GPU against cpu-parallel. With CI=true a missing adapter
//! fails.

use crate::cluster_twins;
use crate::common;

use cluster_twins as twins;
use cluster_twins::floating as ft;
use common::{close, gpu_context, rounds_like_the_cpu};
use meshslim::Mesh;
use meshslim::cluster::floating::{self, UNCLAIMED};
use meshslim::cluster::floating_gpu::FcPart;
use meshslim::cluster::gpu::{GpuClusterMesh, GpuClusterer, Part};
use meshslim::cluster::gpu_schedule::ClusterBuf;
use meshslim::cluster::gpu_schedule::ROUND_SLOTS;
use meshslim::cluster::stages;
use meshslim::compute::types::{ClusterPlaced, Params, Quadric};

/// Meshes, each with the nominal radii (unit-diagonal frame) to build at and whether to lock
/// every 7th vertex (centres of themselves from the start).
fn cases() -> Vec<(&'static str, Mesh, Vec<f32>, bool)> {
    let mut torus = meshslim::mesh::torus(1.0, 0.3, 96, 48);
    meshslim::mesh::add_noise(&mut torus, 0.002, 7);
    let mut sphere = meshslim::mesh::icosphere(5);
    meshslim::mesh::add_noise(&mut sphere, 0.005, 3);
    vec![
        ("noisy_icosphere", sphere, vec![0.01, 0.04], false),
        ("noisy_torus", torus, vec![0.02], false),
        ("grid", meshslim::mesh::grid(60), vec![0.015, 0.05], false),
        ("cube", meshslim::mesh::cube(20), vec![0.03], false),
        (
            "icosphere_locked",
            meshslim::mesh::icosphere(4),
            vec![0.03],
            true,
        ),
    ]
}

fn locked_of(n: usize, lock: bool) -> Vec<bool> {
    (0..n).map(|v| lock && v % 7 == 0).collect()
}

fn rd<T: bytemuck::Pod>(g: &GpuClusterMesh, b: ClusterBuf, n: usize) -> Vec<T> {
    let bytes = g
        .read_buffer(b, (n * std::mem::size_of::<T>()) as u64)
        .unwrap();
    bytemuck::pod_collect_to_vec(&bytes)
}

/// Runs the sort passes `0..passes` on the GPU and checks the result against the twins' sort of
/// the keys and values it started from; returns the sorted keys and values.
fn sort_on_both(
    gpu: &mut GpuClusterMesh,
    label: &str,
    passes: u32,
    nv: usize,
) -> (Vec<u32>, Vec<u32>) {
    let keys: Vec<u32> = rd(gpu, ClusterBuf::SortKeys, nv);
    let vals: Vec<u32> = rd(gpu, ClusterBuf::SortVals, nv);
    for p in 0..passes {
        gpu.run_part(Part::SortPass(p)).unwrap();
    }
    let (gk, gv): (Vec<u32>, Vec<u32>) = (
        rd(gpu, ClusterBuf::SortKeys, nv),
        rd(gpu, ClusterBuf::SortVals, nv),
    );
    let want = twins::sort(&keys, &vals, passes)
        .pop()
        .map_or((keys, vals), |p| (p.1, p.2));
    assert_eq!((&gk, &gv), (&want.0, &want.1), "{label}: the sort");
    (gk, gv)
}

/// The cells part on the GPU against `twins::cells` of the same sorted keys.
fn cells_on_both(gpu: &mut GpuClusterMesh, label: &str, sorted: &(Vec<u32>, Vec<u32>)) -> usize {
    let nv = sorted.0.len();
    gpu.run_part(Part::Cells).unwrap();
    let c = twins::cells(&gpu.cluster_params(), &sorted.0, &sorted.1);
    let n = c.cell_key.len();
    assert_eq!(
        rd::<u32>(gpu, ClusterBuf::CellHead, nv + 1),
        c.cell_head,
        "{label}"
    );
    assert_eq!(
        rd::<u32>(gpu, ClusterBuf::CellStart, n + 1),
        c.cell_start,
        "{label}"
    );
    assert_eq!(
        rd::<u32>(gpu, ClusterBuf::VertexCell, nv),
        c.vertex_cell,
        "{label}"
    );
    assert_eq!(
        rd::<u32>(gpu, ClusterBuf::CellKey, n),
        c.cell_key,
        "{label}"
    );
    n
}

#[test]
fn each_floating_stage_matches_its_cpu_twin() {
    let Some(ctx) = gpu_context() else { return };
    let sim = GpuClusterer::new(&ctx.device, &ctx.queue).unwrap();
    for (name, m, radii, lock) in cases() {
        let (pos, lo, hi) = meshslim::cluster::unit_frame_points(&m);
        let locked = locked_of(pos.len(), lock);
        let locked_u32: Vec<u32> = locked.iter().map(|&l| l as u32).collect();
        let (nv, nf) = (pos.len(), m.triangles.len());
        let indices: &[u32] = bytemuck::cast_slice(&m.triangles);
        let mut gpu = GpuClusterMesh::new(&sim, &pos, &m.triangles, &locked).unwrap();
        let offsets: Vec<u32> = rd(&gpu, ClusterBuf::Offsets, nv + 1);
        let vertex_faces: Vec<u32> = rd(&gpu, ClusterBuf::VertexFaces, 3 * nf);
        let normals: Vec<[f32; 4]> = rd(&gpu, ClusterBuf::FaceNormals, nf);
        let params = Params {
            vertex_count: nv as u32,
            face_count: nf as u32,
            ..Default::default()
        };

        // fc_grades: floats, within 1e-4 of the longest edge there.
        gpu.run_fc_part(FcPart::Ranks).unwrap();
        let grades: Vec<f32> = rd(&gpu, ClusterBuf::FcGrade, nv);
        let mut want = vec![0f32; nv];
        ft::fc_grades(&params, &pos, indices, &offsets, &vertex_faces, &mut want);
        let exact = grades.iter().zip(&want).filter(|(a, b)| a == b).count();
        eprintln!("{name}: {exact} of {nv} grades bit for bit");
        if rounds_like_the_cpu() {
            assert_eq!(
                exact, nv,
                "{name}: lavapipe's grades are the CPU's bit for bit"
            );
        }
        // The grade is L·√((1 + cos θ)/2), L the longest edge: compared as the cosine it stands
        // for, since near θ = 180° (a flat vertex) the root magnifies a cosine's rounding, an ulp
        // of 1, into 2.4e-4 L. Within 32 ulps of 1: the GPU may divide to 2.5 ulps and fuse the
        // dot product (an H200's grade of a noisy icosphere vertex: 3.5778e-5 against the CPU's
        // 3.5662e-5, a cosine 1.4e-7 apart).
        for v in 0..nv {
            let longest = longest_edge(&pos, &m.triangles, &offsets, &vertex_faces, v);
            let cosine = |g: f32| 2.0 * (g as f64 / longest.max(f32::MIN_POSITIVE) as f64).powi(2);
            assert!(
                (cosine(grades[v]) - cosine(want[v])).abs() <= 32.0 * f32::EPSILON as f64,
                "{name}: grade of {v}: {} on the GPU, {} on the CPU (longest edge {longest})",
                grades[v],
                want[v]
            );
        }
        // fc_ranks fed the GPU's grades: exact.
        let (mut ranks, mut keys, mut vals) = (vec![0u32; nv], vec![0u32; nv], vec![0u32; nv]);
        ft::fc_ranks(&params, &grades, &mut ranks, &mut keys, &mut vals);
        assert_eq!(
            rd::<u32>(&gpu, ClusterBuf::FcRank, nv),
            ranks,
            "{name}: fc_rank"
        );
        assert_eq!(
            rd::<u32>(&gpu, ClusterBuf::SortKeys, nv),
            keys,
            "{name}: rank keys"
        );
        assert_eq!(
            rd::<u32>(&gpu, ClusterBuf::SortVals, nv),
            vals,
            "{name}: rank values"
        );
        let (_, order) = sort_on_both(
            &mut gpu,
            name,
            meshslim::cluster::gpu_schedule::RANK_PASSES,
            nv,
        );
        gpu.run_fc_part(FcPart::Order).unwrap();
        assert_eq!(
            rd::<u32>(&gpu, ClusterBuf::FcOrder, nv),
            order,
            "{name}: fc_order"
        );
        // The order is by rank, highest first, as the CPU's u64 ranks order.
        let full: Vec<u64> = (0..nv)
            .map(|v| floating::rank(grades[v], v as u32))
            .collect();
        assert!(
            order
                .windows(2)
                .all(|w| full[w[0] as usize] > full[w[1] as usize])
        );

        for &r in &radii {
            let label = format!("{name} at r = {r}");
            gpu.set_radius(lo, hi, r).unwrap();
            let c = gpu.cluster_params();
            gpu.run_fc_part(FcPart::Keys).unwrap();
            let (mut keys, mut vals) = (vec![0u32; nv], vec![0u32; nv]);
            ft::fc_keys(&c, &pos, &order, &mut keys, &mut vals);
            assert_eq!(
                rd::<u32>(&gpu, ClusterBuf::SortKeys, nv),
                keys,
                "{label}: fc_keys"
            );
            assert_eq!(
                rd::<u32>(&gpu, ClusterBuf::SortVals, nv),
                vals,
                "{label}: fc_keys"
            );
            let (mut centre, mut head) = (vec![0u32; nv], vec![0u32; nv + 1]);
            ft::fc_init(&c, &locked_u32, &mut centre, &mut head);
            assert_eq!(
                rd::<u32>(&gpu, ClusterBuf::FcCentre, nv),
                centre,
                "{label}: fc_init"
            );
            assert_eq!(
                rd::<u32>(&gpu, ClusterBuf::FcHead, nv),
                head[..nv],
                "{label}: fc_init"
            );
            let passes = gpu.hash_passes();
            let sorted = sort_on_both(&mut gpu, &label, passes, nv);
            let cells = cells_on_both(&mut gpu, &label, &sorted);
            let cell_head: Vec<u32> = rd(&gpu, ClusterBuf::CellHead, nv + 1);
            let cell_start: Vec<u32> = rd(&gpu, ClusterBuf::CellStart, cells + 1);
            let cell_key: Vec<u32> = rd(&gpu, ClusterBuf::CellKey, cells);

            // The rounds, each stage from the GPU's buffers before it.
            let mut rounds = 0;
            'rounds: loop {
                for slot in 0..ROUND_SLOTS as u32 {
                    if slot == 0 {
                        gpu.run_fc_part(FcPart::Batch).unwrap();
                    }
                    let f = meshslim::cluster::gpu_schedule::float_params(r, slot);
                    let centre: Vec<u32> = rd(&gpu, ClusterBuf::FcCentre, nv);
                    let mut decided: Vec<u32> = rd(&gpu, ClusterBuf::FcDecided, nv);
                    let mut head: Vec<u32> = rd(&gpu, ClusterBuf::FcHead, nv + 1);
                    gpu.run_fc_part(FcPart::Round(slot)).unwrap();
                    let mut live = vec![0u32; ROUND_SLOTS];
                    ft::fc_decide(
                        &c,
                        &f,
                        &pos,
                        &ranks,
                        &sorted.1,
                        &cell_head,
                        &cell_start,
                        &cell_key,
                        &centre,
                        &mut decided,
                        &mut live,
                    );
                    let what = format!("{label}: round {rounds}");
                    let live_gpu: Vec<u32> = rd(&gpu, ClusterBuf::FcLive, ROUND_SLOTS);
                    assert_eq!(
                        live_gpu[slot as usize], live[slot as usize],
                        "{what}: fc_live"
                    );
                    assert_eq!(
                        rd::<u32>(&gpu, ClusterBuf::FcDecided, nv),
                        decided,
                        "{what}"
                    );
                    let mut after = centre.clone();
                    ft::fc_claim(
                        &c,
                        &f,
                        &pos,
                        &sorted.1,
                        &cell_head,
                        &cell_start,
                        &cell_key,
                        &decided,
                        &mut after,
                        &mut head,
                    );
                    assert_eq!(
                        rd::<u32>(&gpu, ClusterBuf::FcCentre, nv),
                        after,
                        "{what}: centres"
                    );
                    assert_eq!(
                        rd::<u32>(&gpu, ClusterBuf::FcHead, nv),
                        head[..nv],
                        "{what}"
                    );
                    if live[slot as usize] == 0 {
                        break 'rounds;
                    }
                    rounds += 1;
                    assert!(rounds <= nv, "{label}: rounds do not end");
                }
            }
            let centre: Vec<u32> = rd(&gpu, ClusterBuf::FcCentre, nv);
            assert!(
                !centre.contains(&UNCLAIMED),
                "{label}: every vertex claimed"
            );

            // Centres numbered, vertices keyed by cluster.
            let mut head: Vec<u32> = rd(&gpu, ClusterBuf::FcHead, nv + 1);
            gpu.run_fc_part(FcPart::Clusters).unwrap();
            meshslim::rounds::cpu::prefix_sum::prefix_sum(nv as u32, &mut head, &mut Vec::new());
            assert_eq!(
                rd::<u32>(&gpu, ClusterBuf::FcHead, nv + 1),
                head,
                "{label}: head"
            );
            let (mut keys, mut vals) = (vec![0u32; nv], vec![0u32; nv]);
            ft::fc_cluster_keys(&c, &centre, &head, &mut keys, &mut vals);
            assert_eq!(rd::<u32>(&gpu, ClusterBuf::SortKeys, nv), keys, "{label}");
            assert_eq!(rd::<u32>(&gpu, ClusterBuf::SortVals, nv), vals, "{label}");
            let by_cluster = sort_on_both(
                &mut gpu,
                &label,
                meshslim::cluster::gpu_schedule::cluster_passes(nv),
                nv,
            );
            let clusters = cells_on_both(&mut gpu, &label, &by_cluster);
            assert_eq!(clusters as u32, head[nv], "{label}: a cluster per centre");
            let vertex_cluster: Vec<u32> = rd(&gpu, ClusterBuf::VertexCell, nv);
            assert_eq!(
                floating::clusters_of(&centre),
                (vertex_cluster.clone(), clusters),
                "{label}: the driver's clusters_of"
            );

            gpu.run_fc_part(FcPart::Quadrics).unwrap();
            let mut placed = vec![ClusterPlaced::default(); clusters];
            let mut quadric = vec![Quadric::default(); clusters];
            ft::fc_quadrics(
                &c,
                &meshslim::cluster::gpu_schedule::float_params(r, 0),
                &pos,
                indices,
                &offsets,
                &vertex_faces,
                &normals,
                &locked_u32,
                &centre,
                &by_cluster.1,
                &rd::<u32>(&gpu, ClusterBuf::CellHead, nv + 1),
                &rd::<u32>(&gpu, ClusterBuf::CellStart, clusters + 1),
                &mut placed,
                &mut quadric,
            );
            twins::check_placed(
                &label,
                &rd(&gpu, ClusterBuf::ClusterPlaced, clusters),
                &placed,
                &rd(&gpu, ClusterBuf::ClusterQuadric, clusters),
                &quadric,
                r,
            );

            gpu.run_part(Part::Faces).unwrap();
            let f = twins::faces(&c, indices, &vertex_cluster);
            let kept = f.face_origin.len();
            assert!(kept > 0, "{label}: some faces survive");
            assert_eq!(
                rd::<u32>(&gpu, ClusterBuf::ClusterFaces, 3 * kept),
                f.cluster_faces
            );
            assert_eq!(rd::<u32>(&gpu, ClusterBuf::FaceOrigin, kept), f.face_origin);
            eprintln!("{label}: {rounds} rounds, {clusters} clusters, {kept} faces");
        }
    }
}

/// The twins' chain is the CPU driver's: the same grades and ranks, the same centres in the same
/// number of rounds as `floating::claim`, the same clusters.
#[test]
fn the_floating_twins_are_the_cpu_driver() {
    for (name, m, radii, lock) in cases() {
        let (pos, lo, hi) = meshslim::cluster::unit_frame_points(&m);
        let locked = locked_of(pos.len(), lock);
        let csr = stages::Csr::new(pos.len(), &m.triangles);
        let ranks = floating::ranks(&floating::grades(&pos, &m.triangles, &csr));
        for r in radii {
            let twin = ft::run(&pos, &m.triangles, &locked, lo, hi, r, None);
            assert_eq!(
                twin.ranks,
                ranks.iter().map(|&x| (x >> 32) as u32).collect::<Vec<_>>(),
                "{name}: ranks"
            );
            let (centre, rounds) = floating::claim(&pos, &ranks, &locked, lo, hi, r);
            assert_eq!(twin.centre(), centre, "{name} at r = {r}: centres");
            assert_eq!(twin.rounds.len(), rounds, "{name} at r = {r}: rounds");
            let (vertex_cluster, n) = floating::clusters_of(&centre);
            let result = twin.result();
            assert_eq!(result.vertex_cluster, vertex_cluster, "{name} at r = {r}");
            assert_eq!(result.clusters, n, "{name} at r = {r}");
            assert_eq!(
                result.faces,
                stages::cluster_faces(&m.triangles, &vertex_cluster, n, false),
                "{name} at r = {r}: faces"
            );
        }
    }
}

/// The longest edge at `v`, which scales its grade (`floating::grade`): a grade near 0 is a
/// square root of 1 + cos θ near 0, where a cosine's rounding (an ulp of 1) shows.
fn longest_edge(
    pos: &[[f32; 4]],
    faces: &[[u32; 3]],
    offsets: &[u32],
    vertex_faces: &[u32],
    v: usize,
) -> f32 {
    let corner = |u: u32| meshslim::compute::common::xyz(pos[u as usize]);
    vertex_faces[offsets[v] as usize..offsets[v + 1] as usize]
        .iter()
        .flat_map(|&f| faces[f as usize])
        .map(|u| meshslim::compute::common::sub(corner(u), corner(v as u32)))
        .map(meshslim::compute::common::length)
        .fold(0.0, f32::max)
}

/// The ranks the device makes for `pos`, against the CPU's: how many differ. The grades take a
/// square root and divisions, which Vulkan does not round correctly everywhere (nor forbid fused
/// multiply-adds): on lavapipe every grade of these meshes is the CPU's bit for bit, so none;
/// elsewhere a grade an ulp off can cross a 256-ulp rank step.
fn ranks_differing(gpu: &mut GpuClusterMesh, pos: &[[f32; 4]], faces: &[[u32; 3]]) -> usize {
    gpu.run_fc_part(FcPart::Ranks).unwrap();
    let csr = stages::Csr::new(pos.len(), faces);
    let cpu = floating::ranks(&floating::grades(pos, faces, &csr));
    let got: Vec<u32> = rd(gpu, ClusterBuf::FcRank, pos.len());
    got.iter()
        .zip(&cpu)
        .filter(|(g, c)| **g != (**c >> 32) as u32)
        .count()
}

/// The whole GPU build against the twins' chain from the device's own grades: the same rounds,
/// clusters and faces, vertices within rounding, twice the same bits. On lavapipe those grades
/// are the CPU's; elsewhere they may round otherwise (an H200: 2,642 of the grid's ranks
/// differ), and a chain from the CPU's grades claims other centres (there 3,289 faces against
/// 2,619), so the grades are compared on their own (`each_floating_stage_matches_its_cpu_twin`).
#[test]
fn the_gpu_floating_build_equals_the_twins_chain() {
    let Some(ctx) = gpu_context() else { return };
    let sim = GpuClusterer::new(&ctx.device, &ctx.queue).unwrap();
    for (name, m, radii, lock) in cases() {
        let (pos, lo, hi) = meshslim::cluster::unit_frame_points(&m);
        let locked = locked_of(pos.len(), lock);
        let mut gpu = GpuClusterMesh::new(&sim, &pos, &m.triangles, &locked).unwrap();
        let differ = ranks_differing(&mut gpu, &pos, &m.triangles);
        if differ > 0 {
            eprintln!("{name}: {differ} ranks differ from the CPU's on this device");
        }
        let grades: Vec<f32> = rd(&gpu, ClusterBuf::FcGrade, pos.len());
        for r in radii {
            let label = format!("{name} at r = {r}");
            let (g, rounds) = gpu.build_floating(lo, hi, r).unwrap();
            let (again, _) = gpu.build_floating(lo, hi, r).unwrap();
            assert_eq!(g.faces, again.faces, "{label}: the same faces twice");
            assert!(
                g.placed
                    .iter()
                    .zip(&again.placed)
                    .all(|(a, b)| a.pos == b.pos && a.quadric == b.quadric),
                "{label}: the same vertices twice, bit for bit"
            );
            let twin = ft::run(&pos, &m.triangles, &locked, lo, hi, r, Some(&grades));
            let t = twin.result();
            assert_eq!(rounds, twin.rounds.len(), "{label}: rounds");
            assert_eq!(g.vertex_cluster, t.vertex_cluster, "{label}: clusters");
            assert_eq!(g.faces, t.faces, "{label}: faces");
            assert_eq!(g.placed.len(), t.placed.len(), "{label}");
            for (k, (a, b)) in g.placed.iter().zip(&t.placed).enumerate() {
                assert!(
                    (0..3).all(|i| close(a.pos[i], b.pos[i], 1e-4, 1e-3)),
                    "{label}: cluster {k} at {:?} on the GPU, {:?} on the CPU",
                    a.pos,
                    b.pos
                );
            }
        }
    }
}

/// `meshslim simplify --method floating-cell --backend gpu` against `cpu-parallel`: with the same
/// ranks (lavapipe) the same search, radius, rounds, clusters and faces; on a device whose ranks
/// differ, both in the ±5% band or equally far from it. Vertices: the CPU driver
/// scatters its quadrics in face order, the GPU gathers them cluster by cluster, the same sums
/// to rounding; on a curved surface that leaves them within 5% of the radius (measured: 1e-6 r
/// on the sphere, 1.5e-5 r on the torus), but on a flat patch every candidate costs zero and
/// rounding picks among them, so on the cube only the box is shared: within its diagonal, 2√3 r
/// (measured: 0.85 r).
#[test]
fn simplify_floating_on_the_gpu_writes_the_cpu_parallel_faces() {
    let Some(ctx) = gpu_context() else { return };
    let sim = GpuClusterer::new(&ctx.device, &ctx.queue).unwrap();
    let mut sphere = meshslim::mesh::icosphere(5);
    meshslim::mesh::add_noise(&mut sphere, 0.01, 5);
    let meshes = [
        ("noisy_icosphere", sphere, 0.05),
        ("cube", meshslim::mesh::cube(20), 2.0 * 3f64.sqrt()),
        ("torus", meshslim::mesh::torus(1.0, 0.3, 64, 32), 0.05),
    ];
    for (name, m, within) in meshes {
        let (pos, _, _) = meshslim::cluster::unit_frame_points(&m);
        let locked = vec![false; pos.len()];
        let mut gpu = GpuClusterMesh::new(&sim, &pos, &m.triangles, &locked).unwrap();
        let differ = ranks_differing(&mut gpu, &pos, &m.triangles);
        for target in [m.triangles.len() / 10, m.triangles.len() / 50] {
            let run = |backend| {
                let mut o = meshslim::SimplifyOptions::with_faces(target);
                o.method = meshslim::Method::FloatingCell;
                o.backend = backend;
                meshslim::simplify(&m, &o).unwrap()
            };
            let (cpu, rc) = run(meshslim::Backend::CpuParallel);
            let (gpu, rg) = run(meshslim::Backend::Gpu);
            assert_eq!(rg.backend, meshslim::Backend::Gpu);
            let label = format!("{name} to {target}");
            if differ > 0 {
                eprintln!("{label}: {differ} ranks differ from the CPU's on this device");
                assert_eq!(rg.stop_reason, rc.stop_reason, "{label}");
                continue;
            }
            let (cc, cg) = (rc.clustering.unwrap(), rg.clustering.unwrap());
            assert_eq!(cg.cell_size, cc.cell_size, "{label}: radius");
            assert_eq!(cg.centre_rounds, cc.centre_rounds, "{label}: rounds");
            assert_eq!(cg.clusters, cc.clusters, "{label}: clusters");
            assert_eq!(cpu.triangles, gpu.triangles, "{label}");
            let b = m.bounds().unwrap();
            let diagonal = (0..3)
                .map(|i| (b.max[i] - b.min[i]) as f64)
                .map(|x| x * x)
                .sum::<f64>()
                .sqrt();
            let r = cc.cell_size * diagonal; // the radius in the mesh's units
            let worst = cpu
                .positions
                .iter()
                .zip(&gpu.positions)
                .map(|(a, b)| {
                    (0..3)
                        .map(|i| (a[i] - b[i]) as f64)
                        .map(|x| x * x)
                        .sum::<f64>()
                })
                .fold(0f64, f64::max)
                .sqrt();
            eprintln!(
                "{label}: same faces; vertices at most {:.2e} r apart",
                worst / r
            );
            for (a, b) in cpu.positions.iter().zip(&gpu.positions) {
                let d = (0..3)
                    .map(|i| (a[i] - b[i]) as f64)
                    .map(|x| x * x)
                    .sum::<f64>();
                assert!(d.sqrt() <= within * r, "{label}: {a:?} against {b:?}");
            }
        }
    }
}
