//! The generated meshes the commands take as input, named `builtin:NAME[:FACES]`.

use anyhow::Result;

use super::error::UsageError;
use crate::mesh::{self, Mesh};

pub(super) const BUILTIN_PREFIX: &str = "builtin:";

/// Largest FACES accepted in `builtin:NAME:FACES` (a typo should not allocate gigabytes).
pub const MAX_BUILTIN_FACES: usize = 20_000_000;

/// A generated mesh the command line can use as input.
#[derive(Debug)]
pub struct BuiltinMesh {
    pub name: &'static str,
    /// Builds the mesh with at least the given number of faces, or its default size.
    pub(super) make: fn(Option<usize>) -> Mesh,
}

/// Smallest `k >= start` with `faces(k) >= min`.
fn smallest(start: usize, min: usize, faces: impl Fn(usize) -> usize) -> usize {
    let mut k = start;
    while faces(k) < min {
        k += 1;
    }
    k
}

fn icosphere_level(min: Option<usize>) -> u32 {
    match min {
        None => 5,
        Some(n) => smallest(0, n, |l| 20 << (2 * l)) as u32,
    }
}

/// The generated meshes, by name. `simplify --help` lists them (a unit test keeps the two in
/// step).
pub static BUILTINS: &[BuiltinMesh] = &[
    BuiltinMesh {
        name: "sphere",
        make: |n| mesh::icosphere(icosphere_level(n)),
    },
    BuiltinMesh {
        name: "uv-sphere",
        // 2·segments·(rings − 1) faces with rings = segments / 2.
        make: |n| {
            let half = n.map_or(64, |n| smallest(2, n, |h| 4 * h * (h - 1)));
            mesh::uv_sphere(2 * half, half)
        },
    },
    BuiltinMesh {
        name: "torus",
        // 2·nu·nv faces with nu = 2·nv.
        make: |n| {
            let k = n.map_or(64, |n| smallest(3, n, |k| 4 * k * k));
            mesh::torus(1.0, 0.35, 2 * k, k)
        },
    },
    BuiltinMesh {
        name: "double-torus",
        // 176·s² voxel faces, two triangles each.
        make: |n| mesh::double_torus(n.map_or(8, |n| smallest(1, n, |s| 352 * s * s))),
    },
    BuiltinMesh {
        name: "cube",
        make: |n| mesh::cube(n.map_or(40, |n| smallest(1, n, |k| 12 * k * k))),
    },
    BuiltinMesh {
        name: "grid",
        make: |n| mesh::grid(n.map_or(100, |n| smallest(1, n, |k| 2 * k * k))),
    },
    BuiltinMesh {
        name: "noisy-sphere",
        make: |n| mesh::noisy_sphere(icosphere_level(n), 0.01, 1),
    },
    BuiltinMesh {
        name: "bumpy-sphere",
        make: |n| mesh::displaced_sphere(n.unwrap_or(200_000), 1),
    },
];

/// Parses `NAME` or `NAME:FACES` (without the `builtin:` prefix).
pub(super) fn parse_builtin(
    spec: &str,
) -> std::result::Result<(&'static BuiltinMesh, Option<usize>), String> {
    let (name, faces) = match spec.split_once(':') {
        Some((name, faces)) => (name, Some(faces)),
        None => (spec, None),
    };
    let names = || {
        BUILTINS
            .iter()
            .map(|b| b.name)
            .collect::<Vec<_>>()
            .join(", ")
    };
    let kind = BUILTINS.iter().find(|b| b.name == name).ok_or_else(|| {
        format!(
            "unknown built-in mesh {name:?}; the built-in meshes are {}",
            names()
        )
    })?;
    let min_faces = match faces {
        None => None,
        Some(f) => match f.parse::<usize>() {
            Ok(n) if (1..=MAX_BUILTIN_FACES).contains(&n) => Some(n),
            _ => {
                return Err(format!(
                    "the face count in builtin:{name}:{f} must be a whole number from 1 to \
                     {MAX_BUILTIN_FACES}"
                ));
            }
        },
    };
    Ok((kind, min_faces))
}

/// The generated mesh a spec names: `builtin:NAME`, `builtin:NAME:FACES` (at least FACES faces),
/// or the same without the `builtin:` prefix.
pub fn builtin(spec: &str) -> Result<Mesh> {
    let rest = spec.strip_prefix(BUILTIN_PREFIX).unwrap_or(spec);
    let (kind, min_faces) = parse_builtin(rest).map_err(UsageError)?;
    Ok((kind.make)(min_faces))
}
