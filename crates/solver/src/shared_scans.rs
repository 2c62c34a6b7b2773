//! The noise of samples that share a scan, and what it does to the covariance of
//! the estimate.
//!
//! A log's samples chain: sample `k` matches scans `(j, j+1)`, sample `k+1` scans
//! `(j+1, j+2)`. Whatever error scan `j+1` brings — its own range noise as seen by
//! the matcher, the encoder reading interpolated at its timestamp — enters both
//! samples, with opposite signs: the residuals of consecutive samples are
//! negatively correlated (measured on simulated Khepera logs: −0.4 to −0.5 in each
//! of x, y, θ). Treating the samples as independent then overstates the variance
//! of everything that sums over many samples (the radii and `b` most), by a factor
//! 2–3 on those logs.
//!
//! The model: `ŝ_k = ŝ_k,true ⊖δ_start ⊕ … ⊕δ_end + u_k`, i.e. to first order
//! `e_k = A_k δ_end(k) + B_k δ_start(k) + u_k` with one error `δ_j` per scan
//! (covariance `D`, in the scan's sensor frame) and an error `u_k` the samples do
//! not share through a scan: `A_k = diag(R(ŝθ), 1)` maps the end scan's error
//! into `ŝ_k`, `B_k` (−1 on the diagonal, `(ŝy, −ŝx)` in the θ column) the start
//! scan's. `E[e_{k+1} e_kᵀ] = B_{k+1} D A_kᵀ` gives `D` from the pairs of
//! consecutive residuals.
//!
//! `u` is not white: on simulated logs the residuals stay slightly positively
//! correlated over 2–30 samples (autocorrelations within ±0.04, summing to about
//! +0.02; likely the matcher's error following the slowly changing scene): nothing
//! next to the lag-1 −0.45 but is as large as the part that survives summation:
//! the long-run variance of the residuals (what sums over many samples see) is
//! 1.6× the lag-0/lag-1 value on Khepera logs. So `u` enters through its long-run
//! covariance `Λ`, estimated from the sums of the residuals over overlapping
//! windows of `m = max(20, √K)` samples: each window sum holds `m·Λ` plus the
//! shared errors of the scans at its ends (subtracted with `D`), less the part
//! the fit removed from it (added back, as REML does for a variance). The
//! estimator is unchanged (weighted least squares); its covariance is the
//! sandwich `H⁻¹ Var(Σ GᵀWe) H⁻¹` with `Var(Σ GᵀWe) = Σ_k GᵀWΛWG + Σ_j U_j D U_jᵀ`,
//! `U_j` summing `GᵀWA` and `GᵀWB` over the samples that use scan `j`.
//!
//! `Λ̂` is a small quantity (80–95 % of a residual's variance is the two scans')
//! estimated from about `1.5·K/m` windows' worth of data, and a chance low
//! estimate would make everything that sums over samples look too certain. Its
//! uncertainty is propagated: with `ν` the χ² degrees of freedom the estimate is
//! worth, an error over σ is Student-t, variance `ν/(ν − 2)`, and each component
//! of `Λ̂` is widened by that (see `LongRun::widened`). An earlier version used the
//! lag-0 variance `N` at its moment estimate plus one standard error: σ 10–50 %
//! too large on the radii, and it missed the long-range part.
//!
//! Wheel counts read at jittery times (`Sample::read_time_sigma`, what is left
//! after the pipeline smoothed them) add a part to each scan's shared error that
//! is not the same for every scan: the wheel angles at scan `j` are off by
//! `φ̇_j·δ_j`, `δ_j` of that standard deviation, entering the sample that ends at
//! `j` through `+F` and the one that starts there through `−F` (`F = ∂f/∂Δφ`). It
//! is added per scan to the sandwich, and taken out of the lag-1 moments (so `D`
//! keeps only the rest) and out of the window sums of `Λ`.

use crate::kinematics::{residual_of, wrap_fast, Pieces as WheelPieces, Predictor};
use crate::noise::NoiseWeights;
use crate::packed::Packed;
use crate::params::Params;
use crate::sample::measured_part;
use nalgebra::{Matrix3, SMatrix, Vector3};
use serde::Serialize;
use std::collections::{BTreeMap, HashMap};

type Matrix6x3 = SMatrix<f64, 6, 3>;
type Matrix6 = SMatrix<f64, 6, 6>;
type Matrix3x6 = SMatrix<f64, 3, 6>;
type Vector6 = SMatrix<f64, 6, 1>;

/// Fewest scans shared by two samples used for the shared-scan model to be
/// estimated (below, the samples are treated as independent).
pub const MIN_SHARED_SCANS: usize = 20;

/// Fewest samples per window of the long-run estimate of the unshared error (the
/// residuals stay correlated over 10–30 samples on simulated logs).
const MIN_WINDOW: usize = 20;

/// The estimated noise of samples that share scans.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SharedScanNoise {
    /// Covariance `D` of the error each scan brings into both samples that use
    /// it (x, y, θ in the scan's sensor frame; m², rad²).
    pub per_scan: [[f64; 3]; 3],
    /// Long-run covariance `Λ` of the error the samples do not share through a
    /// scan (per sample; it is correlated over tens of samples, so larger than
    /// its one-sample variance).
    pub per_sample: [[f64; 3]; 3],
    /// Scans shared by two of the samples used (the pairs `D` was estimated from).
    pub shared_scans: usize,
    /// Samples per window of the estimate of `per_sample`.
    pub window: usize,
    /// Per component (x, y, θ): the part of a residual's variance that comes
    /// from its two scans, `2·D_ii / Var(e_i)`.
    pub shared_fraction: [f64; 3],
}

/// How the end scan's error enters `ŝ`: `ŝ ⊕ δ`.
fn end_map(sm: &[f64; 3]) -> Matrix3<f64> {
    let (s, c) = sm[2].sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

/// How the start scan's error enters `ŝ`: `⊖δ ⊕ ŝ`.
fn start_map(sm: &[f64; 3]) -> Matrix3<f64> {
    Matrix3::new(-1.0, 0.0, sm[1], 0.0, -1.0, -sm[0], 0.0, 0.0, -1.0)
}

/// The symmetric part of `m` with negative eigenvalues set to zero.
fn nearest_psd(m: &Matrix3<f64>) -> Matrix3<f64> {
    let sym = 0.5 * (m + m.transpose());
    let eig = sym.symmetric_eigen();
    let clamped = eig.eigenvalues.map(|v| v.max(0.0));
    eig.eigenvectors * Matrix3::from_diagonal(&clamped) * eig.eigenvectors.transpose()
}

pub(crate) fn weight(weights: &NoiseWeights, index: usize) -> Matrix3<f64> {
    match weights {
        NoiseWeights::Shared(w) => Matrix3::from_diagonal(&Vector3::new(w[0], w[1], w[2])),
        NoiseWeights::PerSample(info) => Matrix3::from_fn(|i, j| info[index][i][j]),
    }
}

fn to_array3(m: &Matrix3<f64>) -> [[f64; 3]; 3] {
    std::array::from_fn(|i| std::array::from_fn(|j| m[(i, j)]))
}

/// Samples per window of the long-run estimate: `√K` (the usual choice for
/// overlapping windows: long enough for correlation that lasts longer as logs
/// grow, with about `1.5·√K` windows' worth of data), at least [`MIN_WINDOW`], at
/// most a third of the samples.
fn window_length(samples: usize) -> usize {
    ((samples as f64).sqrt() as usize)
        .max(MIN_WINDOW)
        .min(samples / 3)
        .max(1)
}

/// Running sums of a per-sample quantity: `sum(i, j)` is the sum over `i..j`.
struct Prefix<T>(Vec<T>);

impl<T: Copy + std::ops::Add<Output = T> + std::ops::Sub<Output = T>> Prefix<T> {
    fn new(zero: T, items: impl Iterator<Item = T>) -> Self {
        let mut v = vec![zero];
        for x in items {
            let last = v[v.len() - 1];
            v.push(last + x);
        }
        Prefix(v)
    }

    fn sum(&self, i: usize, j: usize) -> T {
        self.0[j] - self.0[i]
    }
}

/// The per-sample pieces of the residual model at the estimate.
struct Pieces {
    /// Residuals `e_k`.
    e: Vec<Vector3<f64>>,
    /// Jacobians `G_k` of the prediction.
    g: Vec<Matrix3x6>,
    /// `G_kᵀ W_k`.
    gw: Vec<Matrix6x3>,
    /// End and start maps `A_k`, `B_k`.
    a: Vec<Matrix3<f64>>,
    b: Vec<Matrix3<f64>>,
    /// Whether sample `k + 1` starts at the scan where sample `k` ends.
    linked: Vec<bool>,
    /// The read-time error of the counts at the start and end scans as it enters
    /// `e_k`, per standard deviation of `δ`, when the counts were read at jittery
    /// times.
    read_time: Option<Vec<[Vector3<f64>; 2]>>,
}

/// `∂f/∂Δφ · φ̇ · σ` at the start scan (negated: the start's rotation error
/// shortens the interval) and at the end scan of `s`, the wheel speeds at the
/// scans taken from the first and last pieces; `None` without a read-time error
/// or scan times.
fn read_time_parts(s: &Packed, pred: &Predictor) -> Option<[Vector3<f64>; 2]> {
    let sigma = s.read_time_sigma?;
    let [t0, t1] = s.scan_times?;
    let whole = t1 - t0;
    let speed = |dl: f64, dr: f64, dt: f64| {
        if dt > 0.0 {
            Vector3::new(dl / dt, dr / dt, 0.0)
        } else {
            Vector3::zeros()
        }
    };
    let (start, end) = match s.profile {
        Some([first, .., last]) => (
            speed(first.dphi_l, first.dphi_r, first.duration),
            speed(last.dphi_l, last.dphi_r, last.duration),
        ),
        _ => {
            let v = speed(s.dphi_l, s.dphi_r, whole);
            (v, v)
        }
    };
    // F by central differences at constant speed.
    let h = 1e-6 * (1.0 + s.dphi_l.abs() + s.dphi_r.abs());
    let f = |dl: f64, dr: f64| pred.predict_pieces(WheelPieces::One(Some((dl, dr))));
    let column = |a: [f64; 3], b: [f64; 3]| {
        Vector3::new(a[0] - b[0], a[1] - b[1], wrap_fast(a[2] - b[2])) / (2.0 * h)
    };
    let (l, r) = (s.dphi_l, s.dphi_r);
    let fl = column(f(l + h, r), f(l - h, r));
    let fr = column(f(l, r + h), f(l, r - h));
    let effect = |v: Vector3<f64>| (fl * v[0] + fr * v[1]) * sigma;
    Some([-effect(start), effect(end)])
}

/// `Var(Σ GᵀWe)` at `params` under the shared-scan model, with the model; `None`
/// when some sample has no scan times or fewer than [`MIN_SHARED_SCANS`] scans
/// are shared (then the samples count as independent). `h_inv` is the inverse
/// information of the fit (held parameters' rows zero). With `shapes` (per sample
/// index, the map `M_k` from a noise of one level to the sample's own; see
/// `crate::noise_shape`) the model is estimated on the residuals whitened by
/// `M_k⁻¹`, and its score mapped back by `M_k`.
pub(crate) fn score_covariance(
    samples: &[Packed],
    params: &Params,
    weights: &NoiseWeights,
    h_inv: &[[f64; 6]; 6],
    shapes: Option<&[Matrix3<f64>]>,
) -> Option<([[f64; 6]; 6], SharedScanNoise)> {
    let times: Vec<[f64; 2]> = samples
        .iter()
        .map(|s| s.scan_times)
        .collect::<Option<_>>()?;
    let pred = Predictor::new(params, true);
    let k_all = samples.len();
    let mut p = Pieces {
        e: Vec::with_capacity(k_all),
        g: Vec::with_capacity(k_all),
        gw: Vec::with_capacity(k_all),
        a: samples.iter().map(|s| end_map(&s.sm)).collect(),
        b: samples.iter().map(|s| start_map(&s.sm)).collect(),
        linked: (0..k_all)
            .map(|k| k + 1 < k_all && times[k][1].to_bits() == times[k + 1][0].to_bits())
            .collect(),
        read_time: samples.iter().map(|s| read_time_parts(s, &pred)).collect(),
    };
    for (k, s) in samples.iter().enumerate() {
        let (pr, jac) = pred.predict_with_jacobian_pieces(s.pieces());
        let gk = Matrix3x6::from_fn(|i, j| jac[i][j]);
        // A free direction's residual is no scan's error (`Sample::free_direction`).
        let e = Vector3::from(measured_part(residual_of(pr, &s.sm), s.free_direction));
        let gw = gk.transpose() * weight(weights, s.index);
        // Whitened to one level: e = M ẽ, G = M G̃, GᵀW = G̃ᵀW̃ M⁻¹ with W̃ = MᵀWM.
        let shape = shapes.and_then(|m| m.get(s.index));
        match shape.and_then(|m| Some((m, m.try_inverse()?))) {
            Some((m, m_inv)) => {
                p.e.push(m_inv * e);
                p.gw.push(gw * m);
                p.g.push(m_inv * gk);
                if let Some(rt) = p.read_time.as_mut() {
                    rt[k] = rt[k].map(|part| m_inv * part);
                }
            }
            None => {
                p.e.push(e);
                p.gw.push(gw);
                p.g.push(gk);
            }
        }
    }
    let (d, shared) = per_scan_covariance(samples, &times, &p.e, p.read_time.as_deref())?;
    // The D part: Σ_j U_j D U_jᵀ, U_j summing GᵀWA and GᵀWB over the samples that
    // use scan j (ordered by time, so that the sums are reproducible).
    let mut per_scan: BTreeMap<u64, Matrix6x3> = BTreeMap::new();
    for (k, t) in times.iter().enumerate() {
        *per_scan
            .entry(t[0].to_bits())
            .or_insert_with(Matrix6x3::zeros) += p.gw[k] * p.b[k];
        *per_scan
            .entry(t[1].to_bits())
            .or_insert_with(Matrix6x3::zeros) += p.gw[k] * p.a[k];
    }
    let mut shared_part = per_scan
        .values()
        .fold(Matrix6::zeros(), |m, u| m + u * d * u.transpose());
    if let Some(rt) = &p.read_time {
        let mut per_scan: BTreeMap<u64, Vector6> = BTreeMap::new();
        for (k, t) in times.iter().enumerate() {
            for (end, part) in rt[k].iter().enumerate() {
                *per_scan
                    .entry(t[end].to_bits())
                    .or_insert_with(Vector6::zeros) += p.gw[k] * part;
            }
        }
        shared_part += per_scan
            .values()
            .fold(Matrix6::zeros(), |m, q| m + q * q.transpose());
    }
    let h_inv = Matrix6::from_fn(|i, j| h_inv[i][j]);
    let window = window_length(k_all);
    let long_run = long_run_covariance(&p, &d, &shared_part, &h_inv, window);
    let unshared = long_run.widened();
    let m = shared_part + unshared_part(&p.gw, &unshared);

    let variance =
        p.e.iter()
            .fold(Matrix3::zeros(), |acc, e| acc + e * e.transpose())
            / k_all as f64;
    let shared_fraction = std::array::from_fn(|i| {
        if variance[(i, i)] > 0.0 {
            (2.0 * d[(i, i)] / variance[(i, i)]).min(1.0)
        } else {
            0.0
        }
    });
    Some((
        std::array::from_fn(|i| std::array::from_fn(|j| 0.5 * (m[(i, j)] + m[(j, i)]))),
        SharedScanNoise {
            per_scan: to_array3(&d),
            per_sample: to_array3(&long_run.lambda),
            shared_scans: shared,
            window,
            shared_fraction,
        },
    ))
}

/// `D` from the pairs of consecutive residuals, `B⁻¹ e_{k+1} e_kᵀ A⁻ᵀ` (A is a
/// rotation), less the read-time error's part of `e_{k+1} e_kᵀ` when there is one,
/// with the number of shared scans; `None` below [`MIN_SHARED_SCANS`].
fn per_scan_covariance(
    samples: &[Packed],
    times: &[[f64; 2]],
    e: &[Vector3<f64>],
    read_time: Option<&[[Vector3<f64>; 2]]>,
) -> Option<(Matrix3<f64>, usize)> {
    let starts: HashMap<u64, usize> = times
        .iter()
        .enumerate()
        .map(|(k, t)| (t[0].to_bits(), k))
        .collect();
    let mut cross = Matrix3::zeros();
    let mut shared = 0;
    for (k, t) in times.iter().enumerate() {
        let Some(&next) = starts.get(&t[1].to_bits()) else {
            continue;
        };
        let b_inv = start_map(&samples[next].sm).try_inverse()?;
        let mut product = b_inv * e[next] * e[k].transpose();
        if let Some(rt) = read_time {
            product -= b_inv * rt[next][0] * rt[k][1].transpose();
        }
        cross += product * end_map(&samples[k].sm);
        shared += 1;
    }
    if shared < MIN_SHARED_SCANS {
        return None;
    }
    Some((nearest_psd(&(cross / shared as f64)), shared))
}

/// The estimate of Λ and what it is worth.
struct LongRun {
    /// Λ̂.
    lambda: Matrix3<f64>,
    /// Per component: the mean square of the window sums over its part `m·Λ̂_cc`
    /// (the rest is the scans' shared error at the windows' ends).
    inflation: Vector3<f64>,
    /// Per component: the mean square of the window sums.
    mean_square: Vector3<f64>,
    /// Overlapping windows of `window` samples out of `samples`.
    samples: usize,
    window: usize,
}

impl LongRun {
    /// Λ̂ widened by its own uncertainty. The overlapping-window estimate of a
    /// long-run variance from K samples in windows of m has the variance of a
    /// χ² with ν₀ = 1.5·K/m degrees of freedom; here each window sum also holds
    /// the shared error of its end scans, which adds noise but no signal: ν =
    /// ν₀ / (inflation)². An error divided by a σ estimated with ν degrees of
    /// freedom has variance ν/(ν − 2) (Student's t): each component of Λ̂ is
    /// widened by that much.
    ///
    /// Where Λ̂ is within its own sampling noise of zero (a short log: a few
    /// windows whose sums are mostly their end scans' errors) that rule shrinks
    /// with it, to nothing at Λ̂ = 0, and everything that sums over samples would
    /// rest on the shared errors alone, which cancel along a chain: a simulated
    /// 20 s Khepera log (49 samples, Λ̂ clamped to zero) put ℓy 4.7σ from the
    /// truth. So no component is taken below one standard error of its estimate,
    /// the window sums' mean square over `m` times `√(2/ν₀)`: the largest value
    /// the data cannot tell from zero. On logs of a few hundred samples Λ̂ stands
    /// well above it and nothing changes.
    fn widened(&self) -> Matrix3<f64> {
        let nu0 = 1.5 * self.samples as f64 / self.window as f64;
        let scale = self.inflation.map(|r| {
            let nu = nu0 / (r * r);
            (nu / (nu - 2.0).max(0.2)).sqrt()
        });
        let widened = Matrix3::from_diagonal(&scale) * self.lambda * Matrix3::from_diagonal(&scale);
        let standard_error = self
            .mean_square
            .map(|q| q / self.window as f64 * (2.0 / nu0).sqrt());
        // A non-negative diagonal added: the sum stays positive semi-definite.
        let floor = Vector3::from_fn(|c, _| (standard_error[c] - widened[(c, c)]).max(0.0));
        widened + Matrix3::from_diagonal(&floor)
    }
}

/// `Σ_k G_kᵀW_k Λ W_kG_k`.
fn unshared_part(gw: &[Matrix6x3], lambda: &Matrix3<f64>) -> Matrix6 {
    gw.iter()
        .fold(Matrix6::zeros(), |m, a| m + a * lambda * a.transpose())
}

/// Λ: the long-run covariance of the part of the residuals that the scans do not
/// share, from sums over overlapping windows of `window` consecutive samples.
///
/// A window's sum `S_w = Σ e_k` holds the shared scan errors only through the
/// scans at its ends (and the small differences `A_k + B_{k+1}` of the maps of
/// the scans inside it): their variance `V_w` under `D` is subtracted. The
/// residuals come from the fit, which removes from each window the part
/// `G_w Δ` (`Δ` the estimate's error): `E[S_w S_wᵀ]` is smaller than the true one by
/// `X_w + X_wᵀ − G_w C G_wᵀ` with `X_w = G_w H⁻¹ (Σ_w GᵀW) Λ` and `C` the
/// covariance; that is added back (REML-style, with Λ from the uncorrected
/// sums).
fn long_run_covariance(
    p: &Pieces,
    d: &Matrix3<f64>,
    shared_part: &Matrix6,
    h_inv: &Matrix6,
    window: usize,
) -> LongRun {
    let k_all = p.e.len();
    let m = window;
    // What scan j between samples k and k+1 adds to a window that holds both.
    let junction: Vec<Matrix3<f64>> = (0..k_all.saturating_sub(1))
        .map(|k| {
            let (a, b) = (p.a[k], p.b[k + 1]);
            let scans = if p.linked[k] {
                (a + b) * d * (a + b).transpose()
            } else {
                a * d * a.transpose() + b * d * b.transpose()
            };
            match &p.read_time {
                Some(rt) => {
                    let (end, start) = (rt[k][1], rt[k + 1][0]);
                    if p.linked[k] {
                        scans + (end + start) * (end + start).transpose()
                    } else {
                        scans + end * end.transpose() + start * start.transpose()
                    }
                }
                None => scans,
            }
        })
        .collect();
    let inner = Prefix::new(Matrix3::zeros(), junction.into_iter());
    let sums = Prefix::new(Vector3::zeros(), p.e.iter().copied());
    let g_sums = Prefix::new(Matrix3x6::zeros(), p.g.iter().copied());
    let gw_sums = Prefix::new(Matrix6x3::zeros(), p.gw.iter().copied());
    let mut raw = Matrix3::zeros();
    let mut squares = Vector3::zeros();
    let windows = k_all + 1 - m;
    for i in 0..windows {
        let j = i + m;
        let s = sums.sum(i, j);
        let mut ends = p.b[i] * d * p.b[i].transpose() + p.a[j - 1] * d * p.a[j - 1].transpose();
        if let Some(rt) = &p.read_time {
            let (start, end) = (rt[i][0], rt[j - 1][1]);
            ends += start * start.transpose() + end * end.transpose();
        }
        raw += s * s.transpose() - ends - inner.sum(i, j - 1);
        squares += s.component_mul(&s);
    }
    let count = (windows * m) as f64;
    let lambda = nearest_psd(&(raw / count));

    let c = h_inv * (unshared_part(&p.gw, &lambda) + shared_part) * h_inv;
    let mut removed = Matrix3::zeros();
    for i in 0..windows {
        let g_w = g_sums.sum(i, i + m);
        let x = g_w * h_inv * gw_sums.sum(i, i + m) * lambda;
        removed += x + x.transpose() - g_w * c * g_w.transpose();
    }
    let lambda = nearest_psd(&((raw + removed) / count));
    let inflation = Vector3::from_fn(|c, _| {
        let signal = m as f64 * lambda[(c, c)];
        if signal > 0.0 {
            squares[c] / windows as f64 / signal
        } else {
            1.0
        }
    });
    LongRun {
        lambda,
        inflation,
        mean_square: squares / windows as f64,
        samples: k_all,
        window,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A long-run estimate at zero from three windows is not taken at its word: it
    /// is raised to one standard error of itself; one well above that is widened
    /// by Student's rule alone.
    #[test]
    fn a_long_run_estimate_within_its_noise_of_zero_is_floored() {
        let (samples, window) = (49, 16);
        let nu0 = 1.5 * samples as f64 / window as f64;
        let mean_square = Vector3::new(4e-7, 3e-7, 2e-7);
        let zero = LongRun {
            lambda: Matrix3::zeros(),
            inflation: Vector3::repeat(1.0),
            mean_square,
            samples,
            window,
        };
        let w = zero.widened();
        for c in 0..3 {
            let se = mean_square[c] / window as f64 * (2.0 / nu0).sqrt();
            assert!(
                (w[(c, c)] - se).abs() < 1e-12 * se,
                "{c}: {} vs {se}",
                w[(c, c)]
            );
        }
        let (samples, window) = (1500, 38);
        let lambda = Matrix3::from_diagonal(&Vector3::new(1e-8, 2e-8, 3e-8));
        let clear = LongRun {
            lambda,
            inflation: Vector3::repeat(1.2),
            mean_square: lambda.diagonal() * (window as f64 * 1.2),
            samples,
            window,
        };
        let nu = 1.5 * samples as f64 / window as f64 / 1.44;
        let w = clear.widened();
        for c in 0..3 {
            let want = lambda[(c, c)] * nu / (nu - 2.0);
            assert!((w[(c, c)] - want).abs() < 1e-9 * want, "{c}");
        }
    }

    #[test]
    fn maps_are_the_first_order_pose_compositions() {
        use odocal_geom::Pose2;
        let s = Pose2::new(0.3, -0.1, 0.7);
        let d = Pose2::new(1e-6, -2e-6, 3e-6);
        let end = s.compose(&d);
        let start = d.inverse().compose(&s);
        let dv = Vector3::new(d.x, d.y, d.theta);
        let want_end = end_map(&s.to_array()) * dv;
        let want_start = start_map(&s.to_array()) * dv;
        for (got, want) in [(end, want_end), (start, want_start)] {
            let diff = [got.x - s.x, got.y - s.y, got.theta - s.theta];
            for i in 0..3 {
                assert!((diff[i] - want[i]).abs() < 1e-11, "{diff:?} vs {want:?}");
            }
        }
    }
}
