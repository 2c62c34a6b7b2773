//! The sideways slide of a skid-steer robot in its turns, as a term of the sample
//! model: the body moves at `v_y = −k·v·ω` in its own frame (outward of the turn for
//! `k > 0`) on top of the differential-drive motion, so that over a sample's interval
//! the robot's displacement is `o + k·w` with
//!
//! ```text
//! w = Σ_pieces R(θ_before) · (Δs·Δθ/Δt) · ((1 − cos Δθ)/Δθ, −sin Δθ/Δθ)
//! ```
//!
//! (each constant-speed piece: a constant sideways velocity in the turning body frame
//! traces the piece's arc turned by −90°; the heading is the wheels' alone). The slide
//! depends on time — the same wheel rotations done faster slide more — so the pieces
//! carry their durations, unlike [`crate::kinematics`].
//!
//! A sideways velocity proportional to ω alone (`v_y = c·ω`: the centre of rotation
//! ahead of or behind the axle) adds `c·((cos Δθ − 1), sin Δθ)` per piece, which is
//! exactly what moving the sensor by `c` along x does: it is not observable, and ℓx is
//! then measured from the point of the robot that does not slide. `k·v·ω` differs in
//! that it grows with the speed, so pairs driven at different speeds with the same
//! turn rate tell it apart.

use crate::kinematics::wrap_fast;
use crate::params::Params;
use crate::sample::Sample;

/// Below this |Δθ| the functions of the arc use their Taylor series.
const SERIES_SWITCH: f64 = 1e-2;

/// `sin x / x`, `(1 − cos x)/x` and their derivatives.
fn arc_functions(x: f64) -> [f64; 4] {
    if x.abs() < SERIES_SWITCH {
        let x2 = x * x;
        [
            1.0 - x2 / 6.0 * (1.0 - x2 / 20.0),
            x * (0.5 - x2 / 24.0 * (1.0 - x2 / 30.0)),
            x * (-1.0 / 3.0 + x2 * (1.0 / 30.0 - x2 / 840.0)),
            0.5 - x2 * (1.0 / 8.0 - x2 / 144.0),
        ]
    } else {
        let (s, c) = x.sin_cos();
        let inv = 1.0 / x;
        [
            s * inv,
            (1.0 - c) * inv,
            (x * c - s) * inv * inv,
            (x * s - (1.0 - c)) * inv * inv,
        ]
    }
}

/// The constant-speed pieces of a sample with their durations `(Δt, Δφ_L, Δφ_R)`:
/// its profile when present and `use_profile`, else the whole interval.
pub(crate) fn timed_pieces(
    sample: &Sample,
    use_profile: bool,
) -> impl Iterator<Item = (f64, f64, f64)> + '_ {
    let profile = sample.profile.as_deref().filter(|_| use_profile);
    let whole = profile
        .is_none()
        .then_some((sample.t, sample.dphi_l, sample.dphi_r));
    profile
        .into_iter()
        .flatten()
        .map(|p| (p.duration, p.dphi_l, p.dphi_r))
        .chain(whole)
}

/// The slide's displacement per unit `k`, `w` (robot frame at the start of the
/// interval; m/s), and its derivative `∂w/∂(r_L, r_R, b)` (`d[row][param]`).
pub(crate) fn slide_with_jacobian(
    r_l: f64,
    r_r: f64,
    b: f64,
    pieces: impl Iterator<Item = (f64, f64, f64)>,
) -> ([f64; 2], [[f64; 3]; 2]) {
    let mut w = [0.0; 2];
    let mut d = [[0.0; 3]; 2];
    let (mut theta, mut d_theta) = (0.0f64, [0.0; 3]);
    let inv_b = 1.0 / b;
    for (dt, al, ar) in pieces {
        let ds = 0.5 * (r_l * al + r_r * ar);
        let dth = (r_r * ar - r_l * al) * inv_b;
        let d_ds = [0.5 * al, 0.5 * ar, 0.0];
        let d_dth = [-al * inv_b, ar * inv_b, -dth * inv_b];
        if dt > 0.0 {
            let [f, g, df, dg] = arc_functions(dth);
            let rate = ds * dth / dt;
            let c = [rate * g, -rate * f];
            let (s, co) = theta.sin_cos();
            w[0] += co * c[0] - s * c[1];
            w[1] += s * c[0] + co * c[1];
            for q in 0..3 {
                let d_rate = (d_ds[q] * dth + ds * d_dth[q]) / dt;
                let dc = [
                    d_rate * g + rate * dg * d_dth[q],
                    -d_rate * f - rate * df * d_dth[q],
                ];
                let dtq = d_theta[q];
                d[0][q] += (-s * c[0] - co * c[1]) * dtq + co * dc[0] - s * dc[1];
                d[1][q] += (co * c[0] - s * c[1]) * dtq + s * dc[0] + co * dc[1];
            }
        }
        theta += dth;
        for q in 0..3 {
            d_theta[q] += d_dth[q];
        }
    }
    (w, d)
}

/// `ŝ_pred` with the slide `k` (θ wrapped) and its Jacobian with respect to
/// `(r_L, r_R, b, ℓx, ℓy, ℓθ, k)`, rows x, y, θ.
pub(crate) fn predict_with_slide(
    params: &Params,
    k: f64,
    sample: &Sample,
    use_profile: bool,
) -> ([f64; 3], [[f64; 7]; 3]) {
    let (s6, g6) =
        crate::kinematics::Predictor::new(params, use_profile).predict_with_jacobian(sample);
    let (w, dw) = slide_with_jacobian(
        params.r_l,
        params.r_r,
        params.b,
        timed_pieces(sample, use_profile),
    );
    // The slide enters the robot's translation, which ŝ sees turned by −ℓθ.
    let (s, c) = params.laser.theta.sin_cos();
    let turn = |v: [f64; 2]| [c * v[0] + s * v[1], -s * v[0] + c * v[1]];
    let sw = turn(w);
    let mut g = [[0.0; 7]; 3];
    for r in 0..3 {
        g[r][..6].copy_from_slice(&g6[r]);
    }
    for q in 0..3 {
        let t = turn([dw[0][q], dw[1][q]]);
        g[0][q] += k * t[0];
        g[1][q] += k * t[1];
    }
    g[0][5] += k * sw[1];
    g[1][5] -= k * sw[0];
    g[0][6] = sw[0];
    g[1][6] = sw[1];
    ([s6[0] + k * sw[0], s6[1] + k * sw[1], wrap_fast(s6[2])], g)
}

/// `ŝ_pred − ŝ` (θ wrapped) for every sample with the sideways slide `k` (0: the
/// six-parameter model's residuals).
pub fn residuals_with_slide(
    params: &Params,
    k: f64,
    samples: &[Sample],
    use_profile: bool,
) -> Vec<[f64; 3]> {
    samples
        .iter()
        .map(|s| {
            let (p, _) = predict_with_slide(params, k, s, use_profile);
            crate::kinematics::residual_of(p, &s.sm.to_array())
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinematics::tests::{params, samples};

    #[test]
    fn a_constant_slide_is_the_arc_turned_outward() {
        // v = 0.5 m/s, ω = 1 rad/s for 0.4 s, k = 0.05 s: v_y = −0.025 m/s, and the
        // body-frame velocity (0, v_y) integrated along the turn.
        let (v, omega, t, k) = (0.5, 1.0, 0.4, 0.05);
        let (r, b) = (0.05, 0.4);
        let al = (v - omega * b / 2.0) / r * t;
        let ar = (v + omega * b / 2.0) / r * t;
        let (w, _) = slide_with_jacobian(r, r, b, [(t, al, ar)].into_iter());
        // Numerical integration of R(ωτ)·(0, −k·v·ω) over [0, t].
        let n = 100_000;
        let (mut x, mut y) = (0.0, 0.0);
        for i in 0..n {
            let th = omega * (i as f64 + 0.5) * t / n as f64;
            let vy = -k * v * omega;
            x += -th.sin() * vy * t / n as f64;
            y += th.cos() * vy * t / n as f64;
        }
        assert!((k * w[0] - x).abs() < 1e-9 && (k * w[1] - y).abs() < 1e-9);
        assert!(w[1] < 0.0, "outward of a left turn is −y");
    }

    #[test]
    fn a_slide_proportional_to_the_turn_alone_is_a_shift_of_lx() {
        // v_y = −c·ω is v_y = −k·v·ω at v = c/k: pieces timed so that Δs/Δt = c give
        // the slide rate c·Δθ, and k = 1. The sum over the pieces is then
        // −c·(cos θ − 1, sin θ) = −(R(θ) − I)(c, 0): the sensor moved back by c.
        let c = 0.07;
        let (r, b) = (0.05, 0.4);
        let pieces = [(0.2, 1.0, 3.0), (0.3, 0.5, 2.0), (0.1, 2.0, 1.5)];
        let mut theta = 0.0f64;
        let mut expected = [0.0; 2];
        let mut scaled = Vec::new();
        for &(_, al, ar) in &pieces {
            let ds = 0.5 * r * (al + ar);
            let dth = r * (ar - al) / b;
            // Choose Δt so that Δs/Δt = c: the slide rate is then c·Δθ.
            scaled.push((ds / c, al, ar));
            theta += dth;
        }
        expected[0] = c * (theta.cos() - 1.0);
        expected[1] = c * theta.sin();
        let (w, _) = slide_with_jacobian(r, r, b, scaled.into_iter());
        // Outward slide −c·ω, so w = −(R(θ) − I)(c, 0).
        assert!((w[0] + expected[0]).abs() < 1e-12, "{w:?} {expected:?}");
        assert!((w[1] + expected[1]).abs() < 1e-12, "{w:?} {expected:?}");
    }

    #[test]
    fn analytic_jacobian_matches_finite_differences() {
        let k = 0.06;
        for s in samples() {
            let p = params();
            let (_, g) = predict_with_slide(&p, k, &s, true);
            let mut v = p.to_vector().to_vec();
            v.push(k);
            for q in 0..7 {
                let h = 1e-6 * v[q].abs().max(0.1);
                let at = |x: &[f64]| {
                    let p = Params::from_vector([x[0], x[1], x[2], x[3], x[4], x[5]]);
                    predict_with_slide(&p, x[6], &s, true).0
                };
                let mut vp = v.clone();
                let mut vm = v.clone();
                vp[q] += h;
                vm[q] -= h;
                let (sp, sm) = (at(&vp), at(&vm));
                for row in 0..3 {
                    let fd = (sp[row] - sm[row]) / (2.0 * h);
                    let scale = g[row][q].abs().max(1e-3);
                    assert!(
                        (fd - g[row][q]).abs() < 1e-6 * scale,
                        "row {row} param {q}: analytic {} vs numeric {fd}",
                        g[row][q]
                    );
                }
            }
        }
    }

    #[test]
    fn no_slide_is_the_differential_drive_prediction() {
        let p = params();
        for s in samples() {
            let (with, _) = predict_with_slide(&p, 0.0, &s, true);
            let (without, _) =
                crate::kinematics::Predictor::new(&p, true).predict_with_jacobian(&s);
            assert_eq!(with, without);
        }
    }
}
