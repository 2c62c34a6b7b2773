//! Small hand-written SVG figures: line/scatter plots and histograms.
//!
//! A plotting library would be a large dependency for three kinds of simple
//! figures; these are plain SVG text with axes, ticks and a legend.

use std::fmt::Write;

const W: f64 = 640.0;
const H: f64 = 420.0;
const LEFT: f64 = 70.0;
const RIGHT: f64 = 20.0;
const TOP: f64 = 40.0;
const BOTTOM: f64 = 50.0;

/// One data series of a [`Figure`].
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend label.
    pub label: String,
    /// CSS colour.
    pub color: &'static str,
    /// Points (x, y); non-finite points are skipped.
    pub points: Vec<(f64, f64)>,
    /// Draw as a polyline (true) or as dots (false).
    pub line: bool,
}

/// A figure with axes, title and labels.
#[derive(Debug, Clone)]
pub struct Figure {
    /// Title above the plot.
    pub title: String,
    /// Label of the horizontal axis.
    pub x_label: String,
    /// Label of the vertical axis.
    pub y_label: String,
    /// Same scale on both axes (trajectories).
    pub equal_axes: bool,
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// Data range with a margin, never empty.
fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    if hi - lo < 1e-12 * (1.0 + lo.abs()) {
        return (lo - 0.5, hi + 0.5);
    }
    let m = 0.05 * (hi - lo);
    (lo - m, hi + m)
}

/// About five round tick values covering `[lo, hi]`.
fn ticks(lo: f64, hi: f64) -> Vec<f64> {
    let raw = (hi - lo) / 5.0;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag);
    let mut t = (lo / step).ceil() * step;
    let mut out = Vec::new();
    while t <= hi + 1e-9 * step && out.len() < 20 {
        out.push(if t.abs() < 1e-12 * step { 0.0 } else { t });
        t += step;
    }
    out
}

fn fmt_tick(v: f64) -> String {
    let a = v.abs();
    if a != 0.0 && !(1e-3..1e4).contains(&a) {
        format!("{v:.1e}")
    } else {
        let s = format!("{v:.4}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

struct Frame {
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
}

impl Frame {
    fn px(&self, x: f64) -> f64 {
        LEFT + (x - self.x0) / (self.x1 - self.x0) * (W - LEFT - RIGHT)
    }
    fn py(&self, y: f64) -> f64 {
        H - BOTTOM - (y - self.y0) / (self.y1 - self.y0) * (H - TOP - BOTTOM)
    }
}

fn header(out: &mut String, fig: &Figure, f: &Frame) {
    let _ = write!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" viewBox="0 0 {W} {H}" font-family="sans-serif" font-size="12">
<rect width="100%" height="100%" fill="white"/>
<text x="{}" y="22" text-anchor="middle" font-size="15">{}</text>
<text x="{}" y="{}" text-anchor="middle">{}</text>
<text x="16" y="{}" text-anchor="middle" transform="rotate(-90 16 {})">{}</text>
<rect x="{LEFT}" y="{TOP}" width="{}" height="{}" fill="none" stroke="black"/>
"#,
        W / 2.0,
        escape(&fig.title),
        (LEFT + W - RIGHT) / 2.0,
        H - 12.0,
        escape(&fig.x_label),
        (TOP + H - BOTTOM) / 2.0,
        (TOP + H - BOTTOM) / 2.0,
        escape(&fig.y_label),
        W - LEFT - RIGHT,
        H - TOP - BOTTOM
    );
    for t in ticks(f.x0, f.x1) {
        let x = f.px(t);
        let _ = writeln!(
            out,
            r##"<line x1="{x:.1}" y1="{:.1}" x2="{x:.1}" y2="{:.1}" stroke="#ccc"/><text x="{x:.1}" y="{:.1}" text-anchor="middle">{}</text>"##,
            TOP,
            H - BOTTOM,
            H - BOTTOM + 16.0,
            fmt_tick(t)
        );
    }
    for t in ticks(f.y0, f.y1) {
        let y = f.py(t);
        let _ = writeln!(
            out,
            r##"<line x1="{LEFT}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#ccc"/><text x="{:.1}" y="{:.1}" text-anchor="end">{}</text>"##,
            W - RIGHT,
            LEFT - 4.0,
            y + 4.0,
            fmt_tick(t)
        );
    }
}

/// A line or scatter plot of several series, as an SVG document.
pub fn plot(fig: &Figure, series: &[Series]) -> String {
    let all = || series.iter().flat_map(|s| s.points.iter());
    let (mut x0, mut x1) = range(all().map(|p| p.0));
    let (mut y0, mut y1) = range(all().map(|p| p.1));
    if fig.equal_axes {
        // Same metres per pixel on both axes.
        let sx = (x1 - x0) / (W - LEFT - RIGHT);
        let sy = (y1 - y0) / (H - TOP - BOTTOM);
        let s = sx.max(sy);
        let (cx, cy) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
        x0 = cx - s * (W - LEFT - RIGHT) / 2.0;
        x1 = cx + s * (W - LEFT - RIGHT) / 2.0;
        y0 = cy - s * (H - TOP - BOTTOM) / 2.0;
        y1 = cy + s * (H - TOP - BOTTOM) / 2.0;
    }
    let f = Frame { x0, x1, y0, y1 };
    let mut out = String::new();
    header(&mut out, fig, &f);
    for (k, s) in series.iter().enumerate() {
        let pts = s
            .points
            .iter()
            .filter(|p| p.0.is_finite() && p.1.is_finite());
        if s.line {
            let mut d = String::new();
            for (x, y) in pts {
                let _ = write!(d, "{:.1},{:.1} ", f.px(*x), f.py(*y));
            }
            let _ = writeln!(
                out,
                r#"<polyline points="{}" fill="none" stroke="{}" stroke-width="1.2"/>"#,
                d.trim_end(),
                s.color
            );
        } else {
            for (x, y) in pts {
                let _ = writeln!(
                    out,
                    r#"<circle cx="{:.1}" cy="{:.1}" r="1.3" fill="{}"/>"#,
                    f.px(*x),
                    f.py(*y),
                    s.color
                );
            }
        }
        let ly = TOP + 16.0 + 16.0 * k as f64;
        let _ = writeln!(
            out,
            r#"<rect x="{:.1}" y="{:.1}" width="12" height="4" fill="{}"/><text x="{:.1}" y="{:.1}">{}</text>"#,
            LEFT + 10.0,
            ly - 6.0,
            s.color,
            LEFT + 26.0,
            ly,
            escape(&s.label)
        );
    }
    out.push_str("</svg>\n");
    out
}

/// A histogram of `values` with `bins` equal bins, as an SVG document.
pub fn histogram(fig: &Figure, values: &[f64], bins: usize, color: &'static str) -> String {
    let bins = bins.max(1);
    let finite: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
    let (lo, hi) = range(finite.iter().copied());
    let width = (hi - lo) / bins as f64;
    let mut counts = vec![0usize; bins];
    for v in &finite {
        let b = (((v - lo) / width) as usize).min(bins - 1);
        counts[b] += 1;
    }
    let top = counts.iter().copied().max().unwrap_or(0).max(1) as f64;
    let f = Frame {
        x0: lo,
        x1: hi,
        y0: 0.0,
        y1: top * 1.05,
    };
    let mut out = String::new();
    header(&mut out, fig, &f);
    for (b, c) in counts.iter().enumerate() {
        let xa = f.px(lo + b as f64 * width);
        let xb = f.px(lo + (b + 1) as f64 * width);
        let yt = f.py(*c as f64);
        let _ = writeln!(
            out,
            r#"<rect x="{xa:.1}" y="{yt:.1}" width="{:.1}" height="{:.1}" fill="{color}" stroke="white" stroke-width="0.5"/>"#,
            (xb - xa).max(0.0),
            (f.py(0.0) - yt).max(0.0)
        );
    }
    out.push_str("</svg>\n");
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fig() -> Figure {
        Figure {
            title: "a < b".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            equal_axes: true,
        }
    }

    #[test]
    fn ticks_are_round_and_cover() {
        let t = ticks(-0.0123, 0.0311);
        assert_eq!(t, vec![-0.01, 0.0, 0.01, 0.02, 0.03]);
        assert_eq!(ticks(0.0, 100.0), vec![0.0, 20.0, 40.0, 60.0, 80.0, 100.0]);
    }

    #[test]
    fn documents_are_well_formed_and_escaped() {
        let s = plot(
            &fig(),
            &[Series {
                label: "odometry".into(),
                color: "blue",
                points: vec![(0.0, 0.0), (1.0, 2.0), (f64::NAN, 1.0)],
                line: true,
            }],
        );
        assert!(s.starts_with("<svg") && s.ends_with("</svg>\n"));
        assert!(s.contains("a &lt; b") && !s.contains("NaN"));
        let h = histogram(&fig(), &[1.0, 1.0, 2.0, 3.0, f64::INFINITY], 3, "gray");
        assert_eq!(h.matches("<rect x=").count(), 1 + 3);
        // Empty input still gives a document.
        assert!(histogram(&fig(), &[], 10, "gray").ends_with("</svg>\n"));
    }
}
