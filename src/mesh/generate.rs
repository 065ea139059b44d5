//! Procedural meshes: the test suite's inputs and the benchmark's million-triangle fallback.
//! All deterministic: the same arguments give the same mesh bit for bit.

use super::Mesh;
use std::collections::HashMap;
use std::f64::consts::PI;

/// SplitMix64: a tiny, well-known deterministic generator, enough for test noise.
#[derive(Debug, Clone)]
pub struct SplitMix64(pub u64);

impl SplitMix64 {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn to_f32(p: [f64; 3]) -> [f32; 3] {
    p.map(|x| x as f32)
}

/// Splits every triangle into four at its edge midpoints (shared midpoints are shared vertices).
/// Attributes are interpolated the same way.
pub fn subdivide_midpoint(mesh: &Mesh) -> Mesh {
    let mut out = mesh.clone();
    let mut mid: HashMap<u64, u32> = HashMap::with_capacity(mesh.triangles.len() * 3 / 2);
    let mut tris = Vec::with_capacity(mesh.triangles.len() * 4);
    let mut fm = mesh
        .face_materials
        .as_ref()
        .map(|_| Vec::with_capacity(mesh.triangles.len() * 4));
    let mut fg = mesh
        .face_groups
        .as_ref()
        .map(|_| Vec::with_capacity(mesh.triangles.len() * 4));
    for (f, t) in mesh.triangles.iter().enumerate() {
        let mut m = [0u32; 3];
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            let key = super::topology::edge_key(a, b);
            m[i] = *mid.entry(key).or_insert_with(|| {
                let (a, b) = (a as usize, b as usize);
                let avg3 = |s: &[[f32; 3]]| [0, 1, 2].map(|k| (s[a][k] + s[b][k]) * 0.5);
                out.positions.push(avg3(&mesh.positions));
                if let (Some(o), Some(s)) = (out.normals.as_mut(), mesh.normals.as_ref()) {
                    o.push(avg3(s));
                }
                if let (Some(o), Some(s)) = (out.uvs.as_mut(), mesh.uvs.as_ref()) {
                    o.push([0, 1].map(|k| (s[a][k] + s[b][k]) * 0.5));
                }
                if let (Some(o), Some(s)) = (out.colors.as_mut(), mesh.colors.as_ref()) {
                    o.push([0, 1, 2, 3].map(|k| (s[a][k] + s[b][k]) * 0.5));
                }
                (out.positions.len() - 1) as u32
            });
        }
        tris.extend_from_slice(&[
            [t[0], m[0], m[2]],
            [m[0], t[1], m[1]],
            [m[2], m[1], t[2]],
            m,
        ]);
        if let (Some(o), Some(s)) = (fm.as_mut(), mesh.face_materials.as_ref()) {
            o.extend_from_slice(&[s[f]; 4]);
        }
        if let (Some(o), Some(s)) = (fg.as_mut(), mesh.face_groups.as_ref()) {
            o.extend_from_slice(&[s[f]; 4]);
        }
    }
    out.triangles = tris;
    out.face_materials = fm;
    out.face_groups = fg;
    out
}

/// Moves every vertex along its normal by a uniform random amount in ±`amplitude` × the bounding
/// box diagonal; deterministic for a given seed. Vertices at one position move together.
pub fn add_noise(mesh: &mut Mesh, amplitude: f64, seed: u64) {
    let diag = mesh.bounds().map_or(1.0, |b| b.diagonal());
    let normals = {
        let mut m = mesh.clone();
        m.recompute_normals();
        m.normals.unwrap_or_default()
    };
    let (class, _) = super::weld::position_classes(&mesh.positions);
    let mut offset: HashMap<u32, f64> = HashMap::new();
    let mut rng = SplitMix64(seed);
    for (v, p) in mesh.positions.iter_mut().enumerate() {
        let d = *offset
            .entry(class[v])
            .or_insert_with(|| (rng.next_f64() * 2.0 - 1.0) * amplitude * diag);
        for k in 0..3 {
            p[k] += (normals[v][k] as f64 * d) as f32;
        }
    }
}

/// Icosahedron subdivided `level` times and projected onto the unit sphere: 20·4^level faces.
pub fn icosphere(level: u32) -> Mesh {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let raw = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ];
    let tris = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    let mut m = Mesh::new(raw.iter().map(|&p| to_f32(p)).collect(), tris);
    for _ in 0..level {
        m = subdivide_midpoint(&m);
    }
    for p in &mut m.positions {
        let l = (p[0] as f64 * p[0] as f64 + p[1] as f64 * p[1] as f64 + p[2] as f64 * p[2] as f64)
            .sqrt();
        *p = p.map(|x| (x as f64 / l) as f32);
    }
    m
}

/// A grid of `nu` × `nv` quads on a parametric surface, closed in u and/or v by index wrapping.
fn param_grid(
    nu: usize,
    nv: usize,
    wrap_u: bool,
    wrap_v: bool,
    f: impl Fn(f64, f64) -> [f64; 3],
) -> Mesh {
    let cu = if wrap_u { nu } else { nu + 1 };
    let cv = if wrap_v { nv } else { nv + 1 };
    let mut pos = Vec::with_capacity(cu * cv);
    for j in 0..cv {
        for i in 0..cu {
            pos.push(to_f32(f(i as f64 / nu as f64, j as f64 / nv as f64)));
        }
    }
    let id = |i: usize, j: usize| ((j % cv) * cu + (i % cu)) as u32;
    let mut tris = Vec::with_capacity(nu * nv * 2);
    for j in 0..nv {
        for i in 0..nu {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            // Alternate the diagonal so the grid has no preferred direction.
            if (i + j) % 2 == 0 {
                tris.push([a, b, c]);
                tris.push([a, c, d]);
            } else {
                tris.push([a, b, d]);
                tris.push([b, c, d]);
            }
        }
    }
    Mesh::new(pos, tris)
}

/// Torus with major radius `big`, minor radius `small`, outward faces.
pub fn torus(big: f64, small: f64, nu: usize, nv: usize) -> Mesh {
    param_grid(nu, nv, true, true, |u, v| {
        let (a, b) = (u * 2.0 * PI, v * 2.0 * PI);
        let r = big + small * b.cos();
        [r * a.cos(), r * a.sin(), small * b.sin()]
    })
}

/// UV sphere: `segments` around, `rings` from pole to pole, single vertices at the poles.
pub fn uv_sphere(segments: usize, rings: usize) -> Mesh {
    assert!(
        segments >= 3 && rings >= 2,
        "uv_sphere needs segments >= 3 and rings >= 2"
    );
    let mut pos = vec![[0.0, 0.0, 1.0]];
    for j in 1..rings {
        let th = PI * j as f64 / rings as f64;
        for i in 0..segments {
            let ph = 2.0 * PI * i as f64 / segments as f64;
            pos.push(to_f32([th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()]));
        }
    }
    pos.push([0.0, 0.0, -1.0]);
    let south = (pos.len() - 1) as u32;
    let ring = |j: usize, i: usize| (1 + (j - 1) * segments + i % segments) as u32;
    let mut tris = Vec::new();
    for i in 0..segments {
        tris.push([0, ring(1, i), ring(1, i + 1)]);
        tris.push([south, ring(rings - 1, i + 1), ring(rings - 1, i)]);
    }
    for j in 1..rings - 1 {
        for i in 0..segments {
            let (a, b, c, d) = (
                ring(j, i),
                ring(j + 1, i),
                ring(j + 1, i + 1),
                ring(j, i + 1),
            );
            tris.push([a, b, c]);
            tris.push([a, c, d]);
        }
    }
    Mesh::new(pos, tris)
}

/// A flat open grid of `n` × `n` quads in the unit square (z = 0), faces pointing +z.
pub fn grid(n: usize) -> Mesh {
    param_grid(n, n, false, false, |u, v| [u, v, 0.0])
}

/// The closed surface of a set of unit voxels, with every exposed voxel face split into two
/// triangles and coincident corners shared. Faces point outward.
pub fn voxel_surface(dims: [usize; 3], filled: impl Fn(usize, usize, usize) -> bool) -> Mesh {
    let inside = |x: i64, y: i64, z: i64| {
        x >= 0
            && y >= 0
            && z >= 0
            && (x as usize) < dims[0]
            && (y as usize) < dims[1]
            && (z as usize) < dims[2]
            && filled(x as usize, y as usize, z as usize)
    };
    let mut ids: HashMap<[i64; 3], u32> = HashMap::new();
    let mut pos = Vec::new();
    let mut vid = |p: [i64; 3]| {
        *ids.entry(p).or_insert_with(|| {
            pos.push(p.map(|c| c as f32));
            (pos.len() - 1) as u32
        })
    };
    let mut tris = Vec::new();
    for z in 0..dims[2] as i64 {
        for y in 0..dims[1] as i64 {
            for x in 0..dims[0] as i64 {
                if !inside(x, y, z) {
                    continue;
                }
                for axis in 0..3 {
                    for dir in [-1i64, 1] {
                        let mut n = [x, y, z];
                        n[axis] += dir;
                        if inside(n[0], n[1], n[2]) {
                            continue;
                        }
                        // Face corners in counter-clockwise order seen from outside.
                        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                        let mut base = [x, y, z];
                        if dir > 0 {
                            base[axis] += 1;
                        }
                        let corner = |du: i64, dv: i64| {
                            let mut c = base;
                            c[u] += du;
                            c[v] += dv;
                            c
                        };
                        let q = if dir > 0 {
                            [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)]
                        } else {
                            [corner(0, 0), corner(0, 1), corner(1, 1), corner(1, 0)]
                        };
                        let q = q.map(&mut vid);
                        tris.push([q[0], q[1], q[2]]);
                        tris.push([q[0], q[2], q[3]]);
                    }
                }
            }
        }
    }
    Mesh::new(pos, tris)
}

/// A cube of side 1 whose faces are `n` × `n` grids: flat regions and sharp feature edges.
pub fn cube(n: usize) -> Mesh {
    let mut m = voxel_surface([n, n, n], |_, _, _| true);
    for p in &mut m.positions {
        *p = p.map(|c| c / n as f32);
    }
    m
}

/// A genus-2 solid: a slab with two square holes through it, as a voxel surface scaled by `1/s`.
/// `s` sets the resolution (s = 1: 10 × 5 × 2 voxels).
pub fn double_torus(s: usize) -> Mesh {
    let (w, h, d) = (10 * s, 5 * s, 2 * s);
    let hole = |x: usize, y: usize| {
        let in_y = (2 * s..3 * s).contains(&y);
        in_y && ((2 * s..4 * s).contains(&x) || (6 * s..8 * s).contains(&x))
    };
    let mut m = voxel_surface([w, h, d], |x, y, _| !hole(x, y));
    for p in &mut m.positions {
        *p = p.map(|c| c / s as f32);
    }
    m
}

/// Unit icosphere with seeded radial noise of relative amplitude `amplitude`.
pub fn noisy_sphere(level: u32, amplitude: f64, seed: u64) -> Mesh {
    let mut m = icosphere(level);
    add_noise(&mut m, amplitude, seed);
    m
}

/// A smooth bumpy sphere with at least `min_faces` triangles: a procedural stand-in for a scan
/// (low-frequency displacement plus fine seeded noise), used when no real scan is at hand.
pub fn displaced_sphere(min_faces: usize, seed: u64) -> Mesh {
    let mut level = 0;
    while 20usize << (2 * level) < min_faces {
        level += 1;
    }
    let mut m = icosphere(level);
    for p in &mut m.positions {
        let [x, y, z] = p.map(|c| c as f64);
        let r = 1.0 + 0.08 * (5.0 * x).sin() * (4.0 * y).cos() + 0.05 * (7.0 * z + 1.3 * x).sin();
        *p = to_f32([x * r, y * r, z * r]);
    }
    add_noise(&mut m, 2e-4, seed);
    m
}

/// Paints `mesh` with vertex colours in the frame of its bounding box: smooth bands along x,
/// a gradient along y, sharp-edged stripes along z — the painted scans the appearance
/// measurements and tests use. Same mesh, same colours; nothing for a mesh without vertices.
pub fn paint(mesh: &mut Mesh) {
    let Some(bb) = mesh.bounds() else {
        return;
    };
    let colors = mesh
        .positions
        .iter()
        .map(|p| {
            // Coordinates in 0..1 over the bounding box.
            let t: [f32; 3] = std::array::from_fn(|k| {
                let span = (bb.max[k] - bb.min[k]).max(1e-12);
                (p[k] - bb.min[k]) / span
            });
            let band = 0.5 + 0.5 * (t[0] * std::f32::consts::TAU * 3.0).sin();
            let stripe = if (t[2] * 8.0).floor() as i32 % 2 == 0 {
                0.9
            } else {
                0.1
            };
            [band, t[1], stripe, 1.0]
        })
        .collect();
    mesh.colors = Some(colors);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::topology;

    #[test]
    fn generated_meshes_have_the_expected_topology() {
        let cases: Vec<(&str, Mesh, i64, usize)> = vec![
            ("icosphere", icosphere(2), 2, 0),
            ("uv_sphere", uv_sphere(16, 8), 2, 0),
            ("torus", torus(1.0, 0.3, 24, 12), 0, 0),
            ("double_torus", double_torus(1), -2, 0),
            ("cube", cube(4), 2, 0),
            ("grid", grid(5), 1, 1),
        ];
        for (name, m, euler, loops) in cases {
            let t = topology(&m);
            assert!(t.is_manifold(), "{name}: {t:?}");
            assert!(t.is_consistently_oriented(), "{name}: {t:?}");
            assert_eq!(t.euler_characteristic, euler, "{name}");
            assert_eq!(t.boundary_loops, loops, "{name}");
            assert_eq!(t.degenerate_faces, 0, "{name}");
            assert_eq!(t.duplicate_faces, 0, "{name}");
            if loops == 0 {
                assert!(t.signed_volume > 0.0, "{name}: faces must point outward");
            }
        }
        assert_eq!(icosphere(3).triangles.len(), 1280);
        assert_eq!(topology(&double_torus(1)).genus, Some(2));
    }

    #[test]
    fn noise_is_deterministic() {
        assert_eq!(noisy_sphere(2, 0.01, 7), noisy_sphere(2, 0.01, 7));
        assert_ne!(noisy_sphere(2, 0.01, 7), noisy_sphere(2, 0.01, 8));
    }
}
