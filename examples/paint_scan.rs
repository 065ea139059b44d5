//! Writes a procedurally painted copy of a mesh: vertex colours with smooth bands, sharp-edged
//! stripes and a gradient, in the frame of the mesh's bounding box — the painted scans the
//! appearance measurements use (docs/PERFORMANCE.md). Same input, same colours.
//!
//! ```sh
//! cargo run --release --example paint_scan -- ../shared/models/horse.ply /tmp/horse-painted.ply
//! meshslim simplify /tmp/horse-painted.ply /tmp/h10.ply --ratio 0.1
//! meshslim compare /tmp/horse-painted.ply /tmp/h10.ply     # colour deviation
//! ```
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let (Some(input), Some(output)) = (args.next(), args.next()) else {
        return Err(
            "usage: paint_scan IN OUT (OUT a .ply or .obj that keeps vertex colours)".into(),
        );
    };
    let mut m = meshslim::io::read(std::path::Path::new(&input))?;
    if m.positions.is_empty() {
        return Err("the mesh has no vertices".into());
    }
    meshslim::mesh::paint(&mut m);
    meshslim::io::write(std::path::Path::new(&output), &m)?;
    println!(
        "{input}: {} vertices painted -> {output}",
        m.positions.len()
    );
    Ok(())
}
