//! The glTF reader: the GLB container, the buffers (embedded, data URIs or files), the scene
//! walk with the node transforms, the primitives' triangles and attributes, materials, textures
//! and images.

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use gltf::json;
use json::validation::Checked;
use serde_json::Value;

use super::document::{Doc, RawAppearance};
use super::encoding::{CHUNK_BIN, CHUNK_JSON, GLB_MAGIC, base64_decode, percent_decode};
use super::transform::{IDENTITY, Mat, det3, local_matrix, mul, normal_matrix};
use crate::error::{Error, Location, Result};
use crate::mesh::{Material, Mesh, TextureImage, Textures, UvOrigin};

fn u32_at(b: &[u8], off: usize) -> Option<u32> {
    Some(u32::from_le_bytes(
        b.get(off..off.checked_add(4)?)?.try_into().ok()?,
    ))
}

/// A GLB's JSON chunk, the JSON chunk's byte offset, and the BIN chunk.
type GlbParts<'a> = (&'a [u8], usize, Option<&'a [u8]>);

/// Splits a GLB container into its JSON chunk (with its byte offset) and BIN chunk.
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
    let carried: RawAppearance = serde_json::from_slice(json_bytes)
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
                let base = add_vertices(doc, &what, accs, (m, &nmat, identity), out)?;
                out.shared.insert((key_m, accs), base);
                base
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
        let tris = primitive_triangles(mode, &idx);
        let mat = primitive_material(doc, prim, &what, out)?;
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

/// The vertices of a primitive's accessors `accs` (POSITION, NORMAL, TEXCOORD_0, COLOR_0;
/// `usize::MAX` for one it lacks) appended to `out` under `(m, its normal matrix, whether m is
/// the identity)`: the mesh's first new vertex.
fn add_vertices(
    doc: &Doc,
    what: &str,
    accs: [usize; 4],
    (m, nmat, identity): (&Mat, &[[f64; 3]; 3], bool),
    out: &mut Out,
) -> Result<u32> {
    let pos_acc = accs[0];
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
            [0, 1, 2].map(|r| (m[0][r] * v[0] + m[1][r] * v[1] + m[2][r] * v[2] + m[3][r]) as f32)
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
                    nmat[0][r] * c[0] as f64 + nmat[1][r] * c[1] as f64 + nmat[2][r] * c[2] as f64
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
    Ok(base as u32)
}

/// A primitive's triangles from its indices in `mode` (a strip's degenerate turns dropped).
fn primitive_triangles(mode: json::mesh::Mode, idx: &[u32]) -> Vec<[u32; 3]> {
    use json::mesh::Mode;
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
    tris
}

/// The material a primitive's faces take: its own, else the file's default (made once).
fn primitive_material(
    doc: &Doc,
    prim: &json::mesh::Primitive,
    what: &str,
    out: &mut Out,
) -> Result<u32> {
    Ok(match &prim.material {
        Some(mt) if mt.value() < doc.root.materials.len() => mt.value() as u32,
        Some(mt) => {
            return Err(doc.err(format!("{what}: material {} does not exist", mt.value())));
        }
        None if doc.root.materials.is_empty() => 0,
        None => *out.default_material.get_or_insert_with(|| {
            out.mesh.materials.push(Material::named("default"));
            out.mesh.materials.len() as u32 - 1
        }),
    })
}
