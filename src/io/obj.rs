//! Wavefront OBJ.
//!
//! The reader is a line parser of its own rather than `tobj`: tobj duplicates every vertex a
//! second object/group/material uses, renumbers vertices in order of first use, misaligns
//! attributes when corners mix forms (`v` and `v/vt`), reports no line numbers and overflows
//! (a panic in debug builds) on an out-of-range relative texture index. Parsing OBJ is simple
//! enough that doing it here gives exact round trips and useful errors. (A test checks that this
//! reader and tobj agree on the triangles of a small file.)
//!
//! Supported: `v x y z [w]` (divided by `w`) and `v x y z r g b` (vertex colours, alpha 1);
//! `vt u [v [w]]`; `vn`; faces `f` with corners `v`, `v/vt`, `v//vn`, `v/vt/vn`, positive or
//! negative (relative) indices, polygons fan-triangulated; `o` and `g` start a group (the whole
//! rest of the line is the name; a name seen again reuses its group); `usemtl` selects a material
//! by name; `mtllib` names are kept verbatim in `material_libs`. The `.mtl` files are never opened,
//! so a missing one is not an error. Lines (`l`), points (`p`), smoothing groups, free-form geometry
//! and unknown statements are ignored.
//!
//! Vertices: mesh vertex `i` is the file's `i`-th `v` line (unused positions included), carrying
//! the attributes of the first corner that uses it. A corner that pairs the same position with a
//! different `vt`/`vn` (an attribute seam) becomes an extra vertex appended after the file's
//! positions. Corners without `vt`/`vn` in a file that has them get a zero UV / zero normal;
//! positions without a colour in a file that has some get white. A position no face uses takes the
//! `vt`/`vn` of the same number when the file has exactly one per position (as `write_obj`
//! writes), else none.
//!
//! Groups and materials: `face_groups`/`face_materials` are `None` when the file has no `o`/`g`
//! (resp. `usemtl`) statement. Names are numbered in order of their first statement; faces before
//! the first statement go to a group/material named `default`.
//!
//! Errors (all with the line): malformed numbers, non-finite values, index 0, indices out of range
//! (indices must refer to elements defined before the face, as the format specifies), faces with
//! fewer than three corners. Zero-area faces are kept.

use std::collections::HashMap;
use std::fs::File;
use std::io::{self, BufRead, BufReader, Write};
use std::path::Path;

use super::lines::Lines;
use crate::error::{Error, Location, Result};
use crate::mesh::{Material, Mesh, UvOrigin};

const NONE: u32 = u32::MAX;
/// Tags a seam vertex number in `triangles` while parsing.
const SEAM: u32 = 1 << 31;

/// Names numbered in order of first appearance.
#[derive(Default)]
struct Names {
    list: Vec<String>,
    map: HashMap<String, u32>,
    used: bool,
}

impl Names {
    fn id(&mut self, name: &str) -> u32 {
        if let Some(&i) = self.map.get(name) {
            return i;
        }
        let i = self.list.len() as u32;
        self.list.push(name.to_string());
        self.map.insert(name.to_string(), i);
        i
    }

    /// Each face's id (those before the first statement get "default", numbered after every
    /// name the file gave) and the names; `None` when the file never named one.
    fn per_face(mut self, ids: Vec<u32>) -> Option<(Vec<u32>, Vec<String>)> {
        if !self.used {
            return None;
        }
        let d = if ids.contains(&NONE) {
            self.id("default")
        } else {
            0
        };
        let ids = ids
            .into_iter()
            .map(|i| if i == NONE { d } else { i })
            .collect();
        Some((ids, self.list))
    }
}

/// Per mesh vertex, the value its corner's index `k` (1: `vt`, 2: `vn`) names in `values`; zero
/// where that index is absent.
fn per_vertex<T: Copy + Default>(corners_of: &[[u32; 3]], k: usize, values: &[T]) -> Vec<T> {
    corners_of
        .iter()
        .map(|c| values.get(c[k] as usize).copied().unwrap_or_default())
        .collect()
}

/// Reads an OBJ file.
pub fn read(path: &Path) -> Result<Mesh> {
    let file = File::open(path).map_err(|e| Error::io(path, e))?;
    read_from(BufReader::with_capacity(1 << 16, file), path)
}

/// A line's keyword and the rest of it, without the whitespace around either.
fn keyword(line: &str) -> (&str, &str) {
    let line = line.trim();
    match line.find(|c: char| c.is_ascii_whitespace()) {
        Some(i) => (&line[..i], line[i..].trim()),
        None => (line, ""),
    }
}

/// The numbers after a keyword, each finite.
fn floats(rest: &str, what: &str, err: &dyn Fn(String) -> Error) -> Result<Vec<f32>> {
    rest.split_ascii_whitespace()
        .map(|t| {
            let x: f32 = t
                .parse()
                .map_err(|_| err(format!("{what}: {t:?} is not a number")))?;
            if x.is_finite() {
                Ok(x)
            } else {
                Err(err(format!("{what} has a non-finite value {t}")))
            }
        })
        .collect()
}

/// A `v` line's position (divided by `w`) and its numbers; `before` positions came earlier.
fn vertex(
    rest: &str,
    before: usize,
    err: &dyn Fn(String) -> Error,
) -> Result<([f32; 3], Vec<f32>)> {
    let what = format!("vertex {}", before + 1);
    let f = floats(rest, &what, err)?;
    let p = match f.len() {
        3 | 6 => [f[0], f[1], f[2]],
        4 if f[3] != 0.0 => [f[0] / f[3], f[1] / f[3], f[2] / f[3]],
        4 => return Err(err(format!("{what} has w = 0"))),
        n => {
            return Err(err(format!(
                "{what}: expected 3, 4 or 6 numbers, found {n}"
            )));
        }
    };
    if !p.iter().all(|c| c.is_finite()) {
        return Err(err(format!("{what} has a non-finite coordinate {p:?}")));
    }
    Ok((p, f))
}

/// A face corner `v`, `v/vt`, `v//vn` or `v/vt/vn` as zero-based (position, texture, normal)
/// indices ([`NONE`] where absent), checked against the `counts` defined so far.
fn corner(c: &str, counts: [usize; 3], err: &dyn Fn(String) -> Error) -> Result<[u32; 3]> {
    let mut parts = c.split('/');
    let mut idx = [NONE; 3];
    let names = ["vertex", "texture coordinate", "normal"];
    for k in 0..3 {
        let Some(s) = parts.next() else { break };
        if s.is_empty() {
            if k == 0 {
                return Err(err(format!("face corner {c:?} has no vertex index")));
            }
            continue;
        }
        let i: i64 = s
            .parse()
            .map_err(|_| err(format!("face corner {c:?}: {s:?} is not an index")))?;
        let n = counts[k] as i64;
        let abs = if i > 0 {
            i - 1
        } else if i < 0 {
            n + i
        } else {
            return Err(err(format!(
                "face corner {c:?}: OBJ indices start at 1, not 0"
            )));
        };
        if abs < 0 || abs >= n {
            return Err(err(format!(
                "face corner {c:?}: {} index {i} is out of range (only {n} defined before this line)",
                names[k]
            )));
        }
        idx[k] = abs as u32;
    }
    if parts.next().is_some() {
        return Err(err(format!(
            "face corner {c:?} has more than three indices"
        )));
    }
    Ok(idx)
}

/// A polygon's fan of triangles, each handed to `push`; fewer than three corners is an error.
fn fan(poly: &[u32], err: &dyn Fn(String) -> Error, mut push: impl FnMut([u32; 3])) -> Result<()> {
    if poly.len() < 3 {
        return Err(err(format!(
            "face with {} corners; a face needs at least 3",
            poly.len()
        )));
    }
    for j in 1..poly.len() - 1 {
        push([poly[0], poly[j], poly[j + 1]]);
    }
    Ok(())
}

/// Reads `path` into `sink` by positions alone, as the out-of-core clustering streams it: vertex
/// `i` is the `i`-th `v` line, faces refer to positions (the `vt`/`vn` of a corner are checked,
/// not kept, so there are no seam vertices), polygons fan-triangulated. Groups, materials and
/// every other statement are skipped. Errors as [`read`]'s, with the line.
pub fn read_into(path: &Path, sink: &mut dyn crate::io::sink::Sink) -> Result<()> {
    let file = File::open(path).map_err(|e| Error::io(path, e))?;
    let r = BufReader::with_capacity(1 << 16, file);
    let (wants_v, wants_f) = (sink.wants_vertices(), sink.wants_faces());
    if wants_v {
        sink.begin_vertices(0, Default::default());
    }
    let mut counts = [0usize; 3];
    let mut poly: Vec<u32> = Vec::new();
    let mut lines = Lines::new(r, path);
    while let Some((at, text)) = lines.next_line()? {
        let err = |m: String| Error::parse(path, at, m);
        let (kw, rest) = keyword(&text);
        match kw {
            "v" => {
                if wants_v {
                    let (p, _) = vertex(rest, counts[0], &err)?;
                    sink.vertex(&crate::io::sink::Vertex {
                        position: p,
                        ..Default::default()
                    });
                }
                if counts[0] >= SEAM as usize - 1 {
                    return Err(err("too many vertices for 32-bit indices".into()));
                }
                counts[0] += 1;
            }
            "vt" => counts[1] += 1,
            "vn" => counts[2] += 1,
            "f" | "fo" if wants_f => {
                poly.clear();
                for c in rest.split_ascii_whitespace() {
                    poly.push(corner(c, counts, &err)?[0]);
                }
                fan(&poly, &err, |t| sink.triangle(t))?;
            }
            _ => {}
        }
    }
    Ok(())
}

fn read_from(r: impl BufRead, path: &Path) -> Result<Mesh> {
    // No group or material until a line names one.
    let mut obj = ObjReader {
        cur_group: NONE,
        cur_mat: NONE,
        ..Default::default()
    };
    let mut lines = Lines::new(r, path);
    while let Some((at, text)) = lines.next_line()? {
        let err = |m: String| Error::parse(path, at, m);
        let (kw, rest) = keyword(&text);
        match kw {
            "v" => obj.vertex_line(rest, &err)?,
            "vt" => obj.texcoord_line(rest, &err)?,
            "vn" => obj.normal_line(rest, &err)?,
            "f" | "fo" => obj.face_line(rest, &err)?,
            "o" | "g" => {
                obj.groups.used = true;
                obj.cur_group = obj
                    .groups
                    .id(if rest.is_empty() { "default" } else { rest });
            }
            "usemtl" => {
                obj.materials.used = true;
                obj.cur_mat = obj
                    .materials
                    .id(if rest.is_empty() { "default" } else { rest });
            }
            "mtllib" if !rest.is_empty() => obj.libs.push(rest.to_string()),
            _ => {}
        }
    }
    if lines.line_no == 0 {
        return Err(Error::parse(path, Location::Byte(0), "empty file"));
    }
    if obj.positions.is_empty() {
        return Err(Error::parse(
            path,
            Location::Line(lines.line_no),
            "no vertices (`v` lines) found",
        ));
    }
    obj.finish(path, lines.line_no)
}

/// What an OBJ file has said so far, line by line.
#[derive(Default)]
struct ObjReader {
    positions: Vec<[f32; 3]>,
    colors: Vec<[f32; 4]>,
    any_color: bool,
    texcoords: Vec<[f32; 2]>,
    normals: Vec<[f32; 3]>,
    /// For each position: the (vt, vn) of the vertex that bears the position's index.
    pos_key: Vec<[u32; 2]>,
    pos_used: Vec<bool>,
    /// Attribute seams: extra vertices appended after the file's positions, tagged with SEAM
    /// in `triangles` until the number of positions is known.
    seams: HashMap<[u32; 3], u32>,
    seam_keys: Vec<[u32; 3]>,
    triangles: Vec<[u32; 3]>,
    face_groups: Vec<u32>,
    face_materials: Vec<u32>,
    groups: Names,
    materials: Names,
    cur_group: u32,
    cur_mat: u32,
    libs: Vec<String>,
    any_vt_corner: bool,
    any_vn_corner: bool,
    /// The face being read, reused from line to line.
    poly: Vec<u32>,
}

impl ObjReader {
    /// A `v` line: a position, and its colour when the line has one.
    fn vertex_line(&mut self, rest: &str, err: &dyn Fn(String) -> Error) -> Result<()> {
        let (p, f) = vertex(rest, self.positions.len(), err)?;
        if f.len() == 6 {
            if !self.any_color {
                self.any_color = true;
                self.colors.resize(self.positions.len(), [1.0; 4]);
            }
            self.colors.push([f[3], f[4], f[5], 1.0]);
        } else if self.any_color {
            self.colors.push([1.0; 4]);
        }
        if self.positions.len() >= SEAM as usize - 1 {
            return Err(err("too many vertices for 32-bit indices".into()));
        }
        self.positions.push(p);
        self.pos_key.push([NONE; 2]);
        self.pos_used.push(false);
        Ok(())
    }

    /// A `vt` line: a texture coordinate (a third number is dropped).
    fn texcoord_line(&mut self, rest: &str, err: &dyn Fn(String) -> Error) -> Result<()> {
        let f = floats(rest, "texture coordinate", err)?;
        if f.is_empty() || f.len() > 3 {
            return Err(err(format!(
                "texture coordinate: expected 1 to 3 numbers, found {}",
                f.len()
            )));
        }
        self.texcoords
            .push([f[0], f.get(1).copied().unwrap_or(0.0)]);
        Ok(())
    }

    /// A `vn` line: a normal.
    fn normal_line(&mut self, rest: &str, err: &dyn Fn(String) -> Error) -> Result<()> {
        let f = floats(rest, "normal", err)?;
        if f.len() != 3 {
            return Err(err(format!(
                "normal: expected 3 numbers, found {}",
                f.len()
            )));
        }
        self.normals.push([f[0], f[1], f[2]]);
        Ok(())
    }

    /// An `f` line: its corners as vertices (a position with another vt/vn than its first
    /// use becomes a seam vertex), fanned into triangles of the current group and material.
    fn face_line(&mut self, rest: &str, err: &dyn Fn(String) -> Error) -> Result<()> {
        self.poly.clear();
        for c in rest.split_ascii_whitespace() {
            let counts = [
                self.positions.len(),
                self.texcoords.len(),
                self.normals.len(),
            ];
            let idx = corner(c, counts, err)?;
            self.any_vt_corner |= idx[1] != NONE;
            self.any_vn_corner |= idx[2] != NONE;
            let pos = idx[0] as usize;
            let key = [idx[1], idx[2]];
            let v = if !self.pos_used[pos] {
                self.pos_used[pos] = true;
                self.pos_key[pos] = key;
                pos as u32
            } else if self.pos_key[pos] == key {
                pos as u32
            } else {
                let next = self.seam_keys.len() as u32;
                let id = *self.seams.entry(idx).or_insert(next);
                if id == next {
                    if next >= SEAM - 1 {
                        return Err(err("too many vertices for 32-bit indices".into()));
                    }
                    self.seam_keys.push(idx);
                }
                id | SEAM
            };
            self.poly.push(v);
        }
        fan(&self.poly, err, |t| {
            self.triangles.push(t);
            self.face_groups.push(self.cur_group);
            self.face_materials.push(self.cur_mat);
        })?;
        Ok(())
    }

    /// The mesh: seam vertices numbered after the positions, every vertex's attributes, the
    /// groups, materials and libraries; `line_no` is the file's last line, for errors.
    fn finish(self, path: &Path, line_no: u64) -> Result<Mesh> {
        let ObjReader {
            positions,
            colors,
            any_color,
            texcoords,
            normals,
            pos_key,
            pos_used,
            seam_keys,
            mut triangles,
            face_groups,
            face_materials,
            groups,
            materials,
            libs,
            any_vt_corner,
            any_vn_corner,
            ..
        } = self;
        let np = positions.len() as u32;
        if (np as u64) + seam_keys.len() as u64 >= u32::MAX as u64 {
            return Err(Error::parse(
                path,
                Location::Line(line_no),
                "too many vertices for 32-bit indices",
            ));
        }
        for t in &mut triangles {
            *t = t.map(|v| if v & SEAM != 0 { np + (v & !SEAM) } else { v });
        }
        // (position, vt, vn) of every mesh vertex.
        // A position no face uses takes the vt/vn of the same number when the file has one per
        // position (as files written by `write_obj` do).
        let (same_t, same_n) = (texcoords.len() == np as usize, normals.len() == np as usize);
        let corners_of: Vec<[u32; 3]> = (0..np)
            .map(|p| match pos_used[p as usize] {
                true => [p, pos_key[p as usize][0], pos_key[p as usize][1]],
                false => [
                    p,
                    if same_t { p } else { NONE },
                    if same_n { p } else { NONE },
                ],
            })
            .chain(seam_keys)
            .collect();
        let mut mesh = Mesh {
            positions: corners_of
                .iter()
                .map(|c| positions[c[0] as usize])
                .collect(),
            triangles,
            ..Default::default()
        };
        if any_vt_corner {
            mesh.uvs = Some(per_vertex(&corners_of, 1, &texcoords));
        }
        if any_vn_corner {
            mesh.normals = Some(per_vertex(&corners_of, 2, &normals));
        }
        if any_color {
            mesh.colors = Some(corners_of.iter().map(|c| colors[c[0] as usize]).collect());
        }
        if let Some((ids, names)) = groups.per_face(face_groups) {
            mesh.face_groups = Some(ids);
            mesh.groups = names;
        }
        if let Some((ids, names)) = materials.per_face(face_materials) {
            mesh.face_materials = Some(ids);
            mesh.materials = names.into_iter().map(Material::named).collect();
        }
        mesh.material_libs = libs;
        Ok(mesh)
    }
}

/// A name as it can stand on one OBJ line.
fn one_line(name: &str) -> String {
    let s: String = name
        .chars()
        .map(|c| if c == '\n' || c == '\r' { ' ' } else { c })
        .collect();
    let s = s.trim();
    if s.is_empty() {
        "default".to_string()
    } else {
        s.to_string()
    }
}

/// Whether the ids `per_face` first appear in the order 0, 1, 2, … and every one of `count` is
/// used, so that a reader numbering names by first appearance gets the same ids back.
/// A per-face name list the writer emits where it changes (`g` for groups, `usemtl` for
/// materials); the same code serves both.
struct Switch<'m> {
    keyword: &'static str,
    ids: Option<&'m [u32]>,
    names: Vec<&'m str>,
    current: u32,
}

impl<'m> Switch<'m> {
    /// Declares every name in id order first when first use would number them otherwise (a
    /// reader numbers them as it meets them), so the ids read back are the ones written.
    fn declared(
        keyword: &'static str,
        ids: Option<&'m [u32]>,
        names: Vec<&'m str>,
        out: &mut String,
    ) -> Switch<'m> {
        use std::fmt::Write as _;
        let mut s = Switch {
            keyword,
            ids,
            names,
            current: NONE,
        };
        if let Some(ids) = s.ids
            && !in_first_use_order(ids, s.names.len())
        {
            let what = if keyword == "g" {
                "groups"
            } else {
                "materials"
            };
            let _ = writeln!(out, "# {what} in id order");
            for (i, name) in s.names.iter().enumerate() {
                let _ = writeln!(out, "{keyword} {}", one_line(name));
                s.current = i as u32;
            }
        }
        s
    }

    /// Switches to face `f`'s name when it differs from the last written.
    fn face(&mut self, f: usize, out: &mut String) {
        use std::fmt::Write as _;
        if let Some(ids) = self.ids
            && ids[f] != self.current
        {
            self.current = ids[f];
            let name = self.names.get(self.current as usize).copied();
            let _ = writeln!(
                out,
                "{} {}",
                self.keyword,
                one_line(name.unwrap_or("default"))
            );
        }
    }
}

fn in_first_use_order(per_face: &[u32], count: usize) -> bool {
    let mut next = 0u32;
    for &g in per_face {
        if g == next {
            next += 1;
        } else if g > next {
            return false;
        }
    }
    next as usize == count
}

/// Writes `mesh` as OBJ: `mtllib` lines, then `v` (with `r g b` when the mesh has colours; alpha
/// is not representable and is dropped), `vt`, `vn` per vertex, then the faces with `g` and `usemtl`
/// lines where the group or material changes. When the group (material) ids would not come back
/// in the same order from first appearance, all names are declared once up front.
/// Every number is written with Rust's `{}`, which reads back bit-exact.
pub fn write_obj<W: Write>(w: &mut W, mesh: &Mesh) -> io::Result<()> {
    write_obj_libs(w, mesh, &mesh.material_libs)
}

/// [`write_obj`] with `libs` as the `mtllib` names (the mesh's, relocated for another folder).
pub fn write_obj_libs<W: Write>(w: &mut W, mesh: &Mesh, libs: &[String]) -> io::Result<()> {
    use std::fmt::Write as _;
    let mut out = String::with_capacity(1 << 16);
    let flush = |out: &mut String, w: &mut W| -> io::Result<()> {
        w.write_all(out.as_bytes())?;
        out.clear();
        Ok(())
    };
    out.push_str("# written by meshslim\n");
    for lib in libs {
        let _ = writeln!(out, "mtllib {}", one_line(lib));
    }
    for (i, p) in mesh.positions.iter().enumerate() {
        let _ = write!(out, "v {} {} {}", p[0], p[1], p[2]);
        if let Some(c) = &mesh.colors {
            let _ = write!(out, " {} {} {}", c[i][0], c[i][1], c[i][2]);
        }
        out.push('\n');
        if out.len() > 60_000 {
            flush(&mut out, w)?;
        }
    }
    // OBJ counts UVs from the image's bottom-left corner.
    if let Some(uvs) = mesh.uvs_from(UvOrigin::BottomLeft) {
        for t in uvs.iter() {
            let _ = writeln!(out, "vt {} {}", t[0], t[1]);
            if out.len() > 60_000 {
                flush(&mut out, w)?;
            }
        }
    }
    if let Some(normals) = &mesh.normals {
        for n in normals {
            let _ = writeln!(out, "vn {} {} {}", n[0], n[1], n[2]);
            if out.len() > 60_000 {
                flush(&mut out, w)?;
            }
        }
    }
    let names = mesh.groups.iter().map(String::as_str).collect();
    let mut groups = Switch::declared("g", mesh.face_groups.as_deref(), names, &mut out);
    let names = mesh.materials.iter().map(|m| m.name.as_str()).collect();
    let mut materials = Switch::declared("usemtl", mesh.face_materials.as_deref(), names, &mut out);
    let (has_t, has_n) = (mesh.uvs.is_some(), mesh.normals.is_some());
    for (f, t) in mesh.triangles.iter().enumerate() {
        groups.face(f, &mut out);
        materials.face(f, &mut out);
        out.push('f');
        for &v in t {
            let i = v as u64 + 1;
            let _ = match (has_t, has_n) {
                (false, false) => write!(out, " {i}"),
                (true, false) => write!(out, " {i}/{i}"),
                (false, true) => write!(out, " {i}//{i}"),
                (true, true) => write!(out, " {i}/{i}/{i}"),
            };
        }
        out.push('\n');
        if out.len() > 60_000 {
            flush(&mut out, w)?;
        }
    }
    flush(&mut out, w)
}
