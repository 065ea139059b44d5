//! What the commands print: the simplify summary and its JSON, the round statistics, the
//! comparison table; and the progress bars on stderr.

use std::io::Write;
use std::path::Path;
use std::sync::mpsc;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use super::args::Input;
use crate::SimplifyReport;

/// `report`'s JSON object with the fields of `extra` (what the command adds: paths, seconds)
/// after its own, pretty-printed on a line.
pub(super) fn write_json_with(
    out: &mut impl Write,
    report: &impl serde::Serialize,
    extra: serde_json::Value,
) -> anyhow::Result<()> {
    let mut json = serde_json::to_value(report)?;
    json.as_object_mut()
        .expect("a report serializes as an object")
        .extend(extra.as_object().cloned().unwrap_or_default());
    writeln!(out, "{}", serde_json::to_string_pretty(&json)?)?;
    Ok(())
}

pub(super) struct Times {
    pub(super) load: f64,
    pub(super) simplify: f64,
    pub(super) save: f64,
}

/// What a clustering method did to the topology: it may join sheets and close handles.
#[derive(Debug, Clone, serde::Serialize)]
pub(super) struct TopologyChange {
    pub non_manifold_edges_before: usize,
    pub non_manifold_edges_after: usize,
    pub euler_characteristic_before: i64,
    pub euler_characteristic_after: i64,
    pub components_before: usize,
    pub components_after: usize,
}

impl TopologyChange {
    pub fn of(before: &crate::Mesh, after: &crate::Mesh) -> TopologyChange {
        let (a, b) = (crate::mesh::topology(before), crate::mesh::topology(after));
        TopologyChange {
            non_manifold_edges_before: a.non_manifold_edges,
            non_manifold_edges_after: b.non_manifold_edges,
            euler_characteristic_before: a.euler_characteristic,
            euler_characteristic_after: b.euler_characteristic,
            components_before: a.connected_components,
            components_after: b.connected_components,
        }
    }
}

pub(super) fn simplify_json(
    input: &Input,
    output: &Path,
    r: &SimplifyReport,
    t: &Times,
    topology: Option<&TopologyChange>,
) -> serde_json::Value {
    serde_json::json!({
        "input": input.display(),
        "output": output.display().to_string(),
        "backend": r.backend,
        "input_faces": r.input_faces,
        "input_vertices": r.input_vertices,
        "target_faces": r.target_faces,
        "output_faces": r.output_faces,
        "output_vertices": r.output_vertices,
        "stop_reason": r.stop_reason,
        "stop_reason_explained": r.stop_reason.explain(),
        "collapses": r.collapses,
        "max_collapse_error": r.max_collapse_error,
        "pinned_vertices": r.pinned_vertices,
        "dropped_degenerate_faces": r.dropped_degenerate_faces,
        "seconds": { "load": t.load, "simplify": t.simplify, "save": t.save },
        "rounds": r.rounds,
        "clustering": r.clustering,
        "decimation": r.decimation,
        "topology": topology,
    })
}

pub(super) fn write_summary(
    out: &mut impl Write,
    input: &Input,
    output: &Path,
    r: &SimplifyReport,
    t: &Times,
    stats: bool,
    topology: Option<&TopologyChange>,
) -> std::io::Result<()> {
    let pct = |n: usize| {
        if r.input_faces == 0 {
            100.0
        } else {
            100.0 * n as f64 / r.input_faces as f64
        }
    };
    writeln!(
        out,
        "input    {}: {} faces, {} vertices",
        input.display(),
        r.input_faces,
        r.input_vertices
    )?;
    writeln!(
        out,
        "output   {}: {} faces, {} vertices ({:.1}% of the faces; target {})",
        output.display(),
        r.output_faces,
        r.output_vertices,
        pct(r.output_faces),
        r.target_faces
    )?;
    match r.stop_reason {
        crate::StopReason::TargetReached => writeln!(out, "result   {}", r.stop_reason.explain())?,
        reason => writeln!(
            out,
            "result   target of {} faces not reached: {}",
            r.target_faces,
            reason.explain()
        )?,
    }
    if let Some(b) = &r.blocked {
        writeln!(out, "why      {}", b.explain())?;
    }
    writeln!(
        out,
        "time     load {:.3} s, simplify {:.3} s, save {:.3} s (backend {})",
        t.load,
        t.simplify,
        t.save,
        r.backend.name()
    )?;
    if let Some(c) = &r.clustering {
        let intermediate = c.intermediate_faces.map_or(String::new(), |n| {
            format!(", {n} faces handed to the rounds")
        });
        writeln!(
            out,
            "method   {}: cell {:.3e} of the diagonal, {} clusters ({} from splitting cells by connectivity){intermediate}",
            c.method.name(),
            c.cell_size,
            c.clusters,
            c.split_clusters
        )?;
    }
    if let Some(tc) = topology {
        let changed = tc.non_manifold_edges_after > tc.non_manifold_edges_before
            || tc.euler_characteristic_after != tc.euler_characteristic_before
            || tc.components_after != tc.components_before;
        writeln!(
            out,
            "topology {}: non-manifold edges {} -> {}, Euler characteristic {} -> {}, components {} -> {}",
            if changed { "changed" } else { "kept" },
            tc.non_manifold_edges_before,
            tc.non_manifold_edges_after,
            tc.euler_characteristic_before,
            tc.euler_characteristic_after,
            tc.components_before,
            tc.components_after
        )?;
    }
    if stats {
        writeln!(out, "collapses           {}", r.collapses)?;
        writeln!(
            out,
            "pinned vertices     {} (kept in place: non-manifold points, seams on a locked border)",
            r.pinned_vertices
        )?;
        writeln!(
            out,
            "dropped degenerate  {} faces with a repeated vertex, removed before simplifying",
            r.dropped_degenerate_faces
        )?;
        writeln!(
            out,
            "max collapse error  {:.3e} of the bounding-box diagonal",
            r.max_collapse_error
        )?;
        if let Some(c) = &r.clustering {
            writeln!(
                out,
                "clustering          {:.3} s; {} cell sizes counted, {} builds; vertices placed: {} single, {} quadric minimum, {} best member, {} centroid",
                c.seconds,
                c.sizes_counted,
                c.builds,
                c.placed_single,
                c.placed_solve,
                c.placed_member,
                c.placed_centroid
            )?;
        }
        if let Some(d) = &r.decimation {
            writeln!(
                out,
                "decimation          {} removal; input vertices: {} simple, {} boundary, {} interior edge, {} corner, {} complex; {} removed, {} refused by the checks",
                d.removal.name(),
                d.simple,
                d.boundary,
                d.interior_edge,
                d.corner,
                d.complex,
                d.removed,
                d.refused
            )?;
        }
        if let Some(rr) = &r.rounds {
            write_rounds(out, rr)?;
        }
    }
    Ok(())
}

/// The round-based backends' statistics: adapter, rounds, removals, time per stage.
fn write_rounds(out: &mut impl Write, rr: &crate::rounds::RoundsReport) -> std::io::Result<()> {
    if let Some(a) = &rr.adapter {
        writeln!(out, "adapter             {a}")?;
        writeln!(
            out,
            "pipelines           {:.3} s to compile shaders and create pipelines (not in the \
             stage times); upload + download {:.3} s",
            rr.pipeline_seconds, rr.transfer_seconds
        )?;
        writeln!(
            out,
            "host                {:.3} s preparing the upload (prepared on the {}); {:.3} s \
             from the rounds' submissions to their counters",
            rr.prepare_seconds,
            rr.prepared_on.as_deref().unwrap_or("host"),
            rr.wait_seconds
        )?;
        writeln!(
            out,
            "device              {} waits, {} submits, {} dispatches, {} bind groups; {} B up, \
             {} B back; host {:.3} s; pipeline cache {}",
            rr.device_waits,
            rr.submits,
            rr.dispatches,
            rr.bind_groups_created,
            rr.bytes_uploaded,
            rr.bytes_read_back,
            rr.host_seconds,
            rr.pipeline_cache.as_deref().unwrap_or("-")
        )?;
    }
    let removed = &rr.faces_removed_per_round;
    writeln!(out, "rounds              {}", rr.rounds)?;
    let list: Vec<String> = removed.iter().map(|n| n.to_string()).collect();
    writeln!(out, "faces removed/round {}", list.join(" "))?;
    let kind = if rr.adapter.is_none() {
        "CPU time"
    } else if rr.gpu_timestamps {
        "GPU time (timestamp queries)"
    } else {
        "wall time of each submission (the device has no timestamp queries)"
    };
    let total = rr.stage_seconds.total();
    writeln!(out, "stage times         {kind}, {total:.3} s in all")?;
    let mut stages = rr.stage_seconds.0.clone();
    stages.sort_by(|a, b| b.1.total_cmp(&a.1));
    for (s, t) in &stages {
        let share = if total > 0.0 { 100.0 * t / total } else { 0.0 };
        writeln!(out, "  {s:<20} {t:>9.4} s {share:>5.1}%")?;
    }
    if let Some((s, _)) = rr.stage_seconds.slowest() {
        writeln!(out, "slowest stage       {s}")?;
    }
    Ok(())
}

pub(super) fn write_comparison(
    out: &mut impl Write,
    a: &Input,
    b: &Input,
    c: &crate::metrics::Comparison,
    load_s: f64,
    compare_s: f64,
) -> std::io::Result<()> {
    let d = &c.distance;
    writeln!(
        out,
        "A  {}: {} faces, {} vertices",
        a.display(),
        c.faces_a,
        c.vertices_a
    )?;
    writeln!(
        out,
        "B  {}: {} faces, {} vertices",
        b.display(),
        c.faces_b,
        c.vertices_b
    )?;
    writeln!(
        out,
        "\ndistance (absolute, and relative to A's bounding-box diagonal {:.6})",
        d.diagonal
    )?;
    writeln!(
        out,
        "  {:<10} {:>22} {:>22} {:>22}  samples (faces + vertices + edges)",
        "", "max (Hausdorff)", "mean", "RMS"
    )?;
    let cell = |abs: f64, rel: f64| format!("{abs:.4e} ({rel:.3e})");
    for (name, s) in [("A -> B", &d.a_to_b), ("B -> A", &d.b_to_a)] {
        writeln!(
            out,
            "  {:<10} {:>22} {:>22} {:>22}  {} + {} + {}",
            name,
            cell(s.distances.max, s.distances.max_rel),
            cell(s.distances.mean, s.distances.mean_rel),
            cell(s.distances.rms, s.distances.rms_rel),
            s.face_samples,
            s.vertex_samples,
            s.edge_samples
        )?;
    }
    let t = &d.two_sided;
    writeln!(
        out,
        "  {:<10} {:>22} {:>22} {:>22}  (max of both; mean of the two means)",
        "both",
        cell(t.max, t.max_rel),
        cell(t.mean, t.mean_rel),
        cell(t.rms, t.rms_rel)
    )?;
    if let Some(look) = &c.appearance {
        writeln!(
            out,
            "\nappearance at the same samples   {:>10} {:>10} {:>10}  {:>10} {:>10}",
            "mean", "RMS", "max", "A -> B", "B -> A"
        )?;
        for (name, s) in [
            ("colour (RGB distance, 0..1)", &look.color),
            ("normals (angle, degrees)", &look.normal_deg),
            ("texture (RGB at the UVs, 0..1)", &look.texture),
        ] {
            if let Some(s) = s {
                writeln!(
                    out,
                    "  {name:<30} {:>10.5} {:>10.5} {:>10.5}  {:>10.5} {:>10.5}",
                    s.mean, s.rms, s.max, s.a_to_b_mean, s.b_to_a_mean
                )?;
            }
        }
    }
    let pct = |r: Option<f64>| r.map_or("n/a".to_string(), |r| format!("{:+.4}%", 100.0 * r));
    writeln!(out)?;
    writeln!(
        out,
        "area     {:.6} -> {:.6} ({})",
        c.area.a,
        c.area.b,
        pct(c.area.relative)
    )?;
    writeln!(
        out,
        "volume   {:.6} -> {:.6} ({}, signed)",
        c.volume.a,
        c.volume.b,
        pct(c.volume.relative)
    )?;
    writeln!(out, "\ntriangle quality of B:")?;
    write_quality(out, &c.quality_b, "  ")?;
    let tp = &c.topology;
    writeln!(
        out,
        "\ntopology           {:>8} {:>8} {:>8}",
        "A", "B", "B - A"
    )?;
    let rows = [
        (
            "euler",
            tp.a.euler_characteristic,
            tp.b.euler_characteristic,
            tp.difference.euler_characteristic,
        ),
        (
            "boundary loops",
            tp.a.boundary_loops,
            tp.b.boundary_loops,
            tp.difference.boundary_loops,
        ),
        (
            "non-manifold edges",
            tp.a.non_manifold_edges,
            tp.b.non_manifold_edges,
            tp.difference.non_manifold_edges,
        ),
        (
            "non-manifold verts",
            tp.a.non_manifold_vertices,
            tp.b.non_manifold_vertices,
            tp.difference.non_manifold_vertices,
        ),
        (
            "components",
            tp.a.connected_components,
            tp.b.connected_components,
            tp.difference.connected_components,
        ),
    ];
    for (name, x, y, dxy) in rows {
        writeln!(out, "  {name:<18} {x:>6} {y:>8} {dxy:>+8}")?;
    }
    writeln!(
        out,
        "\ntime     load {load_s:.3} s, compare {compare_s:.3} s (seed {})",
        c.seed
    )?;
    Ok(())
}

/// Progress bars on stderr for steps that take long enough to wonder about. A bar starts hidden
/// and is revealed only once its step has run for [`Progress::DELAY`], so quick steps print
/// nothing; with `enabled` false (not a terminal, `--quiet`, `--json`) nothing is ever drawn.
pub(super) struct Progress {
    enabled: bool,
}

impl Progress {
    const DELAY: Duration = Duration::from_millis(500);

    pub(super) fn new(enabled: bool) -> Self {
        Progress { enabled }
    }

    /// Runs `f` with a spinner (for steps that report no progress of their own).
    pub(super) fn spinner<T>(&self, msg: String, f: impl FnOnce() -> T) -> T {
        let style = ProgressStyle::with_template("{spinner} {msg} {elapsed}")
            .expect("valid progress template");
        self.run(None, style, msg, |_| f())
    }

    /// Runs `f` with a bar; `f` gets a setter for the fraction done (0..=1).
    pub(super) fn bar<T>(&self, msg: &str, f: impl FnOnce(&dyn Fn(f32)) -> T) -> T {
        let style = ProgressStyle::with_template("{msg} [{bar:40}] {percent:>3}% {elapsed}")
            .expect("valid progress template")
            .progress_chars("=> ");
        self.run(Some(1000), style, msg.to_string(), |pb| {
            f(&|frac: f32| pb.set_position((frac.clamp(0.0, 1.0) * 1000.0) as u64))
        })
    }

    fn run<T>(
        &self,
        len: Option<u64>,
        style: ProgressStyle,
        msg: String,
        f: impl FnOnce(&ProgressBar) -> T,
    ) -> T {
        let pb = ProgressBar::with_draw_target(len, ProgressDrawTarget::hidden())
            .with_style(style)
            .with_message(msg);
        if !self.enabled {
            return f(&pb);
        }
        let (done, wait) = mpsc::channel::<()>();
        let result = std::thread::scope(|s| {
            let reveal = pb.clone();
            s.spawn(move || {
                // Dropping `done` ends the wait early: the step finished in time, draw nothing.
                if let Err(mpsc::RecvTimeoutError::Timeout) = wait.recv_timeout(Self::DELAY) {
                    reveal.set_draw_target(ProgressDrawTarget::stderr());
                    reveal.enable_steady_tick(Duration::from_millis(100));
                }
            });
            let r = f(&pb);
            drop(done);
            r
        });
        pb.finish_and_clear();
        result
    }
}

/// A mesh's triangle quality as `compare` and `info` print it, each line after `indent`.
pub(super) fn write_quality(
    out: &mut dyn std::io::Write,
    q: &crate::metrics::TriangleQuality,
    indent: &str,
) -> std::io::Result<()> {
    writeln!(
        out,
        "{indent}smallest angle     min {:.2} deg, mean {:.2} deg; {:.2}% of the faces under 30 deg, \
         {:.2}% under 10; {} degenerate",
        q.min_angle_deg,
        q.mean_min_angle_deg,
        100.0 * q.share_under_30_deg,
        100.0 * q.share_under_10_deg,
        q.degenerate_faces
    )?;
    writeln!(
        out,
        "{indent}aspect ratio       (circumradius / 2 inradius, 1 = equilateral), faces:"
    )?;
    let mut lower = 1.0;
    for bin in &q.aspect_ratio_histogram {
        let range = match bin.upper {
            Some(u) => format!("[{lower}, {u})"),
            None => format!(">= {lower}"),
        };
        writeln!(out, "{indent}  {range:<12} {}", bin.count)?;
        lower = bin.upper.unwrap_or(lower);
    }
    let bins: Vec<String> = q
        .valence_histogram
        .iter()
        .map(|b| format!("{}: {}/{}", b.valence, b.interior, b.border))
        .collect();
    writeln!(
        out,
        "{indent}valence            {:.1}% regular (6 inside, 4 on a border); vertices inside/on a \
         border by valence: {}",
        100.0 * q.regular_valence_share,
        bins.join(", ")
    )
}
