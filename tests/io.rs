//! File-format layer: round trips for every format and variant, OBJ and PLY parsing details,
//! and (when present) the reference models in `shared/models`; hostile inputs are in
//! tests/io_hostile.rs.

use crate::io_support;

use std::path::{Path, PathBuf};

use io_support::*;
use meshslim::io::{self, Format, WriteOptions};
use meshslim::{Mesh, UvOrigin};

#[test]
fn format_from_extension() {
    assert_eq!(
        Format::from_path(Path::new("a/b.OBJ")).unwrap(),
        Format::Obj
    );
    assert_eq!(Format::from_path(Path::new("x.Ply")).unwrap(), Format::Ply);
    assert_eq!(Format::from_path(Path::new("x.stl")).unwrap(), Format::Stl);
    assert_eq!(
        Format::from_path(Path::new("x.gltf")).unwrap(),
        Format::Gltf
    );
    assert_eq!(Format::from_path(Path::new("x.GLB")).unwrap(), Format::Glb);
    let msg = err_text(Format::from_path(Path::new("model.fbx")));
    assert!(msg.contains("model.fbx") && msg.contains("fbx"), "{msg}");
    assert!(Format::from_path(Path::new("noext")).is_err());
}

#[test]
fn ply_round_trips() {
    let dir = tmp();
    let full = full_mesh();
    let mut attrs = full.clone();
    attrs.groups.clear();
    attrs.face_groups = None;
    attrs.materials.clear();
    attrs.face_materials = None;
    attrs.material_libs.clear();
    // Colours that are exactly k/255 are written as uchar, others as float: both come back exact.
    let mut byte_colors = attrs.clone();
    byte_colors.colors = Some(
        (0..6)
            .map(|i| [i as f32 * 40.0 / 255.0, 1.0, 0.0, 128.0 / 255.0])
            .collect(),
    );
    let mut normals_only = geometry_only(&full);
    normals_only.normals = full.normals.clone();
    for (k, mesh) in [attrs, byte_colors, normals_only, geometry_only(&full)]
        .iter()
        .enumerate()
    {
        for enc in [
            io::ply::PlyEncoding::Ascii,
            io::ply::PlyEncoding::BinaryLittleEndian,
            io::ply::PlyEncoding::BinaryBigEndian,
        ] {
            let path = dir.path().join(format!("m{k}-{enc:?}.ply"));
            let mut f = std::fs::File::create(&path).unwrap();
            io::ply::write_ply(&mut f, mesh, enc).unwrap();
            drop(f);
            let back = io::read(&path).unwrap();
            assert_eq!(&back, mesh, "{enc:?} mesh {k}");
        }
        // Through the public writer: binary by default, ascii on request.
        let path = dir.path().join(format!("w{k}.ply"));
        io::write(&path, mesh).unwrap();
        assert!(
            std::fs::read(&path)
                .unwrap()
                .starts_with(b"ply\nformat binary_little_endian")
        );
        assert_eq!(&io::read(&path).unwrap(), mesh);
        let opts = WriteOptions {
            ply_ascii: true,
            ..Default::default()
        };
        io::write_with(&path, mesh, &opts).unwrap();
        assert!(
            std::fs::read(&path)
                .unwrap()
                .starts_with(b"ply\nformat ascii")
        );
        assert_eq!(&io::read(&path).unwrap(), mesh);
    }
}

#[test]
fn obj_round_trips() {
    let dir = tmp();
    let full = full_mesh();
    // Vertex colours in OBJ have no alpha; this mesh's alphas are all 1.
    let path = dir.path().join("full.obj");
    io::write(&path, &full).unwrap();
    assert_eq!(io::read(&path).unwrap(), full);

    // Group and material ids whose first use is not in id order, and an unused group.
    let mut shuffled = full.clone();
    shuffled.groups = vec!["unused".into(), "second".into(), "first".into()];
    shuffled.face_groups = Some(vec![2, 2, 1, 1, 2, 1, 1, 2]);
    shuffled.face_materials = Some(vec![1, 0, 1, 0, 1, 0, 1, 0]);
    io::write(&path, &shuffled).unwrap();
    assert_eq!(io::read(&path).unwrap(), shuffled);

    // Each attribute alone, and none.
    for (uv, n) in [(true, false), (false, true), (false, false)] {
        let mut m = geometry_only(&full);
        m.uvs = full.uvs.clone().filter(|_| uv);
        m.normals = full.normals.clone().filter(|_| n);
        io::write(&path, &m).unwrap();
        assert_eq!(io::read(&path).unwrap(), m, "uv {uv} normals {n}");
    }

    // Awkward floats survive bit-exact.
    let mut m = geometry_only(&full);
    m.positions[0] = [0.1 + 0.2, f32::MIN_POSITIVE, -1.0e-30];
    m.positions[1] = [f32::MAX, -f32::MAX, 16777217.0];
    io::write(&path, &m).unwrap();
    assert_eq!(io::read(&path).unwrap(), m);
}

#[test]
fn stl_round_trips() {
    let dir = tmp();
    // An STL-unfriendly mesh: attributes and a seam (two vertices at one position) are lost and
    // corners are welded by position, so compare the triangles' corner positions.
    let mut mesh = full_mesh();
    mesh.positions.push(mesh.positions[0]);
    mesh.triangles[0][0] = 6;
    mesh.normals.as_mut().unwrap().push([0.0; 3]);
    mesh.uvs.as_mut().unwrap().push([0.0; 2]);
    mesh.colors.as_mut().unwrap().push([0.0; 4]);
    for ascii in [false, true] {
        let path = dir.path().join(format!("m-{ascii}.stl"));
        io::write_with(
            &path,
            &mesh,
            &WriteOptions {
                stl_ascii: ascii,
                ..Default::default()
            },
        )
        .unwrap();
        let head = std::fs::read(&path).unwrap();
        assert_eq!(head.starts_with(b"solid"), ascii);
        let back = io::read(&path).unwrap();
        assert_eq!(back.vertex_count(), 6, "welded by position");
        assert_eq!(back.face_count(), mesh.face_count());
        for (a, b) in back.triangles.iter().zip(&mesh.triangles) {
            assert_eq!(
                a.map(|v| back.positions[v as usize]),
                b.map(|v| mesh.positions[v as usize])
            );
        }
        assert!(back.normals.is_none() && back.face_groups.is_none());
        // Writing the welded mesh again gives the same mesh.
        io::write(&path, &back).unwrap();
        assert_eq!(io::read(&path).unwrap(), back);
    }
}

#[test]
fn gltf_round_trips() {
    let dir = tmp();
    let full = full_mesh();
    let mut no_libs = full.clone();
    no_libs.material_libs.clear();
    // UVs as glTF counts them come back bit for bit (a mesh read from OBJ or PLY has them
    // converted: `uvs_convert_between_formats`).
    no_libs.uv_origin = UvOrigin::TopLeft;
    let geo = geometry_only(&full);
    let mut one_group = geo.clone();
    one_group.groups = vec!["solo".into()];
    one_group.face_groups = Some(vec![0; 8]);
    for ext in ["gltf", "glb"] {
        for (k, mesh) in [&no_libs, &geo, &one_group].into_iter().enumerate() {
            let path = dir.path().join(format!("m{k}.{ext}"));
            io::write(&path, mesh).unwrap();
            let back = io::read(&path).unwrap();
            assert_eq!(&back, mesh, "{ext} mesh {k}");
        }
    }
    let glb = std::fs::read(dir.path().join("m0.glb")).unwrap();
    assert!(glb.starts_with(b"glTF"));
    let gltf = std::fs::read_to_string(dir.path().join("m0.gltf")).unwrap();
    assert!(gltf.contains("data:application/octet-stream;base64,"));
}

/// OBJ and PLY count UVs from the texture's bottom-left corner, glTF from its top-left: a mesh
/// converted from one to the other keeps its texture the right way up (v → 1 − v), and comes
/// back to the UVs it started with.
#[test]
fn uvs_convert_between_formats() {
    let dir = tmp();
    // v values whose 1 − v is exact in f32, so the comparisons can be exact.
    let uvs = vec![
        [0.1, 0.0],
        [0.2, 0.25],
        [0.3, 0.5],
        [0.4, 0.75],
        [0.5, 1.0],
        [0.6, 0.125],
    ];
    let flipped: Vec<[f32; 2]> = uvs.iter().map(|&[u, v]| [u, 1.0 - v]).collect();
    for from in ["obj", "ply"] {
        let mut m = geometry_only(&full_mesh());
        m.uvs = Some(uvs.clone());
        let src = dir.path().join(format!("src.{from}"));
        io::write(&src, &m).unwrap();
        let read = io::read(&src).unwrap();
        assert_eq!(read.uv_origin, UvOrigin::BottomLeft, "{from}");
        assert_eq!(read.uvs.as_ref().unwrap(), &uvs, "{from}");
        for ext in ["gltf", "glb"] {
            let path = dir.path().join(format!("{from}.{ext}"));
            io::write(&path, &read).unwrap();
            // The reader takes TEXCOORD_0 as the file has it.
            let g = io::read(&path).unwrap();
            assert_eq!(g.uv_origin, UvOrigin::TopLeft, "{from} -> {ext}");
            assert_eq!(g.uvs.as_ref().unwrap(), &flipped, "{from} -> {ext}");
            for back_ext in ["obj", "ply"] {
                let back = dir.path().join(format!("{from}-{ext}.{back_ext}"));
                io::write(&back, &g).unwrap();
                let b = io::read(&back).unwrap();
                assert_eq!(
                    b.uvs.as_ref().unwrap(),
                    &uvs,
                    "{from} -> {ext} -> {back_ext}"
                );
            }
        }
    }
}

/// A textured glTF scan stays textured: materials (PBR factors, texture references,
/// extensions), textures, samplers and images come through reading, simplifying and writing
/// as .gltf or .glb; an image the file names by URI is read and embedded once however many
/// images name it; every extension the written objects use is declared, and only those.
#[test]
fn gltf_textures_survive_simplification() {
    let dir = tmp();
    let mut m = meshslim::mesh::noisy_sphere(3, 0.001, 2);
    m.uvs = Some(
        m.positions
            .iter()
            .map(|p| [0.5 + 0.5 * p[0], 0.5 + 0.5 * p[1]])
            .collect(),
    );
    let path = dir.path().join("scan.gltf");
    io::write(&path, &m).unwrap();
    // A real PNG beside the file, named by URI (twice).
    let png_path = dir.path().join("albedo.png");
    image::RgbaImage::from_pixel(64, 64, image::Rgba([200, 100, 50, 255]))
        .save(&png_path)
        .unwrap();
    let png = std::fs::read(&png_path).unwrap();
    let mut doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let material = serde_json::json!({
        "name": "skin",
        "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0.0},
        "doubleSided": true,
    });
    // A second material with no texture but an extension: still declared on output.
    let unlit = serde_json::json!({"name": "flat", "extensions": {"KHR_materials_unlit": {}}});
    doc["materials"] = serde_json::json!([material, unlit]);
    doc["meshes"][0]["primitives"][0]["material"] = serde_json::json!(0);
    doc["textures"] = serde_json::json!([{"source": 0, "sampler": 0}, {"source": 1}]);
    doc["samplers"] = serde_json::json!([{"magFilter": 9729, "minFilter": 9987}]);
    doc["images"] = serde_json::json!([
        {"uri": "albedo.png", "name": "albedo"},
        {"uri": "./albedo.png"}
    ]);
    doc["extensionsUsed"] = serde_json::json!(["KHR_materials_unlit", "EXT_not_carried"]);
    std::fs::write(&path, serde_json::to_string(&doc).unwrap()).unwrap();

    let read = io::read(&path).unwrap();
    assert_eq!(read.materials.len(), 2);
    assert_eq!(read.materials[0].name, "skin");
    let mut definition = material.clone();
    definition.as_object_mut().unwrap().remove("name");
    assert_eq!(read.materials[0].gltf.as_ref(), Some(&definition));
    let t = &read.textures;
    assert_eq!(t.textures.len(), 2);
    assert_eq!(t.samplers.len(), 1);
    assert_eq!(t.images.len(), 2);
    assert_eq!(
        t.images[0].data.as_deref(),
        Some(&png[..]),
        "the URI's file is read"
    );
    assert_eq!(t.images[0].name.as_deref(), Some("albedo"));
    let (a, b) = (t.images[0].data.as_ref(), t.images[1].data.as_ref());
    assert!(
        std::sync::Arc::ptr_eq(a.unwrap(), b.unwrap()),
        "one file, one copy"
    );

    let opts = meshslim::SimplifyOptions::with_ratio(read.triangles.len(), 0.25).unwrap();
    let (out, _) = meshslim::simplify(&read, &opts).unwrap();
    assert!(out.triangles.len() < read.triangles.len());
    assert_eq!(out.materials, read.materials);
    assert_eq!(out.textures, read.textures);

    // Written elsewhere: the image goes into the file, so nothing points back at albedo.png.
    let away = tmp();
    for ext in ["glb", "gltf"] {
        let p = away.path().join(format!("small.{ext}"));
        io::write(&p, &out).unwrap();
        let back = io::read(&p).unwrap();
        assert_eq!(back.materials, out.materials, "{ext}");
        assert_eq!(back.textures.textures, out.textures.textures, "{ext}");
        assert_eq!(back.textures.samplers, out.textures.samplers, "{ext}");
        for img in &back.textures.images {
            assert_eq!(img.data.as_deref(), Some(&png[..]), "{ext}: image embedded");
            assert_eq!(img.mime_type.as_deref(), Some("image/png"), "{ext}");
            assert_eq!(img.uri, None, "{ext}");
        }
        assert_eq!(back.triangles.len(), out.triangles.len(), "{ext}");
        if ext == "gltf" {
            let written: serde_json::Value =
                serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
            assert_eq!(
                written["extensionsUsed"],
                serde_json::json!(["KHR_materials_unlit"])
            );
            assert_eq!(
                written["images"][0]["bufferView"],
                written["images"][1]["bufferView"]
            );
        }
    }
}

/// Images the reader cannot or must not read keep their URIs (a file outside the glTF's
/// folder is not copied into the output); texture references on a second UV set, which the
/// output would not have, are dropped from the written material; a bad image never fails the
/// read of the geometry.
#[test]
fn gltf_images_outside_the_folder_and_other_uv_sets() {
    let dir = tmp();
    let sub = dir.path().join("scan");
    std::fs::create_dir(&sub).unwrap();
    std::fs::write(dir.path().join("secret.png"), b"\x89PNG secret").unwrap();
    let mut m = geometry_only(&full_mesh());
    m.uvs = full_mesh().uvs;
    let path = sub.join("m.gltf");
    io::write(&path, &m).unwrap();
    let mut doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let abs = dir.path().join("secret.png").display().to_string();
    doc["images"] = serde_json::json!([
        {"uri": "../secret.png"},
        {"uri": abs},
        {"bufferView": 999},
        {"uri": "missing.png"}
    ]);
    doc["textures"] = serde_json::json!([{"source": 0}, {"source": 2}, {"source": 3}]);
    doc["materials"] = serde_json::json!([{
        "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}},
        "occlusionTexture": {"index": 0, "texCoord": 1},
        "emissiveTexture": {"index": 0, "extensions": {"KHR_texture_transform": {"texCoord": 1}}}
    }]);
    doc["meshes"][0]["primitives"][0]["material"] = serde_json::json!(0);
    std::fs::write(&path, serde_json::to_string(&doc).unwrap()).unwrap();
    let read = io::read(&path).unwrap();
    assert_eq!(read.triangles.len(), m.triangles.len());
    for (i, img) in read.textures.images.iter().enumerate() {
        assert_eq!(img.data, None, "image {i} was read");
    }
    assert_eq!(
        read.textures.images[0].uri.as_deref(),
        Some("../secret.png")
    );
    let lost = io::not_kept(&read, io::Format::Glb);
    assert!(
        lost.iter()
            .any(|l| l.contains("4 texture image(s) that could not be read")),
        "{lost:?}"
    );
    assert!(lost.iter().any(|l| l.contains("second UV set")), "{lost:?}");

    let out = dir.path().join("out.gltf");
    io::write(&out, &read).unwrap();
    let written: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let mat = &written["materials"][0];
    assert!(mat.get("occlusionTexture").is_none(), "{mat}");
    assert!(mat.get("emissiveTexture").is_none(), "{mat}");
    assert_eq!(mat["pbrMetallicRoughness"]["baseColorTexture"]["index"], 0);
    // Nothing embedded: the URIs as given, the secret's bytes nowhere.
    for (i, img) in written["images"].as_array().unwrap().iter().enumerate() {
        assert!(img.get("bufferView").is_none(), "image {i}: {img}");
    }
    assert_eq!(written["images"][0]["uri"], "../secret.png");
    assert_eq!(written["images"][1]["uri"], serde_json::json!(abs));
    // The image with neither bytes nor a URI is left out, and the textures follow.
    assert_eq!(written["images"].as_array().unwrap().len(), 3);
    assert_eq!(written["images"][2]["uri"], "missing.png");
    assert_eq!(
        written["textures"],
        serde_json::json!([{"source": 0}, {}, {"source": 2}])
    );
}

#[test]
fn gltf_node_transforms_and_instances() {
    // One triangle mesh drawn twice: by a node translated by (10,0,0) and by a child node of a
    // mirroring parent (scale -1 in x), whose winding must be flipped.
    let dir = tmp();
    let path = dir.path().join("t.gltf");
    let tri = geometry_only(&Mesh::new(
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        vec![[0, 1, 2]],
    ));
    io::write(&path, &tri).unwrap();
    let mut doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    doc["nodes"] = serde_json::json!([
        {"mesh": 0, "translation": [10.0, 0.0, 0.0]},
        {"scale": [-1.0, 1.0, 1.0], "children": [2]},
        {"mesh": 0}
    ]);
    doc["scenes"] = serde_json::json!([{"nodes": [0, 1]}]);
    std::fs::write(&path, serde_json::to_string(&doc).unwrap()).unwrap();
    let m = io::read(&path).unwrap();
    assert_eq!(m.face_count(), 2);
    assert_eq!(
        m.positions[..3],
        [[10.0, 0.0, 0.0], [11.0, 0.0, 0.0], [10.0, 1.0, 0.0]]
    );
    assert_eq!(
        m.positions[3..],
        [[0.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
    );
    assert_eq!(m.triangles, vec![[0, 1, 2], [3, 5, 4]]);
    assert!(m.face_normal(0).unwrap()[2] > 0.0 && m.face_normal(1).unwrap()[2] > 0.0);
}

#[test]
fn obj_corner_forms_negative_indices_and_polygons() {
    let dir = tmp();
    let v = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv -1 0.5 0\n";
    let vt = "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.5 0.5\n";
    let vn = "vn 0 0 1\n";
    let cases = [
        ("plain.obj", format!("{v}f 1 2 3\n"), false, false),
        ("vt.obj", format!("{v}{vt}f 1/1 2/2 3/3\n"), true, false),
        ("vn.obj", format!("{v}{vn}f 1//1 2//1 3//1\n"), false, true),
        (
            "vtvn.obj",
            format!("{v}{vt}{vn}f 1/1/1 2/2/1 3/3/1\n"),
            true,
            true,
        ),
        // Relative indices: -5 is the first of five vertices.
        (
            "neg.obj",
            format!("{v}{vt}{vn}f -5/-5/-1 -4/-4/-1 -3/-3/-1\n"),
            true,
            true,
        ),
    ];
    for (name, text, has_uv, has_n) in cases {
        let m = io::read(&write_text(dir.path(), name, &text)).unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2]], "{name}");
        assert_eq!(m.vertex_count(), 5, "{name}: every `v` line is a vertex");
        assert_eq!(m.positions[2], [1.0, 1.0, 0.0]);
        assert_eq!(m.uvs.is_some(), has_uv, "{name}");
        assert_eq!(m.normals.is_some(), has_n, "{name}");
        if has_uv {
            assert_eq!(m.uvs.as_ref().unwrap()[1], [1.0, 0.0]);
        }
        if has_n {
            assert_eq!(m.normals.as_ref().unwrap()[0], [0.0, 0.0, 1.0]);
        }
    }
    // A quad and a pentagon, fan-triangulated; negative indices relative to the current count.
    let m = io::read(&write_text(
        dir.path(),
        "poly.obj",
        &format!("{v}f 1 2 3 4\nf -5 -4 -3 -2 -1\n"),
    ))
    .unwrap();
    assert_eq!(
        m.triangles,
        vec![[0, 1, 2], [0, 2, 3], [0, 1, 2], [0, 2, 3], [0, 3, 4]]
    );
    // A seam: position 1 with two different texture coordinates becomes two vertices.
    let m = io::read(&write_text(
        dir.path(),
        "seam.obj",
        &format!("{v}{vt}f 1/1 2/2 3/3\nf 1/5 3/3 4/4\n"),
    ))
    .unwrap();
    assert_eq!(m.vertex_count(), 6);
    assert_eq!(m.triangles, vec![[0, 1, 2], [5, 2, 3]]);
    assert_eq!(m.positions[5], m.positions[0]);
    assert_eq!(m.uvs.as_ref().unwrap()[5], [0.5, 0.5]);
}

#[test]
fn obj_groups_materials_and_missing_mtl() {
    let dir = tmp();
    let text = "mtllib does-not-exist.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n\
                f 1 2 3\no body\nusemtl skin\nf 1 2 4\ng arm\nf 2 3 4\nusemtl metal\nf 1 3 4\ng body\nf 1 2 3\n";
    let m = io::read(&write_text(dir.path(), "g.obj", text)).unwrap();
    assert_eq!(m.material_libs, vec!["does-not-exist.mtl".to_string()]);
    assert_eq!(m.groups, vec!["body", "arm", "default"]);
    assert_eq!(m.face_groups, Some(vec![2, 0, 1, 1, 0]));
    let names: Vec<&str> = m.materials.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["skin", "metal", "default"]);
    assert_eq!(m.face_materials, Some(vec![2, 0, 0, 1, 1]));
}

/// The `mtllib` lines of an OBJ file.
fn mtllibs(path: &Path) -> Vec<String> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter_map(|l| l.strip_prefix("mtllib "))
        .map(str::to_string)
        .collect()
}

#[test]
fn obj_material_libraries_are_found_from_another_folder() {
    let dir = tmp();
    for sub in ["scans/raw", "out", "lib"] {
        std::fs::create_dir_all(dir.path().join(sub)).unwrap();
    }
    write_text(
        &dir.path().join("scans/raw"),
        "skin.mtl",
        "newmtl skin\nKd 1 0 0\n",
    );
    write_text(&dir.path().join("lib"), "shared.mtl", "newmtl metal\n");
    write_text(&dir.path().join("scans/raw"), "extra.mtl", "newmtl bone\n");
    // The third line lists two libraries.
    let text = "mtllib skin.mtl\nmtllib ../../lib/shared.mtl\nmtllib skin.mtl extra.mtl\n\
                v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl skin\nf 1 2 3\n";
    let input = write_text(&dir.path().join("scans/raw"), "a.obj", text);
    let m = io::read(&input).unwrap();

    // Written elsewhere, each name leads from the output's folder to the same library.
    let out = dir.path().join("out/a-small.obj");
    io::write_from(&out, &m, &input).unwrap();
    let libs = mtllibs(&out);
    assert_eq!(
        libs,
        [
            "../scans/raw/skin.mtl",
            "../lib/shared.mtl",
            "../scans/raw/skin.mtl ../scans/raw/extra.mtl"
        ]
    );
    for lib in libs.iter().flat_map(|l| l.split(' ')) {
        assert!(out.parent().unwrap().join(lib).is_file(), "{lib}");
    }
    assert_eq!(io::read(&out).unwrap().material_libs, libs);

    // Beside the input, the names stay as they were read, bit for bit.
    let beside = dir.path().join("scans/raw/a-small.obj");
    io::write_from(&beside, &m, &input).unwrap();
    assert_eq!(
        mtllibs(&beside),
        ["skin.mtl", "../../lib/shared.mtl", "skin.mtl extra.mtl"]
    );
    // Other formats have no mtllib to move.
    io::write_from(&dir.path().join("out/a.ply"), &m, &input).unwrap();
}

#[test]
fn obj_agrees_with_tobj() {
    let dir = tmp();
    let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 2 2\nf 1 2 3 4\nf 2 5 3\nf -1 -2 -3\n";
    let path = write_text(dir.path(), "t.obj", text);
    let ours = io::read(&path).unwrap();
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let (models, _) = tobj::load_obj(&path, &opts).unwrap();
    let theirs: Vec<[f32; 3]> = models[0]
        .mesh
        .indices
        .iter()
        .map(|&i| {
            let p = &models[0].mesh.positions[3 * i as usize..];
            [p[0], p[1], p[2]]
        })
        .collect();
    let ours: Vec<[f32; 3]> = ours
        .triangles
        .iter()
        .flatten()
        .map(|&v| ours.positions[v as usize])
        .collect();
    assert_eq!(ours, theirs);
}

#[test]
fn ply_tristrips() {
    let dir = tmp();
    // Two strips: 0 1 2 3 4 (triangles 012, 213 flipped, 234) then, after -1, 5 6 7 7 8:
    // 567, then the degenerate 677 and 778 are dropped... and 7 7 8 → (7,7,8) dropped too.
    // A third strip 0 5 1 6: 051, 561 (flipped: 5,0,... see below).
    let header = "ply\nformat ascii 1.0\ncomment a hand-made strip\nelement vertex 9\nproperty float x\nproperty float y\nproperty float z\n\
                  element tristrips 1\nproperty list int int vertex_indices\nend_header\n";
    let verts: String = (0..9).map(|i| format!("{i} {} 0\n", i * i)).collect();
    let strip = "16 0 1 2 3 4 -1 5 6 7 7 8 -1 0 5 1 6\n";
    let path = write_text(dir.path(), "strip.ply", &format!("{header}{verts}{strip}"));
    let m = io::read(&path).unwrap();
    let expected = vec![
        [0, 1, 2],
        [2, 1, 3],
        [2, 3, 4],
        [5, 6, 7],
        [0, 5, 1],
        [1, 5, 6],
    ];
    assert_eq!(m.triangles, expected);

    // The same strip in binary big endian, with a uchar list count and an unknown element
    // (with a list) before it, and an extra vertex property.
    let mut b = b"ply\nformat binary_big_endian 1.0\nelement vertex 9\nproperty double x\nproperty double y\nproperty double z\nproperty uchar flags\n\
element junk 2\nproperty list ushort short values\nproperty float w\n\
element tristrips 1\nproperty list uchar int vertex_indices\nend_header\n"
        .to_vec();
    for i in 0..9 {
        for c in [i as f64, (i * i) as f64, 0.0] {
            b.extend_from_slice(&c.to_be_bytes());
        }
        b.push(7);
    }
    for k in 0..2u16 {
        b.extend_from_slice(&(k + 1).to_be_bytes());
        for j in 0..=k {
            b.extend_from_slice(&(j as i16 - 5).to_be_bytes());
        }
        b.extend_from_slice(&1.5f32.to_be_bytes());
    }
    let ids: Vec<i32> = strip
        .split_whitespace()
        .skip(1)
        .map(|s| s.parse().unwrap())
        .collect();
    b.push(ids.len() as u8);
    for i in ids {
        b.extend_from_slice(&i.to_be_bytes());
    }
    let path = dir.path().join("strip-be.ply");
    std::fs::write(&path, &b).unwrap();
    let mb = io::read(&path).unwrap();
    assert_eq!(mb.triangles, expected);
    assert_eq!(mb.positions, m.positions);
}

#[test]
fn ply_scalar_types_and_polygons() {
    let dir = tmp();
    let text = "ply\nformat ascii 1.0\nelement vertex 5\nproperty int8 x\nproperty uint16 y\nproperty int32 z\n\
                property uchar red\nproperty uchar green\nproperty uchar blue\nproperty float u\nproperty float v\n\
                element face 3\nproperty uchar flags\nproperty list uint32 uint vertex_index\n\
                element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n\
                -1 0 0 255 0 0 0 0\n1 0 0 0 255 0 1 0\n1 2 0 0 0 255 1 1\n0 3 7 0 0 0 0 1\n-128 65535 -2147483648 1 2 3 0.5 0.5\n\
                9 4 0 1 2 3\n0 2 0 1\n1 3 2 3 4\n0 1\n";
    let m = io::read(&write_text(dir.path(), "types.ply", text)).unwrap();
    assert_eq!(
        m.triangles,
        vec![[0, 1, 2], [0, 2, 3], [2, 3, 4]],
        "quad fanned, 2-index face dropped"
    );
    assert_eq!(m.positions[4], [-128.0, 65535.0, -2147483648.0]);
    assert_eq!(m.colors.as_ref().unwrap()[1], [0.0, 1.0, 0.0, 1.0]);
    assert_eq!(m.uvs.as_ref().unwrap()[2], [1.0, 1.0]);
    assert!(m.normals.is_none());
}

// ---------------------------------------------------------------- reference models

fn models_dir() -> Option<PathBuf> {
    let here = Path::new(env!("CARGO_MANIFEST_DIR"));
    [
        PathBuf::from("/work/shared/models"),
        here.join("../shared/models"),
    ]
    .into_iter()
    .find(|p| p.is_dir())
}

#[test]
fn reference_models() {
    let Some(dir) = models_dir() else {
        eprintln!("note: shared/models not found; skipping the reference-model checks");
        return;
    };
    // (file, vertices, triangles). igea.ply stores 373,830 strip indices: 35,049 strips separated
    // by -1, which decode to 268,686 triangles with no degenerate one among them (the strips are
    // joined by restarts, not by repeated indices), exactly the README's count.
    let expect: [(&str, Option<usize>, usize); 8] = [
        ("stanford-bunny.obj", Some(34834), 69451),
        ("horse.ply", Some(48485), 96966),
        ("igea.ply", Some(134345), 268686),
        ("fandisk.obj", Some(6475), 12946),
        ("teapot.obj", Some(3644), 6320),
        ("spot/spot_triangulated.obj", None, 5856),
        ("nefertiti.obj", Some(49971), 99938),
        // 468 quads and 32 triangles: 500 faces, 968 triangles.
        ("suzanne.obj", Some(507), 968),
    ];
    for (name, verts, tris) in expect {
        let path = dir.join(name);
        if !path.exists() {
            eprintln!("note: {name} missing");
            continue;
        }
        let mut m = io::read(&path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(m.face_count(), tris, "{name}");
        if let Some(v) = verts {
            // The README counts the vertices faces use; the reader keeps every `v` line (the
            // bunny has 1,113 unreferenced ones).
            m.remove_unused_vertices();
            assert_eq!(m.vertex_count(), v, "{name}");
        }
    }
    let spot = io::read(&dir.join("spot/spot_triangulated.obj")).unwrap();
    assert!(spot.uvs.is_some());
    let horse = io::read(&dir.join("horse.ply")).unwrap();
    assert!(horse.normals.is_some());
}

/// The counter behind the allocation bounds above does see allocations.
#[test]
fn allocation_counter_counts() {
    let (v, peak) = peak_alloc(|| vec![1u8; 3 << 20]);
    assert!(peak >= 3 << 20, "{peak}");
    drop(v);
}

/// A pass of the streaming read (io::sink): the faces alone, or the vertices alone, as the
/// out-of-core clustering reads them; the same data as the whole-mesh reader's.
#[derive(Default)]
struct Pass {
    vertices: bool,
    faces: bool,
    seen_vertices: Vec<[f32; 3]>,
    seen_faces: Vec<[u32; 3]>,
}

impl meshslim::io::sink::Sink for Pass {
    fn wants_vertices(&self) -> bool {
        self.vertices
    }
    fn wants_faces(&self) -> bool {
        self.faces
    }
    fn vertex(&mut self, v: &meshslim::io::sink::Vertex) {
        self.seen_vertices.push(v.position);
    }
    fn triangle(&mut self, t: [u32; 3]) {
        self.seen_faces.push(t);
    }
}

#[test]
fn ply_streams_its_vertices_and_faces_in_separate_passes() {
    let dir = tmp();
    let m = full_mesh();
    for ascii in [false, true] {
        let path = dir.path().join(format!("stream-{ascii}.ply"));
        let o = WriteOptions {
            ply_ascii: ascii,
            ..Default::default()
        };
        io::write_with(&path, &m, &o).unwrap();
        let whole = io::read(&path).unwrap();
        let mut faces = Pass {
            faces: true,
            ..Default::default()
        };
        io::ply::read_into(&path, &mut faces).unwrap();
        assert!(faces.seen_vertices.is_empty(), "the vertices were skipped");
        assert_eq!(faces.seen_faces, whole.triangles, "ascii {ascii}");
        let mut vertices = Pass {
            vertices: true,
            ..Default::default()
        };
        io::ply::read_into(&path, &mut vertices).unwrap();
        assert!(vertices.seen_faces.is_empty(), "the faces were not read");
        assert_eq!(vertices.seen_vertices, whole.positions, "ascii {ascii}");
    }
}
