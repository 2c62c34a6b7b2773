//! The clock-offset search: the cost on the coarse grid against the offset, the
//! estimate marked. A single clear minimum is what a trustworthy offset looks like.

use super::style::{legend_column, range, svg, xy_chart, Mark, LEGEND_W, TRIMMED, USED, WIDTH};
use super::{DrawError, Figure};
use odocal_pipeline::time_offset::OffsetEstimate;
use plotters::prelude::*;

/// The clock-offset figure.
pub fn figure(o: &OffsetEstimate) -> Result<Figure, DrawError> {
    let xr = range(o.grid.iter().map(|g| g.0).chain([o.offset]));
    let yr = range(o.grid.iter().map(|g| g.1));
    let svg = svg(380, |root| {
        let (plot, legend) = root.split_horizontally(WIDTH - LEGEND_W);
        let mut chart = xy_chart(
            &plot,
            xr,
            yr,
            "clock offset, laser − encoder (s)",
            "cost (coarse grid)",
        )?;
        chart.draw_series(LineSeries::new(
            o.grid.iter().copied(),
            USED.stroke_width(2),
        ))?;
        chart.draw_series(o.grid.iter().map(|p| Circle::new(*p, 3, USED.filled())))?;
        chart.draw_series(std::iter::once(PathElement::new(
            vec![(o.offset, yr.0), (o.offset, yr.1)],
            TRIMMED.stroke_width(2),
        )))?;
        legend_column(
            &legend,
            &[
                (Mark::Line(USED, 2), "cost on the grid".into()),
                (
                    Mark::Line(TRIMMED, 2),
                    format!("estimate {:+.4} s", o.offset),
                ),
            ],
        )
    })?;
    Ok(Figure {
        name: "time_offset",
        title: "Clock offset: cost against offset".into(),
        caption: format!(
            "The search's coarse grid and the refined estimate {:+.4} s (cost {:.4e}, at the \
             starting offset {:.4e}).",
            o.offset, o.cost, o.cost_at_start
        ),
        svg,
    })
}
