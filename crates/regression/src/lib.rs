//! Regression against published calibration results ("Table I"): published tables
//! reproduced in simulation. Not a pipeline stage: it runs the pipeline
//! (`odocal-pipeline`) on logs simulated (`odocal-sim`) with published parameters.
//!
//! A *published row* is one experiment's calibrated parameters as printed in a paper
//! or shipped with a package, with the number of samples behind it. The regression
//! simulates a robot whose true parameters are the row's ([`simulate_log_text`]),
//! runs the whole pipeline on the simulated log ([`reproduce_from_text`]), and
//! compares the recovered parameters with the row ([`Reproduction::checks`]): within
//! `3σ` of the covariance the pipeline reports, and — for runs with enough samples —
//! within absolute bounds.
//!
//! Two sources of rows ([`load_sources`] reads both):
//! - a *table file* ([`read_table`]), e.g. `fixtures/table-i.json`: the ICRA 2008
//!   Table I (19 rows, with its Table II of UMBmark trials); format in [`table`];
//! - the T-RO 2013 package's published results ([`read_tro_reference`]): for each
//!   configuration `NAME` in [`TRO_CONFIGURATIONS`], `NAME_results.json` (the
//!   parameters and their covariance) and `NAME.tuple` (whose count of tuples is the
//!   number of samples).
//!
//! One module each: [`table`] (published rows, table file), [`tro`] (T-RO reference),
//! [`sources`] (the rows of a run), [`reproduce`] (simulation and pipeline), [`join`]
//! (joined rows as joint calibrations of their simulated component logs),
//! [`checks`] (the rules), [`consistency`] (printed J against eq. (2)), [`format`](mod@format)
//! (Markdown tables), [`document`](mod@document) (`docs/table-i.md`).

#![deny(missing_docs)]

pub mod checks;
pub mod consistency;
pub mod document;
pub mod format;
pub mod join;
pub mod reproduce;
pub mod sources;
pub mod table;
pub mod tro;

pub use checks::{QuantityCheck, Tolerances, QUANTITY_NAMES};
pub use consistency::{
    j_consistency, umbmark_j_consistency, JConsistency, JReading, J_PRINT_TOLERANCE,
};
pub use document::{
    document, kept_findings, timing_line, umbmark_section, DocumentInputs, RowTiming,
    FINDINGS_BEGIN, FINDINGS_END, UMBMARK_ROWS,
};
pub use format::{
    format_j_consistency, format_reproduction, format_summary, format_umbmark, OdometryLine,
};
pub use join::{join_parts, reproduce_join_from_texts, MIN_COMPONENT_SAMPLES};
pub use reproduce::{
    reproduce_from_text, reproduction_options, row_seed, simulate_log_text, Reproduction,
};
pub use sources::{load_sources, SourceError, Sources};
pub use table::{
    parse_table, parse_table_document, read_table, read_table_file, workspace_table_path, PrintedJ,
    PublishedRow, PublishedTable, TableError, UmbmarkTrial,
};
pub use tro::{read_tro_reference, workspace_reference_dir, TRO_CONFIGURATIONS};

#[cfg(test)]
mod tests;
