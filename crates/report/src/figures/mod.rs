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
    let mut out = vec![
        trajectory::figure(&d)?,
        residuals::figure(&d)?,
        histograms::figure(&d)?,
        coverage::figure(&d)?,
    ];
    if let Some(o) = &outcome.offset {
        out.push(time_offset::figure(o)?);
    }
    out.push(icp::figure(&d)?);
    Ok(out)
}
