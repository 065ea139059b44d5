//! Files in and out: reading the mesh an input names, and the checks on output paths that need
//! no mesh, so that a wrong path fails before any work.

use std::path::Path;

use anyhow::{Context, Result};

use super::args::Input;
use super::error::lib;
use super::report::Progress;
use crate::io::Format;
use crate::mesh::Mesh;

pub(super) fn load(input: &Input, progress: &Progress) -> Result<Mesh> {
    match input {
        Input::File(path) => progress
            .spinner(format!("reading {}", path.display()), || {
                crate::io::read(path)
            })
            .map_err(lib)
            .context("cannot read the input"),
        Input::Builtin {
            spec,
            kind,
            min_faces,
        } => Ok(progress.spinner(format!("generating {spec}"), || (kind.make)(*min_faces))),
    }
}

/// Fails when the folder `file` is to be written into does not exist (`what` names it).
pub(super) fn check_directory(file: &Path, what: &str) -> Result<()> {
    if let Some(dir) = file.parent().filter(|d| !d.as_os_str().is_empty())
        && !dir.is_dir()
    {
        anyhow::bail!(
            "{}: {what} {} does not exist",
            file.display(),
            dir.display()
        );
    }
    Ok(())
}

/// The checks that need no mesh, so that a wrong output path fails before any work.
pub(super) fn check_output(input: &Input, output: &Path) -> Result<()> {
    Format::from_path(output).map_err(lib)?;
    check_directory(output, "the output directory")?;
    if let Input::File(input) = input
        && output.exists()
        && same_file(input, output)
    {
        return Err(lib(crate::Error::WouldOverwriteInput(input.clone())));
    }
    Ok(())
}

/// Whether two existing paths name one file: the same canonical path, or (on Unix) the same
/// inode, which also catches hard links.
fn same_file(a: &Path, b: &Path) -> bool {
    if let (Ok(ca), Ok(cb)) = (a.canonicalize(), b.canonicalize())
        && ca == cb
    {
        return true;
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if let (Ok(ma), Ok(mb)) = (std::fs::metadata(a), std::fs::metadata(b)) {
            return ma.dev() == mb.dev() && ma.ino() == mb.ino();
        }
    }
    false
}

/// The texture image at `path` (PNG or JPEG) for the appearance measures.
pub(super) fn load_texture(path: &Path) -> Result<std::sync::Arc<crate::metrics::Texture>> {
    let img = crate::viewer::scene::read_texture(path)
        .map_err(lib)
        .with_context(|| format!("cannot use {} as a texture", path.display()))?;
    let (w, h) = (img.size.0 as usize, img.size.1 as usize);
    let rgb = img
        .rgba
        .chunks_exact(4)
        .map(|p| [0, 1, 2].map(|k| f32::from(p[k]) / 255.0))
        .collect();
    Ok(std::sync::Arc::new(crate::metrics::Texture {
        width: w,
        height: h,
        rgb,
    }))
}

/// The metrics' options `compare` and `bench` were given, the texture read.
pub(super) fn compare_options(
    s: &super::args::SamplingArgs,
) -> Result<crate::metrics::CompareOptions> {
    Ok(crate::metrics::CompareOptions {
        samples: s.samples.map(|n| n as usize),
        seed: s.seed,
        texture: s.texture.as_deref().map(load_texture).transpose()?,
        ..Default::default()
    })
}
