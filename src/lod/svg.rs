//! The fronts of a Pareto run as an SVG plot: error (log scale) against the share of vertices
//! kept, one polyline per generation from pale to dark, the greedy chain dashed.

use super::nsga::Point;
use std::fmt::Write;

const W: f64 = 720.0;
const H: f64 = 480.0;
const LEFT: f64 = 80.0;
const RIGHT: f64 = 20.0;
const TOP: f64 = 40.0;
const BOTTOM: f64 = 60.0;

/// The plot: `fronts` in order (the last drawn darkest), `baseline` dashed, `title` on top.
pub fn fronts_svg(title: &str, fronts: &[Vec<Point>], baseline: &[Point]) -> String {
    let axes = Axes::fit(fronts.iter().flatten().chain(baseline));
    let (x_max, (l0, l1)) = (axes.x_max, axes.decades);
    let px = |x: f64| LEFT + axes.unit([x, 1.0]).0 * (W - LEFT - RIGHT);
    let py = |y: f64| H - BOTTOM - axes.unit([0.0, y]).1 * (H - TOP - BOTTOM);
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(s, r#"<rect width="{W}" height="{H}" fill="white"/>"#);
    let _ = writeln!(
        s,
        r#"<text x="{}" y="22" text-anchor="middle" font-size="14">{}</text>"#,
        W / 2.0,
        escape(title)
    );
    // Axes, the error's decades and the vertex share's tenths.
    let (x0, y0) = (LEFT, H - BOTTOM);
    let _ = writeln!(
        s,
        r#"<path d="M{x0} {TOP} V{y0} H{}" stroke="black" fill="none"/>"#,
        W - RIGHT
    );
    for d in l0 as i32..=l1 as i32 {
        let y = py(10f64.powi(d));
        let _ = writeln!(
            s,
            r##"<path d="M{x0} {y:.1} H{}" stroke="#ddd"/><text x="{}" y="{:.1}" text-anchor="end">1e{d}</text>"##,
            W - RIGHT,
            x0 - 6.0,
            y + 4.0
        );
    }
    for k in 0..=10 {
        let x = x_max * k as f64 / 10.0;
        let _ = writeln!(
            s,
            r#"<text x="{:.1}" y="{}" text-anchor="middle">{:.3}</text>"#,
            px(x),
            y0 + 18.0,
            x
        );
    }
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" text-anchor="middle">share of the vertices kept</text>"#,
        (LEFT + W - RIGHT) / 2.0,
        H - 16.0
    );
    let _ = writeln!(
        s,
        r#"<text x="18" y="{}" text-anchor="middle" transform="rotate(-90 18 {})">error (relative to the diagonal)</text>"#,
        (TOP + y0) / 2.0,
        (TOP + y0) / 2.0
    );
    let line = |s: &mut String, pts: &[Point], style: &str| {
        let d: Vec<String> = pts
            .iter()
            .filter(|p| p[1] > 0.0)
            .map(|p| format!("{:.1},{:.1}", px(p[0]), py(p[1])))
            .collect();
        if !d.is_empty() {
            let _ = writeln!(
                s,
                r#"<polyline points="{}" fill="none" {style}/>"#,
                d.join(" ")
            );
        }
    };
    let n = fronts.len().max(1) as f64;
    for (g, f) in fronts.iter().enumerate() {
        // Pale blue to dark blue.
        let t = (g + 1) as f64 / n;
        let c = (200.0 * (1.0 - t)) as u8;
        line(
            &mut s,
            f,
            &format!(r#"stroke="rgb({c},{c},255)" stroke-width="1.5""#),
        );
    }
    line(
        &mut s,
        baseline,
        r#"stroke="rgb(230,120,0)" stroke-width="2" stroke-dasharray="6 4""#,
    );
    let _ = writeln!(
        s,
        r##"<text x="{}" y="{}" text-anchor="end" fill="#00f">final front (pale: earlier generations)</text><text x="{}" y="{}" text-anchor="end" fill="rgb(230,120,0)">greedy chain</text>"##,
        W - RIGHT - 6.0,
        TOP + 14.0,
        W - RIGHT - 6.0,
        TOP + 30.0
    );
    s.push_str("</svg>\n");
    s
}

/// The plot's axes, shared by the SVG and the viewer's front: the share of vertices kept from 0
/// to the largest, and the error on a log scale over whole decades.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Axes {
    pub x_max: f64,
    /// The first and last decade (powers of ten) of the error axis.
    pub decades: (f64, f64),
}

impl Axes {
    /// Axes holding every point with a positive error (a zero error has no place on a log
    /// scale; it is drawn at the bottom).
    pub fn fit<'a>(points: impl Iterator<Item = &'a Point> + Clone) -> Axes {
        let all = || points.clone().filter(|p| p[1] > 0.0);
        let x_max = all().map(|p| p[0]).fold(0.0, f64::max).max(1e-9);
        let (mut y_lo, mut y_hi) = all().fold((f64::MAX, f64::MIN), |(lo, hi), p| {
            (lo.min(p[1]), hi.max(p[1]))
        });
        if y_lo > y_hi {
            (y_lo, y_hi) = (1e-6, 1e-2);
        }
        let l0 = y_lo.log10().floor();
        Axes {
            x_max,
            decades: (l0, y_hi.log10().ceil().max(l0 + 1.0)),
        }
    }

    /// Where `p` falls in the plot, each coordinate in [0, 1] (y up).
    pub fn unit(&self, p: Point) -> (f64, f64) {
        let (l0, l1) = self.decades;
        let y = (p[1].max(10f64.powf(l0)).log10() - l0) / (l1 - l0);
        (p[0] / self.x_max, y.min(1.0))
    }
}

fn escape(t: &str) -> String {
    t.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}
