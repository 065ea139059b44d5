//! Tiles (src/tiles/): pinned vertices stay put on every QEM backend; a split puts every face in
//! exactly one tile and names every vertex shared between tiles; the merge welds the tiles shut
//! and thins the former borders like the rest; a tile's output does not depend on who ran it.
//! The run under a real Slurm is tests/slurm.rs.

use crate::common;

use common::{expect_code, gpu_context, meshslim};
use meshslim::cluster::stream::Target;
use meshslim::tiles::{Manifest, SplitOptions, merge, simplify_tile, split};
use meshslim::{Backend, Error, Mesh, Method, SimplifyOptions, simplify};
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

fn noisy_torus() -> Mesh {
    let mut m = meshslim::mesh::torus(1.0, 0.3, 160, 60);
    meshslim::mesh::add_noise(&mut m, 0.002, 5);
    m
}

fn split_opts(tiles: usize, ratio: f64) -> SplitOptions {
    SplitOptions {
        // Small blocks: the two face passes cross many block borders.
        block: 777,
        ..SplitOptions::new(tiles, Target::Ratio(ratio))
    }
}

fn bits(p: [f32; 3]) -> [u32; 3] {
    p.map(f32::to_bits)
}

#[test]
fn pinned_vertices_neither_move_nor_go_on_any_backend() {
    let m = noisy_torus();
    // A band of the torus, and every 7th vertex elsewhere: pins in runs and alone.
    let pin: Vec<u32> = (0..m.positions.len() as u32)
        .filter(|&v| m.positions[v as usize][0] > 0.9 || v % 7 == 0)
        .collect();
    let mut backends = vec![Backend::Cpu, Backend::CpuParallel];
    if gpu_context().is_some() {
        backends.push(Backend::Gpu);
    }
    for backend in backends {
        let opts = SimplifyOptions {
            backend,
            pin: pin.clone(),
            ..SimplifyOptions::with_faces(m.triangles.len() / 4)
        };
        let (out, report) = simplify(&m, &opts).unwrap();
        let kept: BTreeSet<[u32; 3]> = out.positions.iter().map(|&p| bits(p)).collect();
        for &v in &pin {
            assert!(
                kept.contains(&bits(m.positions[v as usize])),
                "{backend:?}: pinned vertex {v} moved or went"
            );
        }
        assert!(
            report.pinned_vertices >= pin.len(),
            "{backend:?}: {report:?}"
        );
        // The free vertices still thin out.
        assert!(
            out.positions.len() < pin.len() + (m.positions.len() - pin.len()) / 2,
            "{backend:?}: {} vertices left",
            out.positions.len()
        );
    }
}

#[test]
fn pins_that_cannot_be_honoured_are_refused() {
    let m = noisy_torus();
    let mut opts = SimplifyOptions::with_faces(1000);
    opts.pin = vec![m.positions.len() as u32];
    assert!(matches!(simplify(&m, &opts), Err(Error::InvalidOption(s)) if s.contains("past")));
    opts.pin = vec![0];
    opts.method = Method::Cluster;
    opts.backend = Backend::CpuParallel;
    assert!(matches!(simplify(&m, &opts), Err(Error::InvalidOption(s)) if s.contains("pin")));
}

/// Each tile's faces in global ids, from its PLY and ids file.
fn tile_faces(dir: &Path, m: &Manifest, i: usize) -> Vec<[u32; 3]> {
    let t = &m.tile[i];
    let mesh = meshslim::io::read(&dir.join(&t.file)).unwrap();
    let ids: Vec<u32> = std::fs::read(dir.join(&t.ids))
        .unwrap()
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes(c.try_into().unwrap()))
        .collect();
    assert_eq!(ids.len(), mesh.positions.len());
    mesh.triangles
        .iter()
        .map(|f| f.map(|l| ids[l as usize]))
        .collect()
}

#[test]
fn a_split_puts_every_face_in_one_tile_and_names_the_shared_vertices() {
    let dir = tempfile::tempdir().unwrap();
    let m = noisy_torus();
    let input = dir.path().join("torus.ply");
    meshslim::io::write(&input, &m).unwrap();
    let tiles = dir.path().join("tiles");
    let man = split(&input, &tiles, &split_opts(6, 0.1), &mut |_| {}).unwrap();
    assert_eq!(man, Manifest::read(&tiles).unwrap());
    assert_eq!(man.tiles, 6);
    assert_eq!(man.grid.iter().product::<u32>(), 6);
    assert_eq!(man.input_faces, m.triangles.len() as u64);
    assert_eq!(
        man.target_faces,
        (m.triangles.len() as f64 * 0.1).round() as u64
    );

    // Every input face in exactly one tile, in file order within it.
    let mut all = Vec::new();
    let mut tiles_of: BTreeMap<u32, BTreeSet<usize>> = BTreeMap::new();
    for i in 0..man.tiles {
        let faces = tile_faces(&tiles, &man, i);
        assert_eq!(faces.len() as u64, man.tile[i].faces);
        assert!(!faces.is_empty(), "tile {i} is empty on a torus");
        for f in &faces {
            for v in f {
                tiles_of.entry(*v).or_default().insert(i);
            }
        }
        all.extend(faces);
    }
    let mut want = m.triangles.clone();
    want.sort_unstable();
    all.sort_unstable();
    assert_eq!(all, want);
    // The border of a tile: its vertices that another tile's faces use too.
    for (i, t) in man.tile.iter().enumerate() {
        let want: Vec<u32> = tiles_of
            .iter()
            .filter(|(_, ts)| ts.len() > 1 && ts.contains(&i))
            .map(|(&v, _)| v)
            .collect();
        assert_eq!(t.border, want, "tile {i}");
        // Positions are the input's, bit for bit.
        let mesh = meshslim::io::read(&tiles.join(&t.file)).unwrap();
        let faces = tile_faces(&tiles, &man, i);
        for (local, global) in mesh.triangles.iter().zip(&faces) {
            for (&l, &g) in local.iter().zip(global) {
                assert_eq!(
                    bits(mesh.positions[l as usize]),
                    bits(m.positions[g as usize])
                );
            }
        }
    }
}

/// How many of the split's border vertices are still in `out` at their input position, and
/// how many there were.
fn border_survivors(man: &Manifest, input: &Mesh, out: &Mesh) -> (usize, usize) {
    let border: BTreeSet<[u32; 3]> = man
        .tile
        .iter()
        .flat_map(|t| t.border.iter().map(|&v| bits(input.positions[v as usize])))
        .collect();
    let survivors = out
        .positions
        .iter()
        .filter(|&&p| border.contains(&bits(p)))
        .count();
    (survivors, border.len())
}

#[test]
fn the_merge_welds_the_tiles_shut_and_thins_the_former_borders() {
    let dir = tempfile::tempdir().unwrap();
    let m = noisy_torus();
    let input = dir.path().join("torus.ply");
    meshslim::io::write(&input, &m).unwrap();
    let tiles = dir.path().join("tiles");
    let man = split(&input, &tiles, &split_opts(8, 0.05), &mut |_| {}).unwrap();
    // Backwards: the order the tiles are simplified in does not matter.
    for i in (0..man.tiles).rev() {
        let r = simplify_tile(&tiles, i, &mut |_| {}).unwrap();
        assert_eq!(r.border_vertices, man.tile[i].border.len());
        assert!(r.output_faces < r.input_faces);
    }
    let (out, report) = merge(&tiles, u64::MAX, &mut |_| {}).unwrap();
    assert_eq!(out.triangles.len() as u64, man.target_faces);
    assert!(report.joined_vertices > 0);
    // Welded shut: the torus is closed, and so is the result.
    let topo = meshslim::mesh::topology(&out);
    assert!(topo.is_closed() && topo.is_manifold(), "{topo:?}");
    // No seam of pinned vertices survives: former border vertices still at their input
    // position are rare, as rare as the vertices kept overall.
    let (survivors, border) = border_survivors(&man, &m, &out);
    assert!(
        survivors * 5 < border,
        "{survivors} of {} former border vertices left",
        border
    );
}

#[test]
fn a_merge_over_its_memory_tiles_again_with_the_cuts_moved() {
    let dir = tempfile::tempdir().unwrap();
    let m = noisy_torus();
    let input = dir.path().join("torus.ply");
    meshslim::io::write(&input, &m).unwrap();
    let tiles = dir.path().join("tiles");
    let man = split(&input, &tiles, &split_opts(8, 0.05), &mut |_| {}).unwrap();
    for i in 0..man.tiles {
        simplify_tile(&tiles, i, &mut |_| {}).unwrap();
    }
    // One byte: nothing fits, so the coarser level is the last word.
    let (out, report) = merge(&tiles, 1, &mut |_| {}).unwrap();
    let coarser = report.coarser.as_ref().expect("tiled again");
    assert!(report.simplify.is_none() && coarser.simplify.is_none());
    let level = Manifest::read(&tiles.join("coarser")).unwrap();
    assert_eq!(level.tiles, 2);
    assert_ne!(level.shift, [0.0; 3]);
    let target = man.target_faces as f64;
    let faces = out.triangles.len() as f64;
    assert!(
        (faces - target).abs() < 0.1 * target,
        "{faces} faces for {target}"
    );
    let topo = meshslim::mesh::topology(&out);
    assert!(topo.is_closed() && topo.is_manifold(), "{topo:?}");
    // The first level's seams were inside the coarser tiles, and thinned there.
    let (survivors, border) = border_survivors(&man, &m, &out);
    assert!(
        survivors * 4 < border,
        "{survivors} of {} first-level border vertices left",
        border
    );
}

#[test]
fn tiles_run_in_any_number_of_jobs_write_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let m = noisy_torus();
    meshslim::io::write(&dir.path().join("torus.ply"), &m).unwrap();
    let mut outs = Vec::new();
    for jobs in ["1", "2"] {
        let d = format!("t{jobs}");
        let o = meshslim(
            &[
                "tiles",
                "split",
                "torus.ply",
                &d,
                "--tiles",
                "5",
                "--ratio",
                "0.05",
            ],
            dir.path(),
        );
        expect_code(&o, 0);
        let o = meshslim(&["tiles", "run", &d, "--jobs", jobs], dir.path());
        expect_code(&o, 0);
        assert_eq!(String::from_utf8_lossy(&o.stdout).lines().count(), 5);
        let out = format!("out{jobs}.ply");
        expect_code(&meshslim(&["tiles", "merge", &d, &out], dir.path()), 0);
        outs.push(std::fs::read(dir.path().join(out)).unwrap());
    }
    assert_eq!(outs[0], outs[1]);
}

#[test]
fn the_tile_index_comes_from_the_scheduler_or_the_error_says_how() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path();
    let o = meshslim(
        &[
            "tiles",
            "split",
            "builtin:torus",
            "t",
            "--tiles",
            "3",
            "--faces",
            "500",
        ],
        p,
    );
    expect_code(&o, 0);
    assert!(
        !p.join("t/.input.ply").exists(),
        "the builtin's copy is left"
    );
    let run = |envs: &[(&str, &str)], args: &[&str]| {
        let mut c = std::process::Command::new(env!("CARGO_BIN_EXE_meshslim"));
        c.args(args).current_dir(p);
        c.env_remove("SLURM_ARRAY_TASK_ID")
            .env_remove("JOB_COMPLETION_INDEX");
        for (k, v) in envs {
            c.env(k, v);
        }
        c.output().unwrap()
    };
    let o = run(&[], &["tiles", "simplify", "t"]);
    expect_code(&o, 2);
    assert!(String::from_utf8_lossy(&o.stderr).contains("SLURM_ARRAY_TASK_ID"));
    let o = run(&[("SLURM_ARRAY_TASK_ID", "x")], &["tiles", "simplify", "t"]);
    expect_code(&o, 2);
    let o = run(&[("SLURM_ARRAY_TASK_ID", "7")], &["tiles", "simplify", "t"]);
    expect_code(&o, 1);
    assert!(String::from_utf8_lossy(&o.stderr).contains("tiles 0 to 2"));
    // The merge names the tile that is missing and how to make it.
    let o = run(&[], &["tiles", "merge", "t", "out.ply"]);
    expect_code(&o, 1);
    assert!(String::from_utf8_lossy(&o.stderr).contains("--index 0"));
    for (k, i) in [("SLURM_ARRAY_TASK_ID", "0"), ("JOB_COMPLETION_INDEX", "1")] {
        expect_code(&run(&[(k, i)], &["tiles", "simplify", "t"]), 0);
    }
    expect_code(&run(&[], &["tiles", "simplify", "t", "--index", "2"]), 0);
    expect_code(&run(&[], &["tiles", "merge", "t", "out.ply"]), 0);
    let out = meshslim::io::read(&p.join("out.ply")).unwrap();
    assert_eq!(out.triangles.len(), 500);
}

#[test]
fn a_manifest_that_cannot_be_trusted_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("torus.ply");
    meshslim::io::write(&input, &noisy_torus()).unwrap();
    let tiles = dir.path().join("tiles");
    let man = split(&input, &tiles, &split_opts(4, 0.1), &mut |_| {}).unwrap();
    let refused = |m: &Manifest, what: &str| {
        m.write(&tiles).unwrap();
        let e = simplify_tile(&tiles, 0, &mut |_| {})
            .unwrap_err()
            .to_string();
        assert!(e.contains(what), "{e}");
    };
    let mut m = man.clone();
    m.tile[0].output = "../escape.ply".into();
    refused(&m, "not a file name inside the folder");
    let mut m = man.clone();
    m.tile[0].border.reverse();
    refused(&m, "not strictly ascending");
    let mut m = man.clone();
    m.backend = "gpu".into();
    refused(&m, "simplified by cpu");
}

/// Vertex colours travel through split, simplify and merge: the merged mesh has them, welded
/// shut, and their error is that of a run that weighs them (well under half of a run that
/// lets them ride along).
#[test]
fn tiles_carry_vertex_colours() {
    let dir = tempfile::tempdir().unwrap();
    let mut m = noisy_torus();
    meshslim::mesh::paint(&mut m);
    let input = dir.path().join("painted.ply");
    meshslim::io::write(&input, &m).unwrap();
    let tiles = dir.path().join("tiles");
    let man = split(&input, &tiles, &split_opts(4, 0.1), &mut |_| {}).unwrap();
    for i in 0..man.tiles {
        simplify_tile(&tiles, i, &mut |_| {}).unwrap();
    }
    let (out, _) = merge(&tiles, u64::MAX, &mut |_| {}).unwrap();
    let topo = meshslim::mesh::topology(&out);
    assert!(topo.is_closed() && topo.is_manifold(), "{topo:?}");
    let colors = out.colors.as_ref().expect("the merged mesh has colours");
    assert!(colors.iter().flatten().all(|x| (0.0..=1.0).contains(x)));
    let riding = SimplifyOptions {
        attributes: meshslim::options::AttributeWeights::OFF,
        ..SimplifyOptions::with_faces(out.triangles.len())
    };
    let (plain, _) = simplify(&m, &riding).unwrap();
    let colour = |o: &Mesh| {
        let c = meshslim::metrics::compare(&m, o, &Default::default()).unwrap();
        c.appearance.unwrap().color.unwrap().mean
    };
    let (tiled, ridden) = (colour(&out), colour(&plain));
    assert!(tiled < 0.5 * ridden, "tiled {tiled:.4}, riding {ridden:.4}");
}
