//! Markdown tables of reproductions, their summary, the J consistency checks and
//! the UMBmark comparison.

use crate::checks::Tolerances;
use crate::consistency::JConsistency;
use crate::reproduce::Reproduction;
use crate::table::UmbmarkTrial;
use serde::Serialize;
use std::fmt::Write as _;

/// Value, σ and error of a quantity in display units: (scale, unit, decimals).
fn display_unit(name: &str) -> (f64, &'static str, usize) {
    match name {
        "l_theta" => (180.0 / std::f64::consts::PI, "°", 4),
        "J21" | "J22" => (1.0, "", 6),
        _ => (1e3, "mm", 4),
    }
}

fn quantity_label(name: &str) -> &'static str {
    match name {
        "r_L" => "r_L (mm)",
        "r_R" => "r_R (mm)",
        "b" => "b (mm)",
        "l_x" => "ℓx (mm)",
        "l_y" => "ℓy (mm)",
        "l_theta" => "ℓθ (°)",
        "J21" => "J21",
        _ => "J22",
    }
}

/// A Markdown table of one reproduction: per quantity the published value (and
/// published σ), the recovered value ± reported σ, the error (also relative for
/// lengths of the odometry and J), the error in σ, the bound and the verdict.
pub fn format_reproduction(rep: &Reproduction, tol: &Tolerances) -> String {
    let r = &rep.estimate;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "**{}** — {}; published with {} samples; simulated for {}, {} synchronized, {} used \
         after trimming (stride {}, ≈{:.2} s intervals); absolute bounds {}.\n",
        rep.row.name,
        rep.row.source,
        rep.row.samples,
        rep.target_samples,
        r.samples_synchronized,
        r.samples_used,
        r.stride,
        r.interval_s,
        if rep.bounds_apply(tol) {
            "apply"
        } else {
            "do not apply (fewer samples)"
        }
    );
    let _ = writeln!(
        s,
        "| quantity | published | published σ | recovered ± σ | error | error/σ | bound | ok |"
    );
    let _ = writeln!(s, "|---|---:|---:|---:|---:|---:|---:|:-:|");
    for c in rep.checks(tol) {
        let (k, _, d) = display_unit(c.name);
        let relative = match c.name {
            "l_x" | "l_y" | "l_theta" => String::new(),
            _ => format!(" ({:+.3} %)", 100.0 * c.error / c.published.abs()),
        };
        let _ = writeln!(
            s,
            "| {} | {:.d$} | {} | {:.d$} ± {:.d$} | {:+.d$}{} | {:+.2} | {} | {} |",
            quantity_label(c.name),
            c.published * k,
            c.published_sigma
                .map_or("—".to_string(), |v| format!("{:.d$}", v * k)),
            c.recovered * k,
            c.sigma * k,
            c.error * k,
            relative,
            c.error_in_sigma(),
            c.bound
                .map_or("—".to_string(), |b| format!("{:.d$}", b * k)),
            if c.passed() { "✓" } else { "✗" },
        );
    }
    s
}

/// A Markdown summary table: one line per reproduction.
pub fn format_summary(reps: &[Reproduction], tol: &Tolerances) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "| row | published samples | simulated | used | worst \\|error\\|/σ | absolute bounds | result |"
    );
    let _ = writeln!(s, "|---|---:|---:|---:|---:|:-:|:-:|");
    for rep in reps {
        let failures = rep.failures(tol);
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {:.2} | {} | {} |",
            rep.row.name,
            rep.row.samples,
            rep.target_samples,
            rep.estimate.samples_used,
            rep.worst_error_in_sigma(tol),
            if rep.bounds_apply(tol) {
                "checked"
            } else {
                "—"
            },
            if failures.is_empty() {
                "pass".to_string()
            } else {
                format!("fail ({} check(s))", failures.len())
            }
        );
    }
    s
}

/// A Markdown table of the J consistency checks.
pub fn format_j_consistency(checks: &[JConsistency], tolerance: f64) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "| row | printed J11, J12, J21, J22 | eq. (2), headings as printed | eq. (2), r_L ↔ r_R | largest \\|Δ\\| as printed (relative) | largest \\|Δ\\| swapped (relative) | reading (relative tolerance {:.1e}) |",
        tolerance
    );
    let _ = writeln!(s, "|---|---|---|---|---:|---:|---|");
    let fmt = |v: &[f64; 4]| {
        v.iter()
            .map(|x| {
                if x.is_finite() {
                    format!("{x:.5}")
                } else {
                    "—".into()
                }
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    for c in checks {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {:.1e} ({:.1e}) | {:.1e} ({:.1e}) | {:?} |",
            c.name,
            fmt(&c.printed),
            fmt(&c.from_headings),
            fmt(&c.from_swapped),
            c.abs_deviation_as_printed,
            c.deviation_as_printed,
            c.abs_deviation_swapped,
            c.deviation_swapped,
            c.reading
        );
    }
    s
}

/// One line of the UMBmark comparison: a name and (b, r_L, r_R) in metres.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OdometryLine {
    /// What the numbers are (e.g. "UMBmark trial 1", "odocal on the k22-k29 preset").
    pub name: String,
    /// Wheel distance (m).
    pub b: f64,
    /// Left wheel radius (m).
    pub r_l: f64,
    /// Right wheel radius (m).
    pub r_r: f64,
}

/// A Markdown table of UMBmark trials beside other odometry calibrations: b, radii,
/// mean radius r̄, and the ratios UMBmark can observe (b/r̄, r_R/r_L) of every trial,
/// every line of `shown` and every line of `calibrations`; then each trial's
/// differences from every line of `calibrations`.
pub fn format_umbmark(
    trials: &[UmbmarkTrial],
    shown: &[OdometryLine],
    calibrations: &[OdometryLine],
) -> String {
    let mut s = String::new();
    let lines: Vec<OdometryLine> = trials
        .iter()
        .map(|t| OdometryLine {
            name: format!("UMBmark trial {}", t.trial),
            b: t.b,
            r_l: t.r_l,
            r_r: t.r_r,
        })
        .chain(shown.iter().cloned())
        .chain(calibrations.iter().cloned())
        .collect();
    let _ = writeln!(
        s,
        "| calibration | b (mm) | r_L (mm) | r_R (mm) | r̄ (mm) | b/r̄ | r_R/r_L | J21 | J22 |"
    );
    let _ = writeln!(s, "|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    for l in &lines {
        let mean = 0.5 * (l.r_l + l.r_r);
        let _ = writeln!(
            s,
            "| {} | {:.2} | {:.3} | {:.3} | {:.3} | {:.4} | {:.5} | {:.5} | {:.5} |",
            l.name,
            l.b * 1e3,
            l.r_l * 1e3,
            l.r_r * 1e3,
            mean * 1e3,
            l.b / mean,
            l.r_r / l.r_l,
            -l.r_l / l.b,
            l.r_r / l.b
        );
    }
    if calibrations.is_empty() || trials.is_empty() {
        return s;
    }
    let _ = writeln!(
        s,
        "\nDifferences, UMBmark trial minus calibration: b and r̄ in mm and in %, and the \
         ratios in %.\n"
    );
    let _ = writeln!(
        s,
        "| trial | against | Δb (mm) | Δb (%) | Δr̄ (mm) | Δr̄ (%) | Δ(b/r̄) (%) | Δ(r_R/r_L) (%) |"
    );
    let _ = writeln!(s, "|---|---|---:|---:|---:|---:|---:|---:|");
    for t in trials {
        let tm = 0.5 * (t.r_l + t.r_r);
        for c in calibrations {
            let cm = 0.5 * (c.r_l + c.r_r);
            let pct = |a: f64, b: f64| 100.0 * (a - b) / b;
            let _ = writeln!(
                s,
                "| {} | {} | {:+.2} | {:+.2} | {:+.3} | {:+.2} | {:+.2} | {:+.3} |",
                t.trial,
                c.name,
                (t.b - c.b) * 1e3,
                pct(t.b, c.b),
                (tm - cm) * 1e3,
                pct(tm, cm),
                pct(t.b / tm, c.b / cm),
                pct(t.r_r / t.r_l, c.r_r / c.r_l)
            );
        }
    }
    s
}
