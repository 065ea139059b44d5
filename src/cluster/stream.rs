//! Out-of-core `--method cluster` and `hybrid` (Lindstrom, "Out-of-Core Simplification of Large Polygonal
//! Models", SIGGRAPH 2000): the vertex positions are held, the faces are not. A first pass reads
//! the vertices alone; every later pass (the area, the counting pass, each build of the size
//! search) reads the faces again from the file in blocks of [`BLOCK`] triangles and consumes
//! them as they pass: the cells' quadrics are summed block after block and only the faces that
//! survive are kept. Memory depends on the vertices and the output, not on the faces. The
//! hybrid splits cells by connectivity with a union-find fed block by block, scatters its
//! quadrics (no vertex→face lists), then runs the rounds in memory on the clustered mesh.
//!
//! Not carried: normals, colours and UVs (they would be held per vertex); the output's vertices
//! are the clusters' positions. PLY (ascii or binary) and OBJ stream; an OBJ's faces refer to
//! its positions alone (no seam vertices: nothing is carried that would need them).

use super::{Built, ClusterReport, Points, StopReason, cluster_to, max_error, prepare, tally};
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
        read_into(&self.path, &mut b)?;
        b.flush();
        match b.failed {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }
}

/// A streaming read of a PLY or an OBJ (by positions alone, `obj::read_into`).
fn read_into(path: &Path, sink: &mut dyn Sink) -> Result<()> {
    match crate::io::Format::from_path(path)? {
        crate::io::Format::Obj => crate::io::obj::read_into(path, sink),
        _ => crate::io::ply::read_into(path, sink),
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

/// `--method cluster` or `hybrid` with `--stream` on the PLY file at `path`: the input's counts come from the
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
    let format = crate::io::Format::from_path(path)?;
    if !matches!(format, crate::io::Format::Ply | crate::io::Format::Obj) {
        return Err(Error::InvalidOption(format!(
            "--stream reads PLY (ascii or binary) and OBJ files; {} is neither: convert it, \
             or drop --stream to read it whole",
            path.display()
        )));
    }
    let hybrid = match opts.method {
        Method::Cluster => false,
        Method::Hybrid => true,
        m => {
            return Err(Error::InvalidOption(format!(
                "--stream runs --method cluster and hybrid; --method {} holds the whole mesh",
                m.name()
            )));
        }
    };
    if opts.lock_border || (opts.backend == Backend::Gpu && !hybrid) {
        return Err(Error::InvalidOption(
            "--stream clusters on the CPU (hybrid's rounds may run on --backend gpu), without \
             --lock-border (finding the border needs every face at once)"
                .into(),
        ));
    }
    let t = Instant::now();
    let mut raw = Positions::default();
    read_into(path, &mut raw)?;
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
    let mut work = prepare(&mut pts, opts, hybrid)?;
    let faces = work.pts.face_count();
    let target_faces = match target {
        Target::Faces(n) => n,
        Target::Ratio(r) => SimplifyOptions::with_ratio(faces, r)?.target_faces,
    };
    progress(0.2);
    let mut report = ClusterReport {
        method: opts.method,
        ..Default::default()
    };
    let to = super::hybrid::intermediate(target_faces, faces);
    if hybrid && to as f64 >= super::hybrid::HYBRID_SKIP * faces as f64 {
        // Clustering would keep most faces, and the rounds then hold them anyway: read the
        // mesh whole and run the hybrid as it is (its rounds start from the input).
        drop(work);
        drop(pts);
        let mesh = crate::io::read(path)?;
        let opts = SimplifyOptions {
            target_faces,
            ..opts.clone()
        };
        return super::hybrid::simplify_hybrid(&mesh, &opts, progress);
    }
    let (grid, built, stop) = if hybrid {
        let (grid, built) =
            super::hybrid::cluster_repaired(&mut work, to, target_faces, &mut report)?;
        (grid, built, StopReason::TargetReached)
    } else {
        cluster_to(&work, target_faces, opts.max_error, None, &mut report)?
    };
    opts.cancel.check()?;
    tally(&mut report, &built);
    report.cell_size = grid.h as f64;
    let (clustered, quadrics) = output(work.pts, &built);
    let built_error = max_error(&built);
    let frame = (work.pts.center, work.pts.scale);
    drop(work);
    drop(pts);
    report.seconds = t.elapsed().as_secs_f64();
    let input = Counts { faces, vertices };
    if !hybrid {
        progress(1.0);
        let out = clustered;
        let r = SimplifyReport {
            backend: Backend::CpuParallel,
            auto: None,
            input_faces: faces,
            target_faces,
            output_faces: out.triangles.len(),
            input_vertices: vertices,
            output_vertices: out.positions.len(),
            collapses: vertices.saturating_sub(out.positions.len()),
            max_collapse_error: built_error,
            stop_reason: stop,
            dropped_degenerate_faces: 0,
            pinned_vertices: 0,
            rounds: None,
            blocked: None,
            clustering: Some(report),
        };
        return Ok((out, r));
    }
    // The hybrid's rounds, in memory on the clustered mesh, from the clusters' quadrics.
    progress(0.5);
    report.intermediate_faces = Some(clustered.triangles.len());
    let up = crate::parallel::Upload::with_quadrics(&clustered, frame, &quadrics);
    let opts = &SimplifyOptions {
        target_faces,
        backend: if opts.backend == Backend::Gpu {
            Backend::Gpu
        } else {
            Backend::CpuParallel
        },
        ..opts.clone()
    };
    let (out, mut r) =
        super::hybrid::rounds(&up, &clustered, opts, &mut |f| progress(0.5 + 0.5 * f))?;
    r.max_collapse_error = r.max_collapse_error.max(built_error);
    r.input_faces = input.faces;
    r.input_vertices = input.vertices;
    r.collapses = input.vertices.saturating_sub(out.positions.len());
    r.clustering = Some(report);
    Ok((out, r))
}

/// The input file's counts.
struct Counts {
    faces: usize,
    vertices: usize,
}

/// The clusters the kept faces use, numbered in order of first use (as the in-memory output),
/// at their placed positions, and their quadrics.
fn output(pts: &Points, b: &Built) -> (Mesh, Vec<crate::gpu::types::Quadric>) {
    let mut id = vec![u32::MAX; b.clusters];
    let mut positions = Vec::new();
    let mut quadrics = Vec::new();
    let mut triangles = Vec::with_capacity(b.faces.len());
    for (_, t) in &b.faces {
        triangles.push(t.map(|k| {
            if id[k as usize] == u32::MAX {
                id[k as usize] = positions.len() as u32;
                let p = b.placed[k as usize].pos.map(|x| x as f64);
                positions.push(denormalize(p, pts.center, pts.scale));
                quadrics.push(b.placed[k as usize].quadric);
            }
            id[k as usize]
        }));
    }
    let mesh = Mesh {
        positions,
        triangles,
        ..Mesh::default()
    };
    (mesh, quadrics)
}
