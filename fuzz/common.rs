//! What every target shares: the readers take a path, so each input is written to a file in a
//! folder of this fuzzing process (in /dev/shm when the machine has it, off the disk).

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use meshslim::io::{Format, WriteOptions};
use meshslim::{Mesh, Result};

fn scratch() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let base = if Path::new("/dev/shm").is_dir() {
            PathBuf::from("/dev/shm")
        } else {
            std::env::temp_dir()
        };
        let dir = base.join(format!("meshslim-fuzz-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("a scratch folder for the fuzz inputs");
        dir
    })
}

/// Reads `data` as a file of `format` through the public reader; a mesh it accepts must be
/// valid, and must survive a write and a read back in the same format with its faces.
pub fn read(data: &[u8], format: Format) -> Result<Mesh> {
    let path = scratch().join(format!("input.{}", format.extension()));
    std::fs::write(&path, data).expect("writing the fuzz input");
    let mesh = meshslim::io::read_format(&path, format)?;
    mesh.validate()
        .expect("a reader returned a mesh that fails Mesh::validate");
    let back = scratch().join(format!("back.{}", format.extension()));
    meshslim::io::write_format(&back, &mesh, format, &WriteOptions::default())
        .expect("writing back a mesh a reader accepted");
    let again = meshslim::io::read_format(&back, format)
        .expect("reading back what we wrote from an accepted mesh");
    assert_eq!(
        again.face_count(),
        mesh.face_count(),
        "the faces of an accepted mesh, written and read back"
    );
    Ok(mesh)
}
