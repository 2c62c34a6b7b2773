//! Differential-drive odometry `o` over a sample's interval (constant speeds or a
//! piecewise-constant profile), the predicted sensor displacement
//! `ŝ_pred = ⊖ℓ ⊕ o ⊕ ℓ`, and their analytic Jacobians with respect to
//! `(r_L, r_R, b, ℓx, ℓy, ℓθ)`.

use crate::params::Params;
use crate::sample::{ProfileSegment, Sample};
use odocal_geom::{one_minus_cos_over_x, sin_over_x, wrap_angle, Pose2};

/// Below this |x| the derivatives of `sin(x)/x` and `(1 − cos x)/x` use their
/// Taylor series (the closed forms lose digits to cancellation).
const SERIES_SWITCH: f64 = 1e-2;

/// `d/dx [sin(x)/x]`.
fn d_sin_over_x(x: f64) -> f64 {
    if x.abs() < SERIES_SWITCH {
        let x2 = x * x;
        x * (-1.0 / 3.0 + x2 * (1.0 / 30.0 - x2 / 840.0))
    } else {
        (x * x.cos() - x.sin()) / (x * x)
    }
}

/// `d/dx [(1 − cos x)/x]`.
fn d_one_minus_cos_over_x(x: f64) -> f64 {
    if x.abs() < SERIES_SWITCH {
        let x2 = x * x;
        0.5 - x2 * (1.0 / 8.0 - x2 / 144.0)
    } else {
        (x * x.sin() - (1.0 - x.cos())) / (x * x)
    }
}

/// The wheel rotations `(left, right)` of the constant-speed pieces of a sample.
pub(crate) enum Pieces<'a> {
    /// The whole interval at constant speed.
    One(Option<(f64, f64)>),
    /// A piecewise-constant profile.
    Many(std::slice::Iter<'a, ProfileSegment>),
}

impl Iterator for Pieces<'_> {
    type Item = (f64, f64);
    fn next(&mut self) -> Option<(f64, f64)> {
        match self {
            Pieces::One(p) => p.take(),
            Pieces::Many(it) => it.next().map(|p| (p.dphi_l, p.dphi_r)),
        }
    }
}

/// The pieces of `sample`: its profile when present and `use_profile`, else the
/// whole interval.
pub(crate) fn pieces(sample: &Sample, use_profile: bool) -> Pieces<'_> {
    match (&sample.profile, use_profile) {
        (Some(p), true) => Pieces::Many(p.iter()),
        _ => Pieces::One(Some((sample.dphi_l, sample.dphi_r))),
    }
}

/// `sin x`, `cos x`, `sin(x)/x` and `(1 − cos x)/x` from a single `sin_cos`.
#[derive(Debug, Clone, Copy)]
struct ArcTrig {
    sin: f64,
    cos: f64,
    sin_over_x: f64,
    one_minus_cos_over_x: f64,
}

impl ArcTrig {
    #[inline]
    fn new(x: f64) -> Self {
        let (sin, cos) = x.sin_cos();
        // Same switch as odocal-geom's functions, which handle small angles.
        let (f, g) = if x.abs() < 1e-3 {
            (sin_over_x(x), one_minus_cos_over_x(x))
        } else {
            let inv = 1.0 / x;
            (sin * inv, (1.0 - cos) * inv)
        };
        ArcTrig {
            sin,
            cos,
            sin_over_x: f,
            one_minus_cos_over_x: g,
        }
    }
}

/// A robot displacement with its heading unwrapped and the heading's sine and
/// cosine (carried along so that callers need no further trigonometry).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct RawOdometry {
    /// Forward displacement (m).
    pub x: f64,
    /// Lateral displacement (m).
    pub y: f64,
    /// Heading change (rad), not wrapped.
    pub theta: f64,
    /// `sin theta`.
    pub sin: f64,
    /// `cos theta`.
    pub cos: f64,
}

impl RawOdometry {
    /// No motion: where the integration of an interval starts.
    const ZERO: RawOdometry = RawOdometry {
        x: 0.0,
        y: 0.0,
        theta: 0.0,
        sin: 0.0,
        cos: 1.0,
    };

    /// `1 − cos theta` without cancellation for small angles.
    #[inline]
    pub(crate) fn one_minus_cos(&self) -> f64 {
        if self.cos > 0.0 {
            self.sin * self.sin / (1.0 + self.cos)
        } else {
            1.0 - self.cos
        }
    }

    /// The same displacement with its translation scaled by `k`.
    #[inline]
    pub(crate) fn scale_translation(&self, k: f64) -> Self {
        RawOdometry {
            x: k * self.x,
            y: k * self.y,
            ..*self
        }
    }
}

/// Robot displacement for wheel radii `r_l`, `r_r` and wheel distance `b` over the
/// given pieces. One `sin_cos` per piece; the heading's sine and cosine are
/// propagated by the angle-addition formulas.
#[inline]
pub(crate) fn odometry_raw(
    r_l: f64,
    r_r: f64,
    b: f64,
    pieces: impl Iterator<Item = (f64, f64)>,
) -> RawOdometry {
    let mut o = RawOdometry::ZERO;
    for (al, ar) in pieces {
        let ds = 0.5 * (r_l * al + r_r * ar);
        let dth = (r_r * ar - r_l * al) / b;
        let t = ArcTrig::new(dth);
        let dx = ds * t.sin_over_x;
        let dy = ds * t.one_minus_cos_over_x;
        o.x += o.cos * dx - o.sin * dy;
        o.y += o.sin * dx + o.cos * dy;
        o.theta += dth;
        (o.sin, o.cos) = (o.sin * t.cos + o.cos * t.sin, o.cos * t.cos - o.sin * t.sin);
    }
    o
}

/// Robot displacement and its derivative with respect to `(r_L, r_R, b)`:
/// `d[row][param]`, rows x, y, θ.
#[inline]
pub(crate) fn odometry_with_jacobian(
    r_l: f64,
    r_r: f64,
    b: f64,
    pieces: impl Iterator<Item = (f64, f64)>,
) -> (RawOdometry, [[f64; 3]; 3]) {
    let mut o = RawOdometry::ZERO;
    let mut d = [[0.0; 3]; 3];
    let inv_b = 1.0 / b;
    for (al, ar) in pieces {
        let ds = 0.5 * (r_l * al + r_r * ar);
        let dth = (r_r * ar - r_l * al) * inv_b;
        let d_ds = [0.5 * al, 0.5 * ar, 0.0];
        let d_dth = [-al * inv_b, ar * inv_b, -dth * inv_b];
        let t = ArcTrig::new(dth);
        let (f, g) = (t.sin_over_x, t.one_minus_cos_over_x);
        let (df, dg) = if dth.abs() < SERIES_SWITCH {
            (d_sin_over_x(dth), d_one_minus_cos_over_x(dth))
        } else {
            let inv_x2 = 1.0 / (dth * dth);
            (
                (dth * t.cos - t.sin) * inv_x2,
                (dth * t.sin - (1.0 - t.cos)) * inv_x2,
            )
        };
        let (dx, dy) = (ds * f, ds * g);
        let (s, c) = (o.sin, o.cos);
        for q in 0..3 {
            let d_dx = d_ds[q] * f + ds * df * d_dth[q];
            let d_dy = d_ds[q] * g + ds * dg * d_dth[q];
            let dthq = d[2][q];
            d[0][q] += (-s * dx - c * dy) * dthq + c * d_dx - s * d_dy;
            d[1][q] += (c * dx - s * dy) * dthq + s * d_dx + c * d_dy;
            d[2][q] += d_dth[q];
        }
        o.x += c * dx - s * dy;
        o.y += s * dx + c * dy;
        o.theta += dth;
        (o.sin, o.cos) = (s * t.cos + c * t.sin, c * t.cos - s * t.sin);
    }
    (o, d)
}

/// The robot's displacement `o` over the sample's interval, from the wheel
/// rotations (using the profile when present and `use_profile`).
pub fn odometry(params: &Params, sample: &Sample, use_profile: bool) -> Pose2 {
    let o = odometry_raw(
        params.r_l,
        params.r_r,
        params.b,
        pieces(sample, use_profile),
    );
    Pose2::new(o.x, o.y, o.theta)
}

/// Predicts sensor displacements `ŝ_pred = ⊖ℓ ⊕ o ⊕ ℓ` for fixed parameters, with
/// the sensor rotation's sine and cosine computed once.
#[derive(Debug, Clone, Copy)]
pub struct Predictor {
    params: Params,
    cos_l: f64,
    sin_l: f64,
    use_profile: bool,
}

impl Predictor {
    /// A predictor for `params`; `use_profile` selects the integrated kinematics for
    /// samples that carry a wheel-speed profile.
    pub fn new(params: &Params, use_profile: bool) -> Self {
        let (sin_l, cos_l) = params.laser.theta.sin_cos();
        Predictor {
            params: *params,
            cos_l,
            sin_l,
            use_profile,
        }
    }

    /// `ŝ_pred` as `[x, y, θ]` (θ wrapped) from the odometry `o`.
    #[inline]
    pub(crate) fn sensor_from_odometry(&self, o: &RawOdometry) -> [f64; 3] {
        let l = &self.params.laser;
        let sa = o.sin;
        // v = t_o + (R(α) − I) t_ℓ, then ŝ_t = R(−ℓθ) v.
        let omc = o.one_minus_cos();
        let vx = o.x - omc * l.x - sa * l.y;
        let vy = o.y + sa * l.x - omc * l.y;
        [
            self.cos_l * vx + self.sin_l * vy,
            -self.sin_l * vx + self.cos_l * vy,
            wrap_fast(o.theta),
        ]
    }

    /// `ŝ_pred` for `sample`, as `[x, y, θ]` (θ wrapped).
    pub fn predict(&self, sample: &Sample) -> [f64; 3] {
        self.predict_pieces(pieces(sample, self.use_profile))
    }

    /// `ŝ_pred − ŝ` for `sample` (angle wrapped).
    pub fn residual(&self, sample: &Sample) -> [f64; 3] {
        residual_of(self.predict(sample), &sample.sm.to_array())
    }

    /// `ŝ_pred` (θ wrapped) and its Jacobian `G[row][param]` with respect to
    /// `(r_L, r_R, b, ℓx, ℓy, ℓθ)`, rows x, y, θ.
    pub fn predict_with_jacobian(&self, sample: &Sample) -> ([f64; 3], [[f64; 6]; 3]) {
        self.predict_with_jacobian_pieces(pieces(sample, self.use_profile))
    }

    /// `ŝ_pred` over the given pieces.
    #[inline]
    pub(crate) fn predict_pieces(&self, pieces: Pieces<'_>) -> [f64; 3] {
        let p = &self.params;
        let o = odometry_raw(p.r_l, p.r_r, p.b, pieces);
        self.sensor_from_odometry(&o)
    }

    /// `ŝ_pred` and its Jacobian over the given pieces.
    #[inline]
    pub(crate) fn predict_with_jacobian_pieces(
        &self,
        pieces: Pieces<'_>,
    ) -> ([f64; 3], [[f64; 6]; 3]) {
        let p = &self.params;
        let l = &p.laser;
        let (o, d) = odometry_with_jacobian(p.r_l, p.r_r, p.b, pieces);
        let s_pred = self.sensor_from_odometry(&o);
        let (sa, ca) = (o.sin, o.cos);
        let (c, s) = (self.cos_l, self.sin_l);
        // ∂(R(α) t_ℓ)/∂α
        let rot_x = -(sa * l.x + ca * l.y);
        let rot_y = ca * l.x - sa * l.y;
        let mut g = [[0.0; 6]; 3];
        for q in 0..3 {
            let dvx = d[0][q] + rot_x * d[2][q];
            let dvy = d[1][q] + rot_y * d[2][q];
            g[0][q] = c * dvx + s * dvy;
            g[1][q] = -s * dvx + c * dvy;
            g[2][q] = d[2][q];
        }
        // ∂ŝ_t/∂t_ℓ = R(−ℓθ)(R(α) − I)
        let omc = o.one_minus_cos();
        let (m00, m01, m10, m11) = (-omc, -sa, sa, -omc);
        g[0][3] = c * m00 + s * m10;
        g[0][4] = c * m01 + s * m11;
        g[1][3] = -s * m00 + c * m10;
        g[1][4] = -s * m01 + c * m11;
        // ∂ŝ_t/∂ℓθ = (ŝ_y, −ŝ_x)
        g[0][5] = s_pred[1];
        g[1][5] = -s_pred[0];
        (s_pred, g)
    }
}

/// [`wrap_angle`] behind an explicit in-range test, with the out-of-range case out
/// of line: inlined, `wrap_angle`'s `rem_euclid` gets evaluated speculatively
/// (an `fmod` call per sample in the hot loops).
#[inline]
pub(crate) fn wrap_fast(a: f64) -> f64 {
    #[cold]
    #[inline(never)]
    fn slow(a: f64) -> f64 {
        wrap_angle(a)
    }
    if a > -std::f64::consts::PI && a <= std::f64::consts::PI {
        a
    } else {
        slow(a)
    }
}

/// `predicted − measured`, angle wrapped.
#[inline]
pub(crate) fn residual_of(predicted: [f64; 3], measured: &[f64; 3]) -> [f64; 3] {
    [
        predicted[0] - measured[0],
        predicted[1] - measured[1],
        wrap_fast(predicted[2] - measured[2]),
    ]
}

/// The sensor displacement predicted by the parameters, `ŝ_pred = ⊖ℓ ⊕ o ⊕ ℓ`
/// (using the sample's profile when it has one).
pub fn predict(params: &Params, sample: &Sample) -> Pose2 {
    Pose2::from_array(Predictor::new(params, true).predict(sample))
}

/// `ŝ_pred − ŝ` for one sample, `[x, y, θ]` with the angle wrapped (using the
/// sample's profile when it has one).
pub fn residual(params: &Params, sample: &Sample) -> [f64; 3] {
    Predictor::new(params, true).residual(sample)
}

/// `ŝ_pred − ŝ` for every sample (using profiles when present).
pub fn residuals(params: &Params, samples: &[Sample]) -> Vec<[f64; 3]> {
    let p = Predictor::new(params, true);
    samples.iter().map(|s| p.residual(s)).collect()
}

/// `ŝ_pred` and its 3×6 Jacobian with respect to `(r_L, r_R, b, ℓx, ℓy, ℓθ)`.
pub fn predict_with_jacobian(
    params: &Params,
    sample: &Sample,
    use_profile: bool,
) -> (Pose2, [[f64; 6]; 3]) {
    let (s, g) = Predictor::new(params, use_profile).predict_with_jacobian(sample);
    (Pose2::from_array(s), g)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A robot with unequal radii and a displaced, rotated laser (also used by the
    /// slide's tests).
    pub(crate) fn params() -> Params {
        Params {
            r_l: 0.031,
            r_r: 0.029,
            b: 0.31,
            laser: Pose2::new(0.12, -0.05, 2.7),
        }
    }

    fn seg(duration: f64, l: f64, r: f64) -> ProfileSegment {
        ProfileSegment {
            duration,
            dphi_l: l,
            dphi_r: r,
        }
    }

    /// Constant-speed and profiled samples: arcs, a straight run, a spin, tiny turns.
    pub(crate) fn samples() -> Vec<Sample> {
        vec![
            Sample::from_rotations(0.5, 3.0, 4.0, Pose2::IDENTITY),
            Sample::from_rotations(0.5, 3.0, 3.0, Pose2::IDENTITY),
            Sample::from_rotations(0.5, -3.0, 3.0, Pose2::IDENTITY),
            Sample::from_rotations(0.5, 2.0, 2.0000001, Pose2::IDENTITY),
            Sample::from_profile(
                vec![seg(0.1, 1.0, 2.0), seg(0.2, -1.0, 2.5), seg(0.1, 0.5, 0.5)],
                Pose2::IDENTITY,
            ),
            Sample::from_profile(
                vec![seg(0.1, 1e-4, 2e-4), seg(0.2, 3.0, 3.0)],
                Pose2::IDENTITY,
            ),
        ]
    }

    #[test]
    fn constant_speed_odometry_is_an_arc() {
        let p = params();
        let s = Sample::from_rotations(1.0, 3.0, 4.0, Pose2::IDENTITY);
        let v = 0.5 * (p.r_l * 3.0 + p.r_r * 4.0);
        let w = (p.r_r * 4.0 - p.r_l * 3.0) / p.b;
        let o = odometry(&p, &s, true);
        // Centre of rotation at (0, v/w); the end point lies on the circle.
        let rad = v / w;
        assert!((o.x - rad * w.sin()).abs() < 1e-15);
        assert!((o.y - rad * (1.0 - w.cos())).abs() < 1e-15);
        assert!((o.theta - w).abs() < 1e-15);
    }

    #[test]
    fn profile_odometry_composes_pieces() {
        let p = params();
        let pieces = vec![seg(0.1, 1.0, 2.0), seg(0.2, -1.0, 2.5), seg(0.1, 0.5, 0.5)];
        let s = Sample::from_profile(pieces.clone(), Pose2::IDENTITY);
        let mut expected = Pose2::IDENTITY;
        for piece in &pieces {
            let one =
                Sample::from_rotations(piece.duration, piece.dphi_l, piece.dphi_r, Pose2::IDENTITY);
            expected = expected.compose(&odometry(&p, &one, true));
        }
        let o = odometry(&p, &s, true);
        assert!((o.x - expected.x).abs() < 1e-15 && (o.y - expected.y).abs() < 1e-15);
        assert!((o.theta - expected.theta).abs() < 1e-15);
        // Without the profile: constant speed over the totals, a different displacement.
        let flat = odometry(&p, &s, false);
        assert!((flat.x - o.x).abs() > 1e-4);
    }

    #[test]
    fn prediction_matches_pose_composition() {
        let p = params();
        for s in samples() {
            let o = odometry(&p, &s, true);
            let expected = p.laser.inverse().compose(&o).compose(&p.laser);
            let got = predict(&p, &s);
            assert!((got.x - expected.x).abs() < 1e-15);
            assert!((got.y - expected.y).abs() < 1e-15);
            assert!(wrap_angle(got.theta - expected.theta).abs() < 1e-15);
        }
    }

    #[test]
    fn analytic_jacobian_matches_finite_differences() {
        for laser_theta in [2.7, -3.1, 0.0, std::f64::consts::PI - 1e-5] {
            let mut p = params();
            p.laser.theta = laser_theta;
            for s in samples() {
                let (_, g) = predict_with_jacobian(&p, &s, true);
                let v = p.to_vector();
                for q in 0..6 {
                    let h = 1e-5 * v[q].abs().max(0.1);
                    let mut vp = v;
                    let mut vm = v;
                    vp[q] += h;
                    vm[q] -= h;
                    let sp = Predictor::new(&Params::from_vector(vp), true).predict(&s);
                    let sm = Predictor::new(&Params::from_vector(vm), true).predict(&s);
                    for row in 0..3 {
                        let diff = if row == 2 {
                            wrap_angle(sp[row] - sm[row])
                        } else {
                            sp[row] - sm[row]
                        };
                        let fd = diff / (2.0 * h);
                        let scale = g[row][q].abs().max(1e-3);
                        assert!(
                            (fd - g[row][q]).abs() < 1e-6 * scale,
                            "row {row} param {q}: analytic {} vs numeric {fd} ({s:?})",
                            g[row][q]
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn series_derivatives_match_closed_forms_at_the_switch() {
        let closed_f = |x: f64| (x * x.cos() - x.sin()) / (x * x);
        let closed_g = |x: f64| (x * x.sin() - (1.0 - x.cos())) / (x * x);
        for &x in &[SERIES_SWITCH * 0.999_999, -SERIES_SWITCH * 0.999_999] {
            assert!((d_sin_over_x(x) - closed_f(x)).abs() < 1e-12);
            assert!((d_one_minus_cos_over_x(x) - closed_g(x)).abs() < 1e-12);
        }
        assert_eq!(d_sin_over_x(0.0), 0.0);
        assert_eq!(d_one_minus_cos_over_x(0.0), 0.5);
    }
}
