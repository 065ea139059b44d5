//! The preparation on the device (lavapipe in CI) and the pipelines it shares with the other
//! families: what its stages leave in the rounds' first
//! half against their CPU twins, bit for bit, and the `gpu` backend started from it against the
//! same backend started from the host's preparation, byte for byte. With CI=true a missing
//! adapter fails instead of skipping, and so does lavapipe without f64 in shaders.

use crate::common;

use common::*;
use meshslim::compute::types::FaceExtra;
use meshslim::rounds::gpu::{GpuRounds, GpuSimplifier};
use meshslim::rounds::schedule::Buf;
use meshslim::rounds::{SELECTION_PASSES, Upload};
use meshslim::{Backend, Mesh, SimplifyOptions, simplify};

/// One pipeline cache per device: the rounds and the clustering made from one cache compile the
/// stages they share (prefix sum, adjacency, face planes) once, and each family's own once; a
/// family made again from the cache compiles nothing.
#[test]
fn families_on_one_device_share_its_pipelines() {
    let Some(ctx) = gpu_context() else { return };
    let cache = meshslim::compute::gpu::Pipelines::new(&ctx.device);
    let rounds = GpuSimplifier::on(&cache, &ctx.queue).unwrap();
    let after_rounds = cache.compiled();
    // The rounds, and their preparation where the device runs it (its prefix sum is theirs).
    let mut rounds_stages: Vec<&str> = meshslim::rounds::schedule::STAGES
        .iter()
        .flat_map(|l| l.iter().map(|s| s.entry))
        .collect();
    if rounds.prepare_kernels().is_some() {
        for s in meshslim::rounds::prepare::STAGES
            .iter()
            .flat_map(|l| l.iter())
        {
            if !rounds_stages.contains(&s.entry) {
                rounds_stages.push(s.entry);
            }
        }
    }
    assert_eq!(after_rounds.len(), rounds_stages.len());
    meshslim::cluster::gpu::GpuClusterer::on(&cache, &ctx.queue).unwrap();
    let cluster_stages: Vec<&str> = meshslim::cluster::gpu_schedule::STAGES
        .iter()
        .flat_map(|l| l.iter().map(|s| s.entry))
        .collect();
    let shared = cluster_stages
        .iter()
        .filter(|e| rounds_stages.contains(e))
        .count();
    let radix = if rounds.prepare_kernels().is_some() {
        2
    } else {
        0
    };
    assert_eq!(
        shared,
        7 + radix,
        "prefix sum (3), adjacency (3), face planes, and the preparation's radix sort (2)"
    );
    assert_eq!(
        cache.compiled().len(),
        rounds_stages.len() + cluster_stages.len() - shared,
        "the shared stages compiled once"
    );
    let compiled = cache.compiled().len();
    let again = GpuSimplifier::on(&cache, &ctx.queue).unwrap();
    assert_eq!(again.pipeline_cache, "shared", "made by the first");
    assert_eq!(
        cache.compiled().len(),
        compiled,
        "nothing left to compile: the second simplifier took every pipeline from the cache"
    );
}

/// The process's simplifier when its device runs the preparation's stages.
fn preparing() -> Option<&'static GpuSimplifier> {
    gpu_context()?;
    let (_, sim) = meshslim::rounds::gpu::shared().ok()?;
    if sim.prepare_kernels().is_none() {
        assert!(
            !rounds_like_the_cpu(),
            "lavapipe has f64 in shaders: the preparation's stages should be there"
        );
        eprintln!("note: this adapter has no f64 in shaders; the host prepares");
        return None;
    }
    Some(sim)
}

/// Meshes for the preparation: the generated ones, one with more vertices and faces than a
/// sort block and a scan block hold many times over, and one that welds (every corner written
/// once per face).
fn meshes() -> Vec<(&'static str, Mesh)> {
    let mut all = generated_meshes();
    all.push(("big_sphere", meshslim::mesh::noisy_sphere(6, 0.004, 11)));
    all.push((
        "soup",
        triangle_soup(&meshslim::mesh::noisy_sphere(4, 0.01, 5)),
    ));
    all
}

fn bits(p: &[[f32; 4]]) -> Vec<[u32; 4]> {
    p.iter().map(|q| q.map(f32::to_bits)).collect()
}

#[test]
fn the_device_prepares_what_its_twins_do() {
    let Some(sim) = preparing() else { return };
    let kernels = sim.prepare_kernels().unwrap();
    let mut prepared = 0;
    for (name, mesh) in meshes() {
        let Some(p) = meshslim::rounds::prepare::eligible(&mesh) else {
            continue;
        };
        prepared += 1;
        let want = meshslim::rounds::cpu::prepare::prepare(
            &p,
            bytemuck::cast_slice(&mesh.positions),
            bytemuck::cast_slice(&mesh.triangles),
        );
        let (rounds, up) = GpuRounds::prepared(sim, kernels, &mesh, &p, SELECTION_PASSES).unwrap();
        assert_eq!(up.vertex_count(), want.vertices as usize, "{name}");
        assert_eq!(up.face_count(), want.faces as usize, "{name}");
        let (nv, nf) = (want.vertices as u64, want.faces as u64);
        let read = |b: Buf, bytes: u64| rounds.read_buffer(b, bytes).unwrap();
        let positions: Vec<[f32; 4]> = pod(read(Buf::Positions, 16 * nv));
        assert_eq!(bits(&positions), bits(&want.positions), "{name}: positions");
        let flags: Vec<u32> = pod(read(Buf::Flags, 4 * nv));
        assert_eq!(flags, want.flags, "{name}: flags");
        let attr: Vec<u32> = pod(read(Buf::VertexAttr, 4 * nv));
        assert_eq!(attr, want.vertex_attr, "{name}: vertex attributes");
        let indices: Vec<u32> = pod(read(Buf::Indices, 12 * nf));
        assert_eq!(indices, want.indices, "{name}: indices");
        let extra: Vec<FaceExtra> = pod(read(Buf::FaceExtra, 16 * nf));
        assert_eq!(extra, want.face_extra, "{name}: face extras");
        assert_eq!(
            up.dropped_degenerate,
            mesh.triangles.len() - want.faces as usize,
            "{name}"
        );
    }
    assert!(prepared >= 8, "only {prepared} meshes were plain enough");
}

fn run(m: &Mesh, ratio: f64) -> (Mesh, meshslim::SimplifyReport) {
    let mut o = SimplifyOptions::with_ratio(m.triangles.len(), ratio).unwrap();
    o.backend = Backend::Gpu;
    simplify(m, &o).unwrap()
}

/// `gpu` from the device's preparation writes the mesh it writes from the host's (the rounds
/// after either start are the same), and says where it prepared.
#[test]
fn gpu_prepared_on_the_device_writes_the_hosts_bytes() {
    let Some(sim) = preparing() else { return };
    let ctx = gpu_context().unwrap();
    for (name, mesh) in meshes() {
        if meshslim::rounds::prepare::eligible(&mesh).is_none() {
            continue;
        }
        for ratio in [0.5, 0.05] {
            let (device, dr) = run(&mesh, ratio);
            let opts = SimplifyOptions::with_ratio(mesh.triangles.len(), ratio).unwrap();
            let up = Upload::pinned(&mesh, &opts.pin);
            let (host, hr) =
                meshslim::rounds::gpu::simplify_upload(ctx, sim, &up, &mesh, &opts, &mut |_| {})
                    .unwrap();
            let label = format!("{name} at {ratio}");
            let rr = dr.rounds.as_ref().unwrap();
            assert_eq!(rr.prepared_on.as_deref(), Some("device"), "{label}");
            assert_eq!(device.triangles, host.triangles, "{label}: faces");
            let pos = |m: &Mesh| -> Vec<[u32; 3]> {
                m.positions.iter().map(|p| p.map(f32::to_bits)).collect()
            };
            assert_eq!(pos(&device), pos(&host), "{label}: positions");
            assert_eq!(
                rr.faces_removed_per_round,
                hr.rounds.unwrap().faces_removed_per_round,
                "{label}"
            );
            assert_eq!(dr.dropped_degenerate_faces, hr.dropped_degenerate_faces);
        }
    }
}

/// A mesh the device does not prepare (normals, a pinned border, a box on a plane through a
/// -0.0) is prepared on the host, and the report says so.
#[test]
fn meshes_the_device_does_not_prepare_are_prepared_on_the_host() {
    let Some(_) = preparing() else { return };
    let mut normals = meshslim::mesh::noisy_sphere(3, 0.01, 1);
    normals.recompute_normals();
    let mut zero = meshslim::mesh::grid(10);
    zero.positions[0] = [-0.0, 0.0, 0.0];
    for (name, mesh) in [("normals", normals), ("negative zero", zero)] {
        let (_, r) = run(&mesh, 0.5);
        let rr = r.rounds.unwrap();
        assert_eq!(rr.prepared_on.as_deref(), Some("host"), "{name}");
    }
    let m = meshslim::mesh::grid(10);
    let mut o = SimplifyOptions::with_ratio(m.triangles.len(), 0.5).unwrap();
    o.backend = Backend::Gpu;
    o.pin = vec![0, 1, 2];
    let (_, r) = simplify(&m, &o).unwrap();
    assert_eq!(r.rounds.unwrap().prepared_on.as_deref(), Some("host"));
}
