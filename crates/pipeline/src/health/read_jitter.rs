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

/// A warning when the counts' read-time jitter is detected; `half` is the
/// smoother's half-width (records).
pub fn finding(j: &ReadJitter, half: usize) -> Option<Finding> {
    j.detected().then(|| {
        Finding::warning(
            FindingKind::ReadJitter,
            format!(
                "the wheel counts were read at times that vary around their timestamps by \
                 about ±{:.1} ms (σ_t ≈ {:.1} ms, t = {:.0}, from the third differences of \
                 the counts over {} windows): the wheel rotations carry an error that grows \
                 with speed, which biases the radii low; the counts were smoothed (a local \
                 cubic in time over {} records either side) to remove most of it, and the σ \
                 include what remains; record the counts at the scan's time, or \
                 stamp each reading with the time it was read",
                1e3 * j.sigma_t * 3f64.sqrt(),
                1e3 * j.sigma_t,
                j.t_stat,
                j.windows,
                half
            ),
        )
        .count(j.windows as u64)
    })
}

/// The count at `t0` of a least-squares cubic in time through `(t, count)` points
/// (times relative to `t0`), or `None` when the points do not determine one.
fn cubic_at(t0: f64, pts: &[(f64, f64)]) -> Option<f64> {
    let scale = pts
        .iter()
        .map(|p| (p.0 - t0).abs())
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);
    let mut m = nalgebra::Matrix4::<f64>::zeros();
    let mut v = nalgebra::Vector4::<f64>::zeros();
    for &(t, y) in pts {
        let x = (t - t0) / scale;
        let row = nalgebra::Vector4::new(1.0, x, x * x, x * x * x);
        m += row * row.transpose();
        v += row * y;
    }
    m.cholesky().map(|c| c.solve(&v)[0])
}

/// Half-width in time (s) of the smoother at the reference jitter
/// [`REFERENCE_SIGMA_T_S`]; see [`smoothing_half_width`].
pub const REFERENCE_HALF_WIDTH_S: f64 = 0.4;
/// The read-time jitter (s; ±10 ms uniform) [`REFERENCE_HALF_WIDTH_S`] was chosen at.
pub const REFERENCE_SIGMA_T_S: f64 = 0.00577;

/// Half-width (records either side) of the smoother for read-time jitter `sigma_t`
/// (s) and records `spacing` s apart. A local cubic's error is its noise, falling as
/// the window widens, plus the motion's fourth derivative times the window's
/// fourth power: the best window grows as `σ_t^(2/9)`. The scale was measured on the
/// fast-robot stand-in (motors with a 0.4 s lag, a record per 0.1 s scan): ±0.4 s at
/// ±10 ms jitter, ±0.5 s at ±30 ms (docs/benchmarks.md).
pub fn smoothing_half_width(sigma_t: f64, spacing: f64) -> usize {
    let half_s = REFERENCE_HALF_WIDTH_S * (sigma_t / REFERENCE_SIGMA_T_S).powf(2.0 / 9.0);
    let h = (half_s / spacing.max(1e-6)).round();
    if h.is_finite() {
        (h as usize).clamp(2, 8)
    } else {
        2
    }
}

/// Standard deviation (s) of the read-time error left in a count after [`smooth`]
/// with `half`: a local cubic through `2·half + 1` equally spaced records,
/// evaluated at the middle one, averages their errors with weights whose squares
/// sum to `3(3h² + 3h − 1) / ((2h − 1)(2h + 1)(2h + 3))` (0.26 at `h = 4`).
pub fn left_after_smoothing(sigma_t: f64, half: usize) -> f64 {
    let h = half as f64;
    let c =
        3.0 * (3.0 * h * h + 3.0 * h - 1.0) / ((2.0 * h - 1.0) * (2.0 * h + 1.0) * (2.0 * h + 3.0));
    sigma_t * c.sqrt()
}

/// The median spacing of the records (s).
pub fn median_spacing(encoders: &[EncoderRecord]) -> f64 {
    let mut d: Vec<f64> = encoders.windows(2).map(|w| w[1].t - w[0].t).collect();
    if d.is_empty() {
        return 0.0;
    }
    let mid = d.len() / 2;
    *d.select_nth_unstable_by(mid, f64::total_cmp).1
}

/// Replaces each count by a local cubic in time through the `half` records either
/// side (and itself) evaluated at its timestamp: the smooth wheel motion stays, the
/// read-time error `ω·δt` is mostly averaged out. Records whose neighbourhood spans
/// a gap use the records on their side of it; with fewer than five records the
/// count is kept.
pub fn smooth(encoders: &mut [EncoderRecord], half: usize) {
    let n = encoders.len();
    let orig = encoders.to_vec();
    for j in 0..n {
        let (lo, hi) = (j.saturating_sub(half), (j + half + 1).min(n));
        let near: Vec<&EncoderRecord> = orig[lo..hi]
            .iter()
            .filter(|r| (r.t - orig[j].t).abs() <= MAX_WINDOW_S)
            .collect();
        if near.len() < 5 {
            continue;
        }
        let base = orig[j];
        for side in [false, true] {
            let count = |r: &EncoderRecord| if side { r.right } else { r.left };
            let pts: Vec<(f64, f64)> = near
                .iter()
                .map(|r| (r.t, count(r).wrapping_sub(count(&base)) as f64))
                .collect();
            if let Some(y) = cubic_at(base.t, &pts) {
                let c = count(&base).wrapping_add(y.round() as i64);
                if side {
                    encoders[j].right = c;
                } else {
                    encoders[j].left = c;
                }
            }
        }
    }
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

    /// The angle (ticks) and stamp of record `k` of [`stream`].
    fn truth(k: usize) -> (f64, f64) {
        let t = 0.1 * k as f64 + 0.01 * (k as f64 * 0.7).sin();
        (t, 40_000.0 * (t - 3.0 * (t / 3.0).sin()))
    }

    #[test]
    fn smoothing_keeps_smooth_counts_and_removes_most_jitter() {
        let rms = |recs: &[EncoderRecord]| {
            let s: f64 = recs
                .iter()
                .enumerate()
                .map(|(k, r)| (r.left as f64 - truth(k).1.floor()).powi(2))
                .sum();
            (s / recs.len() as f64).sqrt()
        };
        let mut clean = stream(|_| 0.0);
        smooth(&mut clean, 4);
        assert!(rms(&clean) < 1.5, "clean counts moved: {}", rms(&clean));
        let mut jittered = stream(|k| if k % 2 == 0 { 0.01 } else { -0.01 });
        let before = rms(&jittered);
        smooth(&mut jittered, 4);
        let after = rms(&jittered);
        assert!(after < 0.3 * before, "rms {before} → {after}");
    }

    #[test]
    fn the_window_widens_slowly_with_the_jitter() {
        assert_eq!(smoothing_half_width(REFERENCE_SIGMA_T_S, 0.1), 4);
        assert_eq!(smoothing_half_width(3.0 * REFERENCE_SIGMA_T_S, 0.1), 5);
        assert_eq!(smoothing_half_width(REFERENCE_SIGMA_T_S, 0.02), 8);
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
        assert!(finding(&j, 4)
            .unwrap()
            .message
            .contains("stamp each reading"));
    }

    #[test]
    fn what_is_left_is_the_smoothers_weights() {
        // The cubic's value at the middle is Σ w_i y_i: w_i is its value for a unit
        // count at record i; an error of σ per record leaves σ·√Σw_i².
        for half in 2..=8usize {
            let n = 2 * half + 1;
            let sum_sq: f64 = (0..n)
                .map(|i| {
                    let pts: Vec<(f64, f64)> = (0..n)
                        .map(|k| (0.1 * k as f64, if k == i { 1.0 } else { 0.0 }))
                        .collect();
                    cubic_at(0.1 * half as f64, &pts).unwrap().powi(2)
                })
                .sum();
            let got = left_after_smoothing(1.0, half);
            assert!(
                (got * got - sum_sq).abs() < 1e-9,
                "h {half}: {got} vs {sum_sq}"
            );
        }
        assert!((left_after_smoothing(1.0, 4).powi(2) - 0.2554).abs() < 1e-3);
    }
}
