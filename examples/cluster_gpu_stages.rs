//! Times `--method cluster`'s GPU build stage by stage on a mesh (each step submitted alone and
//! waited for, so the figures add up to more than a build's single submission):
//!
//! ```sh
//! cargo run --release --example cluster_gpu_stages -- MESH [CELL]
//! ```
//!
//! CELL is the cell size relative to the bounding-box diagonal (default 4.9e-3, the 1M scan's
//! at 10%). docs/PERFORMANCE.md quotes its output.

use meshslim::cluster::gpu::{GpuClusterMesh, Part, shared};
use meshslim::cluster::gpu_schedule as sched;
use meshslim::cluster::grid::CellGrid;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let path = args.next().ok_or("usage: cluster_gpu_stages MESH [CELL]")?;
    let h: f32 = args.next().map_or(Ok(4.9e-3), |s| s.parse())?;
    let m = meshslim::io::read(std::path::Path::new(&path))?;
    let (pos, lo, hi) = meshslim::cluster::unit_frame_points(&m);
    let grid = CellGrid::new(lo, hi, h);
    let sim = shared()?;
    let locked = vec![false; pos.len()];
    let mut g = GpuClusterMesh::new(sim, &pos, &m.triangles, &locked)?;
    g.set_grid(&grid);
    g.run_part(Part::Keys)?; // waits for the mesh's upload and set-up too
    let t = Instant::now();
    g.build(&grid)?;
    println!(
        "{path}: {} faces, cell {h:e}: one build {:.4} s",
        m.triangles.len(),
        t.elapsed().as_secs_f64()
    );
    let time = |label: &str, run: &mut dyn FnMut() -> meshslim::Result<()>| {
        let t = Instant::now();
        run().map(|_| println!("  {label:<12} {:.4} s", t.elapsed().as_secs_f64()))
    };
    // The mesh's set-up again (it only depends on the mesh), then a build part by part.
    time("mesh", &mut || {
        g.run_steps(sched::ADJACENCY)?;
        g.run_steps(sched::PLANES)
    })?;
    g.set_grid(&grid);
    let mut parts = vec![Part::Keys];
    parts.extend((0..g.passes()).map(Part::SortPass));
    parts.extend([Part::Cells, Part::Quadrics, Part::Faces]);
    for p in parts {
        time(&format!("{p:?}"), &mut || g.run_part(p))?;
    }
    Ok(())
}
