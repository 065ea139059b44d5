//! Out-of-core `--method cluster` and `hybrid` (Lindstrom, "Out-of-Core Simplification of Large Polygonal
//! Models", SIGGRAPH 2000): the vertex positions are held, the faces are not. A first pass reads
//! the vertices alone; every later pass (the area, the counting pass, each build of the size
//! search) reads the faces again from the file in blocks of [`BLOCK`] triangles and consumes
//! them as they pass: the cells' quadrics are summed block after block and only the faces that
//! survive are kept. Memory depends on the vertices and the output, not on the faces. The
//! hybrid splits cells by connectivity with a union-find fed block by block, scatters its
//! quadrics (no vertex→face lists), then runs its second phase (the greedy queue, or the rounds
//! on `cpu-parallel` and `gpu`) in memory on the clustered mesh.
//!
//! Vertex colours are carried (held per vertex, as the positions are): each cluster takes its
//! nearest member's, as the in-memory clustering without a colour weight does; coloured scans
//! are the big ones. Not carried: normals and UVs. PLY (ascii or binary) and OBJ stream; an
//! OBJ's faces refer to its positions alone (no seam vertices: nothing is carried that would
//! need them).

use super::{Built, ClusterReport, Points, StopReason, cluster_to, max_error, prepare, tally};
use crate::error::{Error, Result};
use crate::io::stream::{BLOCK, FileFaces, read_vertices};
use crate::mesh::Mesh;
use crate::mesh::prepare::denormalize;
use crate::options::{Backend, Method, SimplifyOptions, SimplifyReport};
use std::path::Path;
use std::time::Instant;

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
    let (positions, colors) = read_vertices(path, true)?;
    let vertices = positions.len();
    let mut pts = {
        let m = Mesh {
            positions,
            ..Mesh::default()
        };
        Points::of(&m, Vec::new().into())
    };
    pts.stream = Some(FileFaces::new(path, block));
    // The area pass counts the faces too: --ratio needs the count.
    let mut work = prepare(&mut pts, opts, hybrid, None)?;
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
    // The hybrid's faces' input normals come with its build (the rounds measure from them).
    let (grid, built, stop, normals) = if hybrid {
        let (grid, built, normals) =
            super::repair::cluster_repaired(&mut work, to, target_faces, &mut report)?;
        (grid, built, StopReason::TargetReached, normals)
    } else {
        let (grid, built, stop) =
            cluster_to(&work, target_faces, opts.max_error, None, None, &mut report)?;
        (grid, built, stop, Vec::new())
    };
    opts.cancel.check()?;
    tally(&mut report, &built);
    report.cell_size = grid.h as f64;
    let (clustered, quadrics) = output(work.pts, &built, colors.as_deref());
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
            decimation: None,
        };
        return Ok((out, r));
    }
    // The hybrid's second phase, in memory on the clustered mesh (the rounds from the clusters'
    // quadrics).
    progress(0.5);
    report.intermediate_faces = Some(clustered.triangles.len());
    let opts = &SimplifyOptions {
        target_faces,
        ..opts.clone()
    };
    let c = super::hybrid::Clustered {
        mesh: clustered,
        quadrics,
        normals,
        frame,
        error: built_error,
    };
    let (out, mut r) = super::hybrid::finish(&c, &c.mesh, opts, &mut |f| progress(0.5 + 0.5 * f))?;
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
/// at their placed positions, with their nearest member's colour where the input has colours,
/// and their quadrics.
fn output(
    pts: &Points,
    b: &Built,
    colors: Option<&[[f32; 4]]>,
) -> (Mesh, Vec<crate::compute::types::Quadric>) {
    let mut id = vec![u32::MAX; b.clusters];
    let mut positions = Vec::new();
    let mut out_colors = Vec::new();
    let mut quadrics = Vec::new();
    let mut triangles = Vec::with_capacity(b.faces.len());
    for (_, t) in &b.faces {
        triangles.push(t.map(|k| {
            if id[k as usize] == u32::MAX {
                id[k as usize] = positions.len() as u32;
                let p = b.placed[k as usize].pos.map(|x| x as f64);
                positions.push(denormalize(p, pts.center, pts.scale));
                if let Some(c) = colors {
                    out_colors.push(c[b.placed[k as usize].attr as usize]);
                }
                quadrics.push(b.placed[k as usize].quadric);
            }
            id[k as usize]
        }));
    }
    let mesh = Mesh {
        positions,
        triangles,
        colors: colors.map(|_| out_colors),
        ..Mesh::default()
    };
    (mesh, quadrics)
}
