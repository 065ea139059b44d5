//! glTF 2.0, as `.gltf` (JSON with embedded or external buffers) and `.glb` (binary container).
//!
//! The document is deserialised into the `gltf::json` types; the GLB container, buffers and
//! accessors are read here, with checked arithmetic and every index looked up with `get`. (The
//! `gltf` crate's own importer panics on some hostile inputs: accessors with `count: 0`, strides
//! smaller than the element, URIs that percent-decode to invalid UTF-8.)
//!
//! Read: every triangle primitive (`TRIANGLES`, `TRIANGLE_STRIP`, `TRIANGLE_FAN`; points and lines
//! are skipped) of every mesh instance reachable from the default scene (else the first scene;
//! with no scene at all, every mesh once, untransformed), with the node transforms applied
//! (normals by the inverse transpose; winding flipped under a mirroring transform). Attributes:
//! `POSITION`, `NORMAL`, `TEXCOORD_0`, `COLOR_0` (float or normalised integers), indices u8/u16/u32
//! or none. UVs are kept as glTF counts them, from the image's top-left corner
//! (`Mesh::uv_origin` = `TopLeft`); the OBJ and PLY writers flip them, and this writer flips
//! those read from OBJ or PLY. Primitives that share attribute accessors under the same transform share vertices.
//! Materials: every document material, by name (`material_N` when unnamed), plus `default` for
//! primitives without one; `face_materials` is `None` when the document has no materials. Each
//! material's JSON (PBR factors, texture references, extensions), the textures, samplers and
//! images are carried to the output unchanged (`Mesh::textures`), each image as bytes from its
//! buffer view, data URI or file (written back embedded), so a textured scan comes out
//! textured; the extensions they use stay declared. Groups:
//! one per glTF mesh (`mesh_N` when unnamed); `face_groups` is `None` when only one unnamed mesh
//! is drawn. Vertices missing an attribute another primitive has get zero (white for colours).
//! Not supported (an error): sparse accessors, accessors without a buffer view.
//!
//! Write: one buffer (a base64 data URI in `.gltf`, the BIN chunk in `.glb`) holding positions,
//! normals, UVs and colours (f32) of all vertices once, and u32 indices; one glTF mesh and node
//! per group (groups without faces are dropped) and one primitive per material in it.

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use gltf::json;
use json::validation::Checked;
use serde_json::{Value, json};

use crate::error::{Error, Location, Result};
use crate::mesh::{Material, Mesh, TextureImage, Textures, UvOrigin};

const GLB_MAGIC: &[u8; 4] = b"glTF";
const CHUNK_JSON: u32 = 0x4E4F_534A;
const CHUNK_BIN: u32 = 0x004E_4942;

fn u32_at(b: &[u8], off: usize) -> Option<u32> {
    Some(u32::from_le_bytes(
        b.get(off..off.checked_add(4)?)?.try_into().ok()?,
    ))
}

/// Splits a GLB container into its JSON chunk (with its byte offset) and BIN chunk.
/// A GLB's JSON chunk, the JSON chunk's byte offset, and the BIN chunk.
type GlbParts<'a> = (&'a [u8], usize, Option<&'a [u8]>);

fn split_glb<'a>(b: &'a [u8], path: &Path) -> Result<GlbParts<'a>> {
    let bad = |off: usize, m: &str| Error::parse(path, Location::Byte(off as u64), m.to_string());
    let version = u32_at(b, 4).ok_or_else(|| bad(4, "truncated GLB header"))?;
    if version != 2 {
        return Err(bad(
            4,
            &format!("GLB version {version}; only 2 is supported"),
        ));
    }
    let total = u32_at(b, 8).ok_or_else(|| bad(8, "truncated GLB header"))? as usize;
    if total > b.len() {
        return Err(bad(
            8,
            &format!(
                "the GLB header declares {total} bytes but the file has {}",
                b.len()
            ),
        ));
    }
    let b = &b[..total];
    let mut off = 12;
    let mut json_chunk = None;
    let mut bin = None;
    while off < b.len() {
        let len = u32_at(b, off).ok_or_else(|| bad(off, "truncated chunk header"))? as usize;
        let ty = u32_at(b, off + 4).ok_or_else(|| bad(off, "truncated chunk header"))?;
        let start = off + 8;
        let data = start
            .checked_add(len)
            .and_then(|end| b.get(start..end))
            .ok_or_else(|| {
                bad(
                    off,
                    &format!("chunk of {len} bytes runs past the end of the file"),
                )
            })?;
        match ty {
            CHUNK_JSON if json_chunk.is_none() => json_chunk = Some((data, start)),
            CHUNK_BIN if bin.is_none() => bin = Some(data),
            _ => {}
        }
        off = start + len.div_ceil(4) * 4;
    }
    let (j, at) = json_chunk.ok_or_else(|| bad(12, "GLB without a JSON chunk"))?;
    Ok((j, at, bin))
}

const B64: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

fn base64_encode(data: &[u8]) -> String {
    let mut s = String::with_capacity(data.len().div_ceil(3) * 4);
    for c in data.chunks(3) {
        let n = (c[0] as u32) << 16
            | (*c.get(1).unwrap_or(&0) as u32) << 8
            | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            if k <= c.len() {
                s.push(B64[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

fn base64_decode(s: &str) -> Option<Vec<u8>> {
    let mut out = Vec::with_capacity(s.len() / 4 * 3);
    let (mut acc, mut bits) = (0u32, 0u32);
    for &c in s.trim_end_matches('=').as_bytes() {
        let v = match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            b'\r' | b'\n' | b' ' => continue,
            _ => return None,
        };
        acc = acc << 6 | v as u32;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    Some(out)
}

fn percent_decode(s: &str) -> Vec<u8> {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%'
            && i + 2 < b.len()
            && let Ok(v) =
                u8::from_str_radix(std::str::from_utf8(&b[i + 1..i + 3]).unwrap_or("zz"), 16)
        {
            out.push(v);
            i += 3;
            continue;
        }
        out.push(b[i]);
        i += 1;
    }
    out
}

type Mat = [[f64; 4]; 4]; // column-major: m[col][row]

const IDENTITY: Mat = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 1.0],
];

fn mul(a: &Mat, b: &Mat) -> Mat {
    let mut m = [[0.0; 4]; 4];
    for (c, col) in m.iter_mut().enumerate() {
        for (r, x) in col.iter_mut().enumerate() {
            *x = (0..4).map(|k| a[k][r] * b[c][k]).sum();
        }
    }
    m
}

fn local_matrix(n: &json::Node) -> Mat {
    if let Some(m) = n.matrix {
        let mut out = [[0.0; 4]; 4];
        for c in 0..4 {
            for r in 0..4 {
                out[c][r] = m[c * 4 + r] as f64;
            }
        }
        return out;
    }
    let t = n.translation.unwrap_or([0.0; 3]).map(f64::from);
    let [x, y, z, w] = n
        .rotation
        .as_ref()
        .map_or([0.0, 0.0, 0.0, 1.0], |q| q.0)
        .map(f64::from);
    let s = n.scale.unwrap_or([1.0; 3]).map(f64::from);
    let r = [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y + z * w),
            2.0 * (x * z - y * w),
        ],
        [
            2.0 * (x * y - z * w),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z + x * w),
        ],
        [
            2.0 * (x * z + y * w),
            2.0 * (y * z - x * w),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ];
    let mut m = IDENTITY;
    for c in 0..3 {
        for k in 0..3 {
            m[c][k] = r[c][k] * s[c];
        }
    }
    m[3][..3].copy_from_slice(&t);
    m
}

fn det3(m: &Mat) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[2][1] * m[1][2])
        - m[1][0] * (m[0][1] * m[2][2] - m[2][1] * m[0][2])
        + m[2][0] * (m[0][1] * m[1][2] - m[1][1] * m[0][2])
}

/// Inverse transpose of the upper 3×3 (as a 3×3 column-major), for normals.
#[allow(clippy::needless_range_loop)]
fn normal_matrix(m: &Mat) -> [[f64; 3]; 3] {
    let d = det3(m);
    let d = if d == 0.0 { 1.0 } else { d };
    // Cofactor matrix / det = inverse transpose.
    let a = |c: usize, r: usize| m[c][r];
    let mut n = [[0.0; 3]; 3];
    for c in 0..3 {
        for r in 0..3 {
            let (c1, c2) = ((c + 1) % 3, (c + 2) % 3);
            let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
            n[c][r] = (a(c1, r1) * a(c2, r2) - a(c1, r2) * a(c2, r1)) / d;
        }
    }
    n
}

struct Doc<'a> {
    root: json::Root,
    /// Materials, textures, samplers and images as raw JSON: carried through unchanged
    /// (`json::Root` drops the extensions it does not know).
    carried: Carried,
    buffers: Vec<Vec<u8>>,
    path: &'a Path,
}

#[derive(serde::Deserialize, Default)]
#[serde(default, rename_all = "camelCase")]
struct Carried {
    materials: Vec<Value>,
    textures: Vec<Value>,
    samplers: Vec<Value>,
    images: Vec<Value>,
    extensions_required: Vec<String>,
}

/// The names of the extensions `v` uses: the keys of every `extensions` object in it.
fn extension_names(v: &Value, out: &mut std::collections::BTreeSet<String>) {
    match v {
        Value::Object(o) => {
            for (k, x) in o {
                if let ("extensions", Value::Object(e)) = (k.as_str(), x) {
                    out.extend(e.keys().cloned());
                }
                extension_names(x, out);
            }
        }
        Value::Array(a) => a.iter().for_each(|x| extension_names(x, out)),
        _ => {}
    }
}

impl Doc<'_> {
    fn err(&self, m: impl Into<String>) -> Error {
        Error::parse(self.path, Location::Unknown, m)
    }

    /// Instancing lets a tiny file place one mesh a million times: what the scene expands to is
    /// bounded by the data actually present. 64 elements per buffer byte is far beyond any real
    /// scene's instancing, and with the 1M floor a few GiB at most.
    fn check_expansion(&self, total: usize, what: &str) -> Result<()> {
        let data: usize = self.buffers.iter().map(Vec::len).sum();
        let limit = data.saturating_mul(64).max(1 << 20);
        if total > limit {
            return Err(self.err(format!(
                "the scene instantiates more than {limit} {what} from {data} bytes of buffers; \
                 refusing to expand it further"
            )));
        }
        Ok(())
    }

    /// The bytes of accessor `i` and its layout: (data, stride, element size, count).
    fn accessor_bytes(
        &self,
        i: usize,
        what: &str,
    ) -> Result<(&[u8], usize, usize, usize, &json::Accessor)> {
        let acc = self
            .root
            .accessors
            .get(i)
            .ok_or_else(|| self.err(format!("{what}: accessor {i} does not exist")))?;
        if acc.sparse.is_some() {
            return Err(self.err(format!(
                "{what}: accessor {i} is sparse, which is not supported"
            )));
        }
        let (Checked::Valid(ct), Checked::Valid(ty)) = (&acc.component_type, &acc.type_) else {
            return Err(self.err(format!("{what}: accessor {i} has an invalid type")));
        };
        let elem = ct.0.size() * ty.multiplicity();
        let count = acc.count.0 as usize;
        let view_i = acc
            .buffer_view
            .as_ref()
            .ok_or_else(|| {
                self.err(format!(
                    "{what}: accessor {i} has no buffer view, which is not supported"
                ))
            })?
            .value();
        let view = self
            .root
            .buffer_views
            .get(view_i)
            .ok_or_else(|| self.err(format!("{what}: buffer view {view_i} does not exist")))?;
        let buf = self.buffers.get(view.buffer.value()).ok_or_else(|| {
            self.err(format!(
                "{what}: buffer {} does not exist",
                view.buffer.value()
            ))
        })?;
        let vstart = view.byte_offset.map_or(0, |o| o.0);
        let vdata = vstart
            .checked_add(view.byte_length.0)
            .and_then(|end| buf.get(usize::try_from(vstart).ok()?..usize::try_from(end).ok()?))
            .ok_or_else(|| {
                self.err(format!(
                    "{what}: buffer view {view_i} lies outside its buffer"
                ))
            })?;
        let stride = view.byte_stride.as_ref().map_or(elem, |s| s.0);
        if stride < elem {
            return Err(self.err(format!(
                "{what}: buffer view {view_i} has stride {stride}, smaller than the {elem}-byte element"
            )));
        }
        if count == 0 {
            return Ok((&[], stride, elem, 0, acc));
        }
        let start = acc.byte_offset.map_or(0, |o| o.0) as usize;
        let data = (count - 1)
            .checked_mul(stride)
            .and_then(|x| x.checked_add(elem))
            .and_then(|x| x.checked_add(start))
            .and_then(|end| vdata.get(start..end))
            .ok_or_else(|| {
                self.err(format!("{what}: accessor {i} ({count} elements) runs past the end of buffer view {view_i}"))
            })?;
        Ok((data, stride, elem, count, acc))
    }

    /// Float components of accessor `i` (normalised integers mapped to 0..1 / -1..1), checking
    /// that it has `dims` (one of) components.
    fn floats(&self, i: usize, dims: &[usize], what: &str) -> Result<(Vec<f32>, usize)> {
        let (data, stride, _, count, acc) = self.accessor_bytes(i, what)?;
        let (Checked::Valid(ct), Checked::Valid(ty)) = (&acc.component_type, &acc.type_) else {
            return Err(self.err(format!("{what}: accessor {i} has an invalid type")));
        };
        let n = ty.multiplicity();
        if !dims.contains(&n) {
            return Err(self.err(format!(
                "{what}: accessor {i} has {n} components, expected {dims:?}"
            )));
        }
        use json::accessor::ComponentType as C;
        let ct = ct.0;
        if ct != C::F32 && !acc.normalized {
            return Err(self.err(format!(
                "{what}: accessor {i} has non-normalised integer components"
            )));
        }
        let size = ct.size();
        let mut out = Vec::with_capacity(count * n);
        for e in 0..count {
            let el = &data[e * stride..];
            for k in 0..n {
                let b = &el[k * size..];
                let v = match ct {
                    C::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
                    C::U8 => b[0] as f32 / 255.0,
                    C::I8 => (b[0] as i8 as f32 / 127.0).max(-1.0),
                    C::U16 => u16::from_le_bytes([b[0], b[1]]) as f32 / 65535.0,
                    C::I16 => (i16::from_le_bytes([b[0], b[1]]) as f32 / 32767.0).max(-1.0),
                    C::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32 / u32::MAX as f32,
                };
                out.push(v);
            }
        }
        Ok((out, n))
    }

    fn indices(&self, i: usize, what: &str) -> Result<Vec<u32>> {
        let (data, stride, _, count, acc) = self.accessor_bytes(i, what)?;
        use json::accessor::{ComponentType as C, Type};
        let (Checked::Valid(ct), Checked::Valid(Type::Scalar)) = (&acc.component_type, &acc.type_)
        else {
            return Err(self.err(format!("{what}: index accessor {i} is not a scalar")));
        };
        let mut out = Vec::with_capacity(count);
        for e in 0..count {
            let b = &data[e * stride..];
            out.push(match ct.0 {
                C::U8 => b[0] as u32,
                C::U16 => u16::from_le_bytes([b[0], b[1]]) as u32,
                C::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
                other => {
                    return Err(self.err(format!(
                        "{what}: index accessor {i} has component type {other:?}"
                    )));
                }
            });
        }
        Ok(out)
    }
}

/// A `data:` URI's media type and decoded bytes (`None` for another URI); the error says what
/// is wrong with a data URI that cannot be decoded.
fn data_uri(uri: &str) -> Option<std::result::Result<(&str, Vec<u8>), &'static str>> {
    let rest = uri.strip_prefix("data:")?;
    Some(match rest.split_once(";base64,") {
        None => Err("only base64 data URIs are supported"),
        Some((mime, payload)) => base64_decode(payload)
            .map(|b| (mime, b))
            .ok_or("invalid base64 in the data URI"),
    })
}

/// A relative URI as a path (percent-decoded), to be joined to the glTF's folder.
fn uri_path(uri: &str) -> std::path::PathBuf {
    String::from_utf8_lossy(&percent_decode(uri))
        .into_owned()
        .into()
}

fn load_buffers(root: &json::Root, blob: Option<&[u8]>, path: &Path) -> Result<Vec<Vec<u8>>> {
    let mut out = Vec::new();
    for (i, b) in root.buffers.iter().enumerate() {
        let err = |m: String| Error::parse(path, Location::Unknown, format!("buffer {i}: {m}"));
        let data = match &b.uri {
            None => blob
                .filter(|_| i == 0)
                .ok_or_else(|| err("no URI and no GLB BIN chunk".into()))?
                .to_vec(),
            Some(uri) => match data_uri(uri) {
                Some(decoded) => decoded.map_err(|m| err(m.into()))?.1,
                None => {
                    if uri.contains("://") {
                        return Err(err(format!("unsupported URI {uri:?}")));
                    }
                    let file = path.parent().unwrap_or(Path::new(".")).join(uri_path(uri));
                    std::fs::read(&file)
                        .map_err(|e| err(format!("cannot read {}: {e}", file.display())))?
                }
            },
        };
        if (data.len() as u64) < b.byte_length.0 {
            return Err(err(format!(
                "{} bytes of data, but byteLength is {}",
                data.len(),
                b.byte_length.0
            )));
        }
        out.push(data);
    }
    Ok(out)
}

/// Reads a `.gltf` or `.glb` file (the container is recognised by its magic, not the extension).
pub fn read(path: &Path) -> Result<Mesh> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    if bytes.is_empty() {
        return Err(Error::parse(path, Location::Byte(0), "empty file"));
    }
    let (json_bytes, json_at, blob) = if bytes.starts_with(GLB_MAGIC) {
        let (j, at, bin) = split_glb(&bytes, path)?;
        (j, Some(at), bin)
    } else {
        (&bytes[..], None, None)
    };
    let root: json::Root = serde_json::from_slice(json_bytes).map_err(|e| {
        let at = match json_at {
            Some(off) => Location::Byte(off as u64),
            None => Location::Line(e.line() as u64),
        };
        Error::parse(path, at, format!("invalid glTF JSON: {e}"))
    })?;
    let carried: Carried = serde_json::from_slice(json_bytes)
        .map_err(|e| Error::parse(path, Location::Unknown, format!("invalid glTF JSON: {e}")))?;
    let buffers = load_buffers(&root, blob, path)?;
    let doc = Doc {
        root,
        carried,
        buffers,
        path,
    };
    build(&doc)
}

#[derive(Default)]
struct Out {
    mesh: Mesh,
    normals: Option<Vec<[f32; 3]>>,
    uvs: Option<Vec<[f32; 2]>>,
    colors: Option<Vec<[f32; 4]>>,
    face_materials: Vec<u32>,
    face_groups: Vec<u32>,
    shared: HashMap<([u64; 16], [usize; 4]), u32>,
    default_material: Option<u32>,
    groups_used: Vec<usize>,
}

/// A glTF material object without its name (that is `Material::name`); `None` when nothing else
/// is left, as for a material written from an OBJ's `usemtl` name.
fn material_definition(v: &Value) -> Option<Value> {
    let mut o = v.as_object()?.clone();
    o.remove("name");
    (!o.is_empty()).then_some(Value::Object(o))
}

/// The document's textures, samplers and images, each image's bytes read from its buffer view,
/// data URI or file. An image that cannot be read (a missing file, a bad buffer view) keeps
/// its URI alone: the mesh is still worth simplifying, and `io::not_kept` says so. Images that
/// name the same buffer view or file share one copy of the bytes (so a small file cannot make
/// the reader copy a large buffer many times), and a URI is read only as a path inside the
/// glTF's folder: an absolute path or one climbing out with `..` would copy any file the user
/// can read into the output.
fn textures(doc: &Doc) -> Textures {
    let c = &doc.carried;
    let dir = doc.path.parent().unwrap_or(Path::new("."));
    let mut by_view: HashMap<usize, Option<Arc<[u8]>>> = HashMap::new();
    let mut by_file: HashMap<std::path::PathBuf, Option<Arc<[u8]>>> = HashMap::new();
    let view_bytes = |v: usize| -> Option<Arc<[u8]>> {
        let view = doc.root.buffer_views.get(v)?;
        let buffer = doc.buffers.get(view.buffer.value())?;
        let start = usize::try_from(view.byte_offset.map_or(0, |o| o.0)).ok()?;
        let len = usize::try_from(view.byte_length.0).ok()?;
        let bytes = buffer.get(start..start.checked_add(len)?)?;
        (!bytes.is_empty()).then(|| Arc::from(bytes))
    };
    let mut images = Vec::with_capacity(c.images.len());
    for img in &c.images {
        let text = |k: &str| img.get(k).and_then(Value::as_str).map(str::to_string);
        let uri = text("uri");
        let mut mime_type = text("mimeType");
        let data = if let Some(v) = img.get("bufferView") {
            v.as_u64()
                .and_then(|v| usize::try_from(v).ok())
                .and_then(|v| by_view.entry(v).or_insert_with(|| view_bytes(v)).clone())
        } else {
            match uri.as_deref().map(|u| (u, data_uri(u))) {
                Some((_, Some(decoded))) => decoded.ok().and_then(|(mime, bytes)| {
                    if mime_type.is_none() && !mime.is_empty() {
                        mime_type = Some(mime.to_string());
                    }
                    (!bytes.is_empty()).then(|| Arc::from(bytes))
                }),
                Some((u, None)) if !u.contains("://") => {
                    let given = uri_path(u);
                    use std::path::Component::{CurDir, Normal};
                    let inside = given.components().all(|c| matches!(c, Normal(_) | CurDir));
                    // `a.png` and `./a.png` are one file.
                    let rel: std::path::PathBuf = given
                        .components()
                        .filter(|c| matches!(c, Normal(_)))
                        .collect();
                    inside
                        .then(|| {
                            by_file
                                .entry(rel.clone())
                                .or_insert_with(|| {
                                    std::fs::read(dir.join(&rel))
                                        .ok()
                                        .filter(|b| !b.is_empty())
                                        .map(Arc::from)
                                })
                                .clone()
                        })
                        .flatten()
                }
                _ => None,
            }
        };
        images.push(TextureImage {
            name: text("name"),
            mime_type,
            // An image read is written back embedded; one that could not be keeps its URI.
            uri: uri.filter(|u| data.is_none() && !u.starts_with("data:")),
            data,
        });
    }
    Textures {
        textures: c.textures.clone(),
        samplers: c.samplers.clone(),
        images,
        extensions_required: c.extensions_required.clone(),
    }
}

fn build(doc: &Doc) -> Result<Mesh> {
    let root = &doc.root;
    let mut out = Out::default();
    out.mesh.materials = root
        .materials
        .iter()
        .enumerate()
        .map(|(i, m)| Material {
            name: m.name.clone().unwrap_or_else(|| format!("material_{i}")),
            gltf: doc.carried.materials.get(i).and_then(material_definition),
        })
        .collect();
    out.mesh.textures = textures(doc);
    let scene = root
        .scene
        .as_ref()
        .and_then(|s| root.scenes.get(s.value()))
        .or_else(|| root.scenes.first());
    match scene {
        Some(scene) => {
            let mut budget = 1usize << 20;
            for n in &scene.nodes {
                visit(doc, n.value(), &IDENTITY, 0, &mut budget, &mut out)?;
            }
        }
        None => {
            for m in 0..root.meshes.len() {
                add_mesh(doc, m, &IDENTITY, &mut out)?;
            }
        }
    }
    let mut mesh = out.mesh;
    let nv = mesh.positions.len();
    fn fill<T: Clone>(v: Option<Vec<T>>, n: usize, def: T) -> Option<Vec<T>> {
        v.map(|mut v| {
            v.resize(n, def);
            v
        })
    }
    mesh.normals = fill(out.normals, nv, [0.0; 3]);
    mesh.uvs = fill(out.uvs, nv, [0.0; 2]);
    if mesh.uvs.is_some() {
        mesh.uv_origin = UvOrigin::TopLeft;
    }
    mesh.colors = fill(out.colors, nv, [1.0; 4]);
    if !mesh.materials.is_empty() {
        mesh.face_materials = Some(out.face_materials);
    }
    let single_unnamed = out.groups_used.len() <= 1
        && out
            .groups_used
            .first()
            .is_none_or(|&m| root.meshes[m].name.is_none());
    if !single_unnamed {
        mesh.groups = root
            .meshes
            .iter()
            .enumerate()
            .map(|(i, m)| m.name.clone().unwrap_or_else(|| format!("mesh_{i}")))
            .collect();
        mesh.face_groups = Some(out.face_groups);
    }
    Ok(mesh)
}

fn visit(
    doc: &Doc,
    n: usize,
    parent: &Mat,
    depth: usize,
    budget: &mut usize,
    out: &mut Out,
) -> Result<()> {
    if depth > 256 {
        return Err(doc.err("the node hierarchy is deeper than 256 levels (or cyclic)"));
    }
    if *budget == 0 {
        return Err(doc.err("the scene instantiates more than a million nodes"));
    }
    *budget -= 1;
    let node = doc
        .root
        .nodes
        .get(n)
        .ok_or_else(|| doc.err(format!("node {n} does not exist")))?;
    let local = local_matrix(node);
    let m = if local == IDENTITY {
        *parent
    } else {
        mul(parent, &local)
    };
    if let Some(mesh) = &node.mesh {
        add_mesh(doc, mesh.value(), &m, out)?;
    }
    for c in node.children.iter().flatten() {
        visit(doc, c.value(), &m, depth + 1, budget, out)?;
    }
    Ok(())
}

fn add_mesh(doc: &Doc, mi: usize, m: &Mat, out: &mut Out) -> Result<()> {
    use json::mesh::{Mode, Semantic};
    let gmesh = doc
        .root
        .meshes
        .get(mi)
        .ok_or_else(|| doc.err(format!("mesh {mi} does not exist")))?;
    if !out.groups_used.contains(&mi) {
        out.groups_used.push(mi);
    }
    let identity = *m == IDENTITY;
    let nmat = normal_matrix(m);
    let flip = det3(m) < 0.0;
    let key_m = m
        .as_flattened()
        .iter()
        .map(|x| x.to_bits())
        .collect::<Vec<_>>();
    let key_m: [u64; 16] = key_m.try_into().unwrap_or([0; 16]);
    for (pi, prim) in gmesh.primitives.iter().enumerate() {
        let what = format!("mesh {mi} primitive {pi}");
        let mode = match prim.mode {
            Checked::Valid(m) => m,
            Checked::Invalid => return Err(doc.err(format!("{what}: invalid mode"))),
        };
        if !matches!(
            mode,
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
        ) {
            continue;
        }
        let attr = |s: Semantic| prim.attributes.get(&Checked::Valid(s)).map(|a| a.value());
        let pos_acc = attr(Semantic::Positions)
            .ok_or_else(|| doc.err(format!("{what}: no POSITION attribute")))?;
        let accs = [
            pos_acc,
            attr(Semantic::Normals).unwrap_or(usize::MAX),
            attr(Semantic::TexCoords(0)).unwrap_or(usize::MAX),
            attr(Semantic::Colors(0)).unwrap_or(usize::MAX),
        ];
        let base = match out.shared.get(&(key_m, accs)) {
            Some(&b) => b,
            None => {
                let base = out.mesh.positions.len();
                let (p, _) = doc.floats(pos_acc, &[3], &format!("{what} POSITION"))?;
                let count = p.len() / 3;
                if base + count >= u32::MAX as usize {
                    return Err(doc.err("too many vertices for 32-bit indices"));
                }
                doc.check_expansion(base + count, "vertices")?;
                for (k, c) in p.chunks_exact(3).enumerate() {
                    let q = if identity {
                        [c[0], c[1], c[2]]
                    } else {
                        let v = [c[0] as f64, c[1] as f64, c[2] as f64];
                        [0, 1, 2].map(|r| {
                            (m[0][r] * v[0] + m[1][r] * v[1] + m[2][r] * v[2] + m[3][r]) as f32
                        })
                    };
                    if !q.iter().all(|x| x.is_finite()) {
                        return Err(doc.err(format!(
                            "{what}: vertex {k} has a non-finite coordinate {q:?}"
                        )));
                    }
                    out.mesh.positions.push(q);
                }
                let nv = out.mesh.positions.len();
                if accs[1] != usize::MAX {
                    let (n, _) = doc.floats(accs[1], &[3], &format!("{what} NORMAL"))?;
                    let dst = out.normals.get_or_insert_with(Vec::new);
                    dst.resize(base, [0.0; 3]);
                    dst.extend(n.chunks_exact(3).map(|c| {
                        if identity {
                            [c[0], c[1], c[2]]
                        } else {
                            let v = [0, 1, 2].map(|r| {
                                nmat[0][r] * c[0] as f64
                                    + nmat[1][r] * c[1] as f64
                                    + nmat[2][r] * c[2] as f64
                            });
                            let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                            let l = if l > 0.0 { l } else { 1.0 };
                            v.map(|x| (x / l) as f32)
                        }
                    }));
                    dst.resize(nv, [0.0; 3]);
                }
                if accs[2] != usize::MAX {
                    let (t, _) = doc.floats(accs[2], &[2], &format!("{what} TEXCOORD_0"))?;
                    let dst = out.uvs.get_or_insert_with(Vec::new);
                    dst.resize(base, [0.0; 2]);
                    dst.extend(t.chunks_exact(2).map(|c| [c[0], c[1]]));
                    dst.resize(nv, [0.0; 2]);
                }
                if accs[3] != usize::MAX {
                    let (c, n) = doc.floats(accs[3], &[3, 4], &format!("{what} COLOR_0"))?;
                    let dst = out.colors.get_or_insert_with(Vec::new);
                    dst.resize(base, [1.0; 4]);
                    dst.extend(
                        c.chunks_exact(n)
                            .map(|c| [c[0], c[1], c[2], if n == 4 { c[3] } else { 1.0 }]),
                    );
                    dst.resize(nv, [1.0; 4]);
                }
                out.shared.insert((key_m, accs), base as u32);
                base as u32
            }
        };
        let count = doc.root.accessors.get(pos_acc).map_or(0, |a| a.count.0) as u32;
        let idx = match &prim.indices {
            Some(i) => doc.indices(i.value(), &format!("{what} indices"))?,
            None => (0..count).collect(),
        };
        if let Some(&bad) = idx.iter().find(|&&i| i >= count) {
            return Err(doc.err(format!(
                "{what}: index {bad} is out of range ({count} vertices)"
            )));
        }
        let mut tris = Vec::new();
        match mode {
            Mode::Triangles => tris.extend(idx.chunks_exact(3).map(|t| [t[0], t[1], t[2]])),
            Mode::TriangleStrip => {
                for k in 2..idx.len() {
                    let t = if k % 2 == 0 {
                        [idx[k - 2], idx[k - 1], idx[k]]
                    } else {
                        [idx[k - 1], idx[k - 2], idx[k]]
                    };
                    if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
                        tris.push(t);
                    }
                }
            }
            _ => {
                for k in 2..idx.len() {
                    tris.push([idx[0], idx[k - 1], idx[k]]);
                }
            }
        }
        let mat = match &prim.material {
            Some(mt) if mt.value() < doc.root.materials.len() => mt.value() as u32,
            Some(mt) => {
                return Err(doc.err(format!("{what}: material {} does not exist", mt.value())));
            }
            None if doc.root.materials.is_empty() => 0,
            None => *out.default_material.get_or_insert_with(|| {
                out.mesh.materials.push(Material::named("default"));
                out.mesh.materials.len() as u32 - 1
            }),
        };
        doc.check_expansion(out.mesh.triangles.len() + tris.len(), "triangles")?;
        for t in tris {
            let t = t.map(|v| v + base);
            out.mesh
                .triangles
                .push(if flip { [t[0], t[2], t[1]] } else { t });
            out.face_materials.push(mat);
            out.face_groups.push(mi as u32);
        }
    }
    Ok(())
}

/// Builds the glTF JSON and the binary buffer for `mesh`.
fn build_gltf(mesh: &Mesh) -> (Value, Vec<u8>) {
    let mut bin: Vec<u8> = Vec::new();
    let mut views: Vec<Value> = Vec::new();
    let mut accessors: Vec<Value> = Vec::new();
    let nv = mesh.positions.len();
    let mut push_attr = |bin: &mut Vec<u8>,
                         data: &mut dyn Iterator<Item = f32>,
                         ty: &str,
                         extra: Value|
     -> usize {
        let start = bin.len();
        for x in data {
            bin.extend_from_slice(&x.to_le_bytes());
        }
        views.push(json!({"buffer": 0, "byteOffset": start, "byteLength": bin.len() - start, "target": 34962}));
        let mut a =
            json!({"bufferView": views.len() - 1, "componentType": 5126, "count": nv, "type": ty});
        if let (Value::Object(a), Value::Object(e)) = (&mut a, extra) {
            a.extend(e);
        }
        accessors.push(a);
        accessors.len() - 1
    };
    let mut attrs = serde_json::Map::new();
    if nv > 0 {
        let b = mesh.bounds().unwrap_or(crate::mesh::Aabb {
            min: [0.0; 3],
            max: [0.0; 3],
        });
        let i = push_attr(
            &mut bin,
            &mut mesh.positions.iter().flatten().copied(),
            "VEC3",
            json!({"min": b.min, "max": b.max}),
        );
        attrs.insert("POSITION".into(), json!(i));
        if let Some(n) = &mesh.normals {
            let i = push_attr(
                &mut bin,
                &mut n.iter().flatten().copied(),
                "VEC3",
                json!({}),
            );
            attrs.insert("NORMAL".into(), json!(i));
        }
        // glTF counts UVs from the image's top-left corner.
        if let Some(t) = mesh.uvs_from(UvOrigin::TopLeft) {
            let i = push_attr(
                &mut bin,
                &mut t.iter().flatten().copied(),
                "VEC2",
                json!({}),
            );
            attrs.insert("TEXCOORD_0".into(), json!(i));
        }
        if let Some(c) = &mesh.colors {
            let i = push_attr(
                &mut bin,
                &mut c.iter().flatten().copied(),
                "VEC4",
                json!({}),
            );
            attrs.insert("COLOR_0".into(), json!(i));
        }
    }
    // Faces by (group, material), in face order within each.
    let ngroups = if mesh.face_groups.is_some() {
        mesh.groups.len().max(1)
    } else {
        1
    };
    let nmats = if mesh.face_materials.is_some() {
        mesh.materials.len().max(1)
    } else {
        1
    };
    let mut buckets: Vec<Vec<Vec<u32>>> = vec![vec![Vec::new(); nmats]; ngroups];
    for (f, t) in mesh.triangles.iter().enumerate() {
        let g = mesh
            .face_groups
            .as_ref()
            .map_or(0, |g| g[f] as usize)
            .min(ngroups - 1);
        let m = mesh
            .face_materials
            .as_ref()
            .map_or(0, |m| m[f] as usize)
            .min(nmats - 1);
        buckets[g][m].extend_from_slice(t);
    }
    let mut meshes = Vec::new();
    for (g, mats) in buckets.iter().enumerate() {
        let mut prims = Vec::new();
        for (m, idx) in mats.iter().enumerate() {
            if idx.is_empty() {
                continue;
            }
            let start = bin.len();
            for &i in idx {
                bin.extend_from_slice(&i.to_le_bytes());
            }
            views.push(json!({"buffer": 0, "byteOffset": start, "byteLength": bin.len() - start, "target": 34963}));
            accessors.push(json!({"bufferView": views.len() - 1, "componentType": 5125, "count": idx.len(), "type": "SCALAR"}));
            let mut p = json!({"attributes": attrs, "indices": accessors.len() - 1, "mode": 4});
            if mesh.face_materials.is_some() && m < mesh.materials.len() {
                p["material"] = json!(m);
            }
            prims.push(p);
        }
        if prims.is_empty() {
            continue;
        }
        let mut gm = json!({"primitives": prims});
        if mesh.face_groups.is_some() {
            gm["name"] = json!(mesh.groups.get(g).map_or("default", String::as_str));
        }
        meshes.push(gm);
    }
    let nodes: Vec<Value> = (0..meshes.len()).map(|i| json!({"mesh": i})).collect();
    let mut root = json!({
        "asset": {"version": "2.0", "generator": "meshslim"},
        "scene": 0,
        "scenes": [{"nodes": (0..nodes.len()).collect::<Vec<_>>()}],
        "nodes": nodes,
        "meshes": meshes,
        "accessors": accessors,
        "bufferViews": views,
    });
    if mesh.face_materials.is_some() {
        root["materials"] = Value::Array(
            mesh.materials
                .iter()
                .map(|m| match &m.gltf {
                    Some(Value::Object(o)) => {
                        let mut o = Value::Object(o.clone());
                        drop_other_uv_sets(&mut o);
                        o["name"] = json!(m.name);
                        o
                    }
                    _ => json!({"name": m.name}),
                })
                .collect(),
        );
    }
    let t = &mesh.textures;
    if !t.is_empty() {
        let mut images = Vec::with_capacity(t.images.len());
        // One buffer view per distinct image: images that shared bytes when read share them.
        let mut written: HashMap<*const u8, usize> = HashMap::new();
        // An image with neither bytes nor a URI (a bad buffer view in the input) cannot be
        // written: it is left out and the textures' `source` indices follow.
        let mut new_index = Vec::with_capacity(t.images.len());
        for img in &t.images {
            if img.data.is_none() && img.uri.is_none() {
                new_index.push(None);
                continue;
            }
            new_index.push(Some(images.len()));
            let mut out = serde_json::Map::new();
            if let Some(n) = &img.name {
                out.insert("name".into(), json!(n));
            }
            if let Some(data) = &img.data {
                let view = *written.entry(data.as_ptr()).or_insert_with(|| {
                    bin.resize(bin.len().next_multiple_of(4), 0);
                    let start = bin.len();
                    bin.extend_from_slice(data);
                    views.push(json!({"buffer": 0, "byteOffset": start, "byteLength": data.len()}));
                    views.len() - 1
                });
                out.insert("bufferView".into(), json!(view));
                // An image in a buffer view must name its type.
                let mime = img
                    .mime_type
                    .clone()
                    .unwrap_or_else(|| sniff_mime(data).into());
                out.insert("mimeType".into(), json!(mime));
            } else if let Some(uri) = &img.uri {
                out.insert("uri".into(), json!(uri));
                if let Some(m) = &img.mime_type {
                    out.insert("mimeType".into(), json!(m));
                }
            }
            images.push(Value::Object(out));
        }
        root["bufferViews"] = json!(views);
        let textures: Vec<Value> = t
            .textures
            .iter()
            .map(|tex| {
                let mut tex = tex.clone();
                remap_sources(&mut tex, &new_index);
                tex
            })
            .collect();
        for (key, list) in [("textures", &textures), ("samplers", &t.samplers)] {
            if !list.is_empty() {
                root[key] = json!(list);
            }
        }
        if !images.is_empty() {
            root["images"] = json!(images);
        }
    }
    // Every extension the written materials, textures and samplers use is declared; those the
    // input required stay required.
    let mut used = std::collections::BTreeSet::new();
    for key in ["materials", "textures", "samplers", "images"] {
        if let Some(v) = root.get(key) {
            extension_names(v, &mut used);
        }
    }
    if !used.is_empty() {
        let required: Vec<&String> = t
            .extensions_required
            .iter()
            .filter(|e| used.contains(*e))
            .collect();
        root["extensionsUsed"] = json!(used);
        if !required.is_empty() {
            root["extensionsRequired"] = json!(required);
        }
    }
    (root, bin)
}

/// The MIME type of an encoded image, from its first bytes.
fn sniff_mime(data: &[u8]) -> &'static str {
    if data.starts_with(b"\x89PNG") {
        "image/png"
    } else if data.starts_with(&[0xFF, 0xD8]) {
        "image/jpeg"
    } else if data.len() >= 12 && &data[..4] == b"RIFF" && &data[8..12] == b"WEBP" {
        "image/webp"
    } else if data.starts_with(b"\xABKTX 20\xBB") {
        "image/ktx2"
    } else {
        "application/octet-stream"
    }
}

/// A texture's image references (`source`, and `source` in its extensions such as
/// `KHR_texture_basisu`) mapped to the images written; one to an image left out is removed.
fn remap_sources(tex: &mut Value, new_index: &[Option<usize>]) {
    let Value::Object(o) = tex else { return };
    if let Some(s) = o.get("source").and_then(Value::as_u64) {
        match new_index.get(s as usize).copied().flatten() {
            Some(n) => {
                o.insert("source".into(), json!(n));
            }
            None => {
                o.remove("source");
            }
        }
    }
    if let Some(Value::Object(ext)) = o.get_mut("extensions") {
        ext.values_mut().for_each(|e| remap_sources(e, new_index));
    }
}

/// Texture references on a UV set other than TEXCOORD_0 (`texCoord`, or the
/// `KHR_texture_transform` override), removed from a material: meshslim keeps only the first
/// UV set, and a reference to a missing one makes the file invalid. (`io::not_kept` says so.)
fn drop_other_uv_sets(v: &mut Value) {
    match v {
        Value::Object(o) => {
            o.retain(|_, x| !other_uv_set(x));
            o.values_mut().for_each(drop_other_uv_sets);
        }
        Value::Array(a) => {
            a.retain(|x| !other_uv_set(x));
            a.iter_mut().for_each(drop_other_uv_sets);
        }
        _ => {}
    }
}

/// Whether `v` is a texture reference on a UV set other than the first.
pub(crate) fn other_uv_set(v: &Value) -> bool {
    let set = |x: &Value, p: &str| x.pointer(p).and_then(Value::as_u64).unwrap_or(0);
    v.get("index").is_some()
        && (set(v, "/texCoord") != 0 || set(v, "/extensions/KHR_texture_transform/texCoord") != 0)
}

/// Whether a material refers to a UV set other than the first anywhere.
pub(crate) fn uses_other_uv_sets(v: &Value) -> bool {
    other_uv_set(v)
        || match v {
            Value::Object(o) => o.values().any(uses_other_uv_sets),
            Value::Array(a) => a.iter().any(uses_other_uv_sets),
            _ => false,
        }
}

/// Writes `.gltf` (JSON with the buffer as a base64 data URI) or, with `binary`, `.glb`.
pub fn write_gltf<W: std::io::Write>(w: &mut W, mesh: &Mesh, binary: bool) -> std::io::Result<()> {
    let (mut root, mut bin) = build_gltf(mesh);
    let has_buffer = !bin.is_empty();
    if !binary {
        if has_buffer {
            root["buffers"] = json!([{
                "byteLength": bin.len(),
                "uri": format!("data:application/octet-stream;base64,{}", base64_encode(&bin)),
            }]);
        }
        serde_json::to_writer(&mut *w, &root)?;
        return Ok(());
    }
    if has_buffer {
        root["buffers"] = json!([{ "byteLength": bin.len() }]);
    }
    let mut js = serde_json::to_vec(&root)?;
    while js.len() % 4 != 0 {
        js.push(b' ');
    }
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    let total = 12 + 8 + js.len() + if has_buffer { 8 + bin.len() } else { 0 };
    let total = u32::try_from(total).map_err(|_| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "a GLB file cannot exceed 4 GiB",
        )
    })?;
    w.write_all(GLB_MAGIC)?;
    w.write_all(&2u32.to_le_bytes())?;
    w.write_all(&total.to_le_bytes())?;
    w.write_all(&(js.len() as u32).to_le_bytes())?;
    w.write_all(&CHUNK_JSON.to_le_bytes())?;
    w.write_all(&js)?;
    if has_buffer {
        w.write_all(&(bin.len() as u32).to_le_bytes())?;
        w.write_all(&CHUNK_BIN.to_le_bytes())?;
        w.write_all(&bin)?;
    }
    Ok(())
}
