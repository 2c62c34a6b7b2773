//! Counts read at a time that varies around their timestamp (a driver that stores
//! the counts with each scan, read by a polling loop): each count carries an extra
//! error `ω·δt` (wheel speed times the read-time error), shared by the two samples
//! that use the scan, and errors in the wheel rotations bias the radii low
//! (errors-in-variables) while the σ do not show it.
//!
//! Found from the encoder stream alone. A wheel's angle is smooth in time (motors
//! have lag), so the third divided difference of four consecutive counts,
//! `Δ³ = Σ_i y_i / Π_{j≠i}(t_i − t_j)`, is the jerk over six (tiny over a record's
//! spacing) plus `Σ_i w_i ε_i` with `w_i = 1/Π_{j≠i}(t_i − t_j)` and `ε_i` the
//! count's error. With `ε_i = ω·δt_i + q_i` (independent read-time errors of
//! variance `σ_t²`, quantization of variance `σ_q²`), `z² = Δ³² / Σ_i w_i²` has
//! expectation `σ_q² + ω²·σ_t²` whatever the spacing (at equal spacing
//! `Σ w_i² = 20/(6h³)²`, i.e. the classic `20·ω²σ_t²` of third differences). A
//! least-squares line of `z²` against `ω²` over disjoint windows of both wheels
//! gives `σ_t²` as its slope (the intercept takes the quantization); the slope's
//! t-statistic (heteroscedasticity-consistent standard error) says whether it is
//! there at all.

use crate::finding::{Finding, FindingKind};
use odocal_log::EncoderRecord;
use serde::Serialize;

/// Read-time jitter is reported when its estimate exceeds this (s): below it the
/// wheel-side error is small next to a scan match's (measured in docs/benchmarks.md).
pub const MIN_SIGMA_T_S: f64 = 0.0025;
/// ... and the slope's t-statistic exceeds this.
pub const MIN_T_STAT: f64 = 4.0;
/// Windows longer than this (s) span a gap and are skipped.
const MAX_WINDOW_S: f64 = 2.0;
/// A window whose z² exceeds its expectation this many times is left out (a
/// Gaussian z² does so with probability 6·10⁻⁷).
const OUTLIER_RATIO: f64 = 25.0;
/// At most one window in this many is left out as an outlier.
const MAX_OUTLIERS_PER: usize = 50;
/// Fewest windows (both wheels together) for an estimate.
const MIN_WINDOWS: usize = 40;

/// The estimated read-time jitter of the wheel counts.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ReadJitter {
    /// Standard deviation of the read-time error (s); zero when the slope is
    /// negative.
    pub sigma_t: f64,
    /// The slope's t-statistic.
    pub t_stat: f64,
    /// Variance of a count's error at rest (ticks²): the quantization.
    pub at_rest: f64,
    /// Windows of four records used (both wheels).
    pub windows: usize,
}

impl ReadJitter {
    /// True when the jitter is there and large enough to matter.
    pub fn detected(&self) -> bool {
        self.sigma_t > MIN_SIGMA_T_S && self.t_stat > MIN_T_STAT
    }
}

/// `z²` (ticks²) and `ω²` (ticks²/s²) of one window of four records, or `None`
/// when the window spans a gap or repeats a time.
fn window(times: [f64; 4], counts: [f64; 4]) -> Option<(f64, f64)> {
    let span = times[3] - times[0];
    if !(span > 0.0 && span <= MAX_WINDOW_S) {
        return None;
    }
    let (mut d, mut s) = (0.0, 0.0);
    for i in 0..4 {
        let mut p = 1.0;
        for j in 0..4 {
            if j != i {
                p *= times[i] - times[j];
            }
        }
        if p == 0.0 {
            return None;
        }
        // Scaled by span³ to keep the products near one.
        let w = span.powi(3) / p;
        d += w * counts[i];
        s += w * w;
    }
    let omega = (counts[3] - counts[0]) / span;
    Some((d * d / s, omega * omega))
}

/// Weighted least-squares line `y = a + b·x` through `(y, x)` points with weights
/// `weight(x)`: `(a, b, standard error of b)`, the error heteroscedasticity-
/// consistent (HC0).
fn line_fit(pts: &[(f64, f64)], weight: impl Fn(f64) -> f64) -> Option<(f64, f64, f64)> {
    let ws: Vec<f64> = pts.iter().map(|p| weight(p.1)).collect();
    let sw: f64 = ws.iter().sum();
    let mx = pts.iter().zip(&ws).map(|(p, w)| w * p.1).sum::<f64>() / sw;
    let my = pts.iter().zip(&ws).map(|(p, w)| w * p.0).sum::<f64>() / sw;
    let sxx: f64 = pts
        .iter()
        .zip(&ws)
        .map(|(p, w)| w * (p.1 - mx).powi(2))
        .sum();
    if sxx.is_nan() || sxx <= 0.0 {
        return None;
    }
    let b = pts
        .iter()
        .zip(&ws)
        .map(|(p, w)| w * (p.1 - mx) * (p.0 - my))
        .sum::<f64>()
        / sxx;
    let a = my - b * mx;
    let meat: f64 = pts
        .iter()
        .zip(&ws)
        .map(|(p, w)| (w * (p.1 - mx) * (p.0 - a - b * p.1)).powi(2))
        .sum();
    Some((a, b, meat.sqrt() / sxx))
}

/// Estimates the read-time jitter of the counts (ticks, sorted by time).
pub fn estimate(encoders: &[EncoderRecord]) -> Option<ReadJitter> {
    let mut pts: Vec<(f64, f64)> = Vec::new();
    for w in encoders.chunks_exact(4) {
        let t = [w[0].t, w[1].t, w[2].t, w[3].t];
        let left = |r: &EncoderRecord| r.left;
        let right = |r: &EncoderRecord| r.right;
        for count in [&left as &dyn Fn(&EncoderRecord) -> i64, &right] {
            // Relative to the first count: exact in f64 for any counter.
            let y = std::array::from_fn(|i| count(&w[i]).wrapping_sub(count(&w[0])) as f64);
            pts.extend(window(t, y));
        }
    }
    let n = pts.len();
    if n < MIN_WINDOWS {
        return None;
    }
    // Least squares, then twice weighted by the fitted variance of z² (∝ its
    // expectation squared): the spread of z² grows fast with speed.
    let mean_z2 = pts.iter().map(|p| p.0).sum::<f64>() / n as f64;
    // Then windows beyond OUTLIER_RATIO times their expected z² (a motion that is
    // not smooth there: a bump, a stall; at most one in MAX_OUTLIERS_PER) are left
    // out and the fit repeated.
    let floor = 1e-3 * mean_z2.max(f64::MIN_POSITIVE);
    let mut fit = line_fit(&pts, |_| 1.0)?;
    for round in 0..4 {
        let (a, b) = (fit.0, fit.1.max(0.0));
        let expected = |x: f64| (a + b * x).max(floor);
        if round == 2 {
            let mut ratios: Vec<f64> = pts.iter().map(|p| p.0 / expected(p.1)).collect();
            let k = (ratios.len() - ratios.len() / MAX_OUTLIERS_PER).min(ratios.len() - 1);
            let (_, q, _) = ratios.select_nth_unstable_by(k, f64::total_cmp);
            let limit = OUTLIER_RATIO.max(*q);
            pts.retain(|p| p.0 / expected(p.1) <= limit);
        }
        fit = line_fit(&pts, |x| expected(x).powi(-2))?;
    }
    let (intercept, slope, se) = fit;
    let t_stat = if se > 0.0 { slope / se } else { 0.0 };
    Some(ReadJitter {
        sigma_t: slope.max(0.0).sqrt(),
        t_stat,
        at_rest: intercept,
        windows: pts.len(),
    })
}

/// A warning when the counts' read-time jitter is detected.
pub fn finding(j: &ReadJitter) -> Option<Finding> {
    j.detected().then(|| {
        Finding::warning(
            FindingKind::ReadJitter,
            format!(
                "the wheel counts were read at times that vary around their timestamps by \
                 about ±{:.1} ms (σ_t ≈ {:.1} ms, t = {:.0}, from the third differences of \
                 the counts over {} windows): the wheel rotations carry an error that grows \
                 with speed, which biases the radii low and is only partly in the σ; record \
                 the counts at the scan's time, or stamp each reading with the time it was \
                 read",
                1e3 * j.sigma_t * 3f64.sqrt(),
                1e3 * j.sigma_t,
                j.t_stat,
                j.windows
            ),
        )
        .count(j.windows as u64)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(t: f64, phi: f64) -> EncoderRecord {
        EncoderRecord {
            t,
            left: phi.floor() as i64,
            right: (0.9 * phi).floor() as i64,
            line: 0,
        }
    }

    /// A smooth ramp up and down in speed, read at `t + δ(k)`, stamped `t`.
    fn stream(jitter: impl Fn(usize) -> f64) -> Vec<EncoderRecord> {
        (0..800)
            .map(|k| {
                let t = 0.1 * k as f64 + 0.01 * (k as f64 * 0.7).sin();
                let read = t + jitter(k);
                // Angle (ticks): speed 40 000·(1 − cos(t/3)) ticks/s.
                let phi = 40_000.0 * (read - 3.0 * (read / 3.0).sin());
                record(t, phi)
            })
            .collect()
    }

    #[test]
    fn smooth_counts_show_no_jitter() {
        let j = estimate(&stream(|_| 0.0)).unwrap();
        assert!(!j.detected(), "{j:?}");
        assert!(j.sigma_t < 5e-4, "{j:?}");
    }

    #[test]
    fn jittered_counts_give_the_jitter() {
        // ±10 ms, pseudo-random, uniform: σ_t = 5.77 ms.
        let mut state = 12345u64;
        let deltas: Vec<f64> = (0..800)
            .map(|_| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.02
            })
            .collect();
        let j = estimate(&stream(|k| deltas[k])).unwrap();
        assert!(j.detected(), "{j:?}");
        assert!((j.sigma_t - 0.00577).abs() < 0.0012, "{j:?}");
        assert!(finding(&j).unwrap().message.contains("stamp each reading"));
    }
}
