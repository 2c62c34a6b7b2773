//! Maximum-likelihood refinement of the six parameters (those not held): Levenberg–Marquardt on the
//! weighted residuals `ŝ_pred − ŝ`, started from the closed form.

use crate::constraints::Constraints;
use crate::damping::Damping;
use crate::linalg::unit_diagonal;
use crate::noise::NoiseWeights;
use crate::normal_equations::{accumulate, NormalEquations};
use crate::packed::Packed;
use crate::params::Params;
use nalgebra::{SMatrix, SVector};
use serde::Serialize;

/// Largest number of Levenberg–Marquardt iterations.
pub const MAX_ITERATIONS: usize = 100;

/// Outcome of the refinement.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Refinement {
    /// The refined parameters.
    pub params: Params,
    /// Weighted cost `Σ eᵀWe` at the starting point.
    pub cost_before: f64,
    /// Weighted cost at the refined parameters.
    pub cost_after: f64,
    /// Iterations taken.
    pub iterations: usize,
    /// Whether the cost stopped decreasing before the iteration limit.
    pub converged: bool,
}

/// The normal equations at `params` with the priors added and the held parameters
/// decoupled.
pub(crate) fn constrained_normal_equations(
    samples: &[Packed],
    params: &Params,
    weights: &NoiseWeights,
    constraints: &Constraints,
) -> NormalEquations {
    let mut ne = accumulate(samples, params, weights);
    constraints.apply_to(&mut ne, params);
    ne
}

/// Refines `start` over `samples` (held parameters stay put, priors add their
/// terms to the cost); also returns the Gauss–Newton matrix (Fisher information,
/// priors included, held rows decoupled) at the refined parameters.
pub(crate) fn refine(
    samples: &[Packed],
    start: &Params,
    weights: &NoiseWeights,
    constraints: &Constraints,
) -> (Refinement, [[f64; 6]; 6]) {
    let mut params = constraints.apply_held(start);
    let mut ne = constrained_normal_equations(samples, &params, weights, constraints);
    let cost_before = ne.cost;
    let mut damping = Damping::new();
    let mut iterations = 0;
    let mut converged = false;
    while iterations < MAX_ITERATIONS {
        iterations += 1;
        if ne.cost.is_nan() || ne.cost <= 0.0 {
            converged = true;
            break;
        }
        // Solve (H + λ diag H) δ = −g in unit-diagonal scaling.
        let h = SMatrix::<f64, 6, 6>::from_fn(|i, j| ne.h[i][j]);
        let (hs, s) = unit_diagonal(&h);
        let damped = hs + SMatrix::<f64, 6, 6>::identity() * damping.lambda();
        let gs = SVector::<f64, 6>::from_fn(|i, _| ne.g[i] * s[i]);
        let Some(chol) = damped.cholesky() else {
            if damping.rejected() {
                break;
            }
            continue;
        };
        let step_scaled = -chol.solve(&gs);
        // Predicted decrease of the quadratic model: −2gᵀδ − δᵀHδ.
        let predicted = -2.0 * gs.dot(&step_scaled) - (hs * step_scaled).dot(&step_scaled);
        if Damping::negligible(predicted, ne.cost) {
            converged = true;
            break;
        }
        let mut v = params.to_vector();
        for i in 0..6 {
            v[i] += step_scaled[i] * s[i];
        }
        let trial = constraints.apply_held(&Params::from_vector(v));
        let trial_ne = constrained_normal_equations(samples, &trial, weights, constraints);
        if trial_ne.cost.is_finite() && trial_ne.cost <= ne.cost {
            let decrease = ne.cost - trial_ne.cost;
            params = trial;
            ne = trial_ne;
            if damping.accepted(decrease, ne.cost) {
                converged = true;
                break;
            }
        } else if damping.rejected() {
            converged = true;
            break;
        }
    }
    let cost_after = ne.cost;
    (
        Refinement {
            params,
            cost_before,
            cost_after,
            iterations,
            converged,
        },
        ne.h,
    )
}
