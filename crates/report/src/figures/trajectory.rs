//! The sensor's path three ways: chained scan matching (a wide grey band underneath,
//! so it shows where odometry lies on it), odometry with the calibrated parameters and
//! with the nominal ones; start and ends marked; equal scales; legend beside the plot.

use super::data::FigureData;
use super::style::{legend_column, range, svg, xy_chart, Mark, LEGEND_W, WIDTH};
use super::{DrawError, Figure};
use plotters::prelude::*;

const HEIGHT: u32 = 560;

const SM: RGBColor = RGBColor(170, 170, 170);
const CALIBRATED: RGBColor = RGBColor(31, 119, 180);
const NOMINAL: RGBColor = RGBColor(214, 39, 40);

/// Widens `(x, y)` ranges so one metre spans the same pixels on both axes of a
/// `w × h` pixel plot.
fn equal_scale(x: (f64, f64), y: (f64, f64), w: f64, h: f64) -> ((f64, f64), (f64, f64)) {
    let s = ((x.1 - x.0) / w).max((y.1 - y.0) / h);
    let (cx, cy) = ((x.0 + x.1) / 2.0, (y.0 + y.1) / 2.0);
    (
        (cx - s * w / 2.0, cx + s * w / 2.0),
        (cy - s * h / 2.0, cy + s * h / 2.0),
    )
}

/// The trajectory figure.
pub fn figure(d: &FigureData) -> Result<Figure, DrawError> {
    let sm = d.scan_matching_path();
    let calibrated = d.odometry_path(&d.params);
    let nominal = d.odometry_path(&d.nominal.0);
    let all = || sm.iter().chain(&calibrated).chain(&nominal);
    // Plot area in pixels: the figure minus legend, caption, margins and labels.
    let (pw, ph) = ((WIDTH - LEGEND_W - 90) as f64, (HEIGHT - 100) as f64);
    let (xr, yr) = equal_scale(range(all().map(|p| p.0)), range(all().map(|p| p.1)), pw, ph);
    let end = |p: &[(f64, f64)]| p.last().copied().unwrap_or((0.0, 0.0));
    let drift = |p: &[(f64, f64)]| {
        let (a, b) = (end(p), end(&sm));
        ((a.0 - b.0).powi(2) + (a.1 - b.1).powi(2)).sqrt()
    };
    // The end distances compare the parameters: samples flagged as slip follow scan
    // matching in all three paths, else a slip would count against any calibration.
    let slips = d.slipped.iter().filter(|s| **s).count();
    let (calibrated_end, nominal_end) = if slips > 0 {
        (
            drift(&d.odometry_path_without_slip(&d.params)),
            drift(&d.odometry_path_without_slip(&d.nominal.0)),
        )
    } else {
        (drift(&calibrated), drift(&nominal))
    };
    let excluded = if slips > 0 {
        format!(
            " ({slips} sample(s) flagged as slip left out of this comparison: the paths \
             drawn include them, {:.1} mm and {:.1} mm)",
            1e3 * drift(&calibrated),
            1e3 * drift(&nominal)
        )
    } else {
        String::new()
    };
    let svg = svg(HEIGHT, |root| {
        let (plot, legend) = root.split_horizontally(WIDTH - LEGEND_W);
        let mut chart = xy_chart(&plot, xr, yr, "x (m)", "y (m)")?;
        chart.draw_series(LineSeries::new(sm.iter().copied(), SM.stroke_width(7)))?;
        chart.draw_series(DashedLineSeries::new(
            nominal.iter().copied(),
            6,
            4,
            NOMINAL.stroke_width(2),
        ))?;
        chart.draw_series(LineSeries::new(
            calibrated.iter().copied(),
            CALIBRATED.stroke_width(2),
        ))?;
        // Largest first, so that ends at the same place stay visible as nested squares.
        for (p, c, r) in [
            (&sm, SM, 8),
            (&nominal, NOMINAL, 5),
            (&calibrated, CALIBRATED, 3),
        ] {
            let (x, y) = end(p);
            chart.draw_series(std::iter::once(
                EmptyElement::at((x, y)) + Rectangle::new([(-r, -r), (r, r)], c.filled()),
            ))?;
        }
        chart.draw_series(std::iter::once(
            EmptyElement::at((0.0, 0.0)) + Circle::new((0, 0), 7, BLACK.filled()),
        ))?;
        legend_column(
            &legend,
            &[
                (Mark::Line(SM, 7), "chained scan matching".into()),
                (Mark::Line(CALIBRATED, 2), "odometry, calibrated".into()),
                (Mark::Dashed(NOMINAL, 2), d.nominal.1.into()),
                (Mark::Dot(BLACK), "start (all three)".into()),
                (Mark::Square(BLACK), "end (one square per path)".into()),
            ],
        )
    })?;
    Ok(Figure {
        name: "trajectory",
        title: "Sensor trajectory: odometry against scan matching".into(),
        caption: format!(
            "The laser's path from chaining the {} samples' displacements. At the end, \
             odometry with the calibrated parameters is {:.1} mm from scan matching, with the \
             nominal ones ({}) {:.1} mm{excluded}.",
            d.samples.len(),
            1e3 * calibrated_end,
            d.nominal.1.trim_start_matches("odometry, "),
            1e3 * nominal_end
        ),
        svg,
    })
}
