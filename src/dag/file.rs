//! The `.mslod` file: a cluster DAG, little-endian, checked end to end (docs/MSLOD.md).
//!
//! ```text
//! header   magic "MSLOD\r\n\x1a", version u32, flags u32, vertices u32, triangles u32,
//!          clusters u32, groups u32, diagonal f64                               (40 bytes)
//! vertices positions f32×3 each; then normals f32×3, UVs f32×2, colours f32×4 as flagged
//! triangles u32×3 each (vertex ids)
//! clusters first_triangle, triangle_count, depth, group, parent_group u32; bounds f32×4;
//!          lod_sphere f32×4; error f32                                          (56 bytes)
//! groups   depth u32; sphere f32×4; error f32                                   (24 bytes)
//! checksum FNV-1a 64 of every byte before it
//! ```

use super::{Cluster, Dag, Group, NONE};
use crate::error::{Error, Location, Result};
use crate::mesh::{Mesh, UvOrigin};
use std::path::Path;

pub const MAGIC: [u8; 8] = *b"MSLOD\r\n\x1a";
pub const VERSION: u32 = 1;
const HEADER: usize = 40;
const CLUSTER: usize = 56;
const GROUP: usize = 24;
const NORMALS: u32 = 1;
const UVS: u32 = 2;
const COLORS: u32 = 4;
const UV_TOP_LEFT: u32 = 8;

/// The file's bytes for `dag`.
pub fn to_bytes(dag: &Dag) -> Vec<u8> {
    let m = &dag.mesh;
    let mut flags = 0;
    flags |= NORMALS * m.normals.is_some() as u32;
    flags |= UVS * m.uvs.is_some() as u32;
    flags |= COLORS * m.colors.is_some() as u32;
    flags |= UV_TOP_LEFT * (m.uvs.is_some() && m.uv_origin == UvOrigin::TopLeft) as u32;
    let mut w = Vec::with_capacity(expected_len(flags, counts(dag)).unwrap_or(0) as usize);
    w.extend_from_slice(&MAGIC);
    for x in [VERSION, flags] {
        w.extend_from_slice(&x.to_le_bytes());
    }
    for n in counts(dag) {
        w.extend_from_slice(&(n as u32).to_le_bytes());
    }
    w.extend_from_slice(&dag.diagonal.to_le_bytes());
    let f32s = |w: &mut Vec<u8>, xs: &[f32]| {
        for x in xs {
            w.extend_from_slice(&x.to_le_bytes());
        }
    };
    f32s(&mut w, m.positions.as_flattened());
    if let Some(n) = &m.normals {
        f32s(&mut w, n.as_flattened());
    }
    if let Some(t) = &m.uvs {
        f32s(&mut w, t.as_flattened());
    }
    if let Some(c) = &m.colors {
        f32s(&mut w, c.as_flattened());
    }
    for v in m.triangles.as_flattened() {
        w.extend_from_slice(&v.to_le_bytes());
    }
    for c in &dag.clusters {
        for x in [
            c.first_triangle,
            c.triangle_count,
            c.depth,
            c.group,
            c.parent_group,
        ] {
            w.extend_from_slice(&x.to_le_bytes());
        }
        f32s(&mut w, &c.bounds);
        f32s(&mut w, &c.lod_sphere);
        f32s(&mut w, &[c.error]);
    }
    for g in &dag.groups {
        w.extend_from_slice(&g.depth.to_le_bytes());
        f32s(&mut w, &g.sphere);
        f32s(&mut w, &[g.error]);
    }
    let sum = fnv1a(&w);
    w.extend_from_slice(&sum.to_le_bytes());
    w
}

/// Writes `dag` to `path` (through a temporary file beside it, so a failed write leaves no
/// half file).
pub fn write(path: &Path, dag: &Dag) -> Result<()> {
    let io = |e| Error::Io {
        path: path.to_path_buf(),
        source: e,
    };
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let mut tmp = tempfile::NamedTempFile::new_in(dir).map_err(io)?;
    std::io::Write::write_all(&mut tmp, &to_bytes(dag)).map_err(io)?;
    tmp.persist(path).map_err(|e| io(e.error))?;
    Ok(())
}

/// Reads the DAG in `path`.
pub fn read(path: &Path) -> Result<Dag> {
    let bytes = std::fs::read(path).map_err(|e| Error::Io {
        path: path.to_path_buf(),
        source: e,
    })?;
    from_bytes(&bytes, path)
}

fn counts(dag: &Dag) -> [usize; 4] {
    [
        dag.mesh.positions.len(),
        dag.mesh.triangles.len(),
        dag.clusters.len(),
        dag.groups.len(),
    ]
}

/// The file length the header's flags and counts call for, `None` past u64.
fn expected_len(flags: u32, [v, t, c, g]: [usize; 4]) -> Option<u64> {
    let floats = 3
        + 3 * (flags & NORMALS != 0) as u64
        + 2 * (flags & UVS != 0) as u64
        + 4 * (flags & COLORS != 0) as u64;
    let parts = [
        (v as u64).checked_mul(floats * 4)?,
        (t as u64).checked_mul(12)?,
        (c as u64).checked_mul(CLUSTER as u64)?,
        (g as u64).checked_mul(GROUP as u64)?,
    ];
    parts
        .iter()
        .try_fold(HEADER as u64 + 8, |a, &b| a.checked_add(b))
}

/// A cursor over the file's bytes whose every error names the file and the offset.
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
    path: &'a Path,
}

impl Reader<'_> {
    fn fail<T>(&self, at: usize, msg: impl Into<String>) -> Result<T> {
        Err(Error::parse(self.path, Location::Byte(at as u64), msg))
    }
    fn u32(&mut self) -> u32 {
        let b = &self.bytes[self.at..self.at + 4];
        self.at += 4;
        u32::from_le_bytes([b[0], b[1], b[2], b[3]])
    }
    fn f32(&mut self) -> f32 {
        f32::from_bits(self.u32())
    }
    fn f32s<const N: usize>(&mut self) -> [f32; N] {
        std::array::from_fn(|_| self.f32())
    }
    fn vecs<const N: usize>(&mut self, n: usize) -> Vec<[f32; N]> {
        (0..n).map(|_| self.f32s::<N>()).collect()
    }
}

/// Parses a DAG from `bytes` (`path` names it in errors): every length is checked before it
/// is read and every index before it is used, so a damaged file is an error, never a panic.
pub fn from_bytes(bytes: &[u8], path: &Path) -> Result<Dag> {
    let mut r = Reader { bytes, at: 0, path };
    if bytes.len() < HEADER {
        return r.fail(
            bytes.len(),
            format!(
                "truncated: {} bytes, the header alone is {HEADER}",
                bytes.len()
            ),
        );
    }
    if bytes[..8] != MAGIC {
        return r.fail(0, "not a meshslim cluster DAG (.mslod): wrong magic");
    }
    r.at = 8;
    let version = r.u32();
    if version != VERSION {
        return r.fail(
            8,
            format!("version {version}; this meshslim reads version {VERSION}"),
        );
    }
    let flags = r.u32();
    if flags & !(NORMALS | UVS | COLORS | UV_TOP_LEFT) != 0 {
        return r.fail(12, format!("unknown flags {flags:#x}"));
    }
    if flags & UV_TOP_LEFT != 0 && flags & UVS == 0 {
        return r.fail(12, "a UV origin is flagged but no UVs");
    }
    let n = [r.u32(), r.u32(), r.u32(), r.u32()].map(|x| x as usize);
    let diagonal = f64::from_le_bytes(bytes[32..40].try_into().expect("8 bytes"));
    r.at = HEADER;
    match expected_len(flags, n) {
        Some(len) if len == bytes.len() as u64 => {}
        Some(len) if len > bytes.len() as u64 => {
            return r.fail(
                bytes.len(),
                format!(
                    "truncated: {} bytes, the header's counts need {len}",
                    bytes.len()
                ),
            );
        }
        Some(len) => {
            return r.fail(
                len as usize,
                format!("{} bytes after the checksum", bytes.len() as u64 - len),
            );
        }
        None => return r.fail(16, "counts too large for any file"),
    }
    let body = bytes.len() - 8;
    let stored = u64::from_le_bytes(bytes[body..].try_into().expect("8 bytes"));
    if stored != fnv1a(&bytes[..body]) {
        return r.fail(body, "checksum mismatch: the file is damaged");
    }
    if !(diagonal.is_finite() && diagonal >= 0.0) {
        return r.fail(32, format!("bad diagonal {diagonal}"));
    }
    let [nv, nt, nc, ng] = n;
    let mut mesh = Mesh {
        positions: r.vecs::<3>(nv),
        ..Mesh::default()
    };
    if flags & NORMALS != 0 {
        mesh.normals = Some(r.vecs::<3>(nv));
    }
    if flags & UVS != 0 {
        mesh.uvs = Some(r.vecs::<2>(nv));
        if flags & UV_TOP_LEFT != 0 {
            mesh.uv_origin = UvOrigin::TopLeft;
        }
    }
    if flags & COLORS != 0 {
        mesh.colors = Some(r.vecs::<4>(nv));
    }
    let tri_at = r.at;
    mesh.triangles = (0..nt).map(|_| [r.u32(), r.u32(), r.u32()]).collect();
    if let Some(i) = mesh
        .triangles
        .as_flattened()
        .iter()
        .position(|&v| v as usize >= nv)
    {
        return r.fail(
            tri_at + 4 * i,
            format!(
                "vertex index {} out of range ({nv} vertices)",
                mesh.triangles.as_flattened()[i]
            ),
        );
    }
    let cluster_at = r.at;
    let clusters: Vec<Cluster> = (0..nc)
        .map(|_| Cluster {
            first_triangle: r.u32(),
            triangle_count: r.u32(),
            depth: r.u32(),
            group: r.u32(),
            parent_group: r.u32(),
            bounds: r.f32s(),
            lod_sphere: r.f32s(),
            error: r.f32(),
        })
        .collect();
    let group_at = r.at;
    let groups: Vec<Group> = (0..ng)
        .map(|_| Group {
            depth: r.u32(),
            sphere: r.f32s(),
            error: r.f32(),
        })
        .collect();
    for (i, g) in groups.iter().enumerate() {
        if !(sphere_ok(g.sphere) && g.error.is_finite() && g.error >= 0.0) {
            return r.fail(
                group_at + GROUP * i,
                format!("group {i}: bad sphere or error"),
            );
        }
    }
    for (i, c) in clusters.iter().enumerate() {
        let at = cluster_at + CLUSTER * i;
        check_cluster(c, i, nt, &groups).or_else(|m| r.fail(at, m))?;
    }
    Ok(Dag {
        mesh,
        clusters,
        groups,
        diagonal,
    })
}

/// What is wrong with cluster `i`, if anything.
fn check_cluster(
    c: &Cluster,
    i: usize,
    triangles: usize,
    groups: &[Group],
) -> std::result::Result<(), String> {
    let end = c.first_triangle as u64 + c.triangle_count as u64;
    if end > triangles as u64 {
        return Err(format!(
            "cluster {i}: triangles {}..{end} out of range ({triangles} triangles)",
            c.first_triangle
        ));
    }
    for (what, g) in [("group", c.group), ("parent group", c.parent_group)] {
        if g != NONE && g as usize >= groups.len() {
            return Err(format!(
                "cluster {i}: {what} {g} out of range ({} groups)",
                groups.len()
            ));
        }
    }
    if !(sphere_ok(c.bounds) && sphere_ok(c.lod_sphere) && c.error.is_finite() && c.error >= 0.0) {
        return Err(format!("cluster {i}: bad sphere or error"));
    }
    if let Some(g) = groups.get(c.group as usize)
        && g.error < c.error
    {
        return Err(format!(
            "cluster {i}: error {} above its group's {} (errors must not fall up the DAG)",
            c.error, g.error
        ));
    }
    if let Some(p) = groups.get(c.parent_group as usize)
        && p.error != c.error
    {
        return Err(format!(
            "cluster {i}: error {} is not its parent group's {}",
            c.error, p.error
        ));
    }
    Ok(())
}

fn sphere_ok(s: [f32; 4]) -> bool {
    s.iter().all(|x| x.is_finite()) && s[3] >= 0.0
}

/// FNV-1a 64: a check that the bytes are those written.
fn fnv1a(bytes: &[u8]) -> u64 {
    crate::compute::disk_cache::fnv1a(bytes)
}

/// `bytes` (a whole file) with its last 8 bytes made the checksum of the rest, as a writer
/// ends it: the fuzz target reaches the body's checks this way, which random bytes almost
/// never do past a checksum.
pub fn restamp(bytes: &mut [u8]) {
    if let Some(body) = bytes.len().checked_sub(8) {
        let sum = fnv1a(&bytes[..body]);
        bytes[body..].copy_from_slice(&sum.to_le_bytes());
    }
}
