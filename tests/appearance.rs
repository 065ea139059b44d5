//! Appearance attributes in the quadric (the `cpu` greedy and the rounds of `cpu-parallel`):
//! colours and UVs weighed in the collapse cost and solved for the survivors, on generated,
//! painted meshes.

use crate::common;

use common::*;
use meshslim::mesh::{self, Mesh};
use meshslim::metrics::{CompareOptions, compare};
use meshslim::options::{AttributeWeights, Backend};
use meshslim::{Error, SimplifyOptions, simplify};

fn painted(mut m: Mesh) -> Mesh {
    mesh::paint(&mut m);
    m
}

/// (mean colour deviation, two-sided mean distance relative to the diagonal) of `out` from `m`.
fn errors(m: &Mesh, out: &Mesh) -> (f64, f64) {
    let c = compare(m, out, &CompareOptions::default()).unwrap();
    let colour = c.appearance.unwrap().color.unwrap().mean;
    (colour, c.distance.two_sided.mean_rel)
}

fn run_on(backend: Backend, m: &Mesh, ratio: f64, weights: AttributeWeights) -> Mesh {
    let mut opts = SimplifyOptions::with_ratio(m.triangles.len(), ratio).unwrap();
    opts.attributes = weights;
    opts.backend = backend;
    let (out, report) = simplify(m, &opts).unwrap();
    check_invariants(&format!("painted on {backend:?}"), m, &out, &report);
    out
}

/// The backends whose collapses weigh appearance: the greedy and the rounds.
const BACKENDS: [Backend; 2] = [Backend::Cpu, Backend::CpuParallel];

/// On a painted sphere, small (one sequential queue) and large (the partitioned levels), the
/// colour weight cuts the colour error several times over at a small geometric price, on the
/// greedy and on the rounds; every solved colour stays in 0..1; the same input gives the same
/// output twice.
#[test]
fn the_colour_weight_keeps_the_painting() {
    for (name, m, b) in [
        ("icosphere 20k", painted(mesh::noisy_sphere(5, 0.002, 7))),
        (
            "displaced 130k",
            painted(mesh::displaced_sphere(130_000, 3)),
        ),
    ]
    .into_iter()
    .flat_map(|(name, m)| BACKENDS.map(|b| (name, m.clone(), b)))
    {
        let name = format!("{name} on {b:?}");
        let off = run_on(b, &m, 0.1, AttributeWeights::OFF);
        let on = run_on(b, &m, 0.1, AttributeWeights::default());
        assert_eq!(off.triangles.len(), on.triangles.len(), "{name}");
        let (c_off, d_off) = errors(&m, &off);
        let (c_on, d_on) = errors(&m, &on);
        assert!(
            c_on < 0.5 * c_off,
            "{name}: colour error {c_on:.4} with the weight, {c_off:.4} without"
        );
        assert!(
            d_on < 3.0 * d_off,
            "{name}: distance {d_on:.3e} with the weight, {d_off:.3e} without"
        );
        for c in on.colors.as_ref().unwrap() {
            assert!(c.iter().all(|x| (0.0..=1.0).contains(x)), "{name}: {c:?}");
            assert_eq!(c[3], 1.0, "{name}: alpha was 1 everywhere");
        }
        assert_eq!(
            on,
            run_on(b, &m, 0.1, AttributeWeights::default()),
            "{name}"
        );
    }
}

/// With every weight 0 the colours ride along as before: the geometry is exactly that of the
/// same mesh without colours. Without colours or UVs the weights change nothing.
#[test]
fn zero_weights_and_attribute_free_meshes_take_the_geometric_path() {
    let plain = mesh::noisy_sphere(4, 0.003, 2);
    let coloured = painted(plain.clone());
    for backend in BACKENDS {
        let a = run_on(backend, &plain, 0.1, AttributeWeights::default());
        let b = run_on(backend, &plain, 0.1, AttributeWeights::OFF);
        assert_eq!(a, b, "{backend:?}");
        let mut c = run_on(backend, &coloured, 0.1, AttributeWeights::OFF);
        assert!(c.colors.take().is_some());
        assert_eq!(c, a, "{backend:?}");
    }
}

/// UVs are solved too: on a torus whose UV seam splits its vertices, every output UV lies
/// within the input's UV range and the seam holds (the seamed torus's own checks).
#[test]
fn uvs_are_solved_within_their_range_and_seams_hold() {
    let m = seamed_torus();
    let uvs = m.uvs.as_ref().unwrap();
    let (lo, hi) = uvs
        .iter()
        .fold(([f32::MAX; 2], [f32::MIN; 2]), |(lo, hi), t| {
            (
                [lo[0].min(t[0]), lo[1].min(t[1])],
                [hi[0].max(t[0]), hi[1].max(t[1])],
            )
        });
    for backend in BACKENDS {
        let mut opts = SimplifyOptions::with_ratio(m.triangles.len(), 0.1).unwrap();
        opts.attributes = AttributeWeights {
            uv: 1.0,
            ..AttributeWeights::OFF
        };
        opts.backend = backend;
        let (out, report) = simplify(&m, &opts).unwrap();
        check_seamed_torus(&format!("uv weight 1 on {backend:?}"), &m, &out, &report);
        let moved = out
            .uvs
            .as_ref()
            .unwrap()
            .iter()
            .filter(|t| !uvs.contains(t))
            .count();
        assert!(moved > 0, "{backend:?}: no UV was solved");
        for t in out.uvs.as_ref().unwrap() {
            assert!(
                (0..2).all(|k| t[k] >= lo[k] && t[k] <= hi[k]),
                "{backend:?}: {t:?} outside {lo:?}..{hi:?}"
            );
        }
    }
}

/// A weight that is not a finite number >= 0 is refused with the attribute's name.
#[test]
fn bad_weights_are_refused() {
    let m = mesh::icosphere(2);
    for (w, name) in [
        (
            AttributeWeights {
                color: -1.0,
                ..AttributeWeights::default()
            },
            "color",
        ),
        (
            AttributeWeights {
                uv: f64::NAN,
                ..AttributeWeights::default()
            },
            "uv",
        ),
        (
            AttributeWeights {
                normal: f64::INFINITY,
                ..AttributeWeights::default()
            },
            "normal",
        ),
    ] {
        let mut opts = SimplifyOptions::with_ratio(m.triangles.len(), 0.5).unwrap();
        opts.attributes = w;
        match simplify(&m, &opts) {
            Err(Error::InvalidOption(msg)) => assert!(msg.contains(name), "{msg}"),
            other => panic!("{name}: {other:?}"),
        }
    }
}

/// `compare --json`'s appearance figure `key` ("color", "texture") between two files in `dir`.
fn look(dir: &std::path::Path, a: &str, b: &str, extra: &[&str], key: &str) -> f64 {
    let mut args = vec!["compare", a, b, "--json"];
    args.extend(extra);
    let o = meshslim(&args, dir);
    expect_code(&o, 0);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    v["appearance"][key]["mean"]
        .as_f64()
        .unwrap_or_else(|| panic!("no appearance.{key}: {v}"))
}

/// From the command line: the default colour weight keeps a painting better than
/// `--color-weight 0`; a negative weight is a usage error naming the option; `compare
/// --texture` measures texture colour at the UVs (none against itself) and names a texture it
/// cannot read; an OBJ written from a textured OBJ without materials names its texture.
#[test]
fn the_command_line_weighs_colours_and_measures_textures() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    meshslim::io::write(&d.join("in.ply"), &painted(mesh::noisy_sphere(5, 0.003, 5))).unwrap();
    for (out, extra) in [("a.ply", None), ("b.ply", Some("--color-weight=0"))] {
        let mut args = vec!["simplify", "in.ply", out, "--ratio", "0.1", "--quiet"];
        args.extend(extra);
        expect_code(&meshslim(&args, d), 0);
    }
    let (weighed, riding) = (
        look(d, "in.ply", "a.ply", &[], "color"),
        look(d, "in.ply", "b.ply", &[], "color"),
    );
    assert!(weighed < 0.5 * riding, "{weighed} against {riding}");
    let o = meshslim(&["simplify", "in.ply", "c.ply", "--color-weight=-1"], d);
    expect_code(&o, 2);
    assert!(String::from_utf8_lossy(&o.stderr).contains("--color-weight"));

    // A 4×4 checker texture on the seamed torus.
    let checker = image::RgbImage::from_fn(4, 4, |x, y| {
        if (x + y) % 2 == 0 {
            image::Rgb([230, 40, 40])
        } else {
            image::Rgb([20, 20, 200])
        }
    });
    checker.save(d.join("t.png")).unwrap();
    meshslim::io::write(&d.join("torus.obj"), &seamed_torus()).unwrap();
    let args = ["simplify", "torus.obj", "t10.obj", "--ratio", "0.1", "-q"];
    expect_code(&meshslim(&args, d), 0);
    let tex = ["--texture", "t.png"];
    assert_eq!(look(d, "torus.obj", "torus.obj", &tex, "texture"), 0.0);
    let off = look(d, "torus.obj", "t10.obj", &tex, "texture");
    assert!(off > 0.0 && off < 1.0, "{off}");
    let o = meshslim(
        &["compare", "torus.obj", "t10.obj", "--texture", "nope.png"],
        d,
    );
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("nope.png"));

    // The texture beside the input goes with a simplified OBJ: a material library of its own
    // names it from the output's folder, and every face uses it.
    std::fs::create_dir(d.join("out")).unwrap();
    expect_code(
        &meshslim(&["simplify", "torus.obj", "out/t.obj", "-q"], d),
        0,
    );
    let mtl = std::fs::read_to_string(d.join("out/t.mtl")).unwrap();
    assert!(mtl.lines().any(|l| l == "map_Kd ../t.png"), "{mtl}");
    let back = meshslim::io::read(&d.join("out/t.obj")).unwrap();
    assert_eq!(back.material_libs, ["t.mtl"]);
    assert!(back.uvs.is_some());
    assert!(back.face_materials.unwrap().iter().all(|&m| m == 0));
    assert_eq!(back.materials.len(), 1);
}

/// Attributes that would poison the cost are refused when the file is read, naming the file
/// and the vertex: a NaN colour, a colour channel above 1, a NaN UV.
#[test]
fn bad_attribute_data_is_an_error_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let header = |props: &str| {
        format!(
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
             property float z\n{props}element face 1\nproperty list uchar int vertex_indices\n\
             end_header\n"
        )
    };
    let rgb = "property float red\nproperty float green\nproperty float blue\n";
    let uv = "property float u\nproperty float v\n";
    for (name, text, what) in [
        (
            "nan-colour.ply",
            header(rgb) + "0 0 0 nan 0 0\n1 0 0 0 0 0\n0 1 0 0 0 0\n3 0 1 2\n",
            "colour",
        ),
        (
            "bright.ply",
            header(rgb) + "0 0 0 0 0 0\n1 0 0 0 2 0\n0 1 0 0 0 0\n3 0 1 2\n",
            "colour",
        ),
        (
            "nan-uv.ply",
            header(uv) + "0 0 0 0 0\n1 0 0 1 0\n0 1 0 0 nan\n3 0 1 2\n",
            "UV",
        ),
    ] {
        std::fs::write(d.join(name), text).unwrap();
        let o = meshslim(&["simplify", name, "out.ply", "--ratio", "0.5"], d);
        assert!(!o.status.success(), "{name} was accepted");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(name) && err.contains(what), "{name}: {err}");
        assert!(!err.contains("panicked"), "{name}: {err}");
    }
}

/// `cluster` fits each cluster's colour over its cell: lower colour error than the nearest
/// member's (weight 0), the same cells and positions, colours in 0..1, and the same bytes on
/// one thread as on every core.
#[test]
fn clustering_fits_colours_over_the_cell() {
    let m = painted(mesh::displaced_sphere(60_000, 4));
    let cluster = |w: AttributeWeights| {
        let mut o = SimplifyOptions::with_ratio(m.triangles.len(), 0.05).unwrap();
        o.method = meshslim::Method::Cluster;
        o.attributes = w;
        simplify(&m, &o).unwrap().0
    };
    let fitted = cluster(AttributeWeights::default());
    let nearest = cluster(AttributeWeights::OFF);
    assert_eq!(fitted.positions, nearest.positions);
    assert_eq!(fitted.triangles, nearest.triangles);
    let (c_fit, _) = errors(&m, &fitted);
    let (c_near, _) = errors(&m, &nearest);
    assert!(c_fit < c_near, "fitted {c_fit:.4}, nearest {c_near:.4}");
    for c in fitted.colors.as_ref().unwrap() {
        assert!(c.iter().all(|x| (0.0..=1.0).contains(x)), "{c:?}");
    }
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(|| cluster(AttributeWeights::default()));
    assert_eq!(one, fitted);
}

/// `method` on `m` at 10% with the default weights and with every weight 0, the invariants
/// checked: the colour error with the weight well under half of that without, the distance
/// under three times. Returns the weighted output.
fn keeps_the_painting(m: &Mesh, method: meshslim::Method) -> Mesh {
    let run = |w: AttributeWeights| {
        let mut o = SimplifyOptions::with_ratio(m.triangles.len(), 0.1).unwrap();
        o.method = method;
        o.attributes = w;
        let (out, report) = simplify(m, &o).unwrap();
        check_invariants(&format!("painted {method:?}"), m, &out, &report);
        out
    };
    let on = run(AttributeWeights::default());
    let (c_on, d_on) = errors(m, &on);
    let (c_off, d_off) = errors(m, &run(AttributeWeights::OFF));
    assert!(
        c_on < 0.5 * c_off,
        "{method:?}: colour error {c_on:.4} with the weight, {c_off:.4} without"
    );
    assert!(
        d_on < 3.0 * d_off,
        "{method:?}: distance {d_on:.3e} with the weight, {d_off:.3e} without"
    );
    on
}

/// `hybrid` weighs colours in both halves: its clustering keeps sharp colour steps out of its
/// clusters and its rounds weigh and solve colours.
#[test]
fn the_hybrid_keeps_the_painting() {
    let m = painted(mesh::displaced_sphere(130_000, 5));
    keeps_the_painting(&m, meshslim::Method::Hybrid);
}

/// `decimate` keeps its vertices and their colours, so appearance only charges its cost: a
/// vertex on a colour edge costs what removing it smears. Every output colour is an input one.
#[test]
fn decimation_weighs_colours_in_its_cost() {
    let m = painted(mesh::noisy_sphere(5, 0.002, 7));
    let on = keeps_the_painting(&m, meshslim::Method::Decimate);
    let input = m.colors.as_ref().unwrap();
    for c in on.colors.as_ref().unwrap() {
        assert!(input.contains(c), "{c:?} is not an input colour");
    }
}
