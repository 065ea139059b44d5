//! Reading a PLY or an OBJ in passes without holding its faces: the positions alone, then the
//! faces again in blocks at each later pass (the out-of-core clustering, `tiles split`).

use crate::error::{Error, Result};
use crate::io::sink::{Sink, Vertex};
use std::path::{Path, PathBuf};

/// Triangles a streaming pass holds at once: 12 MiB of indices.
pub const BLOCK: usize = 1 << 20;

/// The faces of a file, read again in blocks at each pass.
pub struct FileFaces {
    path: PathBuf,
    /// Triangles a block holds ([`BLOCK`]; less in tests, to cross block borders).
    block: usize,
    /// Triangles in the file (after fan triangulation), where a pass has counted them (the
    /// clustering's area pass).
    pub faces: usize,
}

/// A consumer of faces in blocks: each block with its first face's id.
pub type OnBlock<'f> = dyn FnMut(usize, &[[u32; 3]]) -> Result<()> + 'f;

/// Hands blocks of triangles to a consumer as the reader produces them.
struct Blocks<'f> {
    buf: Vec<[u32; 3]>,
    block: usize,
    first: usize,
    f: &'f mut OnBlock<'f>,
    /// The consumer's first error: the rest of the file is read but not handed over.
    failed: Option<Error>,
}

impl Blocks<'_> {
    fn flush(&mut self) {
        if self.failed.is_none()
            && !self.buf.is_empty()
            && let Err(e) = (self.f)(self.first, &self.buf)
        {
            self.failed = Some(e);
        }
        self.first += self.buf.len();
        self.buf.clear();
    }
}

impl Sink for Blocks<'_> {
    fn wants_vertices(&self) -> bool {
        false
    }
    fn vertex(&mut self, _: &Vertex) {}
    fn triangle(&mut self, t: [u32; 3]) {
        self.buf.push(t);
        if self.buf.len() == self.block {
            self.flush();
        }
    }
}

impl FileFaces {
    /// The faces of the PLY or OBJ at `path`, read `block` triangles at a time.
    pub fn new(path: &Path, block: usize) -> FileFaces {
        assert!(block > 0, "a block holds at least one triangle");
        FileFaces {
            path: path.to_path_buf(),
            block,
            faces: 0,
        }
    }

    /// Calls `f` with the file's triangles in blocks, in file order, with each block's first
    /// face id.
    pub fn blocks(&self, f: &mut OnBlock) -> Result<()> {
        let mut b = Blocks {
            buf: Vec::with_capacity(self.block),
            block: self.block,
            first: 0,
            f,
            failed: None,
        };
        read_into(&self.path, &mut b)?;
        b.flush();
        match b.failed {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }
}

/// A streaming read of a PLY or an OBJ (by positions alone, `obj::read_into`).
pub fn read_into(path: &Path, sink: &mut dyn Sink) -> Result<()> {
    match crate::io::Format::from_path(path)? {
        crate::io::Format::Obj => crate::io::obj::read_into(path, sink),
        _ => crate::io::ply::read_into(path, sink),
    }
}

/// Linear RGBA per vertex.
pub type Colors = Vec<[f32; 4]>;

/// The positions of a PLY's or an OBJ's vertices and, with `colors`, their colours where the
/// file has them (checked as a whole read checks them: finite and in 0..1); the faces not read.
pub fn read_vertices(path: &Path, colors: bool) -> Result<(Vec<[f32; 3]>, Option<Colors>)> {
    let mut p = Vertices {
        want_colors: colors,
        ..Vertices::default()
    };
    read_into(path, &mut p)?;
    let mesh = crate::mesh::Mesh {
        positions: p.positions,
        colors: p.colors,
        ..Default::default()
    };
    mesh.validate()
        .map_err(|e| Error::parse(path, crate::error::Location::Unknown, e.to_string()))?;
    Ok((mesh.positions, mesh.colors))
}

/// The vertex pass: positions (and colours when wanted), the faces not read.
#[derive(Default)]
struct Vertices {
    want_colors: bool,
    positions: Vec<[f32; 3]>,
    colors: Option<Vec<[f32; 4]>>,
}

impl Sink for Vertices {
    fn wants_faces(&self) -> bool {
        false
    }
    fn begin_vertices(&mut self, reserve: usize, a: crate::io::sink::VertexAttributes) {
        self.positions.reserve(reserve);
        if self.want_colors && a.colors {
            self.colors = Some(Vec::with_capacity(reserve));
        }
    }
    fn vertex(&mut self, v: &Vertex) {
        self.positions.push(v.position);
        if let Some(c) = &mut self.colors {
            c.push(v.color);
        }
    }
    fn triangle(&mut self, _: [u32; 3]) {}
}
