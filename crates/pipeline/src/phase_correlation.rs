//! How much the phases of one log share their errors (`--all-pairs`).
//!
//! The phases of a log pair different scans over the same stretches of driving: a
//! pair of phase 1 (scans 1 and 5) overlaps in time three quarters of one pair of
//! phase 0 (scans 0 and 4) and a quarter of the next. What the wheels did over the
//! shared time — a slip, a scrub in a turn — and what the matcher makes of the same
//! scenery enter both. The joint solve treats the phases as independent logs, which
//! holds when the matcher's own error dominates (the simulated presets: correlation
//! 0–0.15 at full overlap on most axes) and not when the odometry's does: the real
//! MinesRover logs, 0.46–0.83, where the joint σ were 1.7–1.9× too small.
//!
//! Measured on the joint solve's residuals: for every two samples of different phases
//! whose pairs overlap in time by a fraction `f` of the longer, the product of their
//! whitened residuals (per axis, by the axis's RMS over the used samples) estimates
//! `ρ·f`; ρ, the correlation at full overlap, is the regression through the origin,
//! `Σ f·rₐr_b / Σ f²`, with standard error `1/√(Σ f²)`. With `m` phases correlated by
//! ρ the mean's variance is `(1 + (m − 1)·ρ)/m` of one phase's, not `1/m`: the σ are
//! multiplied by `√(1 + (m − 1)·ρ)`, ρ being the largest axis's less two standard
//! errors (so that sampling noise does not inflate), clamped to [0, 1].

use crate::run::Outcome;

/// The correlation of the phases' errors and the factor it puts on the σ.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct PhaseCorrelation {
    /// Phases measured.
    pub phases: usize,
    /// Correlation at full overlap of the residuals in x, y, θ.
    pub rho: [f64; 3],
    /// Standard error of each ρ.
    pub standard_error: f64,
    /// `√(1 + (m − 1)·ρ)` with the largest ρ less two standard errors, in [0, 1].
    pub sigma_factor: f64,
}

/// The correlation between the phases `phases` of one log, from the `residuals` of
/// their estimate (every phase's samples in order) and the samples it used; `None`
/// with fewer than two phases or no overlapping pairs. The estimate must be the
/// log's own: residuals from an estimate that fits other logs too carry their
/// disagreement, which every phase shares.
pub fn measure(
    phases: &[&Outcome],
    residuals: &[[f64; 3]],
    used: &[bool],
) -> Option<PhaseCorrelation> {
    if phases.len() < 2 {
        return None;
    }
    // (phase, t0, t1, residual) of the phases' used samples.
    let mut items: Vec<(usize, f64, f64, [f64; 3])> = Vec::new();
    let mut j = 0;
    for (p, o) in phases.iter().enumerate() {
        for s in &o.synced.samples {
            if let (Some(true), Some(r)) = (used.get(j).copied(), residuals.get(j)) {
                items.push((p, s.pair.t0, s.pair.t1, *r));
            }
            j += 1;
        }
    }
    if items.is_empty() {
        return None;
    }
    let n = items.len() as f64;
    let scale: [f64; 3] =
        std::array::from_fn(|a| (items.iter().map(|it| it.3[a].powi(2)).sum::<f64>() / n).sqrt());
    if scale.iter().any(|s| !(s.is_finite() && *s > 0.0)) {
        return None;
    }
    items.sort_by(|a, b| a.1.total_cmp(&b.1));
    let mut num = [0.0; 3];
    let mut den = 0.0;
    for (x, a) in items.iter().enumerate() {
        // Sorted by start: the pairs that start before `a` ends.
        for b in items[x + 1..].iter().take_while(|b| b.1 < a.2) {
            if a.0 == b.0 {
                continue;
            }
            let overlap = a.2.min(b.2) - b.1;
            let longer = (a.2 - a.1).max(b.2 - b.1);
            if overlap <= 0.0 || longer <= 0.0 {
                continue;
            }
            let f = overlap / longer;
            for (ax, v) in num.iter_mut().enumerate() {
                *v += f * a.3[ax] * b.3[ax] / (scale[ax] * scale[ax]);
            }
            den += f * f;
        }
    }
    if den <= 0.0 {
        return None;
    }
    let rho = num.map(|v| v / den);
    let standard_error = 1.0 / den.sqrt();
    let shared = rho
        .iter()
        .map(|r| (r - 2.0 * standard_error).clamp(0.0, 1.0))
        .fold(0.0, f64::max);
    Some(PhaseCorrelation {
        phases: phases.len(),
        rho,
        standard_error,
        sigma_factor: (1.0 + (phases.len() - 1) as f64 * shared).sqrt(),
    })
}

/// The finding when the phases of a log share their errors enough to scale the σ:
/// each log's correlations and factor; `None` when no factor exceeds 1.
pub fn finding(correlations: &[(String, PhaseCorrelation)]) -> Option<crate::Finding> {
    let scaled: Vec<String> = correlations
        .iter()
        .filter(|(_, c)| c.sigma_factor > 1.0)
        .map(|(name, c)| {
            format!(
                "{name}: its {} phases' residuals correlate by {:.2}, {:.2}, {:.2} (x, y, θ; \
                 ± {:.2}) where their pairs overlap, σ ×{:.2}",
                c.phases, c.rho[0], c.rho[1], c.rho[2], c.standard_error, c.sigma_factor
            )
        })
        .collect();
    (!scaled.is_empty()).then(|| {
        crate::Finding::note(
            crate::FindingKind::PhaseCorrelation,
            format!(
                "every scan pair: the phases share part of their errors (the wheels' and the \
                 scenery's over the same stretch of driving), so they count for less than \
                 independent logs and the σ are scaled by the largest factor: {}",
                scaled.join("; ")
            ),
        )
    })
}
