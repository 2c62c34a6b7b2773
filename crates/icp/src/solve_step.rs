//! The exact minimiser of the point-to-line cost for fixed correspondences.
//!
//! With correspondences `(q_i, n_i, c_i)` (current point in the current frame, unit
//! normal and offset of its reference line), the cost is
//! `Σ (n_iᵀ(R(θ) q_i + t) − c_i)²`. It is quadratic in `x = (t_x, t_y, cos θ, sin θ)`,
//! `xᵀHx − 2gᵀx + const`, under the constraint `cos²θ + sin²θ = 1` — Censi's
//! formulation (ICRA 2008), which he solves through a quartic in the Lagrange
//! multiplier. Here the translation is eliminated first (`t = A⁻¹(g_t − B r)` with
//! `H = [[A, B], [Bᵀ, C]]`), leaving `min rᵀSr − 2hᵀr` over the unit circle with the
//! 2×2 Schur complement `S`. In the eigenbasis of `S` the multiplier `λ` of the global
//! minimum is the root below the smallest eigenvalue of the secular equation
//! `h₁²/(λ₁−λ)² + h₂²/(λ₂−λ)² = 1` (the same quartic), found by safeguarded Newton
//! iterations to machine precision. No linearisation: one call gives the exact
//! optimum for the given correspondences, whatever the rotation.
//!
//! A tiny ridge (1e-9 of the trace of `A`) pulls the translation towards the previous
//! estimate along directions that no correspondence constrains (a corridor), so that
//! the answer stays the first guess there instead of becoming NaN; its effect on a
//! well-constrained problem is ~1e-9 of the correction.

use odocal_geom::Pose2;

/// Accumulated normal equations of the point-to-line cost.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct NormalEquations {
    h: [[f64; 4]; 4],
    g: [f64; 4],
}

impl NormalEquations {
    /// Empty sums.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds the correspondence of current point `q` with the line `normal · x = offset`,
    /// with weight `w` (inverse residual variance, up to a common factor).
    #[inline]
    pub fn add(&mut self, q: [f64; 2], normal: [f64; 2], offset: f64, w: f64) {
        let [nx, ny] = normal;
        let a = [nx, ny, nx * q[0] + ny * q[1], ny * q[0] - nx * q[1]];
        let wa = [w * a[0], w * a[1], w * a[2], w * a[3]];
        let h = &mut self.h;
        h[0][0] += wa[0] * a[0];
        h[0][1] += wa[0] * a[1];
        h[0][2] += wa[0] * a[2];
        h[0][3] += wa[0] * a[3];
        h[1][1] += wa[1] * a[1];
        h[1][2] += wa[1] * a[2];
        h[1][3] += wa[1] * a[3];
        h[2][2] += wa[2] * a[2];
        h[2][3] += wa[2] * a[3];
        h[3][3] += wa[3] * a[3];
        for (g, wa) in self.g.iter_mut().zip(wa) {
            *g += wa * offset;
        }
    }

    /// [`NormalEquations::add`] with the expected effect of the noise of the
    /// reference line's tilt removed (errors-in-variables correction): a tilt `δφ` of
    /// the line moves the correspondence's row by `δφ·b`, `b = [t_x, t_y, t·q, t×q]`
    /// with the tangent `t = (−n_y, n_x)`, and its offset by `δφ·(t·m)`, `m` the
    /// window centroid. Left in, `E[δφ²]·b bᵀ` attenuates the estimated rotation (by
    /// ≈ 1e-4·θ on the URG-04LX model) and couples some translation to it.
    /// `w_tilt_variance` is `w·E[δφ²]`.
    #[inline]
    pub fn add_corrected(
        &mut self,
        q: [f64; 2],
        normal: [f64; 2],
        offset: f64,
        w: f64,
        centroid_along: f64,
        w_tilt_variance: f64,
    ) {
        let [nx, ny] = normal;
        let a = [nx, ny, nx * q[0] + ny * q[1], ny * q[0] - nx * q[1]];
        // Tangent t = (−ny, nx): t·q = −a₃ and t×q (= t_y q_x − t_x q_y) = a₂.
        let b = [-ny, nx, -a[3], a[2]];
        let wa = [w * a[0], w * a[1], w * a[2], w * a[3]];
        let v = w_tilt_variance;
        let vb = [v * b[0], v * b[1], v * b[2], v * b[3]];
        let h = &mut self.h;
        h[0][0] += wa[0] * a[0] - vb[0] * b[0];
        h[0][1] += wa[0] * a[1] - vb[0] * b[1];
        h[0][2] += wa[0] * a[2] - vb[0] * b[2];
        h[0][3] += wa[0] * a[3] - vb[0] * b[3];
        h[1][1] += wa[1] * a[1] - vb[1] * b[1];
        h[1][2] += wa[1] * a[2] - vb[1] * b[2];
        h[1][3] += wa[1] * a[3] - vb[1] * b[3];
        h[2][2] += wa[2] * a[2] - vb[2] * b[2];
        h[2][3] += wa[2] * a[3] - vb[2] * b[3];
        h[3][3] += wa[3] * a[3] - vb[3] * b[3];
        for r in 0..4 {
            self.g[r] += wa[r] * offset - vb[r] * centroid_along;
        }
    }

    /// The Gauss–Newton information matrix `Σ w JᵀJ` in `(x, y, θ)` at rotation `theta`
    /// (`J = [n_x, n_y, nᵀR'(θ)q]` is a linear map of the accumulated vector `a`), and
    /// the weighted RMS distance of the points from the sensor.
    pub fn information(&self, theta: f64) -> ([[f64; 3]; 3], f64) {
        let h = &self.h;
        let (s, c) = theta.sin_cos();
        // Row 3 of the map: (0, 0, −s, c).
        let i02 = -s * h[0][2] + c * h[0][3];
        let i12 = -s * h[1][2] + c * h[1][3];
        let i22 = s * s * h[2][2] - 2.0 * s * c * h[2][3] + c * c * h[3][3];
        let info = [
            [h[0][0], h[0][1], i02],
            [h[0][1], h[1][1], i12],
            [i02, i12, i22],
        ];
        let weight = h[0][0] + h[1][1];
        let rho = ((h[2][2] + h[3][3]) / weight).sqrt();
        (info, rho)
    }

    /// The pose minimising the cost; `previous` anchors unconstrained directions.
    /// `None` when the translation block is not positive definite (e.g. tilt
    /// corrections larger than the information: the caller then solves without
    /// them), the rotation is undetermined or the result is not finite.
    pub fn solve(&self, previous: &Pose2) -> Option<Pose2> {
        let (h, g) = (&self.h, &self.g);
        let ridge = 1e-9 * (h[0][0] + h[1][1]) + f64::MIN_POSITIVE;
        // A (translation block, ridged), B (translation × rotation), C (rotation block).
        let a = [[h[0][0] + ridge, h[0][1]], [h[0][1], h[1][1] + ridge]];
        let b = [[h[0][2], h[0][3]], [h[1][2], h[1][3]]];
        let c = [[h[2][2], h[2][3]], [h[2][3], h[3][3]]];
        let gt = [g[0] + ridge * previous.x, g[1] + ridge * previous.y];
        let gr = [g[2], g[3]];

        // A must be positive definite (a negative definite one has det > 0 too).
        let det = a[0][0] * a[1][1] - a[0][1] * a[0][1];
        if det.is_nan() || det <= 0.0 || a[0][0] <= 0.0 {
            return None;
        }
        let ai = [
            [a[1][1] / det, -a[0][1] / det],
            [-a[0][1] / det, a[0][0] / det],
        ];
        // A⁻¹B and A⁻¹g_t.
        let aib = mul2(&ai, &b);
        let aig = [
            ai[0][0] * gt[0] + ai[0][1] * gt[1],
            ai[1][0] * gt[0] + ai[1][1] * gt[1],
        ];
        // S = C − Bᵀ A⁻¹ B, h = g_r − Bᵀ A⁻¹ g_t.
        let mut s = [[0.0; 2]; 2];
        let mut hv = [0.0; 2];
        for r in 0..2 {
            for col in 0..2 {
                s[r][col] = c[r][col] - (b[0][r] * aib[0][col] + b[1][r] * aib[1][col]);
            }
            hv[r] = gr[r] - (b[0][r] * aig[0] + b[1][r] * aig[1]);
        }
        let s01 = 0.5 * (s[0][1] + s[1][0]);
        let rot = unit_circle_minimiser(s[0][0], s01, s[1][1], hv, previous.theta)?;
        let t = [
            aig[0] - (aib[0][0] * rot[0] + aib[0][1] * rot[1]),
            aig[1] - (aib[1][0] * rot[0] + aib[1][1] * rot[1]),
        ];
        let pose = Pose2::new(t[0], t[1], rot[1].atan2(rot[0]));
        pose.is_finite().then_some(pose)
    }
}

fn mul2(a: &[[f64; 2]; 2], b: &[[f64; 2]; 2]) -> [[f64; 2]; 2] {
    [
        [
            a[0][0] * b[0][0] + a[0][1] * b[1][0],
            a[0][0] * b[0][1] + a[0][1] * b[1][1],
        ],
        [
            a[1][0] * b[0][0] + a[1][1] * b[1][0],
            a[1][0] * b[0][1] + a[1][1] * b[1][1],
        ],
    ]
}

/// Global minimiser `r` of `rᵀSr − 2hᵀr` subject to `|r| = 1`, with
/// `S = [[s00, s01], [s01, s11]]`. `previous_theta` breaks the tie in the degenerate
/// "hard case" (two symmetric minima).
fn unit_circle_minimiser(
    s00: f64,
    s01: f64,
    s11: f64,
    h: [f64; 2],
    previous_theta: f64,
) -> Option<[f64; 2]> {
    // Eigen-decomposition of S: λ1 ≤ λ2, unit eigenvectors v1 ⟂ v2.
    let half_trace = 0.5 * (s00 + s11);
    let radius = (0.5 * (s00 - s11)).hypot(s01);
    let (l1, l2) = (half_trace - radius, half_trace + radius);
    let phi = 0.5 * (2.0 * s01).atan2(s00 - s11); // direction of the larger eigenvalue
    let (sp, cp) = phi.sin_cos();
    let v2 = [cp, sp];
    let v1 = [-sp, cp];
    let h1 = v1[0] * h[0] + v1[1] * h[1];
    let h2 = v2[0] * h[0] + v2[1] * h[1];
    let d = l2 - l1;
    let hn = h1.hypot(h2);
    if !(hn.is_finite() && d.is_finite()) {
        return None;
    }
    // r(μ) = v1·h1/μ + v2·h2/(μ+d) with μ = λ1 − λ > 0; |r(μ)| decreases in μ and the
    // root of |r(μ)| = 1 lies in [|h1|, |h|].
    let norm = |mu: f64| (h1 / mu).hypot(h2 / (mu + d));
    let tiny = 1e-14 * (hn + l2.abs()) + f64::MIN_POSITIVE;
    let (mut lo, mut hi) = (h1.abs(), hn);
    if lo <= tiny && norm(tiny) <= 1.0 {
        // Hard case: h has no component along v1; |r| = 1 needs the v1 component
        // sqrt(1 − (h2/d)²), of either sign; take the one nearer the previous rotation.
        if d <= tiny {
            return None; // S ∝ I and h = 0: the rotation is not determined at all.
        }
        let c2 = h2 / d;
        let c1 = (1.0 - c2 * c2).max(0.0).sqrt();
        let prev = [previous_theta.cos(), previous_theta.sin()];
        let cand = |sign: f64| {
            [
                sign * c1 * v1[0] + c2 * v2[0],
                sign * c1 * v1[1] + c2 * v2[1],
            ]
        };
        let (a, b) = (cand(1.0), cand(-1.0));
        let closer = if a[0] * prev[0] + a[1] * prev[1] >= b[0] * prev[0] + b[1] * prev[1] {
            a
        } else {
            b
        };
        return Some(closer);
    }
    lo = lo.max(tiny);
    // Newton on ψ(μ) = 1/|r(μ)| − 1 (nearly linear in μ), kept inside [lo, hi].
    let mut mu = 0.5 * (lo + hi);
    for _ in 0..100 {
        let a = h1 / mu;
        let b = h2 / (mu + d);
        let nr2 = a * a + b * b;
        let nr = nr2.sqrt();
        let psi = 1.0 / nr - 1.0;
        if psi > 0.0 {
            hi = mu; // |r| < 1: μ too large
        } else {
            lo = mu;
        }
        // d|r|²/dμ = −2(a²/μ + b²/(μ+d)); dψ/dμ = −½ |r|⁻³ d|r|²/dμ.
        let dnr2 = -2.0 * (a * a / mu + b * b / (mu + d));
        let dpsi = -0.5 * dnr2 / (nr2 * nr);
        let mut next = mu - psi / dpsi;
        if !(next > lo && next < hi) {
            next = 0.5 * (lo + hi);
        }
        if (next - mu).abs() <= 4.0 * f64::EPSILON * mu || hi - lo <= 4.0 * f64::EPSILON * hi {
            mu = next;
            break;
        }
        mu = next;
    }
    let a = h1 / mu;
    let b = h2 / (mu + d);
    let r = [a * v1[0] + b * v2[0], a * v1[1] + b * v2[1]];
    let nr = r[0].hypot(r[1]);
    (nr.is_finite() && nr > 0.0).then(|| [r[0] / nr, r[1] / nr])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Lines through a few points with random-looking normals; the exact pose must be
    /// recovered from one solve whatever the rotation.
    #[test]
    fn exact_for_consistent_correspondences() {
        for &truth in &[
            Pose2::new(0.3, -0.2, 0.0),
            Pose2::new(-0.05, 0.04, 0.17),
            Pose2::new(1.0, 2.0, 2.5),
            Pose2::new(0.0, 0.0, -3.0),
        ] {
            let mut ne = NormalEquations::new();
            for i in 0..30 {
                let q = [(i as f64 * 0.37).sin() * 2.0, (i as f64 * 0.91).cos() * 1.5];
                let p = truth.transform_point(q);
                let a = i as f64 * 1.3;
                let n = [a.cos(), a.sin()];
                ne.add(q, n, n[0] * p[0] + n[1] * p[1], 1.0 + 0.1 * i as f64);
            }
            let got = ne.solve(&Pose2::IDENTITY).expect("solvable");
            assert!((got.x - truth.x).abs() < 1e-8, "{got} vs {truth}");
            assert!((got.y - truth.y).abs() < 1e-8, "{got} vs {truth}");
            assert!(odocal_geom::wrap_angle(got.theta - truth.theta).abs() < 1e-9);
        }
    }

    /// Tilt corrections larger than the information itself make the translation
    /// block negative definite (its determinant is positive): no solution, rather
    /// than a maximum passed off as the minimum.
    #[test]
    fn overcorrected_equations_are_refused() {
        let truth = Pose2::new(0.05, -0.02, 0.1);
        let mut plain = NormalEquations::new();
        let mut corrected = NormalEquations::new();
        for i in 0..30 {
            let q = [(i as f64 * 0.37).sin() * 2.0, (i as f64 * 0.91).cos() * 1.5];
            let p = truth.transform_point(q);
            let a = i as f64 * 1.3;
            let n = [a.cos(), a.sin()];
            let offset = n[0] * p[0] + n[1] * p[1];
            plain.add(q, n, offset, 1.0);
            corrected.add_corrected(q, n, offset, 1.0, 0.3, 5.0);
        }
        assert!(corrected.solve(&Pose2::IDENTITY).is_none());
        let got = plain.solve(&Pose2::IDENTITY).expect("plain");
        assert!(
            (got.x - truth.x).abs() < 1e-9 && (got.y - truth.y).abs() < 1e-9,
            "{got}"
        );
        assert!((got.theta - truth.theta).abs() < 1e-9, "{got}");
    }

    #[test]
    fn unconstrained_translation_stays_at_previous() {
        // All normals along y: x is free and must stay at the previous estimate.
        let truth = Pose2::new(0.0, 0.1, 0.02);
        let previous = Pose2::new(0.25, 0.0, 0.0);
        let mut ne = NormalEquations::new();
        for i in 0..40 {
            let x = -2.0 + 0.1 * i as f64;
            for &wall in &[1.0, -1.0] {
                let p = [x, wall];
                let q = truth.inverse().transform_point(p);
                ne.add(q, [0.0, 1.0], wall, 1.0);
            }
        }
        let got = ne.solve(&previous).expect("solvable");
        assert!((got.y - truth.y).abs() < 1e-9 + 0.25 * 0.02, "{got}");
        assert!((got.theta - truth.theta).abs() < 1e-9, "{got}");
        assert!((got.x - previous.x).abs() < 1e-3, "{got}");
    }
}
