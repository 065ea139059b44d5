//! The glTF writer: one buffer of the vertex attributes and indices, a mesh per group and a
//! primitive per material, the materials, textures and images carried from the input, as `.gltf`
//! or `.glb`.

use std::collections::HashMap;

use serde_json::{Value, json};

use super::encoding::{CHUNK_BIN, CHUNK_JSON, GLB_MAGIC, base64_encode};
use crate::mesh::{Mesh, Textures, UvOrigin};

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

/// Builds the glTF JSON and the binary buffer for `mesh`.
fn build_gltf(mesh: &Mesh) -> (Value, Vec<u8>) {
    let mut buf = Buffer::default();
    let attrs = write_attributes(mesh, &mut buf);
    let buckets = faces_by_group_and_material(mesh);
    let meshes = write_meshes(mesh, &buckets, &attrs, &mut buf);
    let t = &mesh.textures;
    let images = (!t.is_empty()).then(|| write_images(t, &mut buf));
    let mut root = scene_root(meshes, &buf);
    if mesh.face_materials.is_some() {
        root["materials"] = materials(mesh);
    }
    if let Some((images, new_index)) = images {
        add_textures(&mut root, t, images, &new_index);
    }
    declare_extensions(&mut root, t);
    (root, buf.bin)
}

/// The binary buffer as it is written, with the buffer views and accessors over it.
#[derive(Default)]
struct Buffer {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Buffer {
    /// Appends one vertex attribute of `count` vertices: its floats, a view and an accessor
    /// over them (with the `extra` accessor fields); returns the accessor's index.
    fn push_attribute(
        &mut self,
        data: &mut dyn Iterator<Item = f32>,
        count: usize,
        ty: &str,
        extra: Value,
    ) -> usize {
        let start = self.bin.len();
        for x in data {
            self.bin.extend_from_slice(&x.to_le_bytes());
        }
        self.views.push(json!({"buffer": 0, "byteOffset": start, "byteLength": self.bin.len() - start, "target": 34962}));
        let mut a = json!({"bufferView": self.views.len() - 1, "componentType": 5126, "count": count, "type": ty});
        if let (Value::Object(a), Value::Object(e)) = (&mut a, extra) {
            a.extend(e);
        }
        self.accessors.push(a);
        self.accessors.len() - 1
    }

    /// Appends one primitive's triangle indices, a view and an accessor over them; returns the
    /// accessor's index.
    fn push_indices(&mut self, idx: &[u32]) -> usize {
        let start = self.bin.len();
        for &i in idx {
            self.bin.extend_from_slice(&i.to_le_bytes());
        }
        self.views.push(json!({"buffer": 0, "byteOffset": start, "byteLength": self.bin.len() - start, "target": 34963}));
        self.accessors.push(json!({"bufferView": self.views.len() - 1, "componentType": 5125, "count": idx.len(), "type": "SCALAR"}));
        self.accessors.len() - 1
    }

    /// Appends an encoded image's bytes, 4-byte aligned, and a view over them; returns the
    /// view's index.
    fn push_image(&mut self, data: &[u8]) -> usize {
        self.bin.resize(self.bin.len().next_multiple_of(4), 0);
        let start = self.bin.len();
        self.bin.extend_from_slice(data);
        self.views
            .push(json!({"buffer": 0, "byteOffset": start, "byteLength": data.len()}));
        self.views.len() - 1
    }
}

/// Writes the vertex attributes the mesh has (positions with their bounds, normals, UVs,
/// colours) to the buffer; returns the primitives' `attributes` object naming their accessors.
fn write_attributes(mesh: &Mesh, buf: &mut Buffer) -> serde_json::Map<String, Value> {
    let nv = mesh.positions.len();
    let mut attrs = serde_json::Map::new();
    if nv == 0 {
        return attrs;
    }
    let b = mesh.bounds().unwrap_or(crate::mesh::Aabb {
        min: [0.0; 3],
        max: [0.0; 3],
    });
    let a = buf.push_attribute(
        &mut mesh.positions.iter().flatten().copied(),
        nv,
        "VEC3",
        json!({"min": b.min, "max": b.max}),
    );
    attrs.insert("POSITION".into(), json!(a));
    if let Some(n) = &mesh.normals {
        let a = buf.push_attribute(&mut n.iter().flatten().copied(), nv, "VEC3", json!({}));
        attrs.insert("NORMAL".into(), json!(a));
    }
    // glTF counts UVs from the image's top-left corner.
    if let Some(t) = mesh.uvs_from(UvOrigin::TopLeft) {
        let a = buf.push_attribute(&mut t.iter().flatten().copied(), nv, "VEC2", json!({}));
        attrs.insert("TEXCOORD_0".into(), json!(a));
    }
    if let Some(c) = &mesh.colors {
        let a = buf.push_attribute(&mut c.iter().flatten().copied(), nv, "VEC4", json!({}));
        attrs.insert("COLOR_0".into(), json!(a));
    }
    attrs
}

/// The triangles' indices by group, then by material, in face order within each.
fn faces_by_group_and_material(mesh: &Mesh) -> Vec<Vec<Vec<u32>>> {
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
    buckets
}

/// Writes each bucket's indices to the buffer; returns a glTF mesh per group that has faces,
/// with a primitive per material that has faces.
fn write_meshes(
    mesh: &Mesh,
    buckets: &[Vec<Vec<u32>>],
    attrs: &serde_json::Map<String, Value>,
    buf: &mut Buffer,
) -> Vec<Value> {
    let mut meshes = Vec::new();
    for (g, mats) in buckets.iter().enumerate() {
        let mut prims = Vec::new();
        for (m, idx) in mats.iter().enumerate() {
            if idx.is_empty() {
                continue;
            }
            let indices = buf.push_indices(idx);
            let mut p = json!({"attributes": attrs, "indices": indices, "mode": 4});
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
    meshes
}

/// The root object: the asset, one scene with a node per mesh, the meshes and the buffer's
/// accessors and views.
fn scene_root(meshes: Vec<Value>, buf: &Buffer) -> Value {
    let nodes: Vec<Value> = (0..meshes.len()).map(|i| json!({"mesh": i})).collect();
    json!({
        "asset": {"version": "2.0", "generator": "meshslim"},
        "scene": 0,
        "scenes": [{"nodes": (0..nodes.len()).collect::<Vec<_>>()}],
        "nodes": nodes,
        "meshes": meshes,
        "accessors": buf.accessors,
        "bufferViews": buf.views,
    })
}

/// The materials: each as read from a glTF file (less references to other UV sets) or just its
/// name, in material order.
fn materials(mesh: &Mesh) -> Value {
    Value::Array(
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
    )
}

/// Writes the images' bytes to the buffer (once per distinct image: images that shared bytes
/// when read share them); returns the image objects and, for each image read, its index among
/// those written.
fn write_images(t: &Textures, buf: &mut Buffer) -> (Vec<Value>, Vec<Option<usize>>) {
    let mut images = Vec::with_capacity(t.images.len());
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
            let view = *written
                .entry(data.as_ptr())
                .or_insert_with(|| buf.push_image(data));
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
    (images, new_index)
}

/// Adds the textures (their `source`s mapped to the images written), the samplers and the
/// images to `root`, each list only when it is not empty.
fn add_textures(root: &mut Value, t: &Textures, images: Vec<Value>, new_index: &[Option<usize>]) {
    let textures: Vec<Value> = t
        .textures
        .iter()
        .map(|tex| {
            let mut tex = tex.clone();
            remap_sources(&mut tex, new_index);
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

/// Declares every extension the written materials, textures and samplers use; those the input
/// required stay required.
fn declare_extensions(root: &mut Value, t: &Textures) {
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
