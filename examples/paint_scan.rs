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
    let bb = m.bounds().ok_or("the mesh has no vertices")?;
    let colors = m
        .positions
        .iter()
        .map(|p| {
            // Coordinates in 0..1 over the bounding box.
            let t: [f32; 3] = std::array::from_fn(|k| {
                let span = (bb.max[k] - bb.min[k]).max(1e-12);
                (p[k] - bb.min[k]) / span
            });
            // Smooth bands along x, a gradient along y, sharp stripes along z.
            let band = 0.5 + 0.5 * (t[0] * std::f32::consts::TAU * 3.0).sin();
            let stripe = if (t[2] * 8.0).floor() as i32 % 2 == 0 {
                0.9
            } else {
                0.1
            };
            [band, t[1], stripe, 1.0]
        })
        .collect();
    m.colors = Some(colors);
    meshslim::io::write(std::path::Path::new(&output), &m)?;
    println!(
        "{input}: {} vertices painted -> {output}",
        m.positions.len()
    );
    Ok(())
}
