//! Recovered parameters against a published row: the 3σ rule and the absolute
//! bounds, quantity by quantity.

use crate::reproduce::Reproduction;
use odocal_geom::wrap_angle;
use odocal_solver::Params;
use serde::Serialize;

/// Names of the quantities compared, in the order of [`Reproduction::checks`].
pub const QUANTITY_NAMES: [&str; 8] = ["r_L", "r_R", "b", "l_x", "l_y", "l_theta", "J21", "J22"];

/// Bounds of the comparison.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Tolerances {
    /// Every quantity within this many reported standard deviations.
    pub sigma_multiple: f64,
    /// The absolute bounds below apply to runs with at least this many samples.
    pub min_samples_for_bounds: usize,
    /// Relative bound for r_L, r_R, b, J21, J22.
    pub relative: f64,
    /// Bound for ℓx, ℓy (m).
    pub position: f64,
    /// Bound for ℓθ (rad).
    pub heading: f64,
}

impl Default for Tolerances {
    /// 3σ; from 1,000 samples on also 0.35 %, 1.5 mm and 0.2°.
    fn default() -> Self {
        Tolerances {
            sigma_multiple: 3.0,
            min_samples_for_bounds: 1000,
            relative: 0.0035,
            position: 1.5e-3,
            heading: 0.2f64.to_radians(),
        }
    }
}

/// One quantity of a [`Reproduction`], compared.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct QuantityCheck {
    /// Name (one of [`QUANTITY_NAMES`]).
    pub name: &'static str,
    /// The published (true) value.
    pub published: f64,
    /// The published standard deviation, when known.
    pub published_sigma: Option<f64>,
    /// The recovered value.
    pub recovered: f64,
    /// The standard deviation the pipeline reported.
    pub sigma: f64,
    /// `recovered − published` (angles wrapped).
    pub error: f64,
    /// The absolute bound, when it applies.
    pub bound: Option<f64>,
    /// `|error| ≤ sigma_multiple·sigma`.
    pub within_sigma: bool,
    /// `|error| ≤ bound` (true when no bound applies).
    pub within_bound: bool,
}

impl QuantityCheck {
    /// The error in reported standard deviations.
    pub fn error_in_sigma(&self) -> f64 {
        self.error / self.sigma
    }

    /// Both rules hold.
    pub fn passed(&self) -> bool {
        self.within_sigma && self.within_bound
    }
}

/// Gradients of J21 = −r_L/b and J22 = r_R/b with respect to (r_L, r_R, b, ℓ).
fn j_gradients(p: &Params) -> [[f64; 6]; 2] {
    [
        [-1.0 / p.b, 0.0, p.r_l / (p.b * p.b), 0.0, 0.0, 0.0],
        [0.0, 1.0 / p.b, -p.r_r / (p.b * p.b), 0.0, 0.0, 0.0],
    ]
}

fn propagate(g: &[f64; 6], cov: &[[f64; 6]; 6]) -> f64 {
    let mut v = 0.0;
    for i in 0..6 {
        for k in 0..6 {
            v += g[i] * cov[i][k] * g[k];
        }
    }
    v.max(0.0).sqrt()
}

impl Reproduction {
    /// Whether the absolute bounds apply: the run asked for at least
    /// [`Tolerances::min_samples_for_bounds`] samples.
    pub fn bounds_apply(&self, tol: &Tolerances) -> bool {
        self.target_samples >= tol.min_samples_for_bounds
    }

    /// Compares every quantity of [`QUANTITY_NAMES`] with the row.
    pub fn checks(&self, tol: &Tolerances) -> Vec<QuantityCheck> {
        let truth = self.truth;
        let rep = &self.estimate;
        let recovered = Params::from_vector(rep.values());
        let mut published: Vec<f64> = truth.to_vector().to_vec();
        let tj = truth.j();
        published.extend([tj[1][0], tj[1][1]]);
        let mut values: Vec<f64> = rep.values().to_vec();
        values.extend([rep.j[1][0], rep.j[1][1]]);
        let mut errors: Vec<f64> = recovered.difference(&truth).to_vec();
        errors.extend([values[6] - published[6], values[7] - published[7]]);
        let g = j_gradients(&recovered);
        let mut sigmas: Vec<f64> = rep.sigma.to_vec();
        sigmas.extend([
            propagate(&g[0], &rep.covariance),
            propagate(&g[1], &rep.covariance),
        ]);
        let published_sigma: Vec<Option<f64>> = (0..8)
            .map(|i| match (i, &self.row.covariance, &self.row.sigma) {
                (0..=5, _, Some(s)) => Some(s[i]),
                (6 | 7, Some(c), _) => Some(propagate(&j_gradients(&truth)[i - 6], c)),
                _ => None,
            })
            .collect();
        let apply = self.bounds_apply(tol);
        (0..8)
            .map(|i| {
                let bound = apply.then(|| match i {
                    3 | 4 => tol.position,
                    5 => tol.heading,
                    _ => tol.relative * published[i].abs(),
                });
                let error = if i == 5 {
                    wrap_angle(errors[i])
                } else {
                    errors[i]
                };
                QuantityCheck {
                    name: QUANTITY_NAMES[i],
                    published: published[i],
                    published_sigma: published_sigma[i],
                    recovered: values[i],
                    sigma: sigmas[i],
                    error,
                    bound,
                    within_sigma: error.abs() <= tol.sigma_multiple * sigmas[i],
                    within_bound: bound.is_none_or(|b| error.abs() <= b),
                }
            })
            .collect()
    }

    /// One sentence per quantity outside its bounds (empty when the row passes).
    pub fn failures(&self, tol: &Tolerances) -> Vec<String> {
        let mut out = Vec::new();
        for c in self.checks(tol) {
            if !c.within_sigma {
                out.push(format!(
                    "{}: {}: error {:.3e} is {:.2}σ, beyond {}σ (σ = {:.3e})",
                    self.row.name,
                    c.name,
                    c.error,
                    c.error_in_sigma(),
                    tol.sigma_multiple,
                    c.sigma
                ));
            }
            if !c.within_bound {
                out.push(format!(
                    "{}: {}: error {:.3e} above the bound {:.3e}",
                    self.row.name,
                    c.name,
                    c.error,
                    c.bound.unwrap_or(f64::NAN)
                ));
            }
        }
        out
    }

    /// The largest `|error|/σ` over the quantities.
    pub fn worst_error_in_sigma(&self, tol: &Tolerances) -> f64 {
        self.checks(tol)
            .iter()
            .map(|c| c.error_in_sigma().abs())
            .fold(0.0, f64::max)
    }
}
