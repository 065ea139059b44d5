//! The PLY reader: the body after the header as a stream of values in any of the three
//! encodings, checked against the file's size before anything is allocated; vertices, faces,
//! triangle strips, and every other element skipped.

use std::fs::File;
use std::io::{self, BufRead, BufReader};
use std::path::Path;

use super::header::{Element, Header, Kind, PlyEncoding, Scalar, read_header};
use crate::error::{Error, Location, Result};
use crate::io::sink::{MeshSink, Sink, Vertex, VertexAttributes};
use crate::mesh::Mesh;

/// Why reading a value failed; turned into an [`Error`] with the element context by the caller.
enum Fail {
    Eof,
    Bad(String),
    Io(io::Error),
}

/// The body of a PLY file as a stream of scalar values, in one of the three encodings.
struct Body<R> {
    r: R,
    binary: bool,
    big: bool,
    /// Byte offset of the next unread byte (binary).
    pos: u64,
    /// Ascii: current line, its number and the cursor in it.
    line: Vec<u8>,
    line_no: u64,
    cursor: usize,
}

impl<R: BufRead> Body<R> {
    fn location(&self) -> Location {
        if self.binary {
            Location::Byte(self.pos)
        } else {
            Location::Line(self.line_no.max(1))
        }
    }

    /// Calls `f` with the next `n` bytes (binary only).
    #[inline]
    fn bytes<T>(
        &mut self,
        n: usize,
        scratch: &mut Vec<u8>,
        f: impl FnOnce(&[u8]) -> T,
    ) -> Result<T, Fail> {
        let buf = self.r.fill_buf().map_err(Fail::Io)?;
        if buf.len() >= n {
            let v = f(&buf[..n]);
            self.r.consume(n);
            self.pos += n as u64;
            return Ok(v);
        }
        scratch.resize(n, 0);
        match self.r.read_exact(scratch) {
            Ok(()) => {}
            Err(e) if e.kind() == io::ErrorKind::UnexpectedEof => return Err(Fail::Eof),
            Err(e) => return Err(Fail::Io(e)),
        }
        self.pos += n as u64;
        Ok(f(scratch))
    }

    /// Skips up to `n` bytes (binary only) a buffer at a time, not a value at a time (a
    /// streaming pass skips the vertices this way); returns how many there were.
    fn skip(&mut self, n: u64) -> io::Result<u64> {
        let mut left = n;
        while left > 0 {
            let buf = self.r.fill_buf()?;
            if buf.is_empty() {
                break;
            }
            let k = (buf.len() as u64).min(left) as usize;
            self.r.consume(k);
            self.pos += k as u64;
            left -= k as u64;
        }
        Ok(n - left)
    }

    /// Next whitespace-separated token (ascii only), reading further lines as needed.
    fn token(&mut self) -> Result<&str, Fail> {
        loop {
            while self.cursor < self.line.len() && self.line[self.cursor].is_ascii_whitespace() {
                self.cursor += 1;
            }
            if self.cursor < self.line.len() {
                break;
            }
            self.line.clear();
            self.cursor = 0;
            let n = self.r.read_until(b'\n', &mut self.line).map_err(Fail::Io)?;
            if n == 0 {
                return Err(Fail::Eof);
            }
            self.line_no += 1;
        }
        let start = self.cursor;
        while self.cursor < self.line.len() && !self.line[self.cursor].is_ascii_whitespace() {
            self.cursor += 1;
        }
        std::str::from_utf8(&self.line[start..self.cursor])
            .map_err(|_| Fail::Bad("a value is not valid text".into()))
    }

    /// One scalar of type `ty`, widened to f64 without loss.
    #[inline]
    fn scalar(&mut self, ty: Scalar, scratch: &mut Vec<u8>) -> Result<f64, Fail> {
        if self.binary {
            let big = self.big;
            self.bytes(ty.size(), scratch, |b| ty.decode(b, big))
        } else {
            let t = self.token()?;
            ty.parse_token(t)
                .ok_or_else(|| Fail::Bad(format!("{t:?} is not a valid {ty:?} value")))
        }
    }

    /// Calls `f` for each item of a list of `n` items of type `ty`, reading the data in chunks so
    /// that a huge declared count allocates nothing before the data is there.
    fn list(
        &mut self,
        n: usize,
        ty: Scalar,
        scratch: &mut Vec<u8>,
        mut f: impl FnMut(f64) -> Result<(), Fail>,
    ) -> Result<(), Fail> {
        if self.binary {
            let size = ty.size();
            let big = self.big;
            let mut left = n;
            while left > 0 {
                let k = left.min(4096);
                let mut res = Ok(());
                self.bytes(k * size, scratch, |b| {
                    for c in b.chunks_exact(size) {
                        if let Err(e) = f(ty.decode(c, big)) {
                            res = Err(e);
                            return;
                        }
                    }
                })?;
                res?;
                left -= k;
            }
            Ok(())
        } else {
            for _ in 0..n {
                let v = self.scalar(ty, scratch)?;
                f(v)?;
            }
            Ok(())
        }
    }
}

/// How a vertex property is used.
#[derive(Clone, Copy)]
enum Role {
    Skip,
    Slot(usize, f64),
}

const X: usize = 0;
const NX: usize = 3;
const R: usize = 6;
const U: usize = 10;

fn vertex_slot(name: &str) -> Option<usize> {
    Some(match name {
        "x" => X,
        "y" => X + 1,
        "z" => X + 2,
        "nx" => NX,
        "ny" => NX + 1,
        "nz" => NX + 2,
        "red" | "r" | "diffuse_red" => R,
        "green" | "g" | "diffuse_green" => R + 1,
        "blue" | "b" | "diffuse_blue" => R + 2,
        "alpha" | "a" | "diffuse_alpha" => R + 3,
        "s" | "u" | "texture_u" | "texture_s" => U,
        "t" | "v" | "texture_v" | "texture_t" => U + 1,
        _ => return None,
    })
}

fn to_index(v: f64) -> Option<i64> {
    (v.fract() == 0.0 && v >= i64::MIN as f64 && v <= i64::MAX as f64).then_some(v as i64)
}

/// Reads a PLY file.
pub fn read(path: &Path) -> Result<Mesh> {
    let mut sink = MeshSink::default();
    read_into(path, &mut sink)?;
    Ok(sink.into_mesh())
}

/// The counts the header declares: vertices and faces (polygons and strips before
/// triangulation), without reading the body: what a memory estimate can go on.
pub fn header_counts(path: &Path) -> Result<(u64, u64)> {
    let file = File::open(path).map_err(|e| Error::io(path, e))?;
    let mut r = BufReader::with_capacity(1 << 12, file);
    let header = read_header(&mut r, path)?;
    let count = |names: &[&str]| -> u64 {
        header
            .elements
            .iter()
            .filter(|e| names.contains(&e.name.as_str()))
            .map(|e| e.count)
            .sum()
    };
    Ok((count(&["vertex"]), count(&["face", "tristrips"])))
}

/// Reads `path` into `sink`, element by element: what [`read`] collects into a mesh, and what
/// the out-of-core clustering streams (its passes skip the vertices or stop after them).
pub fn read_into(path: &Path, sink: &mut dyn Sink) -> Result<()> {
    let file = File::open(path).map_err(|e| Error::io(path, e))?;
    let file_len = file.metadata().map_err(|e| Error::io(path, e))?.len();
    let mut r = BufReader::with_capacity(1 << 16, file);
    let header = read_header(&mut r, path)?;
    let remaining = file_len.saturating_sub(header.len);
    let binary = header.encoding != PlyEncoding::Ascii;
    check_declared_counts(&header, remaining, path)?;
    let (vi, nverts) = vertex_element(&header, path)?;

    let mut body = Body {
        r,
        binary,
        big: header.encoding == PlyEncoding::BinaryBigEndian,
        pos: header.len,
        line: Vec::new(),
        line_no: header.lines,
        cursor: 0,
    };
    let mut scratch = Vec::new();
    let mut seen_vertex = false;

    for (ei, el) in header.elements.iter().enumerate() {
        let fail = |body: &Body<_>, f: Fail, what: &str, i: u64| -> Error {
            match f {
                Fail::Io(e) => Error::io(path, e),
                Fail::Eof => Error::parse(
                    path,
                    body.location(),
                    format!(
                        "unexpected end of file in {what} {i} of {} (the header declares more than the file holds)",
                        el.count
                    ),
                ),
                Fail::Bad(m) => Error::parse(path, body.location(), format!("{what} {i}: {m}")),
            }
        };
        if el.props.is_empty() && ei != vi {
            // Nothing to read, however many elements are declared.
            continue;
        }
        if seen_vertex && !sink.wants_faces() {
            // A vertex pass: nothing after the vertices is wanted.
            return Ok(());
        }
        if ei == vi && !seen_vertex && sink.wants_vertices() {
            seen_vertex = true;
            read_vertices(&mut body, el, sink, remaining, &mut scratch, path, &fail)?;
        } else if (el.name == "face" || el.name == "tristrips") && sink.wants_faces() {
            read_faces(
                &mut body,
                el,
                sink,
                remaining,
                nverts,
                &mut scratch,
                path,
                &fail,
            )?;
        } else {
            if ei == vi {
                seen_vertex = true;
            }
            // Unknown element (or a second vertex element, or one this pass skips).
            skip_element(&mut body, el, &mut scratch, path, &fail)?;
        }
    }
    Ok(())
}

/// Fails fast when the declared counts cannot fit in the `remaining` bytes that follow the
/// header.
fn check_declared_counts(header: &Header, remaining: u64, path: &Path) -> Result<()> {
    let binary = header.encoding != PlyEncoding::Ascii;
    let mut need: u128 = 0;
    for el in &header.elements {
        let per = if binary {
            el.min_binary_bytes() as u128
        } else {
            // Every value is at least one character plus a separator.
            2 * el.props.len() as u128
        };
        need += per * el.count as u128;
        let need_here = if binary { need } else { need.saturating_sub(1) };
        if need_here > remaining as u128 {
            let at = if binary {
                Location::Byte(header.len)
            } else {
                Location::Line(header.lines + 1)
            };
            return Err(Error::parse(
                path,
                at,
                format!(
                    "the header declares {} {} elements (line {}), which need at least {} bytes, \
                     but the file has only {} bytes after the header",
                    el.count, el.name, el.line, need_here, remaining
                ),
            ));
        }
    }
    Ok(())
}

/// Finds the vertex element: its position among the elements and its count, which must fit
/// 32-bit indices.
fn vertex_element(header: &Header, path: &Path) -> Result<(usize, u64)> {
    let Some(vi) = header.elements.iter().position(|e| e.name == "vertex") else {
        return Err(Error::parse(
            path,
            Location::Line(header.lines),
            "the PLY header declares no vertex element",
        ));
    };
    let nverts = header.elements[vi].count;
    if nverts > u32::MAX as u64 {
        return Err(Error::parse(
            path,
            Location::Line(header.elements[vi].line),
            format!("{nverts} vertices exceed the 32-bit index range"),
        ));
    }
    Ok((vi, nverts))
}

/// Turns a read failure into an error naming the element and its number.
type FailFn<'a, R> = dyn Fn(&Body<R>, Fail, &str, u64) -> Error + 'a;

/// Reads a `face` or `tristrips` element into `sink`: polygons fan-triangulated, strips cut
/// into their triangles, every other property skipped.
#[allow(clippy::too_many_arguments)]
fn read_faces<R: BufRead>(
    body: &mut Body<R>,
    el: &Element,
    sink: &mut dyn Sink,
    remaining: u64,
    nverts: u64,
    scratch: &mut Vec<u8>,
    path: &Path,
    fail: &FailFn<'_, R>,
) -> Result<()> {
    let strips = el.name == "tristrips";
    let li = index_list_property(el);
    let what = if strips { "triangle strip" } else { "face" };
    sink.begin_faces(face_reservation(el, li, body.binary, remaining));
    let mut out = Triangles {
        sink,
        strips,
        nverts,
        poly: Vec::new(),
    };
    for i in 0..el.count {
        for (pi, p) in el.props.iter().enumerate() {
            match p.kind {
                Kind::Scalar(s) => {
                    body.scalar(s, scratch)
                        .map_err(|f| fail(body, f, what, i))?;
                }
                Kind::List { count, item } => {
                    let start = body.location();
                    let n = body
                        .scalar(count, scratch)
                        .map_err(|f| fail(body, f, what, i))?;
                    let at = if body.binary { start } else { body.location() };
                    let n = to_index(n).filter(|&n| n >= 0).ok_or_else(|| {
                        Error::parse(path, at, format!("{what} {i}: bad list length {n}"))
                    })? as usize;
                    if Some(pi) != li {
                        body.list(n, item, scratch, |_| Ok(()))
                            .map_err(|f| fail(body, f, what, i))?;
                        continue;
                    }
                    out.read_list(body, n, item, scratch)
                        .map_err(|f| fail(body, f, what, i))?;
                }
            }
        }
    }
    Ok(())
}

/// Which property of a face element holds the vertex indices: `vertex_indices` (or
/// `vertex_index`), else the first list.
fn index_list_property(el: &Element) -> Option<usize> {
    el.props
        .iter()
        .position(|p| p.name == "vertex_indices" || p.name == "vertex_index")
        .or_else(|| {
            el.props
                .iter()
                .position(|p| matches!(p.kind, Kind::List { .. }))
        })
}

/// How many faces to reserve for: the declared count, capped by what the `remaining` bytes can
/// hold (a triangle's list in binary, eight characters in ascii) and by 2^28.
fn face_reservation(el: &Element, li: Option<usize>, binary: bool, remaining: u64) -> usize {
    let est = if binary {
        let item = match li.map(|i| el.props[i].kind) {
            Some(Kind::List { count, item }) => count.size() + 3 * item.size(),
            _ => 4,
        };
        remaining / item as u64
    } else {
        remaining / 8
    };
    el.count.min(est).min(1 << 28) as usize
}

/// Where a face element's triangles go, with what checking and cutting its index lists needs.
struct Triangles<'s> {
    sink: &'s mut dyn Sink,
    /// A `tristrips` element: each list is a strip, not a polygon.
    strips: bool,
    nverts: u64,
    /// The current polygon's indices, reused from face to face.
    poly: Vec<u32>,
}

impl Triangles<'_> {
    /// Reads one list of `n` vertex indices and sends its triangles to the sink.
    #[inline]
    fn read_list<R: BufRead>(
        &mut self,
        body: &mut Body<R>,
        n: usize,
        item: Scalar,
        scratch: &mut Vec<u8>,
    ) -> Result<(), Fail> {
        let (strips, nverts) = (self.strips, self.nverts);
        let sink = &mut *self.sink;
        let poly = &mut self.poly;
        poly.clear();
        // Strip state: the previous two indices and the position in the strip.
        let mut k = 0usize;
        let mut prev = [0u32; 2];
        body.list(n, item, scratch, |v| {
            let idx = to_index(v);
            if strips && idx == Some(-1) {
                k = 0;
                return Ok(());
            }
            let idx = match idx {
                Some(x) if x >= 0 && (x as u64) < nverts => x as u32,
                _ => {
                    return Err(Fail::Bad(format!(
                        "vertex index {v} is out of range (the file has {nverts} vertices)"
                    )));
                }
            };
            if strips {
                if k >= 2 {
                    let t = if k.is_multiple_of(2) {
                        [prev[0], prev[1], idx]
                    } else {
                        [prev[1], prev[0], idx]
                    };
                    if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
                        sink.triangle(t);
                    }
                }
                prev = [prev[1], idx];
                k += 1;
            } else {
                poly.push(idx);
            }
            Ok(())
        })?;
        if !strips && poly.len() >= 3 {
            for j in 1..poly.len() - 1 {
                sink.triangle([poly[0], poly[j], poly[j + 1]]);
            }
        }
        Ok(())
    }
}

/// Skips an element this pass does not read: fixed-size binary records a buffer at a time,
/// anything else value by value.
fn skip_element<R: BufRead>(
    body: &mut Body<R>,
    el: &Element,
    scratch: &mut Vec<u8>,
    path: &Path,
    fail: &FailFn<'_, R>,
) -> Result<()> {
    if let (true, Some(size)) = (body.binary, el.fixed_size()) {
        let done = body
            .skip(el.count * size as u64)
            .map_err(|e| Error::io(path, e))?;
        if done < el.count * size as u64 {
            let i = done / size as u64;
            return Err(fail(body, Fail::Eof, &el.name, i));
        }
        return Ok(());
    }
    for i in 0..el.count {
        for p in &el.props {
            match p.kind {
                Kind::Scalar(s) => {
                    body.scalar(s, scratch)
                        .map_err(|f| fail(body, f, &el.name, i))?;
                }
                Kind::List { count, item } => {
                    let n = body
                        .scalar(count, scratch)
                        .map_err(|f| fail(body, f, &el.name, i))?;
                    let n = to_index(n).filter(|&n| n >= 0).ok_or_else(|| {
                        Error::parse(
                            path,
                            body.location(),
                            format!("{} {i}: bad list length {n}", el.name),
                        )
                    })?;
                    body.list(n as usize, item, scratch, |_| Ok(()))
                        .map_err(|f| fail(body, f, &el.name, i))?;
                }
            }
        }
    }
    Ok(())
}

/// Reads the vertex element into `sink`: positions (which must be finite), and normals, colours
/// and texture coordinates when the element has them.
#[allow(clippy::too_many_arguments)]
fn read_vertices<R: BufRead>(
    body: &mut Body<R>,
    el: &Element,
    sink: &mut dyn Sink,
    remaining: u64,
    scratch: &mut Vec<u8>,
    path: &Path,
    fail: &FailFn<'_, R>,
) -> Result<()> {
    let mut roles = Vec::with_capacity(el.props.len());
    let mut have = [false; 12];
    for p in &el.props {
        match (p.kind, vertex_slot(&p.name)) {
            (Kind::Scalar(s), Some(slot)) if !have[slot] => {
                have[slot] = true;
                let scale = if (R..R + 4).contains(&slot) {
                    s.color_scale()
                } else {
                    1.0
                };
                roles.push(Role::Slot(slot, scale));
            }
            _ => roles.push(Role::Skip),
        }
    }
    if !(have[X] && have[X + 1] && have[X + 2]) {
        return Err(Error::parse(
            path,
            Location::Line(el.line),
            "the vertex element lacks one of the properties x, y, z",
        ));
    }
    let has_n = have[NX] && have[NX + 1] && have[NX + 2];
    let has_c = have[R] && have[R + 1] && have[R + 2];
    let has_uv = have[U] && have[U + 1];
    let per = if body.binary {
        el.min_binary_bytes().max(1)
    } else {
        6
    };
    let cap = el.count.min(remaining / per) as usize;
    sink.begin_vertices(
        cap,
        VertexAttributes {
            normals: has_n,
            colors: has_c,
            uvs: has_uv,
        },
    );
    let fixed = el.fixed_size().filter(|_| body.binary);
    let mut v = [0f64; 12];
    v[R + 3] = 1.0;
    for i in 0..el.count {
        let start = body.location();
        if let Some(size) = fixed {
            // Fast path: the whole record at once.
            let big = body.big;
            body.bytes(size, scratch, |b| {
                let mut off = 0;
                for (p, role) in el.props.iter().zip(&roles) {
                    if let Kind::Scalar(s) = p.kind {
                        if let Role::Slot(slot, scale) = *role {
                            let x = s.decode(&b[off..], big);
                            v[slot] = if scale != 1.0 { x / scale } else { x };
                        }
                        off += s.size();
                    }
                }
            })
            .map_err(|f| fail(body, f, "vertex", i))?;
        } else {
            for (p, role) in el.props.iter().zip(&roles) {
                match p.kind {
                    Kind::Scalar(s) => {
                        let x = body
                            .scalar(s, scratch)
                            .map_err(|f| fail(body, f, "vertex", i))?;
                        if let Role::Slot(slot, scale) = *role {
                            v[slot] = if scale != 1.0 { x / scale } else { x };
                        }
                    }
                    Kind::List { count, item } => {
                        let n = body
                            .scalar(count, scratch)
                            .map_err(|f| fail(body, f, "vertex", i))?;
                        let n = to_index(n).filter(|&n| n >= 0).ok_or_else(|| {
                            Error::parse(
                                path,
                                body.location(),
                                format!("vertex {i}: bad list length {n}"),
                            )
                        })?;
                        body.list(n as usize, item, scratch, |_| Ok(()))
                            .map_err(|f| fail(body, f, "vertex", i))?;
                    }
                }
            }
        }
        let p = [v[X] as f32, v[X + 1] as f32, v[X + 2] as f32];
        if !p.iter().all(|c| c.is_finite()) {
            // Binary: where the vertex starts; ascii: the line it ends on.
            let at = if body.binary { start } else { body.location() };
            return Err(Error::parse(
                path,
                at,
                format!("vertex {i} has a non-finite coordinate {p:?}"),
            ));
        }
        sink.vertex(&Vertex {
            position: p,
            normal: [v[NX] as f32, v[NX + 1] as f32, v[NX + 2] as f32],
            color: [
                v[R] as f32,
                v[R + 1] as f32,
                v[R + 2] as f32,
                v[R + 3] as f32,
            ],
            uv: [v[U] as f32, v[U + 1] as f32],
        });
    }
    Ok(())
}
