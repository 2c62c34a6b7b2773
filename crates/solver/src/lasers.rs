//! Several lasers on one robot: the wheels (`r_L`, `r_R`, `b`) shared, one pose
//! `ℓ_k = (ℓx, ℓy, ℓθ)` per laser, `3 + 3K` parameters.
//!
//! Each laser's samples are first solved on their own by [`calibrate`] (closed form,
//! that laser's outlier trimming and scan-matching noise); the estimates are combined
//! (wheels weighted by their information) and refined together by Levenberg–Marquardt
//! over every laser's kept samples, each laser weighted by its own noise. The
//! covariance is the inverse joint information, with each laser's shared-scan score
//! (when its samples carry scan times) in the sandwich, as the single-laser solve does.
//! Lasers never share a scan, so their scores are independent.

use crate::calibrate::{calibrate, Calibration, SolveOptions};
use crate::constraints::{Constraint, Constraints};
use crate::damping::Damping;
use crate::error::SolveError;
use crate::kinematics::{residual_of, Predictor};
use crate::noise::NoiseWeights;
use crate::noise_shape::{shapes_used, weights_used};
use crate::observability::{parameter_reports, sentence, wheel_signs};
use crate::packed::Packed;
use crate::params::Params;
use crate::sample::Sample;
use crate::shared_scans::score_covariance;
use nalgebra::{DMatrix, DVector, Matrix3};
use odocal_geom::{wrap_angle, Pose2};
use serde::Serialize;

/// Largest number of Levenberg–Marquardt iterations of the joint refinement.
const MAX_ITERATIONS: usize = 100;

/// Smallest eigenvalue, relative to the largest, of the unit-diagonal joint
/// information below which a direction counts as not determined.
const SINGULAR_RATIO: f64 = 1e-13;

/// The joint estimate of [`calibrate_lasers`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LasersCalibration {
    /// `[r_L, r_R, b, ℓx₁, ℓy₁, ℓθ₁, …, ℓxK, ℓyK, ℓθK]` (m, rad).
    pub params: Vec<f64>,
    /// Covariance of [`LasersCalibration::params`], `(3+3K)×(3+3K)`.
    pub covariance: Vec<Vec<f64>>,
    /// Per laser: its own solve (closed form, trimming, noise, own covariance).
    pub own: Vec<Calibration>,
    /// Per input sample: whether the joint estimate used it (kept by its laser's trimming).
    pub used: Vec<bool>,
    /// Weighted cost of the joint fit at its starting point.
    pub cost_before: f64,
    /// Weighted cost at the joint estimate.
    pub cost_after: f64,
    /// Iterations of the joint refinement.
    pub iterations: usize,
    /// The first laser's view of the joint estimate: the shared wheels, ℓ₁, the 6×6
    /// block of the joint covariance and the verdicts from it; the rest (trimming,
    /// noise, motion content) from the first laser's own solve.
    pub first: Calibration,
    /// Per laser: the parameters held or given priors as that laser sees them (the
    /// wheels' shared by all, its own ℓ's).
    pub constraints: Vec<Constraints>,
}

impl LasersCalibration {
    /// Number of lasers.
    pub fn lasers(&self) -> usize {
        (self.params.len() - 3) / 3
    }

    /// Indices in [`LasersCalibration::params`] (and rows and columns of
    /// [`LasersCalibration::covariance`]) of (r_L, r_R, b, ℓx_k, ℓy_k, ℓθ_k): laser
    /// `k`'s six parameters, in the order of a single-laser [`Calibration`]. Laser 0's
    /// are `0..6`, so with one laser they are the whole vector.
    pub fn indices(k: usize) -> [usize; 6] {
        [0, 1, 2, 3 + 3 * k, 4 + 3 * k, 5 + 3 * k]
    }

    /// The six parameters as laser `k` sees them (shared wheels, its own ℓ).
    pub fn params_of(&self, k: usize) -> Params {
        Params::from_vector(Self::indices(k).map(|i| self.params[i]))
    }

    /// The 6×6 block of the joint covariance of (r_L, r_R, b, ℓ_k).
    pub fn covariance_of(&self, k: usize) -> [[f64; 6]; 6] {
        let ix = Self::indices(k);
        std::array::from_fn(|i| std::array::from_fn(|j| self.covariance[ix[i]][ix[j]]))
    }

    /// Laser `k`'s pose in the first laser's frame, `ℓ₁⁻¹ ⊕ ℓ_k`, and its 3×3
    /// covariance propagated from the joint covariance of (ℓ₁, ℓ_k), cross terms included.
    pub fn from_first(&self, k: usize) -> (Pose2, [[f64; 3]; 3]) {
        let l1 = self.params_of(0).laser;
        let lk = self.params_of(k).laser;
        let ix: Vec<usize> = (3..6).chain(3 + 3 * k..6 + 3 * k).collect();
        let c = DMatrix::from_fn(6, 6, |i, j| self.covariance[ix[i]][ix[j]]);
        let (t, jac) = relative_pose(&l1, &lk);
        let out = &jac * c * jac.transpose();
        (
            t,
            std::array::from_fn(|i| std::array::from_fn(|j| out[(i, j)])),
        )
    }
}

/// `t = a⁻¹ ⊕ b` and its Jacobian (3×6) with respect to `(a, b)`.
pub(crate) fn relative_pose(a: &Pose2, b: &Pose2) -> (Pose2, DMatrix<f64>) {
    let (s, c) = a.theta.sin_cos();
    let (dx, dy) = (b.x - a.x, b.y - a.y);
    let t = Pose2::new(
        c * dx + s * dy,
        -s * dx + c * dy,
        wrap_angle(b.theta - a.theta),
    );
    let mut j = DMatrix::zeros(3, 6);
    // ∂/∂a: translation −R(−θa), rotation d R(−θa)/dθa (b − a).
    j[(0, 0)] = -c;
    j[(0, 1)] = -s;
    j[(1, 0)] = s;
    j[(1, 1)] = -c;
    j[(0, 2)] = -s * dx + c * dy;
    j[(1, 2)] = -c * dx - s * dy;
    j[(2, 2)] = -1.0;
    // ∂/∂b: R(−θa), and 1 for the heading.
    j[(0, 3)] = c;
    j[(0, 4)] = s;
    j[(1, 3)] = -s;
    j[(1, 4)] = c;
    j[(2, 5)] = 1.0;
    (t, j)
}

/// One laser's kept samples and their weights in the joint fit.
struct Group<'a> {
    packed: Vec<Packed<'a>>,
    weights: NoiseWeights,
    /// Each sample's noise map for the covariance (`crate::noise_shape`), when the
    /// laser's own solve weighted by the matcher's shapes.
    maps: Option<Vec<Matrix3<f64>>>,
}

/// `(cost, H, g)` of the joint fit at `params`.
fn normal_equations(groups: &[Group], params: &[f64]) -> (f64, DMatrix<f64>, DVector<f64>) {
    let n = params.len();
    let mut sums = (0.0, DMatrix::zeros(n, n), DVector::zeros(n));
    for (k, group) in groups.iter().enumerate() {
        accumulate_group(k, group, params, &mut sums);
    }
    sums
}

/// Adds laser `k`'s samples to `(cost, H, g)` at the joint `params`.
fn accumulate_group(
    k: usize,
    group: &Group,
    params: &[f64],
    (cost, h, g): &mut (f64, DMatrix<f64>, DVector<f64>),
) {
    let ix = LasersCalibration::indices(k);
    let pred = Predictor::new(&Params::from_vector(ix.map(|i| params[i])), true);
    for s in &group.packed {
        let (sp, jac) = pred.predict_with_jacobian_pieces(s.pieces());
        let e = residual_of(sp, &s.sm);
        let w = match &group.weights {
            NoiseWeights::Shared(d) => [[d[0], 0.0, 0.0], [0.0, d[1], 0.0], [0.0, 0.0, d[2]]],
            NoiseWeights::PerSample(info) => info[s.index],
        };
        for r in 0..3 {
            for c in 0..3 {
                *cost += e[r] * w[r][c] * e[c];
                for a in 0..6 {
                    g[ix[a]] += jac[r][a] * w[r][c] * e[c];
                    for b in 0..6 {
                        h[(ix[a], ix[b])] += jac[r][a] * w[r][c] * jac[c][b];
                    }
                }
            }
        }
    }
}

/// Scales `h` to unit diagonal: `(D h D, D)` with `D = diag(1/√h_ii)` (0 where h_ii ≤ 0).
fn unit_diagonal(h: &DMatrix<f64>) -> (DMatrix<f64>, DVector<f64>) {
    let n = h.nrows();
    let s = DVector::from_fn(n, |i, _| {
        let d = h[(i, i)];
        if d > 0.0 && d.is_finite() {
            1.0 / d.sqrt()
        } else {
            0.0
        }
    });
    (DMatrix::from_fn(n, n, |i, j| h[(i, j)] * s[i] * s[j]), s)
}

/// Names of the parameters `3 + 3K` long: `r_L, r_R, b, l_x[1], …`.
fn joint_names(k: usize) -> Vec<String> {
    let mut names: Vec<String> = vec!["r_L".into(), "r_R".into(), "b".into()];
    for laser in 1..=k {
        for p in ["l_x", "l_y", "l_theta"] {
            names.push(format!("{p} of laser {laser}"));
        }
    }
    names
}

/// Calibrates one robot with several lasers: `laser_of[i]` is the laser (0, 1, …) of
/// `samples[i]`; every laser index below the largest must have samples. The wheels
/// are shared, each laser gets its own ℓ. `options.constraints` hold the wheels and
/// the first laser's ℓ (or give them priors); the other lasers' ℓ are free (see
/// [`calibrate_lasers_constrained`]).
pub fn calibrate_lasers(
    samples: &[Sample],
    laser_of: &[usize],
    options: &SolveOptions,
) -> Result<LasersCalibration, SolveError> {
    calibrate_lasers_constrained(samples, laser_of, options, &[])
}

/// [`calibrate_lasers`] with the other lasers' ℓ held or given priors: `more[j]` is
/// (ℓx, ℓy, ℓθ) of laser `j + 1` (lasers beyond `more` free). The wheels' constraints
/// (`options.constraints`, shared by every laser) and each prior count once.
pub fn calibrate_lasers_constrained(
    samples: &[Sample],
    laser_of: &[usize],
    options: &SolveOptions,
    more: &[[Constraint; 3]],
) -> Result<LasersCalibration, SolveError> {
    if laser_of.len() != samples.len() {
        return Err(SolveError::Numerical(format!(
            "{} samples but {} laser indices",
            samples.len(),
            laser_of.len()
        )));
    }
    let k_lasers = laser_of.iter().max().map_or(0, |m| m + 1);
    if more.len() >= k_lasers.max(1) {
        return Err(SolveError::Numerical(format!(
            "constraints given for laser {} but the samples come from {k_lasers} laser(s)",
            more.len() + 1
        )));
    }
    let constraints: Vec<Constraints> = (0..k_lasers)
        .map(|k| laser_constraints(&options.constraints, more, k))
        .collect();
    let joint_constraints: Vec<Constraint> = (0..3 + 3 * k_lasers)
        .map(|i| {
            if i < 3 {
                options.constraints.0[i]
            } else {
                constraints[(i - 3) / 3].0[3 + (i - 3) % 3]
            }
        })
        .collect();
    // Each laser's samples, with their indices in the input.
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); k_lasers];
    for (i, &k) in laser_of.iter().enumerate() {
        members[k].push(i);
    }
    let lenient = SolveOptions {
        accept_weak: true,
        ..*options
    };
    let mut own = Vec::with_capacity(k_lasers);
    let mut own_samples: Vec<Vec<Sample>> = Vec::with_capacity(k_lasers);
    for (idx, c) in members.iter().zip(&constraints) {
        let group: Vec<Sample> = idx.iter().map(|&i| samples[i].clone()).collect();
        let options = SolveOptions {
            constraints: *c,
            ..lenient
        };
        own.push(calibrate(&group, &options)?);
        own_samples.push(group);
    }
    // Start: wheels weighted by each laser's information on them, each laser's own ℓ.
    let mut start = vec![0.0; 3 + 3 * k_lasers];
    for w in 0..3 {
        let info: Vec<f64> = own
            .iter()
            .map(|c| {
                let v = c.covariance[w][w];
                if v.is_finite() && v > 0.0 {
                    1.0 / v
                } else {
                    0.0
                }
            })
            .collect();
        let total: f64 = info.iter().sum();
        start[w] = if total > 0.0 {
            own.iter()
                .zip(&info)
                .map(|(c, i)| c.params.to_vector()[w] * i)
                .sum::<f64>()
                / total
        } else {
            own[0].params.to_vector()[w]
        };
    }
    for (k, c) in own.iter().enumerate() {
        let l = c.params.laser;
        start[3 + 3 * k..6 + 3 * k].copy_from_slice(&[l.x, l.y, l.theta]);
    }
    for (v, c) in start.iter_mut().zip(&joint_constraints) {
        if let Constraint::Held(h) = c {
            *v = *h;
        }
    }
    let groups: Vec<Group> = own
        .iter()
        .zip(&own_samples)
        .map(|(c, group)| {
            let packed: Vec<Packed> = Packed::all(group, options.use_profile)
                .into_iter()
                .filter(|p| c.used[p.index])
                .collect();
            let shapes = shapes_used(c, group);
            Group {
                weights: weights_used(c, group, shapes.as_ref()),
                packed,
                maps: shapes
                    .zip(c.noise_shaping.as_ref())
                    .map(|(m, n)| m.covariance_maps(n)),
            }
        })
        .collect();

    let (params, cost_before, cost_after, iterations, h) = if options.refine {
        refine_joint(&groups, start, &joint_constraints)
    } else {
        let (cost, h, _) = constrained_normal_equations(&groups, &start, &joint_constraints);
        (start, cost, cost, 0, h)
    };
    if !params.iter().all(|v| v.is_finite()) {
        return Err(SolveError::Numerical(format!(
            "the joint estimate is not finite ({params:?})"
        )));
    }
    let inverse = invert(&h).ok_or_else(|| SolveError::NotExcited {
        parameters: joint_names(k_lasers),
        sentence: "the lasers' samples together do not determine every parameter: \
                   calibrate each laser on its own to see which motion is missing"
            .into(),
    })?;
    let inverse = zero_held(inverse, &joint_constraints);
    let (covariance, shared) = sandwich(&groups, &params, &inverse, &joint_constraints);
    // With scans shared by consecutive samples the lasers' true covariances are the
    // sandwiches, not H⁻¹, and an H-weighted fit mixes the lasers' wheels with the
    // wrong weights (the two-lidar fixture: σ_b 1.01 mm jointly, 0.71 mm from the
    // rear lidar alone). Then the estimate is the lasers' own estimates combined by
    // generalized least squares with those covariances (first-order ML for them).
    let (params, covariance) = match shared
        .then(|| combine(&own, &constraints, &joint_constraints))
        .flatten()
    {
        Some(combined) => combined,
        None => (params, covariance),
    };

    let mut used = vec![false; samples.len()];
    for (group, idx) in groups.iter().zip(&members) {
        for p in &group.packed {
            used[idx[p.index]] = true;
        }
    }
    let mut out = LasersCalibration {
        params,
        covariance: (0..covariance.nrows())
            .map(|i| covariance.row(i).iter().copied().collect())
            .collect(),
        first: own[0].clone(),
        own,
        used,
        cost_before,
        cost_after,
        iterations,
        constraints,
    };
    out.first = out.view(0);
    Ok(out)
}

impl LasersCalibration {
    /// Laser `k`'s view of the joint estimate as a single-laser [`Calibration`]: the
    /// shared wheels, ℓ_k, the 6×6 block of the joint covariance and the verdicts
    /// from it, the joint costs and the samples the joint estimate used (all lasers');
    /// trimming rounds, noise and motion content from laser `k`'s own solve.
    pub fn view(&self, k: usize) -> Calibration {
        let params = self.params_of(k);
        let covariance = self.covariance_of(k);
        let mut c = self.own[k].clone();
        let reports = parameter_reports(&params, &covariance, &self.constraints[k]);
        c.observability.sentence = sentence(&reports, &c.observability.motion);
        // The laser's own solve's one-sample findings are not those of the joint
        // information: not carried over (and not judged again on the joint solve).
        c.observability.one_sample = Vec::new();
        c.observability.parameters = reports;
        c.observability.wheel_signs = wheel_signs(&params);
        c.j = params.j();
        c.params = params;
        c.covariance = covariance;
        c.used = self.used.clone();
        c.samples_used = self.used.iter().filter(|u| **u).count();
        c.cost_before = self.cost_before;
        c.cost_after = self.cost_after;
        let dof = (3 * c.samples_used)
            .saturating_sub(self.params.len())
            .max(1);
        c.reduced_chi2 = self.cost_after / dof as f64;
        c
    }
}

/// Levenberg–Marquardt over all `3 + 3K` parameters from `start`: the estimate, the
/// costs before and after, the iterations and the information at the estimate.
fn refine_joint(
    groups: &[Group],
    start: Vec<f64>,
    constraints: &[Constraint],
) -> (Vec<f64>, f64, f64, usize, DMatrix<f64>) {
    let n = start.len();
    let mut params = start;
    let (mut cost, mut h, mut g) = constrained_normal_equations(groups, &params, constraints);
    let cost_before = cost;
    let mut damping = Damping::new();
    let mut iterations = 0;
    while iterations < MAX_ITERATIONS && cost.is_finite() && cost > 0.0 {
        iterations += 1;
        let (hs, s) = unit_diagonal(&h);
        let damped = hs.clone() + DMatrix::identity(n, n) * damping.lambda();
        let gs = g.component_mul(&s);
        let Some(chol) = damped.cholesky() else {
            if damping.rejected() {
                break;
            }
            continue;
        };
        let step = -chol.solve(&gs);
        let predicted = -2.0 * gs.dot(&step) - (&hs * &step).dot(&step);
        if Damping::negligible(predicted, cost) {
            break;
        }
        let mut trial = params.clone();
        for i in 0..n {
            trial[i] += step[i] * s[i];
        }
        for k in 0..(n - 3) / 3 {
            trial[5 + 3 * k] = wrap_angle(trial[5 + 3 * k]);
        }
        let (t_cost, t_h, t_g) = constrained_normal_equations(groups, &trial, constraints);
        if t_cost.is_finite() && t_cost <= cost {
            let decrease = cost - t_cost;
            (params, cost, h, g) = (trial, t_cost, t_h, t_g);
            if damping.accepted(decrease, cost) {
                break;
            }
        } else if damping.rejected() {
            break;
        }
    }
    (params, cost_before, cost, iterations, h)
}

/// `H⁻¹` in unit-diagonal scaling, or `None` when some direction carries no information.
fn invert(h: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    if h.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let (hs, s) = unit_diagonal(h);
    if s.iter().any(|&v| v == 0.0) {
        return None;
    }
    let eig = hs.symmetric_eigen();
    let max = eig.eigenvalues.max();
    if eig
        .eigenvalues
        .iter()
        .any(|&v| v.is_nan() || v <= SINGULAR_RATIO * max)
    {
        return None;
    }
    let inv_s = &eig.eigenvectors
        * DMatrix::from_diagonal(&eig.eigenvalues.map(|v| 1.0 / v))
        * eig.eigenvectors.transpose();
    let n = h.nrows();
    Some(DMatrix::from_fn(n, n, |i, j| inv_s[(i, j)] * s[i] * s[j]))
}

/// `H⁻¹ (M + P) H⁻¹` with `M` the score's covariance: per laser, its shared-scan score
/// (when its samples carry scan times) or its block of `H` (independent samples), and
/// `P` the priors' information. `inverse` is `H⁻¹` with held rows zero.
fn sandwich(
    groups: &[Group],
    params: &[f64],
    inverse: &DMatrix<f64>,
    constraints: &[Constraint],
) -> (DMatrix<f64>, bool) {
    let n = params.len();
    let mut meat = DMatrix::zeros(n, n);
    for (i, c) in constraints.iter().enumerate() {
        if let Constraint::Prior { sigma, .. } = c {
            meat[(i, i)] += 1.0 / (sigma * sigma);
        }
    }
    let mut any_shared = false;
    for (k, group) in groups.iter().enumerate() {
        let ix = LasersCalibration::indices(k);
        let p = Params::from_vector(ix.map(|i| params[i]));
        let h_inv: [[f64; 6]; 6] =
            std::array::from_fn(|i| std::array::from_fn(|j| inverse[(ix[i], ix[j])]));
        match score_covariance(
            &group.packed,
            &p,
            &group.weights,
            &h_inv,
            group.maps.as_deref(),
        ) {
            Some((score, _)) => {
                any_shared = true;
                for a in 0..6 {
                    for b in 0..6 {
                        meat[(ix[a], ix[b])] += score[a][b];
                    }
                }
            }
            None => {
                let mut sums = (0.0, DMatrix::zeros(n, n), DVector::zeros(n));
                accumulate_group(k, group, params, &mut sums);
                meat += sums.1;
            }
        }
    }
    if !any_shared {
        return (inverse.clone(), false);
    }
    let c = inverse * meat * inverse;
    (
        DMatrix::from_fn(n, n, |i, j| 0.5 * (c[(i, j)] + c[(j, i)])),
        true,
    )
}

/// The lasers' own estimates (wheels and ℓ_k, covariance C_k) combined by generalized
/// least squares: `x = (Σ P_kᵀ C_k⁻¹ P_k)⁻¹ Σ P_kᵀ C_k⁻¹ θ_k` with `P_k` selecting the
/// free ones of the wheels and ℓ_k, and its covariance `(Σ P_kᵀ C_k⁻¹ P_k)⁻¹`; `None`
/// when a covariance cannot be inverted. Held parameters keep their values (zero
/// variance); a wheel's prior, in every laser's own estimate, is counted once.
fn combine(
    own: &[Calibration],
    constraints: &[Constraints],
    joint: &[Constraint],
) -> Option<(Vec<f64>, DMatrix<f64>)> {
    let n = 3 + 3 * own.len();
    let mut a = DMatrix::zeros(n, n);
    let mut b = DVector::zeros(n);
    for ((k, c), held) in own.iter().enumerate().zip(constraints) {
        let ix = LasersCalibration::indices(k);
        let free: Vec<usize> = (0..6).filter(|&i| !held.is_held(i)).collect();
        let ck = DMatrix::from_fn(free.len(), free.len(), |i, j| {
            c.covariance[free[i]][free[j]]
        });
        let info = invert(&ck)?;
        let v = c.params.to_vector();
        let theta = DVector::from_fn(free.len(), |i, _| v[free[i]]);
        let weighted = &info * theta;
        for (i, &fi) in free.iter().enumerate() {
            b[ix[fi]] += weighted[i];
            for (j, &fj) in free.iter().enumerate() {
                a[(ix[fi], ix[fj])] += info[(i, j)];
            }
        }
    }
    let repeated = own.len().saturating_sub(1) as f64;
    for (i, c) in joint.iter().enumerate() {
        match *c {
            Constraint::Held(v) => {
                a[(i, i)] = 1.0;
                b[i] = v;
            }
            Constraint::Prior { mean, sigma } if i < 3 => {
                let w = repeated / (sigma * sigma);
                a[(i, i)] -= w;
                b[i] -= w * mean;
            }
            _ => {}
        }
    }
    let inverse = invert(&a)?;
    let x = &inverse * b;
    let covariance = zero_held(inverse, joint);
    let mut params: Vec<f64> = x.iter().copied().collect();
    for (v, c) in params.iter_mut().zip(joint) {
        if let Constraint::Held(h) = c {
            *v = *h;
        }
    }
    for k in 0..own.len() {
        params[5 + 3 * k] = wrap_angle(params[5 + 3 * k]);
    }
    Some((params, covariance))
}

/// The constraints laser `k` sees in [`calibrate_lasers_constrained`]: the wheels' of
/// `shared`, its own ℓ's (`shared`'s for the first laser, `more[k - 1]` for the
/// others, free beyond `more`).
pub fn laser_constraints(shared: &Constraints, more: &[[Constraint; 3]], k: usize) -> Constraints {
    let mut c = *shared;
    if k > 0 {
        let own = more.get(k - 1).copied().unwrap_or_default();
        c.0[3..6].copy_from_slice(&own);
    }
    c
}

/// [`normal_equations`] with the priors added and the held parameters decoupled
/// (zero gradient, unit diagonal, zero coupling), so that a step leaves them in place.
fn constrained_normal_equations(
    groups: &[Group],
    params: &[f64],
    constraints: &[Constraint],
) -> (f64, DMatrix<f64>, DVector<f64>) {
    let (mut cost, mut h, mut g) = normal_equations(groups, params);
    let n = params.len();
    for (i, c) in constraints.iter().enumerate() {
        match *c {
            Constraint::Free => {}
            Constraint::Held(_) => {
                for j in 0..n {
                    h[(i, j)] = 0.0;
                    h[(j, i)] = 0.0;
                }
                h[(i, i)] = 1.0;
                g[i] = 0.0;
            }
            Constraint::Prior { mean, sigma } => {
                let d = if i >= 3 && i % 3 == 2 {
                    wrap_angle(params[i] - mean)
                } else {
                    params[i] - mean
                };
                let w = 1.0 / (sigma * sigma);
                cost += w * d * d;
                g[i] += w * d;
                h[(i, i)] += w;
            }
        }
    }
    (cost, h, g)
}

/// `c` with the rows and columns of held parameters set to zero.
fn zero_held(mut c: DMatrix<f64>, constraints: &[Constraint]) -> DMatrix<f64> {
    for (i, k) in constraints.iter().enumerate() {
        if matches!(k, Constraint::Held(_)) {
            c.row_mut(i).fill(0.0);
            c.column_mut(i).fill(0.0);
        }
    }
    c
}
