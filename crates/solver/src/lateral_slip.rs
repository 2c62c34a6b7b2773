//! A seventh parameter for skid-steer robots: the sideways slide in turns,
//! `v_y = −k·v·ω` (see [`crate::slide_kinematics`] for the model and why a slide
//! proportional to ω alone is only a shift of ℓx).
//!
//! [`fit_lateral_slip`] refines the six parameters and `k` together by maximum
//! likelihood on the samples a [`Calibration`] used, with its noise model, from its
//! estimate and `k = 0`; [`SlideFit::measure_noise_with_slide`] measures the
//! covariance with `k` known on the residuals the model with the slide leaves; and
//! [`SlideFit::apply`] puts the result into the calibration: the parameters at the
//! joint optimum and their covariance widened by what not knowing `k` adds. The
//! six-parameter solve itself is untouched. (`k`'s own σ and its covariance with the
//! six still come from the six-parameter solve's noise model: what not knowing `k`
//! adds is 6 % of ℓθ's variance on the simulated rover.)

use crate::calibrate::{calibrate, Calibration, SolveOptions};
use crate::constraints::Constraints;
use crate::damping::Damping;
use crate::kinematics::residual_of;
use crate::linalg::unit_diagonal;
use crate::noise::NoiseWeights;
use crate::noise_shape::{shapes_used, weights_used};
use crate::normal_equations::NormalEquations;
use crate::observability::wheel_signs;
use crate::params::Params;
use crate::sample::Sample;
use crate::slide_kinematics::{predict_with_slide, residuals_with_slide};
use nalgebra::{SMatrix, SVector};
use odocal_geom::Pose2;
use serde::Serialize;

type Matrix7 = SMatrix<f64, 7, 7>;

/// Largest number of Levenberg–Marquardt iterations.
const MAX_ITERATIONS: usize = 50;

/// Turn rate (rad/s) and forward speed (m/s) above which a sample counts as turning
/// while translating, for the typical speeds of the sentence.
const TURNING_RATE: f64 = 0.1;
const MOVING_SPEED: f64 = 0.02;

/// The slide `v_y = −k·v·ω` estimated from a log.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LateralSlip {
    /// `k` (s): positive when the robot slides outward of its turns.
    pub k: f64,
    /// Standard deviation of `k` (s).
    pub sigma: f64,
    /// Covariance of `k` with `(r_L, r_R, b, ℓx, ℓy, ℓθ)`.
    pub covariance_with_params: [f64; 6],
    /// ℓx with the slide estimated minus ℓx without it (m): what ignoring the
    /// slide moves ℓx by.
    pub l_x_shift: f64,
    /// Every parameter with the slide estimated minus without it (SI units, order
    /// r_L, r_R, b, ℓx, ℓy, ℓθ; `l_x_shift` is the fourth): what ignoring the slide
    /// moves each by.
    pub shifts: [f64; 6],
    /// Median forward speed |v| (m/s) of the samples that turn while translating
    /// (|ω| above 0.1 rad/s, |v| above 0.02 m/s); NaN without such samples.
    pub turning_speed: f64,
    /// Median turn rate |ω| (rad/s) of the same samples.
    pub turn_rate: f64,
    /// Whether the calibration's parameters include the model with the slide, in
    /// the share [`LateralSlip::weight`] (else it was only checked for). Its
    /// covariance holds not knowing `k` either way ([`SlideFit::blend`]).
    pub applied: bool,
    /// The share of the model with the slide in the calibration's estimate (0: the
    /// six-parameter estimate, 1: the seven-parameter one; between, the two weighed
    /// by the evidence for the slide, see [`SlideFit::blend`]).
    pub weight: f64,
    /// `k / σ` as the two models were weighed, with the solver's own σ of `k` (the
    /// `sigma` recorded may be scaled afterwards, when the scan matcher's own error
    /// shows every σ too small).
    pub evidence: f64,
}

impl LateralSlip {
    /// `|k| / σ`.
    pub fn significance(&self) -> f64 {
        if self.sigma > 0.0 {
            self.k.abs() / self.sigma
        } else {
            f64::INFINITY
        }
    }

    /// The share `τ²/(σ_k² + τ²)` of not knowing `k` (the six's covariance with `k`
    /// unknown less theirs with `k` known) that the model without the slide keeps:
    /// the variance of a slide of the data's σ and of a plausible size `τ`
    /// ([`PLAUSIBLE_SLIDE_PER_SPEED`] times the typical speed in turns) over the
    /// data's own; 0 without a speed in turns or a finite σ, 1 when `σ_k` and `τ`
    /// are both 0.
    pub fn plausible_share(&self) -> f64 {
        let tau = PLAUSIBLE_SLIDE_PER_SPEED * self.turning_speed;
        let tau2 = if tau.is_finite() { tau * tau } else { 0.0 };
        let var_k = self.sigma * self.sigma;
        if !var_k.is_finite() {
            return 0.0;
        }
        if var_k + tau2 == 0.0 {
            return 1.0;
        }
        tau2 / (var_k + tau2)
    }

    /// Per parameter, the share of its variance in `covariance` (a calibration's,
    /// blended by [`SlideFit::blend`]) that not knowing `k` brings: `u²/var_k` (`u`
    /// its covariance with `k`) times what the blend kept of it, over the variance
    /// (0 where the variance is not positive).
    pub fn unknown_k_share(&self, covariance: &[[f64; 6]; 6]) -> [f64; 6] {
        let var_k = self.sigma * self.sigma;
        let w = if self.applied { self.weight } else { 0.0 };
        let kept = (1.0 - w) * self.plausible_share() + w;
        std::array::from_fn(|i| {
            let part = kept * self.covariance_with_params[i].powi(2) / var_k;
            if covariance[i][i] > 0.0 && part.is_finite() {
                (part / covariance[i][i]).min(1.0)
            } else {
                0.0
            }
        })
    }

    /// The parameter that ignoring the slide moves most in units of its σ in
    /// `covariance` (a calibration's): its index and `|shift| / σ`
    /// (held parameters, with zero variance, left out); `None` when none moves.
    pub fn largest_shift(&self, covariance: &[[f64; 6]; 6]) -> Option<(usize, f64)> {
        (0..6)
            .filter(|&i| covariance[i][i] > 0.0 && self.shifts[i] != 0.0)
            .map(|i| (i, self.shifts[i].abs() / covariance[i][i].sqrt()))
            .max_by(|a, b| a.1.total_cmp(&b.1))
    }

    /// The slip angle `atan(k·ω)` (degrees) at a turn rate `omega` (rad/s): the angle
    /// between the robot's heading and its velocity.
    pub fn slip_angle_deg(&self, omega: f64) -> f64 {
        (self.k * omega).atan().to_degrees()
    }
}

/// The size of a slide a robot may have, per m/s of its speed in turns (s²/m): the
/// prior scale `τ = PLAUSIBLE_SLIDE_PER_SPEED · v` of `k` for the model without the
/// slide ([`SlideFit::blend`]), `v` the log's typical speed in turns. A slip angle
/// `atan(k·ω)` that grows with the lateral acceleration `v·ω`, as the real
/// MinesRover's does (six wheels, skid-steer: k = 0.073 ± 0.013 s at 0.56 m/s and
/// 0.071 ± 0.017 s at 0.48 m/s on its two logs, 0.13 and 0.15 s²/m): 0.09 s for the
/// simulated rover's 0.44 m/s turns, 0.013 s for a Khepera's 0.066 m/s, whose slow
/// turns no wheel slides in.
pub const PLAUSIBLE_SLIDE_PER_SPEED: f64 = 0.2;

/// The joint estimate of the six parameters and the slide.
#[derive(Debug, Clone, PartialEq)]
pub struct SlideFit {
    /// The six parameters at the joint optimum.
    pub params: Params,
    /// Their covariance with `k` unknown (6×6 block of the 7×7 covariance).
    pub covariance: [[f64; 6]; 6],
    /// The slide.
    pub slip: LateralSlip,
    /// Weighted cost at the joint optimum.
    pub cost: f64,
}

impl SlideFit {
    /// Replaces `calibration`'s estimate, covariance, verdicts and costs by the
    /// joint ones and records the slide as applied (a [`SlideFit::blend`] of weight 1).
    pub fn apply(self, calibration: &mut Calibration) {
        self.blend(calibration, 1.0);
    }

    /// The six's covariance under the model with the slide measured on the residuals
    /// that model leaves: `samples` (those the fit was computed from, with the same
    /// `options`) solved again with the slide at the fit's `k` taken out of `ŝ`, plus
    /// what not knowing `k` adds. The fit's covariance until then took the
    /// six-parameter solve's, whose noise level, share of the matches' sizes and
    /// shared-scan model were measured on residuals that hold the slide the model
    /// leaves out: on 30 simulated MinesRover logs (k = 0.05 s) ℓθ's RMS error/σ was
    /// 0.61, and 1.06 on the same logs simulated without the slide. Unchanged when the
    /// solve fails.
    pub fn measure_noise_with_slide(&mut self, samples: &[Sample], options: &SolveOptions) {
        let with = residuals_with_slide(&self.params, self.slip.k, samples, options.use_profile);
        let without = residuals_with_slide(&self.params, 0.0, samples, options.use_profile);
        let taken_out: Vec<Sample> = samples
            .iter()
            .zip(with.iter().zip(&without))
            .map(|(s, (r7, r6))| {
                let sm = s.sm.to_array();
                Sample {
                    sm: Pose2::from_array(std::array::from_fn(|c| sm[c] - (r7[c] - r6[c]))),
                    ..s.clone()
                }
            })
            .collect();
        let lenient = SolveOptions {
            accept_weak: true,
            ..*options
        };
        let Ok(given_k) = calibrate(&taken_out, &lenient) else {
            return;
        };
        let (u, var_k) = (self.slip.covariance_with_params, self.slip.sigma.powi(2));
        let covariance: [[f64; 6]; 6] = std::array::from_fn(|a| {
            std::array::from_fn(|b| given_k.covariance[a][b] + u[a] * u[b] / var_k)
        });
        if covariance.iter().flatten().all(|v| v.is_finite()) {
            self.covariance = covariance;
        }
    }

    /// Puts the two models into `calibration` (the six-parameter one), the model with
    /// the slide at `weight` (clamped to 0 … 1) — the mixture of the two estimates
    /// as two Gaussians: the mean `θ₆ + w·Δ` (`Δ` the slide's shifts, `θ₇ − θ₆`) and
    /// the covariance `(1 − w)·C₀ + w·C₇ + w(1 − w)·Δ Δᵀ`, which holds both models'
    /// σ and the difference between them. The verdicts are judged again; the cost
    /// and reduced χ² are the model's of the larger weight. At weight 0 the slide is
    /// recorded as checked, not applied; at weight 1 the estimate is the joint one
    /// exactly.
    ///
    /// The model without the slide is the one the evidence favours when `k` is near
    /// zero, not a measurement of `k = 0`, so its covariance `C₀` holds the slide the
    /// data cannot rule out: `k` of the data's σ and of a plausible size `τ`
    /// ([`PLAUSIBLE_SLIDE_PER_SPEED`], the prior of a slide), `C₀ = C₆ + s·u uᵀ/σ_k²`
    /// (`u` the six's covariance with `k`, `u uᵀ/σ_k²` what not knowing `k` adds) with
    /// `s = τ²/(σ_k² + τ²)` — all of it where the data measure `k` far below that size,
    /// a plausible slide's effect where they cannot tell. Taking `C₆`
    /// itself (before stop 48) claimed `k = 0` exactly: on 40 s simulated MinesRover
    /// logs driven without spins (truth `k = 0.05 s`, every pair matched) seed 308
    /// gave `k = 0.000 ± 0.064 s`, weighed in at 0 %, and ℓx 23.5 mm off with σ
    /// 5.0 mm, "well determined" at −4.6σ. `C₇` in full instead would let slides no
    /// wheel does decide: a 40 s Khepera bag (turns at 0.05 m/s, `k = −0.40 ± 0.45
    /// s`) got ℓθ's σ from 4.5 to 38.8 mrad, and one `τ` of 0.1 s for every robot
    /// still to 9.5 mrad (a 0.6° slip angle at its 0.16 rad/s).
    pub fn blend(self, calibration: &mut Calibration, weight: f64) {
        let w = if weight.is_finite() {
            weight.clamp(0.0, 1.0)
        } else {
            0.0
        };
        let without = calibration.params.to_vector();
        let d = self.slip.shifts;
        let params = if w == 1.0 {
            self.params
        } else {
            Params::from_vector(std::array::from_fn(|i| without[i] + w * d[i]))
        };
        let s = self.slip.plausible_share();
        let (c6, c7) = (&calibration.covariance, &self.covariance);
        let (u, var_k) = (self.slip.covariance_with_params, self.slip.sigma.powi(2));
        let covariance: [[f64; 6]; 6] = std::array::from_fn(|a| {
            std::array::from_fn(|b| {
                let c0 = c6[a][b] + s * u[a] * u[b] / var_k;
                (1.0 - w) * c0 + w * c7[a][b] + w * (1.0 - w) * d[a] * d[b]
            })
        });
        let obs = &mut calibration.observability;
        obs.rejudge(&params, &covariance);
        obs.wheel_signs = wheel_signs(&params);
        calibration.params = params;
        calibration.j = params.j();
        calibration.covariance = covariance;
        if w >= 0.5 {
            calibration.cost_after = self.cost;
            let dof = (3 * calibration.samples_used).saturating_sub(7).max(1);
            calibration.reduced_chi2 = self.cost / dof as f64;
        }
        calibration.lateral_slip = Some(LateralSlip {
            applied: w > 0.0,
            weight: w,
            ..self.slip
        });
    }
}

/// Cost, Gauss–Newton matrix and gradient of the seven-parameter model over the
/// samples `calibration` used, with the priors and held parameters of `constraints`.
fn normal_equations(
    samples: &[Sample],
    used: &[usize],
    x: &[f64; 7],
    weights: &NoiseWeights,
    constraints: &Constraints,
    use_profile: bool,
) -> (f64, [[f64; 7]; 7], [f64; 7]) {
    let params = Params::from_vector([x[0], x[1], x[2], x[3], x[4], x[5]]);
    let mut h = [[0.0; 7]; 7];
    let mut g = [0.0; 7];
    let mut cost = 0.0;
    for &i in used {
        let s = &samples[i];
        let (p, jac) = predict_with_slide(&params, x[6], s, use_profile);
        let e = residual_of(p, &s.sm.to_array());
        let w: [[f64; 3]; 3] = match weights {
            NoiseWeights::Shared(d) => {
                std::array::from_fn(|r| std::array::from_fn(|c| if r == c { d[r] } else { 0.0 }))
            }
            NoiseWeights::PerSample(info) => info[i],
        };
        for r in 0..3 {
            for c in 0..3 {
                if w[r][c] == 0.0 {
                    continue;
                }
                cost += e[r] * w[r][c] * e[c];
                for a in 0..7 {
                    let wa = jac[r][a] * w[r][c];
                    g[a] += wa * e[c];
                    for b in a..7 {
                        h[a][b] += wa * jac[c][b];
                    }
                }
            }
        }
    }
    for a in 0..7 {
        for b in 0..a {
            h[a][b] = h[b][a];
        }
    }
    // Priors and held parameters on the six, through the six-parameter rules.
    let mut ne = NormalEquations {
        cost,
        h: std::array::from_fn(|a| std::array::from_fn(|b| h[a][b])),
        g: std::array::from_fn(|a| g[a]),
    };
    constraints.apply_to(&mut ne, &params);
    for a in 0..6 {
        h[a][..6].copy_from_slice(&ne.h[a]);
        g[a] = ne.g[a];
        if constraints.is_held(a) {
            h[a][6] = 0.0;
            h[6][a] = 0.0;
        }
    }
    (ne.cost, h, g)
}

/// The median of `values` (NaN when empty).
fn median(mut values: Vec<f64>) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    let mid = values.len() / 2;
    *values.select_nth_unstable_by(mid, f64::total_cmp).1
}

/// Refines the six parameters and the slide `k` together on the samples
/// `calibration` used (`samples` are the ones it was computed from, with the same
/// `options`). `None` when the seven-parameter information is singular (no turns
/// at different speeds) or the estimate is not finite.
pub fn fit_lateral_slip(
    samples: &[Sample],
    calibration: &Calibration,
    options: &SolveOptions,
) -> Option<SlideFit> {
    let used: Vec<usize> = (0..samples.len())
        .filter(|&i| calibration.used.get(i).copied().unwrap_or(false))
        .collect();
    let shapes = shapes_used(calibration, samples);
    let weights = weights_used(calibration, samples, shapes.as_ref());
    let constraints = &options.constraints;
    let use_profile = options.use_profile;
    let start = calibration.params.to_vector();
    let mut x = [
        start[0], start[1], start[2], start[3], start[4], start[5], 0.0,
    ];
    let ne = |x: &[f64; 7]| normal_equations(samples, &used, x, &weights, constraints, use_profile);
    let (mut cost, mut h, mut g) = ne(&x);
    let mut damping = Damping::new();
    for _ in 0..MAX_ITERATIONS {
        if !(cost.is_finite() && cost > 0.0) {
            break;
        }
        let hm = Matrix7::from_fn(|a, b| h[a][b]);
        let (hs, s) = unit_diagonal(&hm);
        let gs = SVector::<f64, 7>::from_fn(|a, _| g[a] * s[a]);
        let Some(chol) = (hs + Matrix7::identity() * damping.lambda()).cholesky() else {
            if damping.rejected() {
                break;
            }
            continue;
        };
        let step = -chol.solve(&gs);
        let predicted = -2.0 * gs.dot(&step) - (hs * step).dot(&step);
        if Damping::negligible(predicted, cost) {
            break;
        }
        let trial: [f64; 7] = std::array::from_fn(|a| x[a] + step[a] * s[a]);
        let (tc, th, tg) = ne(&trial);
        if tc.is_finite() && tc <= cost {
            let decrease = cost - tc;
            (x, cost, h, g) = (trial, tc, th, tg);
            if damping.accepted(decrease, cost) {
                break;
            }
        } else if damping.rejected() {
            break;
        }
    }
    if !x.iter().all(|v| v.is_finite()) {
        return None;
    }
    // The 7×7 covariance in unit-diagonal scaling; held rows are decoupled.
    let hm = Matrix7::from_fn(|a, b| h[a][b]);
    let (hs, s) = unit_diagonal(&hm);
    if s[6] == 0.0 {
        return None;
    }
    let inverse = hs.cholesky()?.inverse();
    let cov = |a: usize, b: usize| inverse[(a, b)] * s[a] * s[b];
    let var_k = cov(6, 6);
    if !(var_k.is_finite() && var_k > 0.0) {
        return None;
    }
    // Not knowing k adds u·uᵀ/var_k to the six's covariance (u their covariance with
    // k): the six-parameter covariance (with its shared-scan sandwich) plus that.
    let cross: [f64; 6] = std::array::from_fn(|a| {
        if constraints.is_held(a) {
            0.0
        } else {
            cov(a, 6)
        }
    });
    let covariance = std::array::from_fn(|a| {
        std::array::from_fn(|b| calibration.covariance[a][b] + cross[a] * cross[b] / var_k)
    });
    let params = Params::from_vector([x[0], x[1], x[2], x[3], x[4], x[5]]);
    let (mut speeds, mut rates) = (Vec::new(), Vec::new());
    for &i in &used {
        let s = &samples[i];
        let v = 0.5 * (params.r_l * s.dphi_l + params.r_r * s.dphi_r) / s.t;
        let w = (params.r_r * s.dphi_r - params.r_l * s.dphi_l) / params.b / s.t;
        if w.abs() > TURNING_RATE && v.abs() > MOVING_SPEED {
            speeds.push(v.abs());
            rates.push(w.abs());
        }
    }
    Some(SlideFit {
        params,
        covariance,
        slip: LateralSlip {
            k: x[6],
            sigma: var_k.sqrt(),
            covariance_with_params: cross,
            l_x_shift: params.laser.x - calibration.params.laser.x,
            shifts: {
                let (with, without) = (params.to_vector(), calibration.params.to_vector());
                std::array::from_fn(|i| with[i] - without[i])
            },
            turning_speed: median(speeds),
            turn_rate: median(rates),
            applied: false,
            weight: 0.0,
            evidence: if var_k > 0.0 {
                x[6] / var_k.sqrt()
            } else {
                f64::INFINITY
            },
        },
        cost,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibrate::calibrate;
    use odocal_geom::Pose2;

    /// Samples of a drive with spins, slow and fast arcs and straight runs, ŝ
    /// predicted with the slide `k` plus a deterministic pseudo-noise.
    fn samples(truth: &Params, k: f64) -> Vec<Sample> {
        let mut out = Vec::new();
        let mut seed = 12345u64;
        let mut noise = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1);
            ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 2e-4
        };
        for i in 0..300 {
            let (l, r) = [
                (5.0, 5.0),
                (-4.0, 4.0),
                (2.0, 6.0),
                (8.0, 14.0),
                (14.0, 8.0),
                (1.0, 3.0),
            ][i % 6];
            let f = 1.0 + 0.002 * (i % 17) as f64;
            let s = Sample::from_rotations(0.4, l * f, r * f, Pose2::IDENTITY);
            let (p, _) = predict_with_slide(truth, k, &s, true);
            out.push(Sample {
                sm: Pose2::new(p[0] + noise(), p[1] + noise(), p[2] + 0.1 * noise()),
                ..s
            });
        }
        out
    }

    fn truth() -> Params {
        Params {
            r_l: 0.03,
            r_r: 0.031,
            b: 0.3,
            laser: Pose2::new(0.1, 0.02, 0.4),
        }
    }

    #[test]
    fn the_slide_is_recovered_and_moves_lx_back() {
        let (truth, k) = (truth(), 0.05);
        let samples = samples(&truth, k);
        let options = SolveOptions::default();
        let mut cal = calibrate(&samples, &options).unwrap();
        let biased = cal.params.laser.x - truth.laser.x;
        let fit = fit_lateral_slip(&samples, &cal, &options).unwrap();
        let slip = fit.slip;
        assert!((slip.k - k).abs() < 3.0 * slip.sigma, "{slip:?}");
        assert!(slip.significance() > 10.0, "{slip:?}");
        fit.apply(&mut cal);
        let sx = cal.covariance[3][3].sqrt();
        assert!((cal.params.laser.x - truth.laser.x).abs() < 3.0 * sx);
        assert!(
            biased.abs() > 3.0 * sx,
            "ignoring the slide biases ℓx: {biased}"
        );
        assert!(cal.lateral_slip.unwrap().applied);
    }

    #[test]
    fn the_model_with_the_slide_takes_its_noise_from_its_own_residuals() {
        // The same drive and noise with and without a slide of 0.05 s: the six-parameter
        // solve of the sliding drive takes the slide it leaves out for noise.
        let (truth, k) = (truth(), 0.05);
        let sliding = samples(&truth, k);
        let options = SolveOptions::default();
        let six = calibrate(&sliding, &options).unwrap();
        let mut fit = fit_lateral_slip(&sliding, &six, &options).unwrap();
        let taken_from_six = fit.covariance;
        fit.measure_noise_with_slide(&sliding, &options);
        let clean = calibrate(&samples(&truth, 0.0), &options).unwrap();
        let u = fit.slip.covariance_with_params;
        let var_k = fit.slip.sigma.powi(2);
        for i in 0..6 {
            let measured = fit.covariance[i][i];
            let expected = clean.covariance[i][i] + u[i] * u[i] / var_k;
            assert!(
                (measured / expected - 1.0).abs() < 0.1,
                "parameter {i}: {measured:e} against {expected:e} (the clean drive's σ²)"
            );
            assert!(
                measured < 0.9 * taken_from_six[i][i],
                "parameter {i}: {measured:e} against {:e} from the six's residuals",
                taken_from_six[i][i]
            );
        }
    }

    #[test]
    fn no_slide_gives_k_near_zero_and_keeps_the_estimate() {
        let truth = truth();
        let samples = samples(&truth, 0.0);
        let options = SolveOptions::default();
        let cal = calibrate(&samples, &options).unwrap();
        let fit = fit_lateral_slip(&samples, &cal, &options).unwrap();
        assert!(fit.slip.significance() < 4.0, "{:?}", fit.slip);
        for i in 0..6 {
            let d = (fit.params.to_vector()[i] - cal.params.to_vector()[i]).abs();
            assert!(d < 2.0 * cal.covariance[i][i].sqrt(), "parameter {i}: {d}");
            // σ never shrinks by adding a parameter.
            assert!(fit.covariance[i][i] >= cal.covariance[i][i]);
        }
    }
}
