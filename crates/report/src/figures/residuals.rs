//! Residuals `ŝ_pred − ŝ` over time, one panel per component in its own unit (x and y
//! in mm, θ in mrad): the samples used as dots, the trimmed ones as crosses (clipped
//! to the panel's edge when far out), time spans of findings (slip) shaded.

use super::data::FigureData;
use super::style::{
    legend_row, range, svg, symmetric_range, tick, Mark, FONT, SPAN, TRIMMED, USED,
};
use super::{DrawError, Figure};
use plotters::prelude::*;

/// Component name, scale from SI, unit.
pub const COMPONENTS: [(&str, f64, &str); 3] =
    [("x", 1e3, "mm"), ("y", 1e3, "mm"), ("θ", 1e3, "mrad")];

/// The residuals-over-time figure.
pub fn figure(d: &FigureData) -> Result<Figure, DrawError> {
    let (t0, t1) = range(d.times.iter().copied());
    let trimmed = d.used.iter().filter(|u| !**u).count();
    let svg =
        svg(640, |root| {
            let (top, body) = root.split_vertically(30);
            let mut entries = vec![
                (Mark::Dot(USED), "used".to_string()),
                (Mark::Cross(TRIMMED), "trimmed as outlier".to_string()),
            ];
            if !d.spans.is_empty() {
                entries.push((Mark::Band(SPAN), "flagged span (slip)".to_string()));
            }
            legend_row(&top, &entries)?;
            let panels = body.split_evenly((3, 1));
            for (c, panel) in panels.iter().enumerate() {
                let (name, scale, unit) = COMPONENTS[c];
                let value = |k: usize| d.residuals[k][c] * scale;
                let (lo, hi) =
                    symmetric_range((0..d.times.len()).filter(|&k| d.used[k]).map(value));
                let clip = |v: f64| v.clamp(lo, hi);
                let mut chart = ChartBuilder::on(panel)
                    .margin(8)
                    .x_label_area_size(if c == 2 { 36 } else { 18 })
                    .y_label_area_size(64)
                    .build_cartesian_2d(t0..t1, lo..hi)?;
                let mut mesh = chart.configure_mesh();
                mesh.y_desc(format!("{name} ({unit})"))
                    .label_style((FONT, 12))
                    .light_line_style(TRANSPARENT)
                    .x_label_formatter(&tick)
                    .y_label_formatter(&tick);
                if c == 2 {
                    mesh.x_desc("time since the first sample (s)");
                }
                mesh.draw()?;
                chart.draw_series(d.spans.iter().map(|(a, b, _)| {
                    Rectangle::new([(*a, lo), (*b, hi)], SPAN.mix(0.35).filled())
                }))?;
                chart.draw_series(
                    (0..d.times.len())
                        .filter(|&k| d.used[k])
                        .map(|k| Circle::new((d.times[k], value(k)), 2, USED.mix(0.7).filled())),
                )?;
                chart.draw_series((0..d.times.len()).filter(|&k| !d.used[k]).map(|k| {
                    Cross::new((d.times[k], clip(value(k))), 3, TRIMMED.stroke_width(1))
                }))?;
            }
            Ok(())
        })?;
    Ok(Figure {
        name: "residuals_time",
        title: "Residuals over time".into(),
        caption: format!(
            "Odometry with the calibrated parameters minus scan matching, per sample: {} used, \
             {trimmed} trimmed as outliers (crosses; far ones drawn at the panel's edge). Runs \
             of large residuals of one sign are wheel slip or a bad stretch of scan matching.",
            d.used.len() - trimmed
        ),
        svg,
    })
}
