//! Writes the benchmark's 1M-triangle scan to a file, for `meshslim simplify --stats` runs.
fn main() {
    let path = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "scan-1m.ply".into());
    let (name, m) = meshslim::bench::million_triangle_scan().expect("the 1M scan");
    meshslim::io::write(std::path::Path::new(&path), &m).expect("write");
    println!("{name}: {} faces -> {path}", m.triangles.len());
}
