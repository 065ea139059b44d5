//! The report presented: the table on stdout, the error-against-time plot as SVG, and that SVG
//! rendered to PNG.

use std::fmt::Write as _;
use std::io::Write;

use super::backends::BACKENDS;
use super::report::{Report, Row};

/// The report as a table, one row per line, errors relative to the input's diagonal.
pub fn write_table(out: &mut impl Write, report: &Report) -> std::io::Result<()> {
    // A column as wide as its longest entry, and at least as its header.
    let width = |len: fn(&Row) -> usize, header: usize| {
        report
            .rows
            .iter()
            .map(len)
            .chain([header])
            .max()
            .unwrap_or(header)
    };
    let mesh_w = width(|r| r.mesh.len(), 4);
    let backend_w = width(|r| r.backend.len(), 7);
    // The colour column only when some input has colours (attribute-free tables stay as they
    // were).
    let colors = report.rows.iter().any(|r| r.color_err.is_some());
    let textures = report.rows.iter().any(|r| r.texture_err.is_some());
    writeln!(
        out,
        "{:<mesh_w$} {:>9} {:>6} {:<backend_w$} {:>9} {:>9} {:>7} {:>8} {:>9} {:>9}{}{}",
        "mesh",
        "faces",
        "ratio",
        "backend",
        "out faces",
        "median s",
        "Mtri/s",
        "peak MiB",
        "mean err",
        "max err",
        if colors { "  colour err" } else { "" },
        if textures { " texture err" } else { "" }
    )?;
    let opt = |v: Option<f64>, prec: usize, e: bool| match (v, e) {
        (None, _) => "n/a".to_string(),
        (Some(v), true) => format!("{v:.prec$e}"),
        (Some(v), false) => format!("{v:.prec$}"),
    };
    for r in &report.rows {
        writeln!(
            out,
            "{:<mesh_w$} {:>9} {:>6} {:<backend_w$} {:>9} {:>9.4} {:>7.2} {:>8} {:>9} {:>9}{}{}",
            r.mesh,
            r.input_faces,
            r.ratio,
            r.backend,
            if r.missed_target {
                format!("{}*", r.output_faces)
            } else {
                r.output_faces.to_string()
            },
            r.median_s,
            r.mtri_per_s,
            opt(r.peak_mib, 1, false),
            opt(r.mean_err_rel, 2, true),
            opt(r.max_err_rel, 2, true),
            if colors {
                format!("  {:>10}", opt(r.color_err, 4, false))
            } else {
                String::new()
            },
            if textures {
                format!("  {:>10}", opt(r.texture_err, 4, false))
            } else {
                String::new()
            },
        )?;
    }
    let devices: Vec<&str> = report.rows.iter().fold(Vec::new(), |mut v, r| {
        if !v.contains(&r.device.as_str()) {
            v.push(&r.device);
        }
        v
    });
    writeln!(
        out,
        "\nmedian of {} run(s) of the simplify call; errors are two-sided Metro distances \
         relative to the input's bounding-box diagonal; peak MiB is heap held above the \
         baseline during the call (output included; Rust heap only, meshoptimizer's C++ scratch \
         memory is not counted)",
        report.repeat
    )?;
    if colors {
        writeln!(
            out,
            "colour err: mean RGB distance (0..1 units) of the vertex colours at the same samples \
             ('meshslim compare'); n/a where the output has no colours"
        )?;
    }
    if textures {
        writeln!(
            out,
            "texture err: mean RGB distance (0..1 units) of the texture's colour at the \
             interpolated UVs ('meshslim compare --texture'); n/a where the output has no UVs"
        )?;
    }
    if let Some(r) = report.rows.iter().find(|r| r.missed_target) {
        writeln!(
            out,
            "* stopped above its target (e.g. {} {} at {}: {} faces for {}): no collapse was \
             left that keeps the topology and the constraints (`meshslim simplify` says why); \
             its errors are those of a larger mesh",
            r.mesh, r.backend, r.ratio, r.output_faces, r.target_faces
        )?;
    }
    writeln!(
        out,
        "device: {} ({} cores)",
        devices.join(", "),
        report.machine.cores
    )?;
    write_against_peers(out, report, mesh_w, backend_w)
}

/// Under the table, each row whose peer (its backend's [`super::BenchBackend::peer`]) ran on
/// the same mesh at the same ratio: the peer's median time over ours (above 1: ours is
/// faster) and our mean error over the peer's (below 1: ours is closer). Nothing when no
/// peer ran.
fn write_against_peers(
    out: &mut impl Write,
    report: &Report,
    mesh_w: usize,
    backend_w: usize,
) -> std::io::Result<()> {
    let pairs: Vec<(&Row, &Row)> = report
        .rows
        .iter()
        .filter_map(|r| {
            let peer = super::backend(&r.backend)?.peer?;
            let p = report
                .rows
                .iter()
                .find(|p| p.backend == peer && p.mesh == r.mesh && p.ratio == r.ratio)?;
            Some((r, p))
        })
        .collect();
    if pairs.is_empty() {
        return Ok(());
    }
    writeln!(
        out,
        "\nagainst meshoptimizer: speed is its median time over ours (above 1: ours is faster), \
         error our mean error over its (below 1: ours is closer)"
    )?;
    let peer_w = pairs
        .iter()
        .map(|(_, p)| p.backend.len())
        .max()
        .unwrap_or(4);
    writeln!(
        out,
        "{:<mesh_w$} {:>6} {:<backend_w$} {:<peer_w$} {:>6} {:>6}",
        "mesh", "ratio", "backend", "peer", "speed", "error"
    )?;
    for (r, p) in pairs {
        let error = match (r.mean_err_rel, p.mean_err_rel) {
            (Some(ours), Some(theirs)) if theirs > 0.0 => format!("{:.2}", ours / theirs),
            _ => "n/a".to_string(),
        };
        writeln!(
            out,
            "{:<mesh_w$} {:>6} {:<backend_w$} {:<peer_w$} {:>6.2} {:>6}",
            r.mesh,
            r.ratio,
            r.backend,
            p.backend,
            p.median_s / r.median_s,
            error
        )?;
    }
    Ok(())
}

/// Marker shapes and colours (Okabe–Ito, safe for colour-blind readers) by index in
/// [`BACKENDS`], so that a backend looks the same in every plot.
const STYLES: [(&str, &str); 8] = [
    ("circle", "#0072B2"),
    ("square", "#E69F00"),
    ("triangle", "#009E73"),
    ("diamond", "#D55E00"),
    ("down", "#CC79A7"),
    ("circle", "#56B4E9"),
    ("square", "#000000"),
    ("triangle", "#F0E442"),
];

fn style(backend: &str) -> (&'static str, &'static str) {
    let i = BACKENDS
        .iter()
        .position(|b| b.name == backend)
        .unwrap_or(BACKENDS.len());
    STYLES[i % STYLES.len()]
}

fn marker(shape: &str, x: f64, y: f64, colour: &str) -> String {
    let r = 5.5;
    let paint = format!(r##"fill="{colour}" stroke="#222" stroke-width="0.8""##);
    match shape {
        "square" => format!(
            r##"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" {paint}/>"##,
            x - r * 0.9,
            y - r * 0.9,
            r * 1.8,
            r * 1.8
        ),
        "triangle" | "down" => {
            let s = if shape == "down" { -1.0 } else { 1.0 };
            format!(
                r##"<polygon points="{:.1},{:.1} {:.1},{:.1} {:.1},{:.1}" {paint}/>"##,
                x,
                y - s * r * 1.2,
                x - r * 1.1,
                y + s * r * 0.8,
                x + r * 1.1,
                y + s * r * 0.8
            )
        }
        "diamond" => format!(
            r##"<polygon points="{x:.1},{:.1} {:.1},{y:.1} {x:.1},{:.1} {:.1},{y:.1}" {paint}/>"##,
            y - r * 1.3,
            x + r * 1.3,
            y + r * 1.3,
            x - r * 1.3
        ),
        _ => format!(r##"<circle cx="{x:.1}" cy="{y:.1}" r="{r}" {paint}/>"##),
    }
}

fn xml(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A decade range covering `values` (positive ones), at least one decade wide.
fn log_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| *v > 0.0 && v.is_finite())
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if !lo.is_finite() {
        return (-1.0, 0.0);
    }
    let (a, b) = (lo.log10().floor(), hi.log10().ceil());
    (a, if b > a { b } else { a + 1.0 })
}

/// A tick label for 10^e times `m`: plain decimals between 0.001 and 10,000, else `1e-5`.
fn tick_label(m: f64, e: f64) -> String {
    let v = m * 10f64.powf(e);
    if (-3.0..=4.0).contains(&e) {
        let digits = (-e).max(0.0) as usize;
        format!("{v:.digits$}")
    } else {
        format!("{m}e{e}")
    }
}

/// Error against time, log-log: one panel per ratio (shared axes, so panels compare), one
/// marker shape and colour per backend, each backend's markers in one
/// `<g class="series" data-backend="NAME">` group. Rows without an error are left out.
pub fn plot_svg(report: &Report) -> String {
    let (ratios, backends, meshes) = distinct_keys(report);
    let points: Vec<&Row> = report
        .rows
        .iter()
        .filter(|r| r.mean_err_rel.is_some_and(|e| e > 0.0) && r.median_s > 0.0)
        .collect();
    let plot = Plot::new(&points, ratios.len());
    let mut s = String::new();
    write_heading(&mut s, &plot, report, &meshes);
    for (i, &ratio) in ratios.iter().enumerate() {
        write_panel(&mut s, &plot, report, i, ratio);
    }
    write_series(&mut s, &plot, &points, &ratios, &backends, meshes.len() > 1);
    write_legend(&mut s, &plot, &backends);
    let _ = writeln!(s, "</svg>");
    s
}

/// The ratios, backends and meshes of the rows, each in order of first appearance.
fn distinct_keys(report: &Report) -> (Vec<f64>, Vec<&str>, Vec<&str>) {
    let mut ratios: Vec<f64> = Vec::new();
    let mut backends: Vec<&str> = Vec::new();
    let mut meshes: Vec<&str> = Vec::new();
    for r in &report.rows {
        if !ratios.contains(&r.ratio) {
            ratios.push(r.ratio);
        }
        if !backends.contains(&r.backend.as_str()) {
            backends.push(&r.backend);
        }
        if !meshes.contains(&r.mesh.as_str()) {
            meshes.push(&r.mesh);
        }
    }
    (ratios, backends, meshes)
}

/// The plot's geometry: the axes' decade ranges, one panel's plot area and its margins, and the
/// number of panels.
#[derive(Clone, Copy)]
struct Plot {
    /// log10 of the time axis' ends.
    x0: f64,
    x1: f64,
    /// log10 of the error axis' ends.
    y0: f64,
    y1: f64,
    pw: f64,
    ph: f64,
    ml: f64,
    mr: f64,
    mt: f64,
    mb: f64,
    legend_w: f64,
    /// The number of panels (at least one).
    n: f64,
}

impl Plot {
    /// The geometry for `points` in `panels` panels.
    fn new(points: &[&Row], panels: usize) -> Plot {
        let (x0, x1) = log_range(points.iter().map(|r| r.median_s));
        let (y0, y1) = log_range(points.iter().filter_map(|r| r.mean_err_rel));
        Plot {
            x0,
            x1,
            y0,
            y1,
            pw: 400.0,
            ph: 330.0,
            ml: 78.0,
            mr: 18.0,
            mt: 76.0,
            mb: 52.0,
            legend_w: 190.0,
            n: panels.max(1) as f64,
        }
    }

    /// The x of time `t` in panel `panel`.
    fn px(&self, panel: usize, t: f64) -> f64 {
        panel as f64 * (self.ml + self.pw + self.mr)
            + self.ml
            + (t.log10() - self.x0) / (self.x1 - self.x0) * self.pw
    }

    /// The y of error `e`.
    fn py(&self, e: f64) -> f64 {
        self.mt + self.ph - (e.log10() - self.y0) / (self.y1 - self.y0) * self.ph
    }

    /// The x of panel `i`'s plot area's left edge.
    fn left(&self, i: usize) -> f64 {
        i as f64 * (self.ml + self.pw + self.mr) + self.ml
    }
}

/// The `<svg>` element, the white background, the title and the line naming the meshes and the
/// machine.
fn write_heading(s: &mut String, plot: &Plot, report: &Report, meshes: &[&str]) {
    let Plot {
        pw,
        ph,
        ml,
        mr,
        mt,
        mb,
        legend_w,
        n,
        ..
    } = *plot;
    let width = n * (ml + pw + mr) + legend_w;
    let height = mt + ph + mb;
    let _ = writeln!(
        s,
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" viewBox="0 0 {width} {height}" font-family="DejaVu Sans, Helvetica, Arial, sans-serif" font-size="12">"##
    );
    let _ = writeln!(
        s,
        r##"<rect width="{width}" height="{height}" fill="white"/>"##
    );
    let _ = writeln!(
        s,
        r##"<text x="12" y="24" font-size="16" font-weight="bold">Mean two-sided error against simplify time (log-log; lower left is better)</text>"##
    );
    let _ = writeln!(
        s,
        r##"<text x="12" y="44" fill="#444">{} · {} · {} cores · median of {} run(s)</text>"##,
        xml(&meshes.join(", ")),
        xml(&report.machine.cpu),
        report.machine.cores,
        report.repeat
    );
}

/// Panel `i`, for `ratio`: its title (with the target face count when the rows agree on one),
/// grid, frame and axis labels.
fn write_panel(s: &mut String, plot: &Plot, report: &Report, i: usize, ratio: f64) {
    let Plot { pw, ph, mt, .. } = *plot;
    let left = plot.left(i);
    let faces: Vec<usize> = report
        .rows
        .iter()
        .filter(|r| r.ratio == ratio)
        .map(|r| r.target_faces)
        .fold(Vec::new(), |mut v, f| {
            if !v.contains(&f) {
                v.push(f);
            }
            v
        });
    let title = if faces.len() == 1 {
        format!("ratio {ratio} (target {} faces)", faces[0])
    } else {
        format!("ratio {ratio}")
    };
    let _ = writeln!(
        s,
        r##"<text x="{:.1}" y="{:.1}" text-anchor="middle" font-size="14" font-weight="bold">{}</text>"##,
        left + pw / 2.0,
        mt - 10.0,
        xml(&title)
    );
    write_grid(s, plot, i);
    let _ = writeln!(
        s,
        r##"<rect x="{left:.1}" y="{mt}" width="{pw}" height="{ph}" fill="none" stroke="#333"/>"##
    );
    let _ = writeln!(
        s,
        r##"<text x="{:.1}" y="{:.1}" text-anchor="middle">median simplify time (s)</text>"##,
        left + pw / 2.0,
        mt + ph + 38.0
    );
    let (lx, ly) = (left - 58.0, mt + ph / 2.0);
    let _ = writeln!(
        s,
        r##"<text x="{lx:.1}" y="{ly:.1}" text-anchor="middle" transform="rotate(-90 {lx:.1} {ly:.1})">mean two-sided error / bbox diagonal</text>"##
    );
}

/// Panel `i`'s grid: every decade labelled; minor lines at 2..9, labelled at 2 and 5 when the
/// axis spans few decades, so that a narrow range still has numbers to read.
fn write_grid(s: &mut String, plot: &Plot, i: usize) {
    let Plot {
        x0,
        x1,
        y0,
        y1,
        pw,
        ph,
        mt,
        ..
    } = *plot;
    let left = plot.left(i);
    let many = |lo: f64, hi: f64| hi - lo <= 2.0;
    for (lo, hi, vertical) in [(x0, x1, true), (y0, y1, false)] {
        let mut e = lo;
        while e <= hi {
            for m in 1..10 {
                let v = m as f64 * 10f64.powf(e);
                if v.log10() > hi + 1e-9 {
                    break;
                }
                let major = m == 1;
                let labelled = major || (many(lo, hi) && (m == 2 || m == 5));
                let colour = if major { "#bbb" } else { "#e6e6e6" };
                let label = tick_label(m as f64, e);
                if vertical {
                    let x = plot.px(i, v);
                    let _ = writeln!(
                        s,
                        r##"<line x1="{x:.1}" y1="{mt}" x2="{x:.1}" y2="{:.1}" stroke="{colour}"/>"##,
                        mt + ph
                    );
                    if labelled {
                        let _ = writeln!(
                            s,
                            r##"<text x="{x:.1}" y="{:.1}" text-anchor="middle" fill="#333">{label}</text>"##,
                            mt + ph + 16.0
                        );
                    }
                } else {
                    let y = plot.py(v);
                    let _ = writeln!(
                        s,
                        r##"<line x1="{left:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="{colour}"/>"##,
                        left + pw
                    );
                    if labelled {
                        let _ = writeln!(
                            s,
                            r##"<text x="{:.1}" y="{:.1}" text-anchor="end" fill="#333">{label}</text>"##,
                            left - 6.0,
                            y + 4.0
                        );
                    }
                }
            }
            e += 1.0;
        }
    }
}

/// Each backend's markers, in its panel, in one `<g class="series">` group; each marker named by
/// its mesh when there are several.
fn write_series(
    s: &mut String,
    plot: &Plot,
    points: &[&Row],
    ratios: &[f64],
    backends: &[&str],
    name_meshes: bool,
) {
    for backend in backends {
        let (shape, colour) = style(backend);
        let _ = writeln!(s, r##"<g class="series" data-backend="{}">"##, xml(backend));
        for r in points.iter().filter(|r| r.backend == *backend) {
            let panel = ratios.iter().position(|&q| q == r.ratio).unwrap_or(0);
            let (x, y) = (
                plot.px(panel, r.median_s),
                plot.py(r.mean_err_rel.unwrap_or(0.0)),
            );
            let _ = writeln!(s, "{}", marker(shape, x, y, colour));
            if name_meshes {
                let _ = writeln!(
                    s,
                    r##"<text x="{:.1}" y="{:.1}" font-size="10" fill="#555">{}</text>"##,
                    x + 8.0,
                    y - 6.0,
                    xml(&r.mesh)
                );
            }
        }
        let _ = writeln!(s, "</g>");
    }
}

/// The legend right of the panels: a marker and the name of each backend.
fn write_legend(s: &mut String, plot: &Plot, backends: &[&str]) {
    let Plot {
        pw, ml, mr, mt, n, ..
    } = *plot;
    let lx = n * (ml + pw + mr) + 10.0;
    let _ = writeln!(
        s,
        r##"<text x="{lx:.1}" y="{:.1}" font-weight="bold">backend</text>"##,
        mt + 4.0
    );
    for (k, backend) in backends.iter().enumerate() {
        let (shape, colour) = style(backend);
        let y = mt + 26.0 + 24.0 * k as f64;
        let _ = writeln!(s, "{}", marker(shape, lx + 8.0, y, colour));
        let _ = writeln!(
            s,
            r##"<text x="{:.1}" y="{:.1}">{}</text>"##,
            lx + 22.0,
            y + 4.0,
            xml(backend)
        );
    }
}

/// Renders an SVG (the plot) to PNG bytes with resvg, text in the system's fonts.
pub fn svg_to_png(svg: &str) -> Result<Vec<u8>, String> {
    crate::raster::svg_pixmap(svg, Some(resvg::tiny_skia::Color::WHITE))?
        .encode_png()
        .map_err(|e| e.to_string())
}
