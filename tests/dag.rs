//! Cluster DAGs (`meshslim::dag`): the clusters' limits, errors that only grow, cuts that stay
//! closed from any view, the .mslod file and its reader's errors, the same bytes on any number
//! of threads, `gpu` = `cpu-parallel`, and the grouped rounds a level is simplified with.

use crate::common;

use common::*;
use meshslim::dag::{self, CameraCut, Dag, DagOptions, NONE};
use meshslim::mesh::{self, topology};
use meshslim::{Backend, Mesh};
use std::path::Path;

fn built(m: &Mesh, opts: &DagOptions) -> (Dag, dag::DagReport) {
    dag::build(m, opts).unwrap()
}

/// The closed meshes the cuts are checked on: a noisy sphere, a torus, a genus-2 surface.
fn closed_meshes() -> Vec<(&'static str, Mesh)> {
    vec![
        ("noisy_sphere", mesh::noisy_sphere(5, 0.01, 7)),
        ("torus", mesh::torus(1.0, 0.3, 160, 80)),
        ("double_torus", mesh::double_torus(14)),
    ]
}

fn assert_closed_manifold(what: &str, m: &Mesh) {
    let t = topology(m);
    assert!(m.face_count() > 0, "{what}: empty cut");
    assert_eq!(t.boundary_edges, 0, "{what}: cracks ({t:?})");
    assert_eq!(t.non_manifold_edges, 0, "{what}: non-manifold edges");
    assert_eq!(t.non_manifold_vertices, 0, "{what}: non-manifold vertices");
}

#[test]
fn clusters_keep_their_limits_and_every_level_halves_to_one_root() {
    for (name, m) in closed_meshes() {
        let opts = DagOptions::default();
        let (d, r) = built(&m, &opts);
        for c in &d.clusters {
            assert!(c.triangle_count as usize <= opts.max_triangles, "{name}");
            let mut vs: Vec<u32> = d.triangles(c).as_flattened().to_vec();
            vs.sort_unstable();
            vs.dedup();
            assert!(
                vs.len() <= opts.max_vertices,
                "{name}: {} vertices",
                vs.len()
            );
        }
        let t = &r.triangles_per_level;
        assert_eq!(t[0], m.face_count(), "{name}: the input first");
        for w in t.windows(2) {
            assert!(
                (w[1] as f64) <= 0.6 * w[0] as f64,
                "{name}: a level kept {} of {}",
                w[1],
                w[0]
            );
        }
        assert!(*t.last().unwrap() <= 256, "{name}: root level {t:?}");
        assert_eq!(r.root_groups, 1, "{name}");
        assert_eq!(r.dag_triangles, d.mesh.face_count());
        assert_eq!(r.dag_triangles, t.iter().sum::<usize>(), "{name}");
        assert_eq!(r.levels, d.levels(), "{name}");
        let roots = d.clusters.iter().filter(|c| c.group == NONE).count();
        assert_eq!(roots, d.per_depth().last().unwrap().0, "{name}");
    }
}

/// A cluster's error is its parent group's, a group's is at least each of its clusters', and a
/// group's sphere holds its clusters' spheres: the projected error then only grows up the DAG.
#[test]
fn errors_and_spheres_grow_up_the_dag() {
    let (d, _) = built(&mesh::noisy_sphere(5, 0.01, 3), &DagOptions::default());
    let dist = |a: [f32; 4], b: [f32; 4]| {
        (0..3)
            .map(|i| (a[i] as f64 - b[i] as f64).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    for c in &d.clusters {
        match d.groups.get(c.parent_group as usize) {
            Some(p) => {
                assert_eq!(c.error, p.error);
                assert_eq!(c.lod_sphere, p.sphere);
            }
            None => assert_eq!((c.error, c.depth), (0.0, 0)),
        }
        if let Some(g) = d.groups.get(c.group as usize) {
            assert!(g.error >= c.error);
            let s = c.lod_sphere;
            assert!(dist(g.sphere, s) + s[3] as f64 <= g.sphere[3] as f64);
        }
        for &v in d.triangles(c).as_flattened() {
            let p = d.mesh.positions[v as usize];
            let b = c.bounds;
            assert!(
                dist(b, [p[0], p[1], p[2], 0.0]) <= b[3] as f64,
                "bounds miss a vertex"
            );
        }
    }
    assert!(d.groups.iter().any(|g| g.error > 0.0));
}

/// A cluster's error is what a cut trusts to keep it under a pixel: no vertex of a coarser
/// cluster lies farther from the input than twice its error (measured on the horse: at most
/// 1.8x; the error is the grouped rounds' quadric distance, not a bound, hence the slack).
#[test]
fn no_vertex_lies_far_beyond_its_clusters_error() {
    for (name, m) in closed_meshes() {
        let (d, _) = built(&m, &DagOptions::default());
        let bvh = meshslim::metrics::TriangleBvh::new(&m);
        let mut coarse = 0;
        for c in d.clusters.iter().filter(|c| c.depth > 0) {
            coarse += 1;
            for &v in d.triangles(c).as_flattened() {
                let p = d.mesh.positions[v as usize].map(|x| x as f64);
                let far = bvh.closest(p, None).unwrap().dist2.sqrt();
                assert!(
                    far <= 2.0 * c.error as f64 + 1e-6,
                    "{name}: a depth-{} cluster's vertex {far:.3e} from the input, its error {:.3e}",
                    c.depth,
                    c.error
                );
            }
        }
        assert!(coarse > 10, "{name}: {coarse} coarse clusters");
    }
}

#[test]
fn cuts_at_any_error_are_closed_and_coarsen_as_the_error_grows() {
    for (name, m) in closed_meshes() {
        let (d, _) = built(&m, &DagOptions::default());
        let mut last = usize::MAX;
        for e in [0.0, 1e-4, 5e-4, 2e-3, 1e-2, 1.0] {
            let ids = d.cut_at_error(e * d.diagonal);
            let cut = d.mesh_of(&ids);
            assert_closed_manifold(&format!("{name} at {e}"), &cut);
            assert!(cut.face_count() <= last, "{name}: finer at a larger error");
            last = cut.face_count();
        }
        let zero = d.mesh_of(&d.cut_at_error(0.0));
        if name == "noisy_sphere" {
            assert_eq!(zero.face_count(), m.face_count(), "{name}: 0 is the input");
        }
        // Flat parts (the double torus is voxels) simplify without error: at 0 they are
        // drawn coarse, but never coarser than what is exact.
        assert!(d.cut_at_error(-1.0).is_empty());
    }
}

#[test]
fn view_dependent_cuts_are_closed_from_any_camera_and_finer_near_it() {
    for (name, m) in closed_meshes() {
        let (d, _) = built(&m, &DagOptions::default());
        let r = d.diagonal;
        let cameras = [
            [0.0, 0.0, 0.6 * r],
            [0.0, 0.0, 3.0 * r],
            [r, -r, r],
            [0.0, 0.0, 0.0],
            [0.1 * r, 0.45 * r, 0.0],
        ];
        for eye in cameras {
            let cam = CameraCut {
                eye,
                pixels: 1.0,
                fov_deg: 60.0,
                height: 1080.0,
            };
            let cut = d.mesh_of(&d.cut_from_camera(&cam));
            assert_closed_manifold(&format!("{name} from {eye:?}"), &cut);
        }
        // A camera near one side draws that side finer than the far side.
        let cam = CameraCut {
            eye: [0.8 * r, 0.0, 0.0],
            pixels: 1.0,
            fov_deg: 60.0,
            height: 400.0,
        };
        let cut = d.mesh_of(&d.cut_from_camera(&cam));
        let (near, far) = cut.triangles.iter().fold((0, 0), |(n, f), t| {
            let x: f32 = t.iter().map(|&v| cut.positions[v as usize][0]).sum();
            if x > 0.0 { (n + 1, f) } else { (n, f + 1) }
        });
        assert!(near > far, "{name}: near {near}, far {far}");
    }
}

#[test]
fn open_meshes_and_colours_go_through() {
    let mut m = mesh::grid(120);
    mesh::paint(&mut m);
    let (d, r) = built(&m, &DagOptions::default());
    assert!(r.levels >= 4, "{r:?}");
    assert!(d.mesh.colors.is_some());
    for e in [0.0, 1e-3, 1e-2] {
        let cut = d.mesh_of(&d.cut_at_error(e * d.diagonal));
        let t = topology(&cut);
        assert_eq!(t.non_manifold_edges, 0);
        assert_eq!(
            t.boundary_loops, 1,
            "at {e}: the grid's one border, no cracks"
        );
        assert_eq!(cut.colors.as_ref().unwrap().len(), cut.positions.len());
    }
}

#[test]
fn the_same_bytes_on_any_number_of_threads() {
    let m = mesh::noisy_sphere(5, 0.01, 11);
    let bytes = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| dag::file::to_bytes(&built(&m, &DagOptions::default()).0))
    };
    assert_eq!(bytes(1), bytes(3));
}

#[test]
fn the_file_reads_back_what_was_written() {
    let mut m = mesh::torus(1.0, 0.3, 64, 32);
    mesh::paint(&mut m);
    let (d, _) = built(&m, &DagOptions::default());
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.mslod");
    dag::file::write(&path, &d).unwrap();
    let back = dag::file::read(&path).unwrap();
    assert_eq!(back, d);
    assert_eq!(dag::file::to_bytes(&back), std::fs::read(&path).unwrap());
}

fn read_err(bytes: &[u8]) -> String {
    match dag::file::from_bytes(bytes, Path::new("x.mslod")) {
        Ok(_) => panic!("a damaged file was read"),
        Err(e) => e.to_string(),
    }
}

/// Rewrites the checksum, so the reader's other checks are reached.
fn resum(b: &mut [u8]) {
    let n = b.len() - 8;
    let h = b[..n].iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &x| {
        (h ^ x as u64).wrapping_mul(0x0000_0100_0000_01b3)
    });
    b[n..].copy_from_slice(&h.to_le_bytes());
}

#[test]
fn damaged_files_are_clear_errors_never_panics() {
    let (d, _) = built(&mesh::icosphere(3), &DagOptions::default());
    let good = dag::file::to_bytes(&d);
    for n in (0..good.len()).step_by(7) {
        let e = read_err(&good[..n]);
        assert!(e.contains("x.mslod") && e.contains("truncated"), "{n}: {e}");
    }
    for at in (0..good.len()).step_by(13) {
        let mut b = good.clone();
        b[at] ^= 0x5a;
        read_err(&b);
    }
    let mut b = good.clone();
    b[0] = b'X';
    assert!(read_err(&b).contains("wrong magic"));
    let mut b = good.clone();
    b[8] = 9;
    assert!(read_err(&b).contains("version 9"));
    let mut b = good.clone();
    b.push(0);
    assert!(read_err(&b).contains("after the checksum"));
    // A cluster whose error is over its group's, written with a valid checksum.
    let mut bad = d.clone();
    let c = bad.clusters.iter().position(|c| c.group != NONE).unwrap();
    bad.clusters[c].error = bad.groups[bad.clusters[c].group as usize].error * 2.0 + 1.0;
    let mut b = dag::file::to_bytes(&bad);
    resum(&mut b);
    let e = read_err(&b);
    assert!(
        e.contains("must not fall") || e.contains("parent group"),
        "{e}"
    );
    // A vertex index out of range.
    let mut b = good.clone();
    let at = 40 + 12 * d.mesh.positions.len();
    b[at..at + 4].copy_from_slice(&u32::MAX.to_le_bytes());
    resum(&mut b);
    let e = read_err(&b);
    assert!(
        e.contains("out of range") && e.contains(&format!("byte offset {at}")),
        "{e}"
    );
}

#[test]
fn bad_options_are_errors() {
    let m = mesh::icosphere(2);
    for opts in [
        DagOptions {
            max_triangles: 0,
            ..DagOptions::default()
        },
        DagOptions {
            group_size: 1,
            ..DagOptions::default()
        },
        DagOptions {
            stuck_ratio: 1.5,
            ..DagOptions::default()
        },
    ] {
        assert!(dag::build(&m, &opts).is_err());
    }
    let (d, r) = built(&Mesh::default(), &DagOptions::default());
    assert_eq!((d.clusters.len(), r.levels), (0, 1));
}

/// A noisy sphere in four groups by the signs of x and y, the vertices two groups share
/// pinned, each group with its own target: half, a quarter, all of its faces (already met),
/// a third.
fn four_groups() -> (Mesh, Vec<u32>, Vec<u32>, Vec<u32>) {
    let mut m = mesh::noisy_sphere(4, 0.01, 5);
    let group: Vec<u32> = m
        .triangles
        .iter()
        .map(|t| {
            let c = t.map(|v| m.positions[v as usize]);
            let x = c[0][0] + c[1][0] + c[2][0];
            let y = c[0][1] + c[1][1] + c[2][1];
            (x > 0.0) as u32 + 2 * (y > 0.0) as u32
        })
        .collect();
    let mut owner = vec![u32::MAX; m.positions.len()];
    let mut pin = Vec::new();
    for (t, &g) in m.triangles.iter().zip(&group) {
        for &v in t {
            match owner[v as usize] {
                u32::MAX => owner[v as usize] = g,
                o if o != g && o != u32::MAX - 1 => {
                    owner[v as usize] = u32::MAX - 1;
                    pin.push(v);
                }
                _ => {}
            }
        }
    }
    let mut count = [0u32; 4];
    for &g in &group {
        count[g as usize] += 1;
    }
    let targets = vec![count[0] / 2, count[1] / 4, count[2], count[3] / 3];
    m.face_groups = Some(group);
    m.groups = (0..4).map(|g| format!("quarter {g}")).collect();
    (m, targets, count.to_vec(), pin)
}

/// Grouped rounds (one run for every group of a DAG level): each group ends at or just under
/// its own target, a group already at its target is left as it was, the shared border stays
/// where it was, and each group's error is its own.
#[test]
fn grouped_rounds_land_each_group_on_its_own_target() {
    let (m, targets, count, pin) = four_groups();
    let opts = meshslim::SimplifyOptions {
        pin: pin.clone(),
        ..meshslim::SimplifyOptions::with_faces(0)
    };
    let run = |b| meshslim::rounds::simplify_grouped(&m, targets.clone(), b, &opts).unwrap();
    let (out, errors) = run(Backend::CpuParallel);
    let mut kept = [0u32; 4];
    for &g in out.face_groups.as_ref().unwrap() {
        kept[g as usize] += 1;
    }
    for g in 0..4 {
        let (k, t) = (kept[g], targets[g]);
        if t >= count[g] {
            assert_eq!(k, count[g], "group {g} was at its target: untouched");
            assert_eq!(errors[g], 0.0, "group {g}: no collapse, no error");
        } else {
            // A round removes a sixth of a group's faces or so: its last lands within that.
            assert!(
                k <= t && k * 4 >= t * 3,
                "group {g}: {k} faces for a target of {t}"
            );
            assert!(errors[g] > 0.0, "group {g}: collapses without an error");
        }
    }
    let positions: std::collections::HashSet<[u32; 3]> =
        out.positions.iter().map(|p| p.map(f32::to_bits)).collect();
    for &v in &pin {
        let p = m.positions[v as usize].map(f32::to_bits);
        assert!(positions.contains(&p), "pinned vertex {v} moved or went");
    }
    assert_closed_manifold("grouped rounds", &out);
    if gpu_context().is_some() && rounds_like_the_cpu() {
        let (g, ge) = run(Backend::Gpu);
        assert_eq!(g.positions, out.positions);
        assert_eq!(g.triangles, out.triangles);
        assert_eq!(g.face_groups, out.face_groups);
        assert_eq!(ge, errors);
    }
}

#[test]
fn gpu_builds_the_bytes_of_cpu_parallel() {
    let Some(_) = gpu_context() else { return };
    if !rounds_like_the_cpu() {
        return;
    }
    let m = mesh::noisy_sphere(4, 0.01, 5);
    let on = |backend| {
        let opts = DagOptions {
            backend,
            ..DagOptions::default()
        };
        dag::file::to_bytes(&built(&m, &opts).0)
    };
    let cpu_parallel = on(Backend::CpuParallel);
    assert_eq!(on(Backend::Gpu), cpu_parallel);
    let d = dag::file::from_bytes(&cpu_parallel, Path::new("p.mslod")).unwrap();
    for e in [1e-3, 1e-2] {
        assert_closed_manifold("cpu-parallel", &d.mesh_of(&d.cut_at_error(e * d.diagonal)));
    }
}

#[test]
fn the_command_line_builds_describes_and_cuts() {
    let dir = tempfile::tempdir().unwrap();
    let o = meshslim(
        &["dag", "build", "builtin:torus", "t.mslod", "--json"],
        dir.path(),
    );
    expect_code(&o, 0);
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    for k in [
        "levels",
        "triangles_per_level",
        "clusters",
        "groups",
        "root_groups",
    ] {
        assert!(j.get(k).is_some(), "{k} missing: {j}");
    }
    assert!(j["seconds"]["build"].as_f64().unwrap() > 0.0);
    let o = meshslim(&["dag", "info", "t.mslod"], dir.path());
    expect_code(&o, 0);
    assert!(String::from_utf8_lossy(&o.stdout).contains("clusters"));
    let o = meshslim(
        &[
            "dag", "cut", "t.mslod", "far.ply", "--error", "0.01", "--json",
        ],
        dir.path(),
    );
    expect_code(&o, 0);
    let far = meshslim::io::read(&dir.path().join("far.ply")).unwrap();
    assert_closed_manifold("far", &far);
    let o = meshslim(
        &[
            "dag", "cut", "t.mslod", "near.obj", "--camera", "0,0,1.5", "--pixels", "1",
        ],
        dir.path(),
    );
    expect_code(&o, 0);
    let near = meshslim::io::read(&dir.path().join("near.obj")).unwrap();
    assert!(near.face_count() > far.face_count());
    // Usage errors: exit 2 and a message naming what is wrong.
    let o = meshslim(&["dag", "build", "builtin:torus", "t.ply"], dir.path());
    expect_code(&o, 2);
    assert!(String::from_utf8_lossy(&o.stderr).contains(".mslod"));
    let o = meshslim(&["dag", "cut", "t.mslod", "x.ply"], dir.path());
    expect_code(&o, 2);
    std::fs::write(dir.path().join("bad.mslod"), b"MSLOD").unwrap();
    let o = meshslim(&["dag", "info", "bad.mslod"], dir.path());
    expect_code(&o, 1);
    assert!(String::from_utf8_lossy(&o.stderr).contains("bad.mslod: byte offset 5: truncated"));
}

/// Normals made again on every level must not become seams that stall the next one, and a UV
/// seam must not open a crack: a torus with normals and a UV seam reaches one small root.
#[test]
fn normals_and_uv_seams_neither_stall_nor_crack() {
    let mut m = mesh::subdivide_midpoint(&mesh::subdivide_midpoint(&seamed_torus()));
    m.recompute_normals();
    let (d, r) = built(&m, &DagOptions::default());
    assert_eq!((r.root_groups, r.stuck_groups), (1, 0), "{r:?}");
    assert!(*r.triangles_per_level.last().unwrap() <= 256, "{r:?}");
    assert!(d.mesh.normals.is_some() && d.mesh.uvs.is_some());
    for e in [0.0, 1e-3, 1e-2, 1.0] {
        assert_closed_manifold(
            &format!("at {e}"),
            &d.mesh_of(&d.cut_at_error(e * d.diagonal)),
        );
    }
}

/// A scan in many pieces: separate small spheres share no edge, so only the spatial fallback
/// groups them; they still reach one root, every level halves, and every cut is closed.
#[test]
fn separate_pieces_still_reach_one_root() {
    let piece = mesh::icosphere(2);
    let mut m = Mesh::new(Vec::new(), Vec::new());
    for k in 0..64u32 {
        let at = [k % 4, k / 4 % 4, k / 16].map(|x| x as f32 * 3.0);
        let base = m.positions.len() as u32;
        m.positions.extend(
            piece
                .positions
                .iter()
                .map(|p| [0, 1, 2].map(|i| p[i] + at[i])),
        );
        m.triangles
            .extend(piece.triangles.iter().map(|t| t.map(|v| v + base)));
    }
    let (d, r) = built(&m, &DagOptions::default());
    assert_eq!(r.root_groups, 1, "{:?}", r.triangles_per_level);
    // 64 tetrahedra (256 triangles) are as far as 64 closed pieces go: the last level may halve
    // no further, and its group may stick.
    assert!(r.stuck_groups <= 1, "{r:?}");
    assert!(*r.triangles_per_level.last().unwrap() <= 256, "{r:?}");
    for w in r.triangles_per_level.windows(2) {
        let halved = (w[1] as f64) <= 0.6 * w[0] as f64;
        assert!(halved || w[1] <= 256, "{:?}", r.triangles_per_level);
    }
    for e in [0.001, 0.01, 0.05, 1.0] {
        assert_closed_manifold(&format!("at {e}"), &d.mesh_of(&d.cut_at_error(e)));
    }
}
