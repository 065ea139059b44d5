//! Writes the 4.3M-triangle scan: the benchmark's 1M scan (igea subdivided once, 1e-4 noise)
//! subdivided once more, for the memory figures of `simplify --stream` against the greedy
//! (docs/PERFORMANCE.md, "Streaming"). Needs ../shared/models/igea.ply (or $MESHSLIM_MODELS).
//!
//! ```sh
//! cargo run --release --example write_scan_4m -- /tmp/scan-4m.ply
//! ```
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "scan-4m.ply".into());
    let (name, m) = meshslim::bench::million_triangle_scan()?;
    if name != "igea-subdivided" {
        return Err("igea.ply is not there: the 4.3M scan is igea subdivided twice".into());
    }
    let m = meshslim::mesh::subdivide_midpoint(&m);
    meshslim::io::write(std::path::Path::new(&path), &m)?;
    println!(
        "{name} subdivided again: {} faces -> {path}",
        m.triangles.len()
    );
    Ok(())
}
