//! Whether the tiles' former borders are simplified like the rest: the error and the edge
//! length of the faces near the grid's cut planes against those elsewhere, for the tiled result
//! and, as the reference, a whole-mesh simplification of the same input; and crops around a
//! point where two cuts cross, for a wireframe screenshot of the seam before and after the merge.
//!
//! ```text
//! meshslim tiles split scan-4m.ply work --tiles 16 --ratio 0.01 && meshslim tiles run work --jobs 2
//! meshslim tiles merge work tiled.ply && meshslim simplify scan-4m.ply whole.ply --ratio 0.01
//! cargo run --release --example tiles_borders -- scan-4m.ply work tiled.ply whole.ply CROPS_DIR
//! meshslim view CROPS_DIR/tiled.ply --wireframe --screenshot tiled-seam.png
//! ```

use meshslim::Mesh;
use meshslim::metrics::TriangleBvh;
use meshslim::tiles::{Manifest, welded};
use std::path::{Path, PathBuf};

/// The cut planes of the tiles' grid: (axis, coordinate), as `tiles split` placed them over the
/// input's box (a first level's manifest: a coarser level's cuts are shifted).
fn cuts(input: &Mesh, m: &Manifest) -> Vec<(usize, f64)> {
    let b = input.bounds().expect("a mesh with vertices");
    let mut out = Vec::new();
    for k in 0..3 {
        let (lo, hi) = (b.min[k] as f64, b.max[k] as f64);
        for j in 1..m.grid[k] {
            out.push((k, lo + (hi - lo) * j as f64 / m.grid[k] as f64));
        }
    }
    out
}

fn centroid(m: &Mesh, f: &[u32; 3]) -> [f64; 3] {
    let p = f.map(|v| m.positions[v as usize]);
    [0, 1, 2].map(|k| (p[0][k] as f64 + p[1][k] as f64 + p[2][k] as f64) / 3.0)
}

fn mean_edge(m: &Mesh) -> f64 {
    let mut s = 0.0;
    for f in &m.triangles {
        let p = f.map(|v| m.positions[v as usize].map(|x| x as f64));
        for i in 0..3 {
            let (a, b) = (p[i], p[(i + 1) % 3]);
            s += ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt();
        }
    }
    s / (3 * m.triangles.len()) as f64
}

/// Near the cuts (within `band`) and elsewhere: faces, mean distance of face samples to the
/// input's surface (area-weighted), mean edge length.
fn measure(name: &str, out: &Mesh, bvh: &TriangleBvh, cuts: &[(usize, f64)], band: f64) {
    // [faces, area, area * distance, edge length sum]
    let mut acc = [[0.0f64; 4]; 2];
    for f in &out.triangles {
        let c = centroid(out, f);
        let near = cuts.iter().any(|&(k, x)| (c[k] - x).abs() < band) as usize;
        let p = f.map(|v| out.positions[v as usize].map(|x| x as f64));
        let e = |a: [f64; 3], b: [f64; 3]| {
            [0, 1, 2]
                .map(|k| b[k] - a[k])
                .iter()
                .map(|x| x * x)
                .sum::<f64>()
        };
        let (u, v) = (
            [0, 1, 2].map(|k| p[1][k] - p[0][k]),
            [0, 1, 2].map(|k| p[2][k] - p[0][k]),
        );
        let cr = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        let area = 0.5 * (cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]).sqrt();
        // Seven samples: the centroid, the corners' thirds and the edges' midpoints.
        let w = [
            [1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0],
            [2.0 / 3.0, 1.0 / 6.0, 1.0 / 6.0],
            [1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0],
            [1.0 / 6.0, 1.0 / 6.0, 2.0 / 3.0],
            [0.5, 0.5, 0.0],
            [0.0, 0.5, 0.5],
            [0.5, 0.0, 0.5],
        ];
        let d: f64 = w
            .iter()
            .map(|w| {
                let q = [0, 1, 2].map(|k| w[0] * p[0][k] + w[1] * p[1][k] + w[2] * p[2][k]);
                bvh.closest(q, None).map_or(0.0, |h| h.dist2.sqrt())
            })
            .sum::<f64>()
            / w.len() as f64;
        let a = &mut acc[near];
        a[0] += 1.0;
        a[1] += area;
        a[2] += area * d;
        a[3] += (e(p[0], p[1]).sqrt() + e(p[1], p[2]).sqrt() + e(p[2], p[0]).sqrt()) / 3.0;
    }
    let row = |a: [f64; 4]| (a[0], a[2] / a[1], a[3] / a[0]);
    let (nf, nd, ne) = row(acc[1]);
    let (ef, ed, ee) = row(acc[0]);
    println!(
        "{name:>6}: near the cuts {nf:>6} faces, mean distance {nd:.4e}, mean edge {ne:.4e} | \
         elsewhere {ef:>6} faces, mean distance {ed:.4e}, mean edge {ee:.4e} | near/elsewhere: \
         distance {:.3}, edge {:.3}",
        nd / ed,
        ne / ee
    );
}

/// The faces of `m` whose centroid lies within `half` of `c` on every axis.
fn crop(m: &Mesh, c: [f64; 3], half: f64) -> Mesh {
    let mut out = Mesh {
        positions: m.positions.clone(),
        ..Mesh::default()
    };
    out.triangles = m
        .triangles
        .iter()
        .filter(|f| {
            let x = centroid(m, f);
            (0..3).all(|k| (x[k] - c[k]).abs() < half)
        })
        .copied()
        .collect();
    out.remove_unused_vertices();
    out
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<PathBuf> = std::env::args_os().skip(1).map(PathBuf::from).collect();
    let [input, dir, tiled, whole, crops] = &args[..] else {
        return Err("usage: tiles_borders INPUT TILES_DIR TILED_OUT WHOLE_OUT CROPS_DIR".into());
    };
    let input_mesh = meshslim::io::read(input)?;
    let manifest = Manifest::read(dir)?;
    if manifest.shift != [0.0; 3] {
        return Err("a coarser level's manifest: give the first level's folder".into());
    }
    let tiled_mesh = meshslim::io::read(tiled)?;
    let whole_mesh = meshslim::io::read(whole)?;
    let cuts = cuts(&input_mesh, &manifest);
    let edge = mean_edge(&whole_mesh);
    // Within two mean edges of a cut: the strip the pinned seam occupied.
    let band = 2.0 * edge;
    println!(
        "{} cut planes of a {:?} grid; band {band:.4e} (two mean edges of the whole-mesh result)",
        cuts.len(),
        manifest.grid
    );
    let bvh = TriangleBvh::new(&input_mesh);
    measure("tiled", &tiled_mesh, &bvh, &cuts, band);
    measure("whole", &whole_mesh, &bvh, &cuts, band);

    // A point where two cuts of different axes cross, on the surface: the vertex of the result
    // nearest both planes.
    let (a, b) = cuts
        .iter()
        .flat_map(|a| cuts.iter().map(move |b| (*a, *b)))
        .find(|(a, b)| a.0 != b.0)
        .ok_or("the grid has cuts along fewer than two axes")?;
    let at = tiled_mesh
        .positions
        .iter()
        .map(|p| p.map(|x| x as f64))
        .min_by(|p, q| {
            let d = |p: &[f64; 3]| (p[a.0] - a.1).powi(2) + (p[b.0] - b.1).powi(2);
            d(p).total_cmp(&d(q))
        })
        .ok_or("an empty result")?;
    std::fs::create_dir_all(crops)?;
    let half = 12.0 * edge;
    let welded_mesh = welded(dir)?;
    for (name, m) in [
        ("welded", &welded_mesh),
        ("tiled", &tiled_mesh),
        ("whole", &whole_mesh),
    ] {
        let c = crop(m, at, half);
        let path = Path::new(crops).join(format!("{name}.ply"));
        meshslim::io::write(&path, &c)?;
        println!(
            "crop {name}: {} faces around {at:?} -> {}",
            c.triangles.len(),
            path.display()
        );
    }
    Ok(())
}
