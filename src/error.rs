//! The one error type of the library. Every variant carries what a user needs to act on it:
//! the file, where in it (line or byte offset) and what was wrong.

use std::fmt;
use std::path::PathBuf;

/// Where in an input file a problem was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Location {
    /// 1-based line number of a text format.
    Line(u64),
    /// 0-based byte offset into a binary format.
    Byte(u64),
    /// No finer position is known (for example an error reported by a third-party parser).
    Unknown,
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Location::Line(n) => write!(f, "line {n}"),
            Location::Byte(n) => write!(f, "byte offset {n}"),
            Location::Unknown => write!(f, "unknown position"),
        }
    }
}

#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{path}: {location}: {message}")]
    Parse {
        path: PathBuf,
        location: Location,
        message: String,
    },
    #[error(
        "{path}: unsupported file extension {ext:?} (supported: .obj, .ply, .stl, .gltf, .glb)"
    )]
    UnsupportedFormat { path: PathBuf, ext: String },
    #[error("invalid mesh: {0}")]
    InvalidMesh(String),
    #[error("invalid option: {0}")]
    InvalidOption(String),
    #[error("refusing to overwrite the input file {0}; choose another output path")]
    WouldOverwriteInput(PathBuf),
    /// No GPU adapter, a lost device, a shader or pipeline the driver refused.
    #[error("GPU: {0}")]
    Gpu(String),
    /// A buffer larger than the device allows.
    #[error(
        "GPU: buffer {label} needs {size} bytes but the device allows at most {limit} ({which}); \
         the mesh is too big for this device, use --backend cpu-parallel"
    )]
    BufferTooLarge {
        label: String,
        size: u64,
        limit: u64,
        which: &'static str,
    },
    /// Stopped on request ([`crate::options::Cancel`]); nothing was written.
    #[error("cancelled")]
    Cancelled,
    /// A broken invariant inside the library: a bug, reported instead of a panic.
    #[error("internal error (please report): {0}")]
    Internal(String),
}

impl Error {
    pub(crate) fn parse(
        path: &std::path::Path,
        location: Location,
        message: impl Into<String>,
    ) -> Self {
        Error::Parse {
            path: path.to_path_buf(),
            location,
            message: message.into(),
        }
    }
    pub(crate) fn io(path: &std::path::Path, source: std::io::Error) -> Self {
        Error::Io {
            path: path.to_path_buf(),
            source,
        }
    }
}

pub type Result<T, E = Error> = std::result::Result<T, E>;
