//! The laser's range scale in the covariance.
//!
//! A laser whose ranges read `(1 + s)` times the true distance makes every
//! scan-matched translation `(1 + s)` times too long, and the calibration then finds
//! `r_L`, `r_R`, `b`, `ℓx`, `ℓy` all `(1 + s)` times too large, while ℓθ and the
//! ratios `J21 = −r_L/b`, `J22 = r_R/b` (how the robot turns per wheel rotation) stay
//! the same. The data cannot tell `s`; the range finder's data sheet can. With a
//! systematic scale of standard deviation `σ_s` the covariance of the estimate is
//!
//! `Σ_total = Σ_data + σ_s² p_s p_sᵀ`, `p_s = (r_L, r_R, b, ℓx, ℓy, 0)`
//!
//! (the first-order change of the parameters per unit of scale).

use crate::constraints::Constraints;
use crate::noise::NoiseWeights;
use crate::packed::Packed;
use crate::params::Params;
use crate::refine::refine;

/// The direction the parameters move in when the laser's range scale changes, per
/// unit of relative scale: `(r_L, r_R, b, ℓx, ℓy, 0)` (order of
/// [`crate::PARAMETER_NAMES`]).
pub fn range_scale_direction(params: &Params) -> [f64; 6] {
    [
        params.r_l,
        params.r_r,
        params.b,
        params.laser.x,
        params.laser.y,
        0.0,
    ]
}

/// The relative range scale [`constrained_scale_direction`] probes with: small enough
/// for the response to be linear (at 1 %, with `b` held, the radii move 18 % less
/// than 100 times this), large enough for the refinement to move (its cost falls by
/// about `10⁻⁸·N/σ²`, far above its relative tolerance of 10⁻¹²).
const PROBE: f64 = 1e-4;

/// How the estimate moves per unit of range scale, with held parameters or priors
/// (without them it is [`range_scale_direction`] `p` exactly: the problem is invariant
/// under scaling every distance, and the caller uses `p`). It is measured: every
/// scan-matched translation is made longer by [`PROBE`] and the estimate refined again
/// from where it is (held parameters stay, priors resist), the move divided by the probe. For
/// example, with `b` held the rotations tie `r_L = −J21·b` and `r_R = J22·b`: the radii
/// then move far less than their share, `b` not at all, and ℓθ a little. When that
/// refinement does not converge to finite numbers, `p` with the held entries zeroed.
pub(crate) fn constrained_scale_direction(
    samples: &[Packed],
    params: &Params,
    weights: &NoiseWeights,
    constraints: &Constraints,
) -> [f64; 6] {
    let p = range_scale_direction(params);
    let held_zeroed = std::array::from_fn(|i| if constraints.is_held(i) { 0.0 } else { p[i] });
    let longer: Vec<Packed> = samples
        .iter()
        .map(|s| Packed {
            sm: [s.sm[0] * (1.0 + PROBE), s.sm[1] * (1.0 + PROBE), s.sm[2]],
            ..*s
        })
        .collect();
    let (moved, _) = refine(&longer, params, weights, constraints);
    let d = moved.params.difference(params);
    let direction: [f64; 6] = std::array::from_fn(|i| {
        if constraints.is_held(i) {
            0.0
        } else {
            d[i] / PROBE
        }
    });
    if moved.converged && direction.iter().all(|v| v.is_finite()) {
        direction
    } else {
        held_zeroed
    }
}

/// The covariance a range scale of relative standard deviation `sigma_scale` (0.01:
/// 1 %) adds when the estimate moves by `direction` per unit of scale:
/// `σ_s² d dᵀ`. A `sigma_scale` that is not a finite non-negative number adds nothing.
pub fn scale_covariance_along(direction: &[f64; 6], sigma_scale: f64) -> [[f64; 6]; 6] {
    let s2 = if sigma_scale.is_finite() && sigma_scale > 0.0 {
        sigma_scale * sigma_scale
    } else {
        0.0
    };
    std::array::from_fn(|i| std::array::from_fn(|j| s2 * direction[i] * direction[j]))
}

/// The covariance the laser's range scale adds, `σ_s² p_s p_sᵀ`, for a relative scale
/// standard deviation `sigma_scale` (0.01: 1 %), every parameter free. A `sigma_scale`
/// that is not a finite non-negative number adds nothing.
pub fn range_scale_covariance(params: &Params, sigma_scale: f64) -> [[f64; 6]; 6] {
    scale_covariance_along(&range_scale_direction(params), sigma_scale)
}

/// `covariance` (the data's) with the laser's range scale added along `direction`
/// (see [`scale_covariance_along`]): `Σ_data + σ_s² d dᵀ`.
pub fn with_scale_along(
    covariance: &[[f64; 6]; 6],
    direction: &[f64; 6],
    sigma_scale: f64,
) -> [[f64; 6]; 6] {
    let scale = scale_covariance_along(direction, sigma_scale);
    std::array::from_fn(|i| std::array::from_fn(|j| covariance[i][j] + scale[i][j]))
}

/// `covariance` (the data's) with the laser's range scale added, every parameter
/// free: `Σ_data + σ_s² p_s p_sᵀ`.
pub fn with_range_scale(
    covariance: &[[f64; 6]; 6],
    params: &Params,
    sigma_scale: f64,
) -> [[f64; 6]; 6] {
    with_scale_along(covariance, &range_scale_direction(params), sigma_scale)
}

#[cfg(test)]
mod tests {
    use super::*;
    use odocal_geom::Pose2;

    fn params() -> Params {
        Params {
            r_l: 0.0746,
            r_r: 0.0741,
            b: 0.305,
            laser: Pose2::new(0.094, 0.006, -0.033),
        }
    }

    /// Variance of `f(params)` under `cov`, by a central-difference gradient.
    fn variance_of(f: impl Fn(&Params) -> f64, p: &Params, cov: &[[f64; 6]; 6]) -> f64 {
        let v = p.to_vector();
        let g: [f64; 6] = std::array::from_fn(|i| {
            let h = 1e-7 * v[i].abs().max(1e-3);
            let (mut a, mut b) = (v, v);
            a[i] += h;
            b[i] -= h;
            (f(&Params::from_vector(a)) - f(&Params::from_vector(b))) / (2.0 * h)
        });
        (0..6)
            .map(|i| (0..6).map(|j| g[i] * cov[i][j] * g[j]).sum::<f64>())
            .sum()
    }

    #[test]
    fn scaling_the_laser_moves_the_parameters_along_the_direction() {
        // A laser reading 1 % long: the estimate a scan matcher's translations give
        // is the truth with every distance 1 % longer, ℓθ the same.
        let p = params();
        let s = 0.01;
        let scaled = Params {
            r_l: p.r_l * (1.0 + s),
            r_r: p.r_r * (1.0 + s),
            b: p.b * (1.0 + s),
            laser: Pose2::new(p.laser.x * (1.0 + s), p.laser.y * (1.0 + s), p.laser.theta),
        };
        let d = range_scale_direction(&p);
        let diff = scaled.difference(&p);
        for i in 0..6 {
            assert!(
                (diff[i] - s * d[i]).abs() < 1e-15,
                "{i}: {} vs {}",
                diff[i],
                s * d[i]
            );
        }
        // The turning ratios are unchanged by the scale.
        let (j, js) = (p.j(), scaled.j());
        assert!((j[1][0] - js[1][0]).abs() < 1e-12 && (j[1][1] - js[1][1]).abs() < 1e-12);
    }

    #[test]
    fn the_scale_widens_distances_and_leaves_turning_and_heading_alone() {
        let p = params();
        let mut data = [[0.0; 6]; 6];
        let sd = [2e-4, 2e-4, 8e-4, 1e-3, 1.5e-3, 4e-3];
        for i in 0..6 {
            data[i][i] = sd[i] * sd[i];
        }
        data[0][2] = 0.5 * sd[0] * sd[2];
        data[2][0] = data[0][2];
        let total = with_range_scale(&data, &p, 0.01);
        let d = range_scale_direction(&p);
        for i in 0..6 {
            let want = sd[i] * sd[i] + 1e-4 * d[i] * d[i];
            assert!((total[i][i] - want).abs() < 1e-18, "{i}");
        }
        // ℓθ's variance and its covariances untouched.
        for i in 0..6 {
            assert_eq!(total[5][i], data[5][i]);
        }
        // J21 = −r_L/b and J22 = r_R/b: the same variance with and without the scale.
        let j21 = |q: &Params| -q.r_l / q.b;
        let j22 = |q: &Params| q.r_r / q.b;
        for f in [&j21 as &dyn Fn(&Params) -> f64, &j22] {
            let (a, b) = (variance_of(f, &p, &data), variance_of(f, &p, &total));
            assert!((a - b).abs() < 1e-9 * a, "{a} vs {b}");
        }
        // J11 = r_L/2 does depend on it: its variance grows by (σ_s·r_L/2)².
        let j11 = |q: &Params| q.r_l / 2.0;
        let grown = variance_of(j11, &p, &total) - variance_of(j11, &p, &data);
        assert!((grown - (0.01 * p.r_l / 2.0).powi(2)).abs() < 1e-3 * grown);
    }

    #[test]
    fn no_or_invalid_scale_adds_nothing() {
        let p = params();
        for s in [0.0, -0.01, f64::NAN, f64::INFINITY] {
            assert_eq!(range_scale_covariance(&p, s), [[0.0; 6]; 6]);
        }
    }
}
