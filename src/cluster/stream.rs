//! Out-of-core `--method cluster` (Lindstrom, "Out-of-Core Simplification of Large Polygonal
//! Models", SIGGRAPH 2000): the vertex positions are held, the faces are not. A first pass reads
//! the vertices alone; every later pass (the area, the counting pass, each build of the size
//! search) reads the faces again from the file in blocks of [`BLOCK`] triangles and consumes
//! them as they pass: the cells' quadrics are summed block after block and only the faces that
//! survive are kept. Memory depends on the vertices and the output, not on the faces.
//!
//! Not carried: normals, colours and UVs (they would be held per vertex); the output's vertices
//! are the clusters' positions. Only PLY (ascii or binary) streams so far.

use super::{
    BAND, Built, ClusterReport, Points, StopReason, cluster_to, max_error, prepare, tally,
};
use crate::error::{Error, Result};
use crate::io::sink::{Sink, Vertex};
use crate::mesh::Mesh;
use crate::mesh::prepare::denormalize;
use crate::options::{Backend, Method, SimplifyOptions, SimplifyReport};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Triangles a streaming pass holds at once: 12 MiB of indices.
pub const BLOCK: usize = 1 << 20;

/// The faces of a file, read again in blocks at each pass.
pub struct FileFaces {
    path: PathBuf,
    /// Triangles a block holds ([`BLOCK`]; less in tests, to cross block borders).
    block: usize,
    /// Triangles in the file (after fan triangulation), counted by the first face pass.
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
        crate::io::ply::read_into(&self.path, &mut b)?;
        b.flush();
        match b.failed {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }
}

/// The vertex pass: positions only, the faces not read.
#[derive(Default)]
struct Positions(Vec<[f32; 3]>);

impl Sink for Positions {
    fn wants_faces(&self) -> bool {
        false
    }
    fn begin_vertices(&mut self, reserve: usize, _: crate::io::sink::VertexAttributes) {
        self.0.reserve(reserve);
    }
    fn vertex(&mut self, v: &Vertex) {
        self.0.push(v.position);
    }
    fn triangle(&mut self, _: [u32; 3]) {}
}

/// How many faces to keep, once the file's count is known.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Target {
    Faces(usize),
    Ratio(f64),
}

/// `--method cluster --stream` on the PLY file at `path`: the input's counts come from the
/// file; `opts.target_faces` is replaced by `target`. Returns the simplified mesh (positions
/// and faces) and the report; the input's face and vertex counts are the file's.
pub fn simplify_file(
    path: &Path,
    target: Target,
    opts: &SimplifyOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<(Mesh, SimplifyReport)> {
    simplify_file_in_blocks(path, target, opts, BLOCK, progress)
}

/// [`simplify_file`] with blocks of `block` triangles (the tests cross many block borders on
/// small meshes).
#[doc(hidden)]
pub fn simplify_file_in_blocks(
    path: &Path,
    target: Target,
    opts: &SimplifyOptions,
    block: usize,
    progress: &mut dyn FnMut(f32),
) -> Result<(Mesh, SimplifyReport)> {
    assert!(block > 0, "a block holds at least one triangle");
    if crate::io::Format::from_path(path)? != crate::io::Format::Ply {
        return Err(Error::InvalidOption(format!(
            "--stream reads PLY files (ascii or binary); {} is not one: convert it, or drop \
             --stream to read it whole",
            path.display()
        )));
    }
    if opts.method != Method::Cluster {
        return Err(Error::InvalidOption(format!(
            "--stream runs --method cluster; --method {} holds the whole mesh",
            opts.method.name()
        )));
    }
    if opts.lock_border || opts.backend == Backend::Gpu {
        return Err(Error::InvalidOption(
            "--stream runs on the CPU without --lock-border (finding the border needs every \
             face at once)"
                .into(),
        ));
    }
    let t = Instant::now();
    let mut raw = Positions::default();
    crate::io::ply::read_into(path, &mut raw)?;
    let vertices = raw.0.len();
    let mut pts = {
        let m = Mesh {
            positions: raw.0,
            ..Mesh::default()
        };
        Points::of(&m, Vec::new().into())
    };
    pts.stream = Some(FileFaces {
        path: path.to_path_buf(),
        block,
        faces: 0,
    });
    // The area pass counts the faces too: --ratio needs the count.
    let work = prepare(&mut pts, opts, false)?;
    let faces = work.pts.face_count();
    let target_faces = match target {
        Target::Faces(n) => n,
        Target::Ratio(r) => SimplifyOptions::with_ratio(faces, r)?.target_faces,
    };
    progress(0.2);
    let mut report = ClusterReport {
        method: Method::Cluster,
        ..Default::default()
    };
    let (grid, built, stop) = cluster_to(&work, target_faces, opts.max_error, None, &mut report)?;
    opts.cancel.check()?;
    progress(0.9);
    tally(&mut report, &built);
    report.cell_size = grid.h as f64;
    let out = output(work.pts, &built);
    report.seconds = t.elapsed().as_secs_f64();
    let report = SimplifyReport {
        backend: Backend::CpuParallel,
        auto: None,
        input_faces: faces,
        target_faces,
        output_faces: out.triangles.len(),
        input_vertices: vertices,
        output_vertices: out.positions.len(),
        collapses: vertices.saturating_sub(out.positions.len()),
        max_collapse_error: max_error(&built),
        stop_reason: stop,
        dropped_degenerate_faces: 0,
        pinned_vertices: 0,
        rounds: None,
        blocked: None,
        clustering: Some(report),
    };
    debug_assert!(
        stop != StopReason::TargetReached
            || (out.triangles.len() as f64 - target_faces as f64).abs()
                <= BAND * target_faces as f64 + 1.0
    );
    Ok((out, report))
}

/// The clusters the kept faces use, numbered in order of first use (as the in-memory output),
/// at their placed positions.
fn output(pts: &Points, b: &Built) -> Mesh {
    let mut id = vec![u32::MAX; b.clusters];
    let mut positions = Vec::new();
    let mut triangles = Vec::with_capacity(b.faces.len());
    for (_, t) in &b.faces {
        triangles.push(t.map(|k| {
            if id[k as usize] == u32::MAX {
                id[k as usize] = positions.len() as u32;
                let p = b.placed[k as usize].pos.map(|x| x as f64);
                positions.push(denormalize(p, pts.center, pts.scale));
            }
            id[k as usize]
        }));
    }
    Mesh {
        positions,
        triangles,
        ..Mesh::default()
    }
}
