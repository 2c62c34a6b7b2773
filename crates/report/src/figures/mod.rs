//! The report's figures, drawn with `plotters` into SVG text: the trajectory, the
//! residuals over time and their histograms, the motion coverage, the clock-offset
//! cost curve (when estimated) and the scan matcher's quality per pair.

mod coverage;
mod data;
mod histograms;
mod icp;
mod residuals;
mod style;
mod time_offset;
mod trajectory;

pub use coverage::{coverage_advice, MotionClass};
pub use data::FigureData;

use crate::report::Report;
use odocal_pipeline::{Options, Outcome};
use rayon::prelude::*;

/// One figure: a file stem (for `--plots`), a title and a caption for the page, and
/// the SVG document.
#[derive(Debug, Clone)]
pub struct Figure {
    /// Short name; `--plots` writes `NAME.svg`, the page uses `fig-NAME` as its id.
    pub name: &'static str,
    /// Title.
    pub title: String,
    /// What to read from it, one or two sentences.
    pub caption: String,
    /// The SVG document.
    pub svg: String,
}

/// Error while drawing a figure (plotting into a string does not fail in practice).
pub type DrawError = Box<dyn std::error::Error>;

/// Every figure for `outcome`, in page order; the clock-offset curve only when the
/// offset was estimated.
pub fn figures(
    opts: &Options,
    outcome: &Outcome,
    report: &Report,
) -> Result<Vec<Figure>, DrawError> {
    let d = FigureData::new(opts, outcome, report);
    type Draw = fn(&FigureData) -> Result<Figure, DrawError>;
    let draws: [Draw; 4] = [
        trajectory::figure,
        residuals::figure,
        histograms::figure,
        coverage::figure,
    ];
    // Drawn on the current rayon pool's threads (each figure alone), kept in order.
    let (drawn, icp) = rayon::join(
        || {
            draws
                .par_iter()
                .map(|draw| draw(&d).map_err(|e| e.to_string()))
                .collect::<Vec<_>>()
        },
        || icp::figure(&d).map_err(|e| e.to_string()),
    );
    let mut out = drawn.into_iter().collect::<Result<Vec<_>, _>>()?;
    if let Some(o) = &outcome.offset {
        out.push(time_offset::figure(o)?);
    }
    out.push(icp?);
    Ok(out)
}
