//! The closed form with some parameters held at known values: step 1 restricted to
//! the `(J21, J22)` the held radii and wheel distance allow, step 2 minimising
//! `xᵀMx` over the free entries of `x = [b, ℓx, ℓy, cos ℓθ, sin ℓθ]` (a linear
//! solve for each ℓθ, and a search over ℓθ when it is free).

use crate::constraints::Constraints;
use crate::error::SolveError;
use crate::kinematics::RawOdometry;
use crate::observability::{step1_not_excited, step2_not_excited, MotionContent};
use crate::packed::Packed;
use crate::step1::Step1;
use crate::step2::{a_conditions, build_m, solve_m, Step2, A_SINGULAR_CONDITION};
use nalgebra::{DMatrix, DVector};
use odocal_geom::Pose2;
use std::f64::consts::PI;

/// Step 1 under the held values of `r_L`, `r_R`, `b`: `(J21, J22)` on the line (or
/// point) they allow, fitted by least squares. `s1` is the unconstrained step 1
/// (used when the held values leave both free).
pub(crate) fn step1_held(
    samples: &[Packed],
    theta_weights: Option<&[f64]>,
    held: &Constraints,
    s1: &Step1,
) -> Result<(f64, f64), SolveError> {
    let (rl, rr, b) = (held.held(0), held.held(1), held.held(2));
    // (J21, J22) = c + p·z over the free scalar z.
    let (c, p) = match (rl, rr, b) {
        (Some(rl), Some(rr), Some(b)) => return Ok((-rl / b, rr / b)),
        (Some(rl), _, Some(b)) => ([-rl / b, 0.0], [0.0, 1.0]),
        (_, Some(rr), Some(b)) => ([0.0, rr / b], [1.0, 0.0]),
        (Some(rl), Some(rr), None) => ([0.0, 0.0], [-rl, rr]),
        _ => {
            if s1.condition.is_finite() && s1.j21.is_finite() && s1.j22.is_finite() {
                return Ok((s1.j21, s1.j22));
            }
            return Err(step1_not_excited(samples, s1));
        }
    };
    let (mut num, mut den, mut scale) = (0.0, 0.0, 0.0);
    for s in samples {
        let w = theta_weights.map_or(1.0, |w| w[s.index]);
        let ap = s.dphi_l * p[0] + s.dphi_r * p[1];
        let ac = s.dphi_l * c[0] + s.dphi_r * c[1];
        num += w * ap * (s.sm[2] - ac);
        den += w * ap * ap;
        scale += w * (s.dphi_l * s.dphi_l + s.dphi_r * s.dphi_r) * (p[0] * p[0] + p[1] * p[1]);
    }
    if den.is_nan() || den <= 1e-12 * scale {
        return Err(step1_not_excited(samples, s1));
    }
    let z = num / den;
    Ok((c[0] + p[0] * z, c[1] + p[1] * z))
}

/// `min xᵀMx` over the free entries of `x[..3]` with `x[3..] = (cos θ, sin θ)` and
/// the held entries of `known`; returns the cost and the minimiser, or `None` when
/// the free block is not positive definite.
fn profile_at(m: &[[f64; 5]; 5], known: &[Option<f64>; 3], theta: f64) -> Option<(f64, [f64; 5])> {
    let mut x = [0.0; 5];
    x[3] = theta.cos();
    x[4] = theta.sin();
    let free: Vec<usize> = (0..3).filter(|&i| known[i].is_none()).collect();
    for i in 0..3 {
        if let Some(v) = known[i] {
            x[i] = v;
        }
    }
    if !free.is_empty() {
        let n = free.len();
        let mff = DMatrix::from_fn(n, n, |a, b| m[free[a]][free[b]]);
        let rhs = DVector::from_fn(n, |a, _| {
            -(0..5)
                .filter(|j| !free.contains(j))
                .map(|j| m[free[a]][j] * x[j])
                .sum::<f64>()
        });
        let sol = mff.cholesky()?.solve(&rhs);
        for (a, &i) in free.iter().enumerate() {
            x[i] = sol[a];
        }
    }
    let cost: f64 = (0..5)
        .map(|i| (0..5).map(|j| x[i] * m[i][j] * x[j]).sum::<f64>())
        .sum();
    cost.is_finite().then_some((cost, x))
}

/// Grid steps over ℓθ before the golden-section refinement.
const THETA_GRID: usize = 720;

/// Step 2 with some of `b`, `ℓx`, `ℓy`, `ℓθ` held (indices 2–5 of `held`).
pub(crate) fn step2_held(
    samples: &[Packed],
    j21: f64,
    j22: f64,
    held: &Constraints,
    s1: &Step1,
    unit: &mut Vec<RawOdometry>,
) -> Result<Step2, SolveError> {
    let m = build_m(samples, j21, j22, unit);
    if (2..6).all(|i| !held.is_held(i)) {
        return match solve_m(&m) {
            Some(s2) if s2.a_condition_scaled <= A_SINGULAR_CONDITION && s2.b > 0.0 => Ok(s2),
            other => Err(step2_not_excited(
                samples,
                &Step1 { j21, j22, ..*s1 },
                other.map(|s2| s2.a_weakest_direction),
            )),
        };
    }
    let known = [held.held(2), held.held(3), held.held(4)];
    let (a_condition, a_condition_scaled, a_weakest_direction) = a_conditions(&m);
    let not_excited = || {
        let names: Vec<String> = ["b", "l_x", "l_y"]
            .iter()
            .zip(&known)
            .filter(|(_, k)| k.is_none())
            .map(|(n, _)| n.to_string())
            .collect();
        let motion = MotionContent::classify(samples, -j21, j22);
        SolveError::NotExcited {
            parameters: names,
            sentence: format!(
                "with the held values the motion does not excite them ({}); {}",
                motion.describe(),
                crate::observability::PARTIAL_CALIBRATION_HINT
            ),
        }
    };
    let at = |t: f64| profile_at(&m, &known, t);
    let (cost, x) = match held.held(5) {
        Some(t) => at(t).ok_or_else(not_excited)?,
        None => {
            let step = 2.0 * PI / THETA_GRID as f64;
            let mut best: Option<(f64, f64)> = None;
            for k in 0..THETA_GRID {
                let t = -PI + k as f64 * step;
                // x and −x cost the same: keep the half with b > 0.
                if let Some((c, x)) = at(t) {
                    if x[0] > 0.0 && best.is_none_or(|(bc, _)| c < bc) {
                        best = Some((c, t));
                    }
                }
            }
            let (_, t0) = best.ok_or_else(not_excited)?;
            let g = (5f64.sqrt() - 1.0) / 2.0;
            let cost_at = |t: f64| at(t).map_or(f64::INFINITY, |r| r.0);
            let (mut a, mut b) = (t0 - step, t0 + step);
            for _ in 0..60 {
                let (c, d) = (b - g * (b - a), a + g * (b - a));
                if cost_at(c) <= cost_at(d) {
                    b = d;
                } else {
                    a = c;
                }
            }
            at(0.5 * (a + b)).ok_or_else(not_excited)?
        }
    };
    if x[0].is_nan() || x[0] <= 0.0 {
        return Err(not_excited());
    }
    Ok(Step2 {
        b: x[0],
        laser: Pose2::new(x[1], x[2], x[4].atan2(x[3])),
        a_condition,
        a_condition_scaled,
        a_weakest_direction,
        residual: cost,
    })
}
