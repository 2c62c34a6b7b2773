//! Internal consistency of a published table: the printed J columns against
//! eq. (2) from the printed radii and wheel distance.

use crate::table::{PrintedJ, PublishedRow, UmbmarkTrial};
use serde::Serialize;

/// Relative tolerance of the J consistency check: printing precision of about four
/// significant digits.
pub const J_PRINT_TOLERANCE: f64 = 1e-3;

/// How the printed J columns of a row relate to its printed radii and b.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum JReading {
    /// J agrees with eq. (2) under the printed headings.
    AsPrinted,
    /// J agrees with eq. (2) only with the r_L and r_R headings exchanged.
    HeadingsSwapped,
    /// Both readings agree (the radii are too close to tell).
    Ambiguous,
    /// Neither reading agrees.
    Neither,
}

/// The internal-consistency check of one published row: J recomputed from
/// (b, radii) by eq. (2), `J = [[r_L/2, r_R/2], [−r_L/b, r_R/b]]`, against the
/// printed J columns.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct JConsistency {
    /// Row name.
    pub name: String,
    /// Printed J11, J12, J21, J22 (NaN where not printed).
    pub printed: [f64; 4],
    /// J from the printed headings: r_L = column "r_L".
    pub from_headings: [f64; 4],
    /// J with the radius headings exchanged: r_L = column "r_R".
    pub from_swapped: [f64; 4],
    /// Largest relative deviation of the printed J from `from_headings`.
    pub deviation_as_printed: f64,
    /// Largest relative deviation of the printed J from `from_swapped`.
    pub deviation_swapped: f64,
    /// Largest absolute deviation of the printed J from `from_headings`.
    pub abs_deviation_as_printed: f64,
    /// Largest absolute deviation of the printed J from `from_swapped`.
    pub abs_deviation_swapped: f64,
    /// The verdict at the tolerance asked.
    pub reading: JReading,
}

fn j_entries(r_l: f64, r_r: f64, b: f64) -> [f64; 4] {
    [r_l / 2.0, r_r / 2.0, -r_l / b, r_r / b]
}

fn max_relative_deviation(printed: &[f64; 4], model: &[f64; 4]) -> f64 {
    printed
        .iter()
        .zip(model)
        .filter(|(p, _)| p.is_finite())
        .map(|(p, m)| ((p - m) / m).abs())
        .fold(0.0, f64::max)
}

fn max_absolute_deviation(printed: &[f64; 4], model: &[f64; 4]) -> f64 {
    printed
        .iter()
        .zip(model)
        .filter(|(p, _)| p.is_finite())
        .map(|(p, m)| (p - m).abs())
        .fold(0.0, f64::max)
}

/// Checks a row's printed J columns against eq. (2) under the printed and the
/// swapped radius headings; `None` when the row has no J columns. `tolerance` is
/// the relative deviation accepted as printing precision (e.g. `1e-3` for four
/// significant digits).
pub fn j_consistency(row: &PublishedRow, tolerance: f64) -> Option<JConsistency> {
    let p = &row.printed;
    Some(check_j(
        &row.name,
        p.r_l,
        p.r_r,
        p.b,
        row.j.as_ref()?,
        tolerance,
    ))
}

/// [`j_consistency`] for a UMBmark trial; `None` when it has no J columns.
pub fn umbmark_j_consistency(trial: &UmbmarkTrial, tolerance: f64) -> Option<JConsistency> {
    let name = format!("UMBmark {}", trial.trial);
    Some(check_j(
        &name,
        trial.r_l,
        trial.r_r,
        trial.b,
        trial.j.as_ref()?,
        tolerance,
    ))
}

fn check_j(name: &str, r_l: f64, r_r: f64, b: f64, j: &PrintedJ, tolerance: f64) -> JConsistency {
    let printed = [
        j.j11.unwrap_or(f64::NAN),
        j.j12.unwrap_or(f64::NAN),
        j.j21,
        j.j22,
    ];
    let from_headings = j_entries(r_l, r_r, b);
    let from_swapped = j_entries(r_r, r_l, b);
    let d1 = max_relative_deviation(&printed, &from_headings);
    let d2 = max_relative_deviation(&printed, &from_swapped);
    let reading = match (d1 <= tolerance, d2 <= tolerance) {
        (true, true) => JReading::Ambiguous,
        (true, false) => JReading::AsPrinted,
        (false, true) => JReading::HeadingsSwapped,
        (false, false) => JReading::Neither,
    };
    JConsistency {
        name: name.to_string(),
        printed,
        from_headings,
        from_swapped,
        deviation_as_printed: d1,
        deviation_swapped: d2,
        abs_deviation_as_printed: max_absolute_deviation(&printed, &from_headings),
        abs_deviation_swapped: max_absolute_deviation(&printed, &from_swapped),
        reading,
    }
}
