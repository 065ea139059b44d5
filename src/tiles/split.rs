//! `tiles split`: the input streamed into tiles. Memory holds the positions (12 B a vertex), a
//! border flag (1 B), each vertex's first tile in the first face pass and its local id in the
//! second (4 B), and a map from (tile, border vertex) to its local id; the faces pass through
//! in blocks twice and go to one part file per tile.

use super::{FORMAT, Manifest, TILE_SHARE, Tile, at, grid_for};
use crate::Backend;
use crate::cluster::stream::Target;
use crate::error::{Error, Result};
use crate::io::stream::{Colors, FileFaces, read_vertices};
use rustc_hash::FxHashMap;
use std::fs::File;
use std::io::{BufWriter, Read, Write};
use std::path::Path;

/// At most this many tiles: a split keeps two files open per tile.
pub const MAX_TILES: usize = 256;

/// What `tiles split` is asked.
#[derive(Debug, Clone)]
pub struct SplitOptions {
    pub tiles: usize,
    /// The faces the merge ends at.
    pub target: Target,
    /// Simplifies the tiles and the merge: `cpu`, the one backend whose pins also refuse a new
    /// edge between two pinned vertices (the rounds' do not yet, and two tiles could then
    /// both hold an edge the weld would give three faces).
    pub backend: Backend,
    /// Triangles per streamed block ([`crate::io::stream::BLOCK`]; less in tests).
    pub block: usize,
    /// Each tile's target as a multiple of its share of the final one ([`TILE_SHARE`]; 1 for
    /// a coarser level, whose merge has nothing left to simplify).
    pub share: f64,
    /// For a coarser level, the grid of the level before: the cuts are then moved, per axis,
    /// as far from its cuts as they can be.
    pub after: Option<[u32; 3]>,
}

impl SplitOptions {
    /// `tiles` tiles to `target`, the defaults for the rest.
    pub fn new(tiles: usize, target: Target) -> SplitOptions {
        SplitOptions {
            tiles,
            target,
            backend: Backend::Cpu,
            block: crate::io::stream::BLOCK,
            share: TILE_SHARE,
            after: None,
        }
    }
}

/// Splits the PLY or OBJ at `input` into `opts.tiles` tiles in `dir` (created if missing),
/// writing each tile's PLY and ids and the manifest, which it returns. `progress` receives the
/// fraction done.
pub fn split(
    input: &Path,
    dir: &Path,
    opts: &SplitOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<Manifest> {
    check_options(input, opts)?;
    clear_manifest(dir)?;
    // Vertex colours travel with the tiles (coloured scans are the big ones): each tile's
    // simplification weighs them, the pinned borders keep theirs, and the merge joins them.
    let (positions, colors) = read_vertices(input, true)?;
    let cells = Cells::new(&positions, opts.tiles, opts.after);
    let faces = FileFaces::new(input, opts.block);
    let tile_of = |t: &[u32; 3]| cells.tile(t.map(|v| positions[v as usize]));
    progress(0.1);

    let nv = positions.len();
    let (border, tile_faces) = first_pass(&faces, &tile_of, nv, opts.tiles)?;
    let total: u64 = tile_faces.iter().sum();
    let target_faces = target_faces(input, opts, total)?;
    progress(0.4);

    let _parts = Parts {
        dir,
        tiles: opts.tiles,
    };
    let mut writers = open_parts(dir, opts.tiles)?;
    let mut borders = second_pass(
        &faces,
        &tile_of,
        &border,
        &mut writers,
        dir,
        total,
        progress,
    )?;

    // Each tile's PLY: the header, its vertices looked up by global id, its face records.
    let mut tile = Vec::with_capacity(opts.tiles);
    for (i, parts) in writers.into_iter().enumerate() {
        let vertices = write_tile(
            dir,
            i,
            opts.tiles,
            parts,
            &positions,
            colors.as_ref(),
            tile_faces[i],
        )?;
        let mut b = std::mem::take(&mut borders[i]);
        b.sort_unstable();
        let share = target_faces as f64 * opts.share * tile_faces[i] as f64 / total as f64;
        tile.push(Tile {
            file: part_name(i, ".ply"),
            ids: part_name(i, ".ids"),
            output: part_name(i, ".out.ply"),
            output_ids: part_name(i, ".out.ids"),
            faces: tile_faces[i],
            vertices,
            target_faces: (share.round() as u64).min(tile_faces[i]),
            border: b,
        });
        progress(0.8 + 0.2 * (i + 1) as f32 / opts.tiles as f32);
    }
    let manifest = Manifest {
        format: FORMAT.into(),
        input: input.display().to_string(),
        input_faces: total,
        input_vertices: nv as u64,
        target_faces,
        backend: opts.backend.name().into(),
        grid: cells.grid,
        tiles: opts.tiles,
        shift: cells.shift,
        tile,
    };
    write_manifest(dir, &manifest)?;
    Ok(manifest)
}

/// The faces the merge ends at, from the input's `total` faces; an error when it has none.
fn target_faces(input: &Path, opts: &SplitOptions, total: u64) -> Result<u64> {
    if total == 0 {
        return Err(Error::InvalidMesh(format!(
            "{} has no faces, so there is nothing to split",
            input.display()
        )));
    }
    Ok(match opts.target {
        Target::Faces(n) => n as u64,
        Target::Ratio(r) => {
            crate::SimplifyOptions::with_ratio(total as usize, r)?.target_faces as u64
        }
    })
}

/// Writes the manifest into `dir`, after removing the outputs of an earlier split there,
/// which would be merged with the new tiles.
fn write_manifest(dir: &Path, manifest: &Manifest) -> Result<()> {
    for t in &manifest.tile {
        for f in [&t.output, &t.output_ids] {
            let _ = std::fs::remove_file(at(dir, f));
        }
    }
    manifest.write(dir)
}

/// Refuses a split the options or the input's format cannot make: a tile count out of range,
/// a backend other than `cpu`, an input other than PLY or OBJ.
fn check_options(input: &Path, opts: &SplitOptions) -> Result<()> {
    if opts.tiles == 0 || opts.tiles > MAX_TILES {
        return Err(Error::InvalidOption(format!(
            "--tiles must be 1 to {MAX_TILES} (two files are open per tile while splitting), got {}",
            opts.tiles
        )));
    }
    if opts.backend != Backend::Cpu {
        return Err(Error::InvalidOption(format!(
            "tiles are simplified by the cpu backend; {} cannot keep two tiles' borders apart yet",
            opts.backend.name()
        )));
    }
    let format = crate::io::Format::from_path(input)?;
    if !matches!(format, crate::io::Format::Ply | crate::io::Format::Obj) {
        return Err(Error::InvalidOption(format!(
            "tiles split streams PLY and OBJ files; {} is neither: convert it first \
             (meshslim simplify IN OUT.ply --ratio 1)",
            input.display()
        )));
    }
    Ok(())
}

/// Creates `dir` if missing and removes an earlier split's manifest there first, so a split
/// that fails leaves no manifest that names these tiles with its old borders; its outputs go
/// at the end.
fn clear_manifest(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    match std::fs::remove_file(dir.join(super::MANIFEST)) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
            Err(Error::io(&dir.join(super::MANIFEST), e))
        }
        _ => Ok(()),
    }
}

/// The name of tile `i`'s file with extension `ext`.
fn part_name(i: usize, ext: &str) -> String {
    format!("tile-{i:04}{ext}")
}

/// Pass 1 over the `nv` vertices' faces: whether a face of another tile than a vertex's first
/// uses it too (a border vertex), and each of the `tiles` tiles' face count.
fn first_pass(
    faces: &FileFaces,
    tile_of: &impl Fn(&[u32; 3]) -> u32,
    nv: usize,
    tiles: usize,
) -> Result<(Vec<bool>, Vec<u64>)> {
    let mut first = vec![u32::MAX; nv];
    let mut border = vec![false; nv];
    let mut tile_faces = vec![0u64; tiles];
    faces.blocks(&mut |_, block| {
        for t in block {
            let k = tile_of(t);
            tile_faces[k as usize] += 1;
            for v in t.map(|v| v as usize) {
                if first[v] == u32::MAX {
                    first[v] = k;
                } else if first[v] != k {
                    border[v] = true;
                }
            }
        }
        Ok(())
    })?;
    Ok((border, tile_faces))
}

/// The part files of `tiles` tiles in `dir`, created: per tile its face records' and its
/// global ids' writer.
fn open_parts(dir: &Path, tiles: usize) -> Result<Vec<(BufWriter<File>, BufWriter<File>)>> {
    let mut writers = Vec::with_capacity(tiles);
    for i in 0..tiles {
        let open = |ext: &str| -> Result<BufWriter<File>> {
            let p = at(dir, &part_name(i, ext));
            let f = File::create(&p).map_err(|e| Error::io(&p, e))?;
            Ok(BufWriter::with_capacity(1 << 16, f))
        };
        writers.push((open(".faces.part")?, open(".ids.part")?));
    }
    Ok(writers)
}

/// Pass 2: faces renumbered per tile in order of first use, written as binary PLY face
/// records to a part file per tile; each tile's global ids appended as they are numbered.
/// Returns each tile's border vertices (global ids, unsorted).
fn second_pass(
    faces: &FileFaces,
    tile_of: &impl Fn(&[u32; 3]) -> u32,
    border: &[bool],
    writers: &mut [(BufWriter<File>, BufWriter<File>)],
    dir: &Path,
    total: u64,
    progress: &mut dyn FnMut(f32),
) -> Result<Vec<Vec<u32>>> {
    let tiles = writers.len();
    let mut count = vec![0u32; tiles];
    // Non-border vertices have one tile and so one local id; border vertices one per tile.
    let mut local = vec![u32::MAX; border.len()];
    let mut local_border: FxHashMap<(u32, u32), u32> = FxHashMap::default();
    let mut done = 0u64;
    faces.blocks(&mut |_, block| {
        for t in block {
            let k = tile_of(t);
            let (fw, iw) = &mut writers[k as usize];
            let mut rec = [0u8; 13];
            rec[0] = 3;
            for (c, &v) in t.iter().enumerate() {
                let slot = if border[v as usize] {
                    local_border.entry((k, v)).or_insert(u32::MAX)
                } else {
                    &mut local[v as usize]
                };
                if *slot == u32::MAX {
                    *slot = count[k as usize];
                    count[k as usize] += 1;
                    iw.write_all(&v.to_le_bytes())
                        .map_err(|e| Error::io(dir, e))?;
                }
                rec[1 + 4 * c..5 + 4 * c].copy_from_slice(&slot.to_le_bytes());
            }
            fw.write_all(&rec).map_err(|e| Error::io(dir, e))?;
        }
        done += block.len() as u64;
        progress(0.4 + 0.4 * done as f32 / total as f32);
        Ok(())
    })?;
    drop(local);
    let mut borders: Vec<Vec<u32>> = vec![Vec::new(); tiles];
    for &(k, v) in local_border.keys() {
        borders[k as usize].push(v);
    }
    Ok(borders)
}

/// Tile `i`'s PLY (of `tiles`) from its part files `(fw, iw)`: the header, its vertices
/// looked up by global id, its `faces` face records; the faces' part removed and the ids'
/// kept as the tile's ids. Returns its vertex count.
fn write_tile(
    dir: &Path,
    i: usize,
    tiles: usize,
    (fw, iw): (BufWriter<File>, BufWriter<File>),
    positions: &[[f32; 3]],
    colors: Option<&Colors>,
    faces: u64,
) -> Result<u64> {
    // Scratch files: flushed, not synced (the tile's PLY is written atomically from them).
    for w in [fw, iw] {
        w.into_inner().map_err(|e| Error::io(dir, e.into_error()))?;
    }
    let part = |ext: &str| at(dir, &part_name(i, ext));
    let ids = super::read_ids(&part(".ids.part"))?;
    let ply = part(".ply");
    crate::io::write_atomic(&ply, |w| {
        write!(
            w,
            "ply\nformat binary_little_endian 1.0\ncomment meshslim tile {i} of {}\n\
             element vertex {}\nproperty float x\nproperty float y\nproperty float z\n{}\
             element face {}\nproperty list uchar int vertex_indices\nend_header\n",
            tiles,
            ids.len(),
            if colors.is_some() {
                "property float red\nproperty float green\nproperty float blue\n\
                 property float alpha\n"
            } else {
                ""
            },
            faces
        )?;
        for &g in &ids {
            for x in positions[g as usize] {
                w.write_all(&x.to_le_bytes())?;
            }
            if let Some(c) = colors {
                for x in c[g as usize] {
                    w.write_all(&x.to_le_bytes())?;
                }
            }
        }
        let mut body = File::open(part(".faces.part"))?;
        let mut buf = vec![0u8; 1 << 16];
        loop {
            let n = body.read(&mut buf)?;
            if n == 0 {
                break Ok(());
            }
            w.write_all(&buf[..n])?;
        }
    })?;
    std::fs::remove_file(part(".faces.part")).map_err(|e| Error::io(&part(".faces.part"), e))?;
    std::fs::rename(part(".ids.part"), part(".ids")).map_err(|e| Error::io(&part(".ids"), e))?;
    Ok(ids.len() as u64)
}

/// Removes the part files a split left when it fails (on success they are gone already).
struct Parts<'d> {
    dir: &'d Path,
    tiles: usize,
}

impl Drop for Parts<'_> {
    fn drop(&mut self) {
        for i in 0..self.tiles {
            for ext in [".faces.part", ".ids.part"] {
                let _ = std::fs::remove_file(self.dir.join(part_name(i, ext)));
            }
        }
    }
}

/// The grid of tiles over the box of the positions.
struct Cells {
    min: [f64; 3],
    /// Cells per unit length, per axis.
    inv: [f64; 3],
    grid: [u32; 3],
    shift: [f64; 3],
}

impl Cells {
    fn new(positions: &[[f32; 3]], tiles: usize, after: Option<[u32; 3]>) -> Cells {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in positions {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k] as f64);
                hi[k] = hi[k].max(p[k] as f64);
            }
        }
        let ext = [0, 1, 2].map(|k| (hi[k] - lo[k]).max(0.0));
        let grid = grid_for(tiles, ext);
        Cells {
            min: lo,
            inv: [0, 1, 2].map(|k| {
                if ext[k] > 0.0 {
                    grid[k] as f64 / ext[k]
                } else {
                    0.0
                }
            }),
            grid,
            shift: after.map_or([0.0; 3], |a| [0, 1, 2].map(|k| Cells::moved(grid[k], a[k]))),
        }
    }

    /// The shift, in cells, that puts the boundaries of `g` cells (at `(j - s) / g` of the box)
    /// farthest from those of the `before` cells of the level before (at `i / before`), so that
    /// level's seams lie inside this level's tiles; the candidates are eighths of a cell.
    fn moved(g: u32, before: u32) -> f64 {
        let gap = |s: f64| {
            (1..g)
                .flat_map(|j| (1..before).map(move |i| (j, i)))
                .map(|(j, i)| ((j as f64 - s) / g as f64 - i as f64 / before as f64).abs())
                .fold(f64::INFINITY, f64::min)
        };
        (1..8)
            .map(|e| e as f64 / 8.0)
            .fold((0.0, f64::NEG_INFINITY), |best, s| {
                let d = gap(s);
                if d > best.1 { (s, d) } else { best }
            })
            .0
    }

    /// The tile of a face: the cell its centroid falls in, clamped to the grid (with a shift
    /// `s`, the first cell is `1 - s` cells wide and the last `1 + s`).
    fn tile(&self, t: [[f32; 3]; 3]) -> u32 {
        let c = [0, 1, 2].map(|k| {
            let centroid = (t[0][k] as f64 + t[1][k] as f64 + t[2][k] as f64) / 3.0;
            let x = ((centroid - self.min[k]) * self.inv[k] + self.shift[k]).floor();
            (x.max(0.0) as u32).min(self.grid[k] - 1)
        });
        c[0] + self.grid[0] * (c[1] + self.grid[1] * c[2])
    }
}
