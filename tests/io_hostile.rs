//! File-format layer, hostile inputs: empty, truncated, lying and corrupted files of every format
//! give an error naming the file and the offset, or a mesh, never a panic or a runaway
//! allocation; writes are atomic and validated.

use crate::io_support;

use io_support::*;
use meshslim::Mesh;
use meshslim::io::{self, WriteOptions};

#[test]
fn hostile_empty_files() {
    let dir = tmp();
    for ext in ["obj", "ply", "stl", "gltf", "glb"] {
        let p = write_text(dir.path(), &format!("empty.{ext}"), "");
        let msg = assert_read_err(&p, "empty");
        assert!(
            msg.contains("line 1") || msg.contains("byte offset 0"),
            "{msg}"
        );
    }
}

fn binary_ply_header(nv: u64, nf: u64) -> Vec<u8> {
    format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {nv}\nproperty float x\nproperty float y\nproperty float z\n\
         element face {nf}\nproperty list uchar int vertex_indices\nend_header\n"
    )
    .into_bytes()
}

#[test]
fn hostile_ply() {
    let dir = tmp();
    let path = dir.path().join("h.ply");
    let head = binary_ply_header(3, 1);
    let hl = head.len();
    let mut good = head.clone();
    for c in [0f32, 0., 0., 1., 0., 0., 0., 1., 0.] {
        good.extend_from_slice(&c.to_le_bytes());
    }
    good.push(3);
    for i in [0i32, 1, 2] {
        good.extend_from_slice(&i.to_le_bytes());
    }
    std::fs::write(&path, &good).unwrap();
    assert_eq!(io::read(&path).unwrap().triangles, vec![[0, 1, 2]]);

    // Truncated in the face list: the data runs out at the end of the file.
    std::fs::write(&path, &good[..good.len() - 3]).unwrap();
    let msg = assert_read_err(&path, &format!("byte offset {}", hl + 37));
    assert!(msg.contains("end of file in face 0"), "{msg}");
    // Declared counts larger than the file: refused at the end of the header, before reading.
    let mut more = binary_ply_header(1000, 1);
    more.extend_from_slice(&good[hl..]);
    std::fs::write(&path, &more).unwrap();
    let msg = assert_read_err(&path, "byte offset");
    assert!(msg.contains("1000 vertex elements"), "{msg}");
    // Truncated inside the list of a face that claims a long list (the minimum-size check passes,
    // the data runs out).
    let mut long = good[..good.len() - 13].to_vec();
    long.push(200);
    long.extend_from_slice(&[0; 12]);
    std::fs::write(&path, &long).unwrap();
    let msg = assert_read_err(&path, "byte offset");
    assert!(msg.contains("end of file in face 0"), "{msg}");

    // Four billion faces declared in a tiny file: fails at once.
    let mut huge = binary_ply_header(3, 4_000_000_000);
    huge.extend_from_slice(&good[hl..]);
    std::fs::write(&path, &huge).unwrap();
    let (msg, peak) = peak_alloc(|| assert_read_err(&path, "byte offset"));
    assert!(msg.contains("4000000000 face"), "{msg}");
    assert!(
        peak < 1 << 20,
        "allocated {peak} bytes for a {} byte file",
        huge.len()
    );
    // The same in ascii.
    let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                element face 4000000000\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    let p = write_text(dir.path(), "huge-ascii.ply", text);
    let msg = assert_read_err(&p, "line 10");
    assert!(msg.contains("4000000000 face"), "{msg}");
    // Vertex count above the index range.
    let mut many = binary_ply_header(5_000_000_000, 0);
    many.extend_from_slice(&[0; 64]);
    std::fs::write(&path, &many).unwrap();
    assert_read_err(&path, "byte offset");

    // Index out of range (binary: offset of the bad index; ascii: its line).
    let mut bad = good.clone();
    let n = bad.len();
    bad[n - 4..].copy_from_slice(&7i32.to_le_bytes());
    std::fs::write(&path, &bad).unwrap();
    let msg = assert_read_err(&path, &format!("byte offset {}", n));
    assert!(
        msg.contains("face 0") && msg.contains("out of range"),
        "{msg}"
    );
    let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 -3\n";
    let p = write_text(dir.path(), "range.ply", text);
    assert_read_err(&p, "line 13");

    // Non-finite coordinates, named by vertex.
    let mut nan = good.clone();
    nan[hl + 16..hl + 20].copy_from_slice(&f32::NAN.to_le_bytes());
    std::fs::write(&path, &nan).unwrap();
    let msg = assert_read_err(&path, &format!("byte offset {}", hl + 12));
    assert!(
        msg.contains("vertex 1") && msg.contains("non-finite"),
        "{msg}"
    );
    let text = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n1 inf 0\n";
    let p = write_text(dir.path(), "inf.ply", text);
    let msg = assert_read_err(&p, "line 9");
    assert!(msg.contains("vertex 1"), "{msg}");

    // Header problems, by line.
    let p = write_text(
        dir.path(),
        "nomagic.ply",
        "plx\nformat ascii 1.0\nend_header\n",
    );
    assert_read_err(&p, "line 1");
    let p = write_text(
        dir.path(),
        "type.ply",
        "ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\nend_header\n",
    );
    assert_read_err(&p, "line 4");
    let p = write_text(
        dir.path(),
        "noend.ply",
        "ply\nformat ascii 1.0\nelement vertex 1\n",
    );
    assert_read_err(&p, "end_header");
    let p = write_text(
        dir.path(),
        "word.ply",
        "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 zero 0\n",
    );
    assert_read_err(&p, "line 8");
    // A binary body without any newline is not taken for a header line forever.
    let mut junk = b"ply\n".to_vec();
    junk.extend(std::iter::repeat_n(b'x', 3 << 20));
    std::fs::write(&path, &junk).unwrap();
    assert_read_err(&path, "line 2");
}

#[test]
fn hostile_obj() {
    let dir = tmp();
    let v = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    for (name, text, loc, what) in [
        (
            "range.obj",
            format!("{v}f 1 2 4\n"),
            "line 4",
            "out of range",
        ),
        (
            "neg.obj",
            format!("{v}f -1 -2 -4\n"),
            "line 4",
            "out of range",
        ),
        ("zero.obj", format!("{v}f 0 1 2\n"), "line 4", "start at 1"),
        (
            "vt.obj",
            format!("{v}vt 0 0\nf 1/1 2/2 3/1\n"),
            "line 5",
            "texture coordinate index 2",
        ),
        (
            "nan.obj",
            format!("{v}v nan 0 0\nf 1 2 4\n"),
            "line 4",
            "vertex 4",
        ),
        (
            "inf.obj",
            "v 0 0 0\nv 1 -inf 0\n".to_string(),
            "line 2",
            "non-finite",
        ),
        (
            "num.obj",
            "v 0 0 0\nv 1 x 0\n".to_string(),
            "line 2",
            "not a number",
        ),
        (
            "idx.obj",
            format!("{v}f 1 2 three\n"),
            "line 4",
            "not an index",
        ),
        ("short.obj", format!("{v}f 1 2\n"), "line 4", "at least 3"),
        (
            "novert.obj",
            "# nothing here\n".to_string(),
            "line 1",
            "no vertices",
        ),
    ] {
        let p = write_text(dir.path(), name, &text);
        let msg = assert_read_err(&p, loc);
        assert!(msg.contains(what), "{name}: {msg}");
    }
    // Zero-area faces are kept.
    let p = write_text(
        dir.path(),
        "flat.obj",
        "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\nf 1 1 2\n",
    );
    let m = io::read(&p).unwrap();
    assert_eq!(m.face_count(), 2);
    assert_eq!(m.face_area(0), 0.0);
}

#[test]
fn hostile_stl() {
    let dir = tmp();
    let path = dir.path().join("h.stl");
    // Binary STL whose count needs far more bytes than the file has.
    let mut b = vec![0u8; 80];
    b.extend_from_slice(&4_000_000_000u32.to_le_bytes());
    b.extend_from_slice(&[0; 50]);
    std::fs::write(&path, &b).unwrap();
    let msg = assert_read_err(&path, "byte offset 80");
    assert!(msg.contains("4000000000 triangles"), "{msg}");
    // Too short for a binary header.
    std::fs::write(&path, [1u8; 20]).unwrap();
    assert_read_err(&path, "byte offset");
    // NaN in a binary triangle: offset of the vertex.
    let mut b = vec![0u8; 80];
    b.extend_from_slice(&1u32.to_le_bytes());
    let mut rec = [0u8; 50];
    rec[24..28].copy_from_slice(&f32::NAN.to_le_bytes());
    b.extend_from_slice(&rec);
    std::fs::write(&path, &b).unwrap();
    let msg = assert_read_err(&path, "byte offset 108");
    assert!(msg.contains("triangle 0"), "{msg}");
    // Ascii errors by line.
    let p = write_text(
        dir.path(),
        "a.stl",
        "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 nan\nendloop\nendfacet\nendsolid x\n",
    );
    assert_read_err(&p, "line 6");
    let p = write_text(
        dir.path(),
        "b.stl",
        "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0\n",
    );
    assert_read_err(&p, "line 5");
    let p = write_text(
        dir.path(),
        "c.stl",
        "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\n",
    );
    assert_read_err(&p, "line 6");
    // A binary file whose header starts with "solid" is still read as binary.
    let mut b = b"solid but binary".to_vec();
    b.resize(80, b' ');
    b.extend_from_slice(&1u32.to_le_bytes());
    let mut rec = [0u8; 50];
    for (k, c) in [1f32, 0., 0., 0., 1., 0.].iter().enumerate() {
        rec[24 + 4 * k..28 + 4 * k].copy_from_slice(&c.to_le_bytes());
    }
    b.extend_from_slice(&rec);
    std::fs::write(&path, &b).unwrap();
    assert_eq!(io::read(&path).unwrap().face_count(), 1);
}

#[test]
fn hostile_gltf() {
    let dir = tmp();
    let tri = Mesh::new(
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        vec![[0, 1, 2]],
    );
    let path = dir.path().join("t.gltf");
    io::write(&path, &tri).unwrap();
    let good: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let edit = |f: &dyn Fn(&mut serde_json::Value)| {
        let mut d = good.clone();
        f(&mut d);
        std::fs::write(&path, serde_json::to_string_pretty(&d).unwrap()).unwrap();
    };
    edit(&|d| d["accessors"][0]["count"] = serde_json::json!(4_000_000_000u64));
    assert!(assert_read_err(&path, "unknown").contains("runs past"));
    edit(&|d| d["accessors"][0]["count"] = serde_json::json!(0));
    assert!(assert_read_err(&path, "unknown").contains("out of range"));
    edit(&|d| d["bufferViews"][0]["byteStride"] = serde_json::json!(4));
    assert_read_err(&path, "stride");
    edit(&|d| d["meshes"][0]["primitives"][0]["indices"] = serde_json::json!(99));
    assert_read_err(&path, "accessor 99");
    edit(&|d| d["nodes"][0]["children"] = serde_json::json!([0]));
    assert_read_err(&path, "cyclic");
    edit(&|d| d["buffers"][0]["uri"] = serde_json::json!("%FF%FE-missing.bin"));
    assert_read_err(&path, "missing.bin");
    std::fs::write(
        &path,
        "{\"asset\": {\"version\": \"2.0\"},\n \"meshes\": [ nope ]}",
    )
    .unwrap();
    assert_read_err(&path, "line 2");
    let glb = dir.path().join("t.glb");
    std::fs::write(&glb, b"glTF\x02\0\0\0\xff\xff\0\0").unwrap();
    assert_read_err(&glb, "byte offset 8");

    // A node tree that references its children four times at every level: 4^8 instances of a
    // 200-triangle grid, 13M triangles from 4 KB of buffers. Refused before it is expanded.
    let grid = dir.path().join("grid.gltf");
    io::write(&grid, &meshslim::mesh::grid(10)).unwrap();
    let mut d: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&grid).unwrap()).unwrap();
    let mut nodes: Vec<serde_json::Value> = (0..8)
        .map(|i| serde_json::json!({ "children": [i + 1, i + 1, i + 1, i + 1] }))
        .collect();
    nodes.push(serde_json::json!({ "mesh": 0 }));
    d["nodes"] = serde_json::Value::Array(nodes);
    d["scenes"] = serde_json::json!([{ "nodes": [0] }]);
    d["scene"] = serde_json::json!(0);
    std::fs::write(&grid, serde_json::to_string(&d).unwrap()).unwrap();
    let (msg, peak) = peak_alloc(|| assert_read_err(&grid, "unknown"));
    assert!(msg.contains("refusing to expand"), "{msg}");
    assert!(peak < 256 << 20, "{peak} bytes");
}

/// Corrupted files of every format give `Ok` or `Err`, never a panic or a runaway allocation.
#[test]
fn corrupted_files_never_panic() {
    let dir = tmp();
    let mut rng = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        rng
    };
    let mesh = full_mesh();
    let variants: [(&str, WriteOptions); 7] = [
        ("obj", WriteOptions::default()),
        ("ply", WriteOptions::default()),
        (
            "ply",
            WriteOptions {
                ply_ascii: true,
                ..Default::default()
            },
        ),
        ("stl", WriteOptions::default()),
        (
            "stl",
            WriteOptions {
                stl_ascii: true,
                ..Default::default()
            },
        ),
        ("gltf", WriteOptions::default()),
        ("glb", WriteOptions::default()),
    ];
    for (k, (ext, opts)) in variants.iter().enumerate() {
        let src = dir.path().join(format!("src{k}.{ext}"));
        io::write_with(&src, &mesh, opts).unwrap();
        let good = std::fs::read(&src).unwrap();
        let path = dir.path().join(format!("fuzz{k}.{ext}"));
        for _ in 0..150 {
            let mut b = good.clone();
            match next() % 4 {
                0 => b.truncate(next() as usize % b.len()),
                1 => {
                    for _ in 0..1 + next() % 4 {
                        let i = next() as usize % b.len();
                        b[i] = next() as u8;
                    }
                }
                2 => {
                    // Digits and separators, where text formats keep their numbers.
                    let i = next() as usize % b.len();
                    b[i] = b"0123456789-./ \n9"[next() as usize % 16];
                }
                _ => {
                    let i = next() as usize % b.len();
                    let j = (i + 1 + next() as usize % 8).min(b.len());
                    b.drain(i..j);
                }
            }
            std::fs::write(&path, &b).unwrap();
            let (result, peak) = peak_alloc(|| io::read(&path));
            if let Ok(m) = result {
                m.validate().unwrap();
            }
            // The files are a few kilobytes: a reader that believed a corrupted count would
            // reach far past this.
            assert!(
                peak < 16 << 20,
                "{ext}: {peak} bytes allocated for a {} byte file",
                b.len()
            );
        }
    }
}

#[test]
fn writes_are_atomic_and_validated() {
    let dir = tmp();
    let path = dir.path().join("out.ply");
    io::write(&path, &full_mesh()).unwrap();
    let before = std::fs::read(&path).unwrap();
    // An invalid mesh is refused and the existing file is untouched.
    let bad = Mesh::new(vec![[0.0; 3]], vec![[0, 1, 2]]);
    assert!(io::write(&path, &bad).is_err());
    assert_eq!(std::fs::read(&path).unwrap(), before);
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(
        names,
        vec![std::ffi::OsString::from("out.ply")],
        "no temporary file left behind"
    );
    // Unsupported extension, missing directory.
    assert!(err_text(io::write(&dir.path().join("x.fbx"), &full_mesh())).contains("x.fbx"));
    assert!(io::write(&dir.path().join("no/such/dir/x.obj"), &full_mesh()).is_err());
    assert!(err_text(io::read(&dir.path().join("missing.obj"))).contains("missing.obj"));
}

/// A mesh built in memory (not read, so no reader caught it) is checked at the library's
/// boundary: `validate` names the first bad vertex and the first bad face, however many bad
/// ones follow and wherever they fall among the chunks it checks on every core.
#[test]
fn validate_names_the_first_offender() {
    let m = meshslim::mesh::grid(300);
    let (nv, nf) = (m.positions.len(), m.triangles.len());
    assert!(nv > 3 * (1 << 14) && nf > 3 * (1 << 14));
    m.validate().unwrap();
    let err = |m: &Mesh| m.validate().unwrap_err().to_string();
    let mut bad = m.clone();
    for (i, c) in [
        (70_000, f32::INFINITY),
        (40_000, f32::NAN),
        (90_000, f32::NAN),
    ] {
        bad.positions[i][1] = c;
    }
    let msg = err(&bad);
    assert!(msg.contains("vertex 40000 has a non-finite"), "{msg}");
    let mut bad = m.clone();
    bad.positions[nv - 1][2] = f32::NEG_INFINITY;
    assert!(err(&bad).contains(&format!("vertex {}", nv - 1)));
    let mut bad = m.clone();
    bad.triangles[nf - 1] = [0, nv as u32 + 7, 1];
    bad.triangles[50_001] = [1, 2, nv as u32];
    bad.triangles[60_000] = [u32::MAX, 0, 1];
    let msg = err(&bad);
    assert!(
        msg.contains(&format!("face 50001 refers to vertex {nv},")),
        "{msg}"
    );
    let mut bad = m.clone();
    bad.triangles[0] = [0, 1, nv as u32];
    assert!(err(&bad).contains(&format!("face 0 refers to vertex {nv},")));
}
