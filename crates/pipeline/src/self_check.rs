//! The scan matcher's own error on a log without ground truth: closure of scan
//! triples.
//!
//! For consecutive samples `(a, b)` and `(b, c)` matched directly (not through the
//! scans between, [`crate::chained`]) the matcher also matches `(a, c)`
//! directly, from the guess `ŝ_ab ⊕ ŝ_bc`. The closure error `ŝ_ac ⊖ (ŝ_ab ⊕ ŝ_bc)`
//! holds the errors of three matches; with errors of similar size and independent
//! (they share scans, so partly correlated: the figure is a lower bound then), its
//! variance is about three times one match's, so one match's error is the closure's
//! RMS over √3. Closures far beyond the typical one are left out first, as the solver
//! leaves out samples ([`OUTLIER_CHI2`]).

use crate::health::scan_jitter::median;
use crate::matching::{match_pairs, MatchStats, ScanNoise};
use crate::samples::PairSample;
use odocal_geom::{wrap_angle, Pose2};
use odocal_icp::IcpParams;
use odocal_log::ScanStore;
use serde::Serialize;

/// Triples matched at most (evenly spread over the log).
pub const MAX_TRIPLES: usize = 60;

/// Fewer closed triples than this give no figure.
pub const MIN_TRIPLES: usize = 5;

/// A closure whose squared error, in units of the typical closure's, exceeds this
/// (over x, y and θ: χ² with 3 degrees of freedom, 99.99 %) is left out as an
/// outlier, as the solver leaves out samples: one wrong match among its three —
/// often the pair twice as long, which no sample holds — is not the matcher's
/// typical error, and the solver's noise it is compared with is that of the samples
/// kept.
pub const OUTLIER_CHI2: f64 = odocal_solver::CHI2_3DOF_9999;

/// At most this many rounds of leaving outliers out.
const MAX_ROUNDS: usize = 10;

/// One match's typical error over the closures kept.
#[derive(Debug, Clone, Copy, PartialEq)]
struct TypicalError {
    /// Closures kept.
    closures: usize,
    /// One match's translation error, RMS per axis (m).
    xy_m: f64,
    /// One match's rotation error, RMS (rad).
    theta_rad: f64,
}

/// One match's error from the closures' squared errors (`[e_x² + e_y², e_θ²]`): RMS
/// over the closures kept, each holding three matches' errors (x and y two axes).
/// Closures beyond [`OUTLIER_CHI2`] of the typical closure are left out, the typical
/// closure measured first by the medians (robust to the outliers), then by the RMS of
/// those kept, until the set kept settles. `None` when fewer than [`MIN_TRIPLES`]
/// are kept.
fn typical_error(errors: &[[f64; 2]]) -> Option<TypicalError> {
    // Medians of χ² with 2 and 1 degrees of freedom.
    const MEDIAN_CHI2_2: f64 = 1.386_294;
    const MEDIAN_CHI2_1: f64 = 0.454_936;
    let rms = |kept: &[bool]| {
        let n = kept.iter().filter(|k| **k).count();
        let sum = |c: usize| -> f64 {
            errors
                .iter()
                .zip(kept)
                .filter(|(_, k)| **k)
                .map(|(e, _)| e[c])
                .sum()
        };
        let n_f = n.max(1) as f64;
        (n, [sum(0) / (6.0 * n_f), sum(1) / (3.0 * n_f)])
    };
    let median = |c: usize| median(errors.iter().map(|e| e[c]).collect()).unwrap_or(0.0);
    if errors.len() < MIN_TRIPLES {
        return None;
    }
    // One match's variance per axis: a closure's error holds three matches'.
    let mut variance = [
        median(0) / (3.0 * MEDIAN_CHI2_2),
        median(1) / (3.0 * MEDIAN_CHI2_1),
    ];
    let mut kept = vec![true; errors.len()];
    for _ in 0..MAX_ROUNDS {
        if !variance.iter().all(|v| v.is_finite() && *v > 0.0) {
            // Errors of zero (a noise-free log): nothing stands out.
            kept.fill(true);
            break;
        }
        let next: Vec<bool> = errors
            .iter()
            .map(|e| e[0] / (3.0 * variance[0]) + e[1] / (3.0 * variance[1]) <= OUTLIER_CHI2)
            .collect();
        if next == kept {
            break;
        }
        kept = next;
        variance = rms(&kept).1;
    }
    let (closures, variance) = rms(&kept);
    (closures >= MIN_TRIPLES).then(|| TypicalError {
        closures,
        xy_m: variance[0].sqrt(),
        theta_rad: variance[1].sqrt(),
    })
}

/// The matcher's error per pair, measured by the closure of scan triples.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MatchSelfCheck {
    /// Triples whose direct match succeeded (and were used).
    pub triples: usize,
    /// Triples tried.
    pub tried: usize,
    /// Triples that closed but were left out as outliers (beyond [`OUTLIER_CHI2`] of
    /// the typical closure).
    pub left_out: usize,
    /// One match's translation error, RMS per axis (m).
    pub xy_m: f64,
    /// One match's rotation error, RMS (rad).
    pub theta_rad: f64,
    /// The median range noise of the log's scans (m), for scale.
    pub range_noise_m: f64,
    /// The median tilt noise of the log's local lines (rad; `None` when its scans
    /// have too few, e.g. sparse scans): what the matcher's bias on rotations
    /// grows with ([`crate::matcher_bias`]).
    pub tilt_sigma_rad: Option<f64>,
    /// The angle between neighbouring rays of the log's scans (rad; 0 when unknown):
    /// with the range noise it stands for the local lines' tilt noise where that is
    /// not measured ([`crate::matcher_bias`]).
    pub ray_spacing_rad: f64,
    /// The factor by which this error multiplied the solver's σ (1: the noise model
    /// already covered it; see [`crate::match_quality::sigma_inflation`]).
    pub sigma_factor: f64,
}

/// Measures the matcher's error on `samples` (in time order) with the scans they
/// were matched on; `None` when fewer than [`MIN_TRIPLES`] triples close.
/// `noise` is the store's [`crate::matching::typical_scan_noise`], and `params`
/// those the samples were matched with, their typical noise set (see
/// [`crate::matching::with_typical_noise`]).
pub fn closure_check(
    scans: &ScanStore,
    samples: &[PairSample],
    params: &IcpParams,
    noise: ScanNoise,
) -> Option<MatchSelfCheck> {
    let triples: Vec<(&MatchStats, &MatchStats, (usize, usize))> = samples
        .windows(2)
        // Direct matches only: a pair matched through the scans between its two was
        // refused directly, and so, mostly, is the pair twice as long over it.
        // Matches that leave a direction free keep the guess there: no closure.
        .filter(|w| {
            w[0].pair.second == w[1].pair.first
                && w.iter()
                    .all(|s| s.icp.links == 1 && s.icp.fixes_every_direction())
        })
        .map(|w| (&w[0].icp, &w[1].icp, (w[0].pair.first, w[1].pair.second)))
        .collect();
    let every = (triples.len() / MAX_TRIPLES).max(1);
    let chosen: Vec<_> = triples
        .into_iter()
        .step_by(every)
        .take(MAX_TRIPLES)
        .collect();
    let chained: Vec<Pose2> = chosen
        .iter()
        .map(|(ab, bc, _)| ab.pose.compose(&bc.pose))
        .collect();
    let pairs: Vec<(usize, usize)> = chosen.iter().map(|t| t.2).collect();
    let direct = match_pairs(scans, &pairs, &chained, params, || {});
    let errors: Vec<[f64; 2]> = direct
        .iter()
        .zip(&chained)
        .filter_map(|(d, c)| {
            let d = d.as_ref().ok().filter(|d| d.fixes_every_direction())?;
            let e = c.between(&d.pose);
            Some([e.x * e.x + e.y * e.y, wrap_angle(e.theta).powi(2)])
        })
        .collect();
    let typical = typical_error(&errors)?;
    Some(MatchSelfCheck {
        triples: typical.closures,
        tried: pairs.len(),
        left_out: errors.len() - typical.closures,
        xy_m: typical.xy_m,
        theta_rad: typical.theta_rad,
        range_noise_m: noise.range_sigma_m,
        tilt_sigma_rad: noise.tilt_sigma_rad,
        ray_spacing_rad: scans
            .get(pairs[0].0)
            .map_or(0.0, |s| s.geometry.resolution.abs()),
        sigma_factor: 1.0,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Closures of three matches with errors σ_xy per axis and σ_θ: the Box–Muller
    /// transform of evenly spread uniforms, each coordinate's in its own order.
    fn gaussian_closures(n: usize, sigma_xy: f64, sigma_theta: f64) -> Vec<[f64; 2]> {
        (0..n)
            .map(|i| {
                let u =
                    |k: usize| ((i * 7919 + k * 104_729) % n) as f64 / n as f64 + 0.5 / n as f64;
                let g = |a: f64, b: f64| (-2.0 * a.ln()).sqrt() * (std::f64::consts::TAU * b).cos();
                let s3 = 3f64.sqrt();
                let (x, y, t) = (
                    s3 * sigma_xy * g(u(1), u(2)),
                    s3 * sigma_xy * g(u(3), u(4)),
                    s3 * sigma_theta * g(u(5), u(6)),
                );
                [x * x + y * y, t * t]
            })
            .collect()
    }

    #[test]
    fn gaussian_closures_give_one_matchs_error_and_lose_none() {
        let errors = gaussian_closures(60, 0.002, 0.001);
        let t = typical_error(&errors).unwrap();
        assert_eq!(t.closures, 60);
        assert!((t.xy_m / 0.002 - 1.0).abs() < 0.25, "{}", t.xy_m);
        assert!((t.theta_rad / 0.001 - 1.0).abs() < 0.35, "{}", t.theta_rad);
    }

    #[test]
    fn wrong_matches_are_left_out_and_do_not_set_the_error() {
        let mut errors = gaussian_closures(52, 0.002, 0.001);
        let clean = typical_error(&errors).unwrap();
        // Three closures with a wrong match: 7 to 22 cm, 0.7° to 1°.
        errors.extend([
            [0.22f64.powi(2), 0.0],
            [0.095f64.powi(2), 1e-4],
            [0.07f64.powi(2), 3e-4],
        ]);
        let t = typical_error(&errors).unwrap();
        assert_eq!(t.closures, clean.closures);
        assert_eq!(t, clean);
        // Kept, they would have made the error seven times larger.
        let n = errors.len() as f64;
        let rms_all = (errors.iter().map(|e| e[0]).sum::<f64>() / (6.0 * n)).sqrt();
        assert!(rms_all > 5.0 * t.xy_m, "{rms_all} against {}", t.xy_m);
    }

    #[test]
    fn noise_free_closures_keep_every_triple_and_too_few_give_none() {
        let t = typical_error(&[[0.0, 0.0]; 10]).unwrap();
        assert_eq!((t.closures, t.xy_m, t.theta_rad), (10, 0.0, 0.0));
        assert_eq!(typical_error(&[[1e-6, 1e-6]; MIN_TRIPLES - 1]), None);
    }
}
