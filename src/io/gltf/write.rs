//! The glTF writer: one buffer of the vertex attributes and indices, a mesh per group and a
//! primitive per material, the materials, textures and images carried from the input, as `.gltf`
//! or `.glb`.

use std::collections::HashMap;

use serde_json::{Value, json};

use super::encoding::{CHUNK_BIN, CHUNK_JSON, GLB_MAGIC, base64_encode};
use crate::mesh::{Mesh, UvOrigin};

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
    let mut bin: Vec<u8> = Vec::new();
    let mut views: Vec<Value> = Vec::new();
    let mut accessors: Vec<Value> = Vec::new();
    let nv = mesh.positions.len();
    let mut attrs = serde_json::Map::new();
    // One vertex attribute: its floats appended to the buffer, a view and an accessor over
    // them, and the accessor named in the primitives' `attributes`.
    let mut push_attr = |name: &str,
                         data: &mut dyn Iterator<Item = f32>,
                         ty: &str,
                         extra: Value| {
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
        attrs.insert(name.into(), json!(accessors.len() - 1));
    };
    if nv > 0 {
        let b = mesh.bounds().unwrap_or(crate::mesh::Aabb {
            min: [0.0; 3],
            max: [0.0; 3],
        });
        push_attr(
            "POSITION",
            &mut mesh.positions.iter().flatten().copied(),
            "VEC3",
            json!({"min": b.min, "max": b.max}),
        );
        if let Some(n) = &mesh.normals {
            push_attr(
                "NORMAL",
                &mut n.iter().flatten().copied(),
                "VEC3",
                json!({}),
            );
        }
        // glTF counts UVs from the image's top-left corner.
        if let Some(t) = mesh.uvs_from(UvOrigin::TopLeft) {
            push_attr(
                "TEXCOORD_0",
                &mut t.iter().flatten().copied(),
                "VEC2",
                json!({}),
            );
        }
        if let Some(c) = &mesh.colors {
            push_attr(
                "COLOR_0",
                &mut c.iter().flatten().copied(),
                "VEC4",
                json!({}),
            );
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
