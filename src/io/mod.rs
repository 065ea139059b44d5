//! Reading and writing meshes: OBJ, PLY, STL, glTF and GLB, chosen by file extension.
//!
//! Every reader returns a mesh that passed [`Mesh::validate`] (a failure becomes a
//! [`Error::Parse`] naming the file) and reports malformed input as an error with the file and,
//! where it can, the line (text formats and headers) or byte offset (binary formats). No reader
//! allocates what a header declares before the data is there, and none panics on any input.
//! Zero-area faces are kept by every reader: they are valid topology and the topology report
//! counts them. Each format module documents what it reads, what it writes and what it repairs.
//!
//! Writes are atomic: the file is written to a temporary file in the target's directory and then
//! renamed over the target, so a failed or interrupted write never leaves a half-written file.

pub mod gltf;
mod lines;
pub mod obj;
pub mod ply;
pub mod sink;
pub mod stl;
pub mod stream;
pub mod texture;

use std::io::{BufWriter, Write};
use std::path::{Component, Path};

use crate::error::{Error, Location, Result};
use crate::mesh::Mesh;

/// A mesh file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Format {
    Obj,
    Ply,
    Stl,
    /// glTF 2.0 JSON (`.gltf`); written with the buffer embedded as a base64 data URI.
    Gltf,
    /// Binary glTF 2.0 (`.glb`).
    Glb,
}

impl Format {
    /// The format a path's extension names (case-insensitive).
    pub fn from_path(path: &Path) -> Result<Format> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        Ok(match ext.as_str() {
            "obj" => Format::Obj,
            "ply" => Format::Ply,
            "stl" => Format::Stl,
            "gltf" => Format::Gltf,
            "glb" => Format::Glb,
            _ => {
                return Err(Error::UnsupportedFormat {
                    path: path.to_path_buf(),
                    ext,
                });
            }
        })
    }

    /// The usual file extension, without the dot.
    pub fn extension(self) -> &'static str {
        match self {
            Format::Obj => "obj",
            Format::Ply => "ply",
            Format::Stl => "stl",
            Format::Gltf => "gltf",
            Format::Glb => "glb",
        }
    }
}

/// Choices for writers whose format has variants. The default is binary for both.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct WriteOptions {
    /// Write PLY as ascii instead of binary little endian.
    pub ply_ascii: bool,
    /// Write STL as ascii instead of binary.
    pub stl_ascii: bool,
}

/// Reads a mesh, the format chosen by the file extension.
pub fn read(path: &Path) -> Result<Mesh> {
    if path.is_dir() {
        return Err(Error::Io {
            path: path.to_path_buf(),
            source: std::io::Error::new(
                std::io::ErrorKind::IsADirectory,
                "a directory, not a mesh file (.obj, .ply, .stl, .gltf or .glb)",
            ),
        });
    }
    read_format(path, Format::from_path(path)?)
}

/// Reads a mesh in the given format, whatever the extension.
pub fn read_format(path: &Path, format: Format) -> Result<Mesh> {
    let mesh = match format {
        Format::Obj => obj::read(path)?,
        Format::Ply => ply::read(path)?,
        Format::Stl => stl::read(path)?,
        Format::Gltf | Format::Glb => gltf::read(path)?,
    };
    mesh.validate()
        .map_err(|e| Error::parse(path, Location::Unknown, e.to_string()))?;
    Ok(mesh)
}

/// Writes a mesh with the default options, the format chosen by the file extension.
pub fn write(path: &Path, mesh: &Mesh) -> Result<()> {
    write_with(path, mesh, &WriteOptions::default())
}

/// What of `mesh` a file in `format` does not keep, one phrase each, for a note before writing
/// (empty when it keeps everything the mesh has).
pub fn not_kept(mesh: &Mesh, format: Format) -> Vec<String> {
    let mut lost = Vec::new();
    let gltf = matches!(format, Format::Gltf | Format::Glb);
    let gltf_materials =
        !mesh.textures.is_empty() || mesh.materials.iter().any(|m| m.gltf.is_some());
    if gltf_materials && !gltf {
        lost.push(format!(
            "the glTF material definitions and {} texture image(s) (.glb and .gltf keep them)",
            mesh.textures.images.len()
        ));
    }
    if gltf {
        let unread = mesh
            .textures
            .images
            .iter()
            .filter(|i| i.data.is_none())
            .count();
        if unread > 0 {
            lost.push(format!(
                "{unread} texture image(s) that could not be read: their URIs are written as \
                 the input gave them, relative to its folder"
            ));
        }
        if mesh
            .materials
            .iter()
            .filter_map(|m| m.gltf.as_ref())
            .any(gltf::uses_other_uv_sets)
        {
            lost.push("texture references on a second UV set (only TEXCOORD_0 is kept)".into());
        }
    }
    if !mesh.material_libs.is_empty() && format != Format::Obj && format != Format::Stl {
        lost.push(format!(
            "the colours and textures of the OBJ material libraries ({}){}",
            mesh.material_libs.join(", "),
            if gltf {
                ": glTF gets the material names"
            } else {
                ""
            }
        ));
    }
    let mut attrs: Vec<&str> = Vec::new();
    if format == Format::Stl {
        for (has, what) in [
            (mesh.normals.is_some(), "normals"),
            (mesh.uvs.is_some(), "UVs"),
            (mesh.colors.is_some(), "colours"),
        ] {
            if has {
                attrs.push(what);
            }
        }
    }
    if matches!(format, Format::Stl | Format::Ply) {
        if mesh.face_materials.is_some() {
            attrs.push("materials");
        }
        if mesh.face_groups.is_some() {
            attrs.push("groups");
        }
    }
    if !attrs.is_empty() {
        lost.push(format!("the {}", attrs.join(", ")));
    }
    lost
}

/// Writes `mesh`, read from the file `input`, to `path` as [`write`] does, with an OBJ's
/// material libraries named from the output's folder: `mtllib` names are relative to the OBJ
/// that names them, so a simplified scan written to another folder would lose its colours and
/// textures with the names kept verbatim.
///
/// An OBJ with UVs from an input without materials but with one texture beside it (a scan and
/// its PNG) gets a material library of its own naming that texture ([`texture`]).
pub fn write_from(path: &Path, mesh: &Mesh, input: &Path) -> Result<()> {
    let format = Format::from_path(path)?;
    if format == Format::Obj
        && let Some((textured, lib)) = texture::with_own_material(mesh, input, path)?
    {
        textured.validate()?;
        return write_atomic(path, |w| obj::write_obj_libs(w, &textured, &[lib]));
    }
    if format != Format::Obj || mesh.material_libs.is_empty() {
        return write_format(path, mesh, format, &WriteOptions::default());
    }
    let libs = relocate_material_libs(&mesh.material_libs, input, path);
    mesh.validate()?;
    write_atomic(path, |w| obj::write_obj_libs(w, mesh, &libs))
}

/// `libs`, named relative to the folder of `input`, named relative to the folder of `output`:
/// unchanged when both are the same folder (or a name is absolute), else a `/`-separated path
/// from the output's folder (absolute when there is none, as between Windows drives). A name
/// that is no file but whose space-separated words are (`mtllib a.mtl b.mtl` lists two) has
/// each word moved. A folder name with spaces puts spaces in the result, which readers that
/// split `mtllib` lines on whitespace misread; this one keeps the line whole.
pub fn relocate_material_libs(libs: &[String], input: &Path, output: &Path) -> Vec<String> {
    let folder = |p: &Path| {
        let d = match p.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        std::fs::canonicalize(d)
            .or_else(|_| std::path::absolute(d))
            .unwrap_or_else(|_| d.to_path_buf())
    };
    let (from, to) = (folder(input), folder(output));
    if from == to {
        return libs.to_vec();
    }
    let moved = |lib: &str| -> String {
        if Path::new(lib).is_absolute() {
            return lib.to_string();
        }
        // Canonical when it exists, so `../` in the name does not come back twice.
        let target = std::fs::canonicalize(from.join(lib)).unwrap_or_else(|_| from.join(lib));
        match pathdiff::diff_paths(&target, &to) {
            // Between Windows drives the "relative" path still holds a drive or root.
            Some(rel)
                if rel
                    .components()
                    .all(|c| matches!(c, Component::Normal(_) | Component::ParentDir)) =>
            {
                rel.components()
                    .map(|c| c.as_os_str().to_string_lossy())
                    .collect::<Vec<_>>()
                    .join("/")
            }
            _ => target.to_string_lossy().into_owned(),
        }
    };
    libs.iter()
        .map(|lib| {
            let words: Vec<&str> = lib.split_whitespace().collect();
            if words.len() > 1
                && !from.join(lib).is_file()
                && words.iter().all(|w| from.join(w).is_file())
            {
                words.iter().map(|w| moved(w)).collect::<Vec<_>>().join(" ")
            } else {
                moved(lib)
            }
        })
        .collect()
}

/// Writes a mesh, the format chosen by the file extension.
pub fn write_with(path: &Path, mesh: &Mesh, options: &WriteOptions) -> Result<()> {
    write_format(path, mesh, Format::from_path(path)?, options)
}

/// Writes a mesh in the given format, atomically (temporary file in the same directory, then a
/// rename over `path`). The mesh is validated first.
pub fn write_format(
    path: &Path,
    mesh: &Mesh,
    format: Format,
    options: &WriteOptions,
) -> Result<()> {
    mesh.validate()?;
    write_atomic(path, |w| match format {
        Format::Obj => obj::write_obj(w, mesh),
        Format::Ply => ply::write_ply(
            w,
            mesh,
            if options.ply_ascii {
                ply::PlyEncoding::Ascii
            } else {
                ply::PlyEncoding::BinaryLittleEndian
            },
        ),
        Format::Stl if options.stl_ascii => stl::write_ascii(w, mesh),
        Format::Stl => stl::write_binary(w, mesh),
        Format::Gltf => gltf::write_gltf(w, mesh, false),
        Format::Glb => gltf::write_gltf(w, mesh, true),
    })
}

/// Writes a file atomically: `fill` writes into a temporary file in the same directory, which
/// then replaces `path` by a rename, so a reader never sees half a file and a failure leaves the
/// old one in place.
pub fn write_atomic(
    path: &Path,
    fill: impl FnOnce(&mut BufWriter<&mut std::fs::File>) -> std::io::Result<()>,
) -> Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let mut tmp = tempfile::Builder::new()
        .prefix(".meshslim-")
        .suffix(".tmp")
        .tempfile_in(dir)
        .map_err(|e| Error::io(path, e))?;
    {
        let mut w = BufWriter::with_capacity(1 << 16, tmp.as_file_mut());
        fill(&mut w)
            .and_then(|()| w.flush())
            .map_err(|e| Error::io(path, e))?;
    }
    tmp.as_file().sync_all().map_err(|e| Error::io(path, e))?;
    // A temporary file is created private (0600); give the result the permissions the target had,
    // or the usual 0644 for a new file.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(path)
            .map(|m| m.permissions().mode() & 0o7777)
            .unwrap_or(0o644);
        let _ = tmp
            .as_file()
            .set_permissions(std::fs::Permissions::from_mode(mode));
    }
    tmp.persist(path).map_err(|e| Error::io(path, e.error))?;
    Ok(())
}
