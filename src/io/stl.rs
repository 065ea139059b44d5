//! STL, ascii and binary.
//!
//! Read with a parser of its own rather than `stl_io`, whose errors carry no position (binary
//! errors are a bare "failed to fill whole buffer") and whose ascii/binary probe misreads binary
//! files whose 80-byte header starts with `solid`, as many exporters write.
//!
//! Detection: a file whose size is exactly `84 + 50 * count` (count from bytes 80..84) is
//! binary; otherwise a file starting with `solid` is ascii; otherwise binary. A binary file whose
//! count needs more bytes than it has fails at once, before any allocation; bytes after the last
//! declared triangle are ignored. Ascii facets with more than three vertices are fan-triangulated;
//! several `solid`s in one file are concatenated. Facet normals are ignored.
//!
//! STL stores each triangle's three corners separately; the reader welds corners with
//! bitwise-identical positions ([`crate::mesh::weld`]). Zero-area triangles are kept.
//!
//! Writer: binary by default (facet normals computed from the geometry, zero for degenerate
//! faces; attribute bytes zero), ascii on request, numbers written with `{}` so they read back
//! bit-exact. Attributes, materials and groups have no place in STL and are not written.

use std::fs::File;
use std::io::{self, BufRead, BufReader, Read, Write};
use std::path::Path;

use super::lines::Lines;
use crate::error::{Error, Location, Result};
use crate::mesh::Mesh;

/// Reads an STL file, ascii or binary, and welds its corners.
pub fn read(path: &Path) -> Result<Mesh> {
    let file = File::open(path).map_err(|e| Error::io(path, e))?;
    let len = file.metadata().map_err(|e| Error::io(path, e))?.len();
    let mut r = BufReader::with_capacity(1 << 16, file);
    if len == 0 {
        return Err(Error::parse(path, Location::Byte(0), "empty file"));
    }
    let head = r.fill_buf().map_err(|e| Error::io(path, e))?;
    let mut count_bytes = [0u8; 4];
    let sized_binary = if head.len() >= 84 {
        count_bytes.copy_from_slice(&head[80..84]);
        84 + 50 * u32::from_le_bytes(count_bytes) as u64 == len
    } else {
        false
    };
    let starts_solid = {
        let t = head
            .iter()
            .position(|b| !b.is_ascii_whitespace())
            .unwrap_or(head.len());
        head[t..].starts_with(b"solid")
    };
    let soup = if !sized_binary && starts_solid {
        read_ascii(r, path)?
    } else {
        read_binary(r, len, path)?
    };
    Ok(crate::mesh::weld(&soup).mesh)
}

fn read_binary(mut r: impl Read, len: u64, path: &Path) -> Result<Mesh> {
    if len < 84 {
        return Err(Error::parse(
            path,
            Location::Byte(len),
            format!(
                "{len} bytes is too short for a binary STL (84-byte header) and it does not start with \"solid\""
            ),
        ));
    }
    let mut head = [0u8; 84];
    r.read_exact(&mut head).map_err(|e| Error::io(path, e))?;
    let count = u32::from_le_bytes([head[80], head[81], head[82], head[83]]) as u64;
    let need = 84 + 50 * count;
    if need > len {
        return Err(Error::parse(
            path,
            Location::Byte(80),
            format!(
                "the header declares {count} triangles, which need {need} bytes, but the file has only {len} bytes"
            ),
        ));
    }
    let mut mesh = Mesh::default();
    mesh.positions.reserve(3 * count as usize);
    mesh.triangles.reserve(count as usize);
    let mut rec = [0u8; 50];
    for i in 0..count {
        let off = 84 + 50 * i;
        r.read_exact(&mut rec).map_err(|e| match e.kind() {
            io::ErrorKind::UnexpectedEof => Error::parse(
                path,
                Location::Byte(off),
                format!("unexpected end of file in triangle {i}"),
            ),
            _ => Error::io(path, e),
        })?;
        let f = |k: usize| f32::from_le_bytes([rec[k], rec[k + 1], rec[k + 2], rec[k + 3]]);
        let base = mesh.positions.len() as u32;
        for c in 0..3 {
            let o = 12 + 12 * c;
            let p = [f(o), f(o + 4), f(o + 8)];
            if !p.iter().all(|x| x.is_finite()) {
                return Err(Error::parse(
                    path,
                    Location::Byte(off + o as u64),
                    format!("vertex {c} of triangle {i} has a non-finite coordinate {p:?}"),
                ));
            }
            mesh.positions.push(p);
        }
        mesh.triangles.push([base, base + 1, base + 2]);
    }
    Ok(mesh)
}

fn read_ascii(r: impl BufRead, path: &Path) -> Result<Mesh> {
    let mut mesh = Mesh::default();
    let mut lines = Lines::new(r, path);
    let mut in_loop = false;
    let mut facet = 0u64;
    let mut poly: Vec<u32> = Vec::new();
    while let Some((at, text)) = lines.next_line()? {
        let mut words = text.split_ascii_whitespace();
        match words.next() {
            Some("vertex") => {
                if !in_loop {
                    return Err(Error::parse(path, at, "\"vertex\" outside \"outer loop\""));
                }
                let mut p = [0f32; 3];
                for c in &mut p {
                    let t = words.next().unwrap_or("");
                    *c = t.parse().map_err(|_| {
                        Error::parse(path, at, format!("facet {facet}: {t:?} is not a number"))
                    })?;
                }
                if words.next().is_some() {
                    return Err(Error::parse(
                        path,
                        at,
                        "a vertex line has more than three numbers",
                    ));
                }
                if !p.iter().all(|x| x.is_finite()) {
                    return Err(Error::parse(
                        path,
                        at,
                        format!("a vertex of facet {facet} has a non-finite coordinate {p:?}"),
                    ));
                }
                if mesh.positions.len() >= u32::MAX as usize - 1 {
                    return Err(Error::parse(
                        path,
                        at,
                        "too many vertices for 32-bit indices",
                    ));
                }
                poly.push(mesh.positions.len() as u32);
                mesh.positions.push(p);
            }
            Some("outer") => {
                in_loop = true;
                poly.clear();
            }
            Some("endloop") => {
                if !in_loop {
                    return Err(Error::parse(path, at, "\"endloop\" without \"outer loop\""));
                }
                in_loop = false;
                if poly.len() < 3 {
                    return Err(Error::parse(
                        path,
                        at,
                        format!("facet {facet} has {} vertices; it needs 3", poly.len()),
                    ));
                }
                for j in 1..poly.len() - 1 {
                    mesh.triangles.push([poly[0], poly[j], poly[j + 1]]);
                }
                facet += 1;
            }
            Some("solid") | Some("facet") | Some("endfacet") | Some("endsolid") | None => {}
            Some(other) => {
                return Err(Error::parse(
                    path,
                    at,
                    format!("unexpected keyword {other:?} in an ascii STL"),
                ));
            }
        }
    }
    if in_loop {
        return Err(Error::parse(
            path,
            Location::Line(lines.line_no),
            "end of file inside a facet",
        ));
    }
    Ok(mesh)
}

fn facet_normal(mesh: &Mesh, f: usize) -> [f32; 3] {
    mesh.face_normal(f)
        .map_or([0.0; 3], |n| n.map(|x| x as f32))
}

/// Writes `mesh` as binary STL.
pub fn write_binary<W: Write>(w: &mut W, mesh: &Mesh) -> io::Result<()> {
    let count = u32::try_from(mesh.triangles.len()).map_err(|_| {
        io::Error::new(
            io::ErrorKind::InvalidInput,
            "more than 2^32 triangles do not fit in binary STL",
        )
    })?;
    let mut head = [b' '; 80];
    let tag = b"binary STL written by meshslim";
    head[..tag.len()].copy_from_slice(tag);
    w.write_all(&head)?;
    w.write_all(&count.to_le_bytes())?;
    let mut buf = Vec::with_capacity(50 * 1024);
    for (f, t) in mesh.triangles.iter().enumerate() {
        for c in facet_normal(mesh, f) {
            buf.extend_from_slice(&c.to_le_bytes());
        }
        for &v in t {
            for c in mesh.positions[v as usize] {
                buf.extend_from_slice(&c.to_le_bytes());
            }
        }
        buf.extend_from_slice(&[0, 0]);
        if buf.len() >= 50 * 1000 {
            w.write_all(&buf)?;
            buf.clear();
        }
    }
    w.write_all(&buf)
}

/// Writes `mesh` as ascii STL.
pub fn write_ascii<W: Write>(w: &mut W, mesh: &Mesh) -> io::Result<()> {
    use std::fmt::Write as _;
    let mut out = String::from("solid meshslim\n");
    for (f, t) in mesh.triangles.iter().enumerate() {
        let n = facet_normal(mesh, f);
        let _ = writeln!(out, "facet normal {} {} {}\n  outer loop", n[0], n[1], n[2]);
        for &v in t {
            let p = mesh.positions[v as usize];
            let _ = writeln!(out, "    vertex {} {} {}", p[0], p[1], p[2]);
        }
        out.push_str("  endloop\nendfacet\n");
        if out.len() > 60_000 {
            w.write_all(out.as_bytes())?;
            out.clear();
        }
    }
    out.push_str("endsolid meshslim\n");
    w.write_all(out.as_bytes())
}
