//! The PLY writer: ascii or binary in either byte order, with normals, colours and texture
//! coordinates when the mesh has them.

use std::io::{self, Write};

use super::header::PlyEncoding;
use crate::mesh::{Mesh, UvOrigin};

/// Whether every colour channel is exactly `k/255` as the reader computes it, so `uchar` loses
/// nothing.
fn colors_are_bytes(colors: &[[f32; 4]]) -> bool {
    colors.iter().flatten().all(|&c| {
        let k = (c * 255.0).round();
        (0.0..=255.0).contains(&k) && ((k as f64 / 255.0) as f32) == c
    })
}

/// Writes `mesh` as PLY in the given encoding.
pub fn write_ply<W: Write>(w: &mut W, mesh: &Mesh, encoding: PlyEncoding) -> io::Result<()> {
    let nv = mesh.positions.len();
    // PLY's u, v follow OBJ's convention (the tools that write them: MeshLab, Blender).
    let uvs = mesh.uvs_from(UvOrigin::BottomLeft);
    let byte_colors = mesh.colors.as_deref().is_some_and(colors_are_bytes);
    let idx_type = if nv > i32::MAX as usize {
        "uint"
    } else {
        "int"
    };
    let mut h = String::from("ply\n");
    h += match encoding {
        PlyEncoding::Ascii => "format ascii 1.0\n",
        PlyEncoding::BinaryLittleEndian => "format binary_little_endian 1.0\n",
        PlyEncoding::BinaryBigEndian => "format binary_big_endian 1.0\n",
    };
    h += "comment written by meshslim\n";
    h += &format!("element vertex {nv}\nproperty float x\nproperty float y\nproperty float z\n");
    if mesh.normals.is_some() {
        h += "property float nx\nproperty float ny\nproperty float nz\n";
    }
    if mesh.colors.is_some() {
        let t = if byte_colors { "uchar" } else { "float" };
        for c in ["red", "green", "blue", "alpha"] {
            h += &format!("property {t} {c}\n");
        }
    }
    if mesh.uvs.is_some() {
        h += "property float s\nproperty float t\n";
    }
    h += &format!(
        "element face {}\nproperty list uchar {idx_type} vertex_indices\nend_header\n",
        mesh.triangles.len()
    );
    w.write_all(h.as_bytes())?;

    if encoding == PlyEncoding::Ascii {
        let mut line = String::new();
        for i in 0..nv {
            use std::fmt::Write as _;
            line.clear();
            let p = mesh.positions[i];
            let _ = write!(line, "{} {} {}", p[0], p[1], p[2]);
            if let Some(n) = &mesh.normals {
                let _ = write!(line, " {} {} {}", n[i][0], n[i][1], n[i][2]);
            }
            if let Some(c) = &mesh.colors {
                for ch in c[i] {
                    if byte_colors {
                        let _ = write!(line, " {}", (ch * 255.0).round() as u8);
                    } else {
                        let _ = write!(line, " {ch}");
                    }
                }
            }
            if let Some(t) = &uvs {
                let _ = write!(line, " {} {}", t[i][0], t[i][1]);
            }
            line.push('\n');
            w.write_all(line.as_bytes())?;
        }
        for t in &mesh.triangles {
            writeln!(w, "3 {} {} {}", t[0], t[1], t[2])?;
        }
        return Ok(());
    }

    let big = encoding == PlyEncoding::BinaryBigEndian;
    let mut buf: Vec<u8> = Vec::with_capacity(64 * 1024);
    macro_rules! put {
        ($x:expr) => {
            if big {
                buf.extend_from_slice(&$x.to_be_bytes())
            } else {
                buf.extend_from_slice(&$x.to_le_bytes())
            }
        };
    }
    for i in 0..nv {
        for c in mesh.positions[i] {
            put!(c);
        }
        if let Some(n) = &mesh.normals {
            for c in n[i] {
                put!(c);
            }
        }
        if let Some(c) = &mesh.colors {
            for ch in c[i] {
                if byte_colors {
                    buf.push((ch * 255.0).round() as u8);
                } else {
                    put!(ch);
                }
            }
        }
        if let Some(t) = &uvs {
            put!(t[i][0]);
            put!(t[i][1]);
        }
        if buf.len() >= 60 * 1024 {
            w.write_all(&buf)?;
            buf.clear();
        }
    }
    for t in &mesh.triangles {
        buf.push(3);
        for &v in t {
            put!(v);
        }
        if buf.len() >= 60 * 1024 {
            w.write_all(&buf)?;
            buf.clear();
        }
    }
    w.write_all(&buf)
}
