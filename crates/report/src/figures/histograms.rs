//! Histograms of the residuals of the samples used, one per component, against the
//! Gaussian of the estimated scan-matching σ: heavy tails or a shifted centre show
//! where the noise model does not hold.

use super::data::FigureData;
use super::residuals::COMPONENTS;
use super::style::{legend_row, svg, tick, Mark, FONT, USED};
use super::{DrawError, Figure};
use plotters::prelude::*;

const BINS: usize = 31;
const GAUSS: RGBColor = RGBColor(0, 0, 0);

/// Bin counts of `values` over `[lo, hi)` in `BINS` equal bins (outside values dropped).
fn counts(values: &[f64], lo: f64, hi: f64) -> Vec<usize> {
    let w = (hi - lo) / BINS as f64;
    let mut out = vec![0; BINS];
    for v in values {
        let b = ((v - lo) / w).floor();
        if b >= 0.0 && (b as usize) < BINS {
            out[b as usize] += 1;
        }
    }
    out
}

/// The histogram figure.
pub fn figure(d: &FigureData) -> Result<Figure, DrawError> {
    let svg = svg(330, |root| {
        let (top, body) = root.split_vertically(30);
        legend_row(
            &top,
            &[
                (Mark::Square(USED), "residuals of the samples used".into()),
                (Mark::Line(GAUSS, 2), "Gaussian with the estimated σ".into()),
            ],
        )?;
        for (c, panel) in body.split_evenly((1, 3)).iter().enumerate() {
            let (name, scale, unit) = COMPONENTS[c];
            let values: Vec<f64> = (0..d.residuals.len())
                .filter(|&k| d.used[k])
                .map(|k| d.residuals[k][c] * scale)
                .filter(|v| v.is_finite())
                .collect();
            let sigma = d.sm_sigma[c] * scale;
            let half = if sigma.is_finite() && sigma > 0.0 {
                4.0 * sigma
            } else {
                1.0
            };
            let (lo, hi) = (-half, half);
            let n = counts(&values, lo, hi);
            let width = (hi - lo) / BINS as f64;
            let gauss = |x: f64| {
                values.len() as f64 * width * (-0.5 * (x / sigma).powi(2)).exp()
                    / (sigma * (2.0 * std::f64::consts::PI).sqrt())
            };
            let top_count = n.iter().copied().max().unwrap_or(0) as f64;
            let y_max = top_count.max(gauss(0.0)).max(1.0) * 1.1;
            let mut chart = ChartBuilder::on(panel)
                .margin(8)
                .x_label_area_size(36)
                .y_label_area_size(if c == 0 { 50 } else { 36 })
                .build_cartesian_2d(lo..hi, 0.0..y_max)?;
            chart
                .configure_mesh()
                .x_desc(format!("{name} residual ({unit})"))
                .y_desc(if c == 0 { "samples" } else { "" })
                .x_labels(5)
                .label_style((FONT, 12))
                .light_line_style(TRANSPARENT)
                .x_label_formatter(&tick)
                .y_label_formatter(&tick)
                .draw()?;
            chart.draw_series(n.iter().enumerate().map(|(b, &count)| {
                let x = lo + b as f64 * width;
                Rectangle::new(
                    [(x, 0.0), (x + width, count as f64)],
                    USED.mix(0.6).filled(),
                )
            }))?;
            chart.draw_series(LineSeries::new(
                (0..=200).map(|i| {
                    let x = lo + (hi - lo) * i as f64 / 200.0;
                    (x, gauss(x))
                }),
                GAUSS.stroke_width(2),
            ))?;
        }
        Ok(())
    })?;
    Ok(Figure {
        name: "residual_histograms",
        title: "Residual histograms against the noise model".into(),
        caption: "Residuals of the samples used (±4σ shown) with the Gaussian of the \
                  scan-matching σ the covariance assumes; bars above the curve in the tails \
                  mean heavier tails than assumed."
            .into(),
        svg,
    })
}
