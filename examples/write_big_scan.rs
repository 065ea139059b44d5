//! Writes a deterministic scan-like mesh of about N triangles straight to a binary PLY, row by
//! row, without holding it: memory stays a few kilobytes whatever N, so a 100M-triangle input
//! for the streaming and tiling paths can be made on any machine.
//!
//! ```sh
//! cargo run --release --example write_big_scan -- 100000000 /tmp/scan-100m.ply
//! ```
//!
//! The surface is a closed torus (no poles, so no degenerate faces) displaced by a few octaves
//! of waves with hashed phases, plus a small per-vertex jitter like a scanner's noise: rows of
//! R vertices around the tube, C rows around the ring (C = 2R), 2·R·C triangles. The same N
//! writes the same bytes on every machine.

use std::f64::consts::TAU;
use std::io::{BufWriter, Write};

/// A 32-bit integer hash (lowbias32, Chris Wellons): the jitter and the phases.
fn hash(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^ (x >> 16)
}

/// In [-1, 1).
fn unit(x: u32) -> f64 {
    hash(x) as f64 / 2_147_483_648.0 - 1.0
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let usage = "usage: write_big_scan TRIANGLES OUT.ply";
    let n: u64 = args.next().ok_or(usage)?.parse()?;
    let out = args.next().ok_or(usage)?;
    // 2·R·C = n with C = 2R: R = sqrt(n / 4), at least a 3 × 6 torus.
    let r = ((n as f64 / 4.0).sqrt().round() as u64).max(3);
    let c = 2 * r;
    let (verts, faces) = (r * c, 2 * r * c);
    if verts > u32::MAX as u64 {
        return Err(format!("{n} triangles need more than 2^32 vertices").into());
    }
    let file = std::fs::File::create(&out).map_err(|e| format!("{out}: {e}"))?;
    let mut w = BufWriter::with_capacity(1 << 20, file);
    write!(
        w,
        "ply\nformat binary_little_endian 1.0\ncomment meshslim write_big_scan {n}\n\
         element vertex {verts}\nproperty float x\nproperty float y\nproperty float z\n\
         element face {faces}\nproperty list uchar int vertex_indices\nend_header\n"
    )?;
    // Waves on the torus's two angles: (frequency around the ring, around the tube, amplitude).
    let waves: Vec<(f64, f64, f64, f64)> = (0..6u32)
        .map(|k| {
            let f = 3.0 * (k as f64 + 1.0);
            let phase = TAU * (unit(1000 + k) + 1.0) / 2.0;
            (f.round(), (f / 2.0).round(), 0.02 / (k as f64 + 1.0), phase)
        })
        .collect();
    let (big, small) = (1.0f64, 0.35f64);
    // The mean edge is about 2π·big / C: the jitter is a twentieth of it.
    let jitter = 0.05 * TAU * big / c as f64;
    for i in 0..c {
        let u = TAU * i as f64 / c as f64;
        for j in 0..r {
            let v = TAU * j as f64 / r as f64;
            let id = (i * r + j) as u32;
            let mut d = 0.0;
            for &(fu, fv, a, ph) in &waves {
                d += a * (fu * u + fv * v + ph).sin();
            }
            let tube = small * (1.0 + d) + jitter * unit(id);
            let ring = big + tube * v.cos();
            let p = [ring * u.cos(), ring * u.sin(), tube * v.sin()];
            for x in p {
                w.write_all(&(x as f32).to_le_bytes())?;
            }
        }
    }
    for i in 0..c {
        let i1 = (i + 1) % c;
        for j in 0..r {
            let j1 = (j + 1) % r;
            let (a, b, cc, dd) = (i * r + j, i1 * r + j, i1 * r + j1, i * r + j1);
            for t in [[a, b, cc], [a, cc, dd]] {
                w.write_all(&[3u8])?;
                for x in t {
                    w.write_all(&(x as u32).to_le_bytes())?;
                }
            }
        }
    }
    w.flush()?;
    println!("{out}: {faces} triangles, {verts} vertices ({r} x {c} torus)");
    Ok(())
}
