//! The scan matcher's quality per pair over time: the mean point-to-line residual and
//! the standard deviation of ŝ's position from its covariance; trimmed pairs marked.

use super::data::FigureData;
use super::style::{legend_row, range, svg, tick, Mark, FONT, TRIMMED, USED};
use super::{DrawError, Figure};
use plotters::prelude::*;

/// The ICP figure.
pub fn figure(d: &FigureData) -> Result<Figure, DrawError> {
    let (t0, t1) = range(d.times.iter().copied());
    type Quantity = fn(&odocal_pipeline::samples::PairSample) -> f64;
    let panels: [(&str, Quantity); 2] = [
        ("mean residual (mm)", |s| s.icp.mean_residual * 1e3),
        ("σ of position (mm)", |s| {
            (s.icp.covariance[0][0] + s.icp.covariance[1][1])
                .max(0.0)
                .sqrt()
                * 1e3
        }),
    ];
    let svg = svg(440, |root| {
        let (top, body) = root.split_vertically(30);
        legend_row(
            &top,
            &[
                (Mark::Dot(USED), "pair used".into()),
                (Mark::Cross(TRIMMED), "pair trimmed".into()),
            ],
        )?;
        for (c, (panel, (label, q))) in body.split_evenly((2, 1)).iter().zip(panels).enumerate() {
            let values: Vec<f64> = d.pairs.iter().map(q).collect();
            let (_, hi) = range(values.iter().copied().chain([0.0]));
            let mut chart = ChartBuilder::on(panel)
                .margin(8)
                .x_label_area_size(if c == 1 { 36 } else { 18 })
                .y_label_area_size(64)
                .build_cartesian_2d(t0..t1, 0.0..hi)?;
            let mut mesh = chart.configure_mesh();
            mesh.y_desc(label)
                .label_style((FONT, 12))
                .light_line_style(TRANSPARENT)
                .x_label_formatter(&tick)
                .y_label_formatter(&tick);
            if c == 1 {
                mesh.x_desc("time since the first sample (s)");
            }
            mesh.draw()?;
            chart.draw_series(
                (0..values.len())
                    .filter(|&k| d.used[k])
                    .map(|k| Circle::new((d.times[k], values[k]), 2, USED.mix(0.7).filled())),
            )?;
            chart.draw_series(
                (0..values.len())
                    .filter(|&k| !d.used[k])
                    .map(|k| Cross::new((d.times[k], values[k]), 3, TRIMMED.stroke_width(1))),
            )?;
        }
        Ok(())
    })?;
    Ok(Figure {
        name: "icp_quality",
        title: "Scan matching per pair".into(),
        caption: "The matcher's mean point-to-line residual and the σ of its displacement \
                  (from its covariance) per pair; stretches of high values are poor geometry \
                  or fast motion."
            .into(),
        svg,
    })
}
