//! The texture a mesh without material definitions goes with: scans ship as an OBJ (or PLY)
//! with UVs and one PNG or JPEG beside it, and no `.mtl` (../shared/models/spot). The viewer
//! draws with that image; an OBJ written from such an input names it through a material library
//! of its own, so that other tools show the simplified scan textured too.

use crate::error::Result;
use crate::mesh::{Material, Mesh};
use std::path::{Path, PathBuf};

/// Texture file extensions looked for (and, in the viewer, read through the `image` crate).
pub const TEXTURE_EXTENSIONS: [&str; 3] = ["png", "jpg", "jpeg"];

pub fn is_texture_file(p: &Path) -> bool {
    p.extension()
        .is_some_and(|e| TEXTURE_EXTENSIONS.iter().any(|x| e.eq_ignore_ascii_case(x)))
}

/// The folder of `path` (the current one for a bare file name).
fn folder(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// The one PNG or JPEG in the folder of the mesh file `path`, if there is exactly one (the
/// viewer's own screenshots, `meshslim-*`, are not textures).
pub fn lone_texture_beside(path: &Path) -> Option<PathBuf> {
    let found: Vec<PathBuf> = std::fs::read_dir(folder(path))
        .into_iter()
        .flatten()
        .flatten()
        .map(|e| e.path())
        .filter(|p| is_texture_file(p))
        .filter(|p| {
            !p.file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with("meshslim-"))
        })
        .collect();
    match <[PathBuf; 1]>::try_from(found) {
        Ok([only]) => Some(only),
        Err(_) => None,
    }
}

/// The name of the material an OBJ written with a texture of its own uses.
pub const TEXTURED: &str = "textured";

/// For an OBJ written to `out` from `mesh`, read from `input`: when the mesh has UVs but no
/// materials and the input's folder holds one texture, writes `<out stem>.mtl` beside `out`
/// naming it (`map_Kd`, relative to the output's folder), and returns the mesh with every face
/// on that material and the library's name to write as `mtllib`. `None`: nothing to add.
pub(crate) fn with_own_material(
    mesh: &Mesh,
    input: &Path,
    out: &Path,
) -> Result<Option<(Mesh, String)>> {
    if mesh.uvs.is_none() || !mesh.material_libs.is_empty() || !mesh.materials.is_empty() {
        return Ok(None);
    }
    let Some(image) = lone_texture_beside(input) else {
        return Ok(None);
    };
    let Some(name) = image.file_name().map(|n| n.to_string_lossy().into_owned()) else {
        return Ok(None);
    };
    let map = super::relocate_material_libs(&[name], input, out).remove(0);
    let stem = out
        .file_stem()
        .map_or("mesh".into(), |s| s.to_string_lossy());
    let lib = format!("{stem}.mtl");
    let mtl = folder(out).join(&lib);
    super::write_atomic(&mtl, |w| {
        use std::io::Write;
        writeln!(w, "# written by meshslim: the texture beside the input")?;
        writeln!(w, "newmtl {TEXTURED}")?;
        writeln!(w, "Kd 1 1 1")?;
        writeln!(w, "map_Kd {map}")
    })?;
    let mut m = mesh.clone();
    m.materials = vec![Material::named(TEXTURED)];
    m.face_materials = Some(vec![0; m.triangles.len()]);
    Ok(Some((m, lib)))
}
