//! Odometry-only mode with a heading that does not come from the wheels. The mode
//! recovers wheel rotations from the odometry poses with the nominal parameters; that
//! is right only when the odometry's heading was itself integrated from the wheel
//! difference with them. Many ROS robots (kobuki_node by default, TurtleBot3, iRobot
//! Create 3) publish `/odom` with the heading of a gyro instead: then the recovered
//! wheel difference is the gyro's rotation seen through the nominal parameters, and
//! the calibration returns the nominal rotation Jacobian whatever the wheels are —
//! wrong, with small σ and halves that agree.
//!
//! The physics that tells them apart: scan matching measures the robot's rotation
//! whatever the laser's pose, ŝθ = J21·Δφ_L + J22·Δφ_R. With wheel-derived odometry,
//! J21, J22 are those of the true wheels, which differ from the nominal ones by the
//! wheels' own errors (real radii and wheel distances differ from the nominal ones by
//! tenths of a percent to percents). With a gyro's heading they are the nominal ones
//! exactly (to the gyro's scale error), and a gyro bias adds a rotation that grows with
//! time rather than with wheel travel. So ŝθ is fitted on (Δφ_L, Δφ_R, Δt) and the
//! check fires when the fitted J21, J22 agree with the nominal ones within
//! [`CHI2_NOMINAL`] (χ², 2 degrees of freedom) while the log measures them to within
//! [`SIGMA_GATE`] (a wheel-derived heading is never that exactly nominal) or the
//! odometry turns with time beyond [`DRIFT_SIGMAS`] (wheels do not turn the odometry
//! while they stand); a log too imprecise to tell is not judged. An IMU topic in a bag
//! is a hint named by the command line, never the evidence: the check sees only the
//! samples. A robot whose nominal parameters are already exact
//! to that precision (say, from an earlier calibration) also fires: the message says
//! so, and `--accept-weak` keeps the result.

use crate::finding::{Finding, FindingKind};
use crate::samples::PairSample;
use odocal_solver::Params;

/// The fitted rotation Jacobian is "the nominal one" when its χ² against it (2
/// degrees of freedom) is below this: the 99.9 % quantile.
pub const CHI2_NOMINAL: f64 = 13.8;
/// The check judges on the Jacobian alone only when the relative σ of both fitted
/// terms is below this (0.2 %): then a wheel error of 1 % shows at 5σ. (Measured:
/// simulated wheel-heading odometry of TurtleBot, Khepera and Pioneer runs, 20–60 s,
/// gives χ² 166–31 000 at σ up to 0.22 %; gyro-heading odometry of the same runs
/// gives χ² 0.2–6.1; see docs/benchmarks.md.)
pub const SIGMA_GATE: f64 = 0.002;
/// A rotation per second not explained by the wheels (a gyro's bias) beyond this many
/// σ and [`MIN_DRIFT`] is evidence on its own when the Jacobian is nominal: wheels do
/// not turn the odometry while they stand.
pub const DRIFT_SIGMAS: f64 = 6.0;
/// Smallest drift (rad/s) taken as a gyro's bias.
pub const MIN_DRIFT: f64 = 1e-3;
/// Samples dropped as outliers are beyond this many robust σ of the fit.
pub const OUTLIER_SIGMAS: f64 = 5.0;
/// The residual σ (rad) is at least this: below it, residuals are numerical noise.
pub const SIGMA_FLOOR_RAD: f64 = 1e-4;
/// Fewest samples the fit is made on.
pub const MIN_SAMPLES: usize = 20;

/// How a refusal or finding for this cause starts.
pub const CAUSE: &str = "the odometry's heading appears to come from a gyro/IMU, not from \
    the wheels";

/// What to do, in words.
pub const WAY_OUT: &str = "calibrate from the wheel joint states instead \
    (--joint-states-topic /joint_states --wheel-joints LEFT,RIGHT: that mode does not use \
    the odometry), or record /odom integrated from the wheels alone (kobuki_node: \
    use_imu_heading false; not a gyro-heading driver's or an EKF's such as \
    robot_localization); if the nominal parameters are already exact (say, from an \
    earlier calibration), there is nothing to correct and --accept-weak shows the result";

/// What the fit of the odometry's rotation against scan matching found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeadingFit {
    /// J21 / J21(nominal) − 1 and J22 / J22(nominal) − 1.
    pub deviation: [f64; 2],
    /// σ of the two deviations.
    pub sigma: [f64; 2],
    /// χ² of the deviations against 0 with their covariance.
    pub chi2: f64,
    /// The rotation per second not explained by the wheels (rad/s): a gyro's bias.
    pub drift: f64,
    /// σ of `drift` (rad/s).
    pub drift_sigma: f64,
    /// Samples the fit kept.
    pub samples: usize,
}

impl HeadingFit {
    /// True when the fitted Jacobian is the nominal one and either the log measures it
    /// precisely enough, or the odometry also turns with time rather than with the
    /// wheels (a gyro's bias): the heading does not come from the wheels.
    pub fn heading_not_from_wheels(&self) -> bool {
        let precise = self.sigma.iter().all(|s| *s < SIGMA_GATE);
        let drifts = self.drift.abs() > (DRIFT_SIGMAS * self.drift_sigma).max(MIN_DRIFT);
        self.chi2 < CHI2_NOMINAL && (precise || drifts)
    }

    /// The cause in words, with the evidence and what to do, for findings and
    /// refusals; starts with [`CAUSE`].
    pub fn cause(&self) -> String {
        format!(
            "{CAUSE}: odometry-only calibration needs a heading integrated from the wheels \
             (the odometry's rotation follows the nominal wheel parameters exactly: J21, J22 \
             {:+.3} % ± {:.3} % and {:+.3} % ± {:.3} % from the nominal ones, χ² {:.1}, \
             where real wheels differ by tenths of a percent or more; rotation not \
             explained by the wheels {:+.4} ± {:.4} rad/s); {WAY_OUT}",
            100.0 * self.deviation[0],
            100.0 * self.sigma[0],
            100.0 * self.deviation[1],
            100.0 * self.sigma[1],
            self.chi2,
            self.drift,
            self.drift_sigma
        )
    }

    /// The warning finding (with `--accept-weak`: the numbers are shown, weak).
    pub fn finding(&self) -> Finding {
        Finding::warning(FindingKind::GyroHeading, self.cause())
    }
}

/// Solves the 3×3 system `a x = b`; `None` when singular.
fn solve3(a: &[[f64; 3]; 3], b: &[f64; 3]) -> Option<([f64; 3], [[f64; 3]; 3])> {
    let det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
        - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
        + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    let scale = a[0][0] * a[1][1] * a[2][2];
    if !(det.is_finite() && det.abs() > 1e-12 * scale.abs().max(f64::MIN_POSITIVE)) {
        return None;
    }
    let mut inv = [[0.0; 3]; 3];
    for (i, row) in inv.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            let (r0, r1) = ((j + 1) % 3, (j + 2) % 3);
            let (c0, c1) = ((i + 1) % 3, (i + 2) % 3);
            *v = (a[r0][c0] * a[r1][c1] - a[r0][c1] * a[r1][c0]) / det;
        }
    }
    let x = std::array::from_fn(|i| (0..3).map(|j| inv[i][j] * b[j]).sum());
    Some((x, inv))
}

/// Least squares of ŝθ on (Δφ_L, Δφ_R, Δt) over the kept rows: the coefficients and
/// (XᵀX)⁻¹.
fn fit(rows: &[([f64; 3], f64)], keep: &[bool]) -> Option<([f64; 3], [[f64; 3]; 3])> {
    let mut a = [[0.0; 3]; 3];
    let mut b = [0.0; 3];
    for ((x, y), _) in rows.iter().zip(keep).filter(|(_, k)| **k) {
        for i in 0..3 {
            b[i] += x[i] * y;
            for j in 0..3 {
                a[i][j] += x[i] * x[j];
            }
        }
    }
    solve3(&a, &b)
}

/// Fits the odometry's rotation against scan matching and compares it with the
/// nominal rotation Jacobian; `None` with too few samples or a singular fit.
pub fn fit_heading(samples: &[PairSample], nominal: &Params) -> Option<HeadingFit> {
    let rows: Vec<([f64; 3], f64)> = samples
        .iter()
        .map(|s| {
            (
                [s.wheel.dphi_l, s.wheel.dphi_r, s.wheel.dt],
                s.icp.pose.theta,
            )
        })
        .filter(|(x, y)| x.iter().all(|v| v.is_finite()) && y.is_finite())
        .collect();
    if rows.len() < MIN_SAMPLES || !(nominal.r_l > 0.0 && nominal.r_r > 0.0 && nominal.b > 0.0) {
        return None;
    }
    let mut keep = vec![true; rows.len()];
    let mut result = None;
    for _ in 0..5 {
        let (c, inv) = fit(&rows, &keep)?;
        let residuals: Vec<f64> = rows
            .iter()
            .map(|(x, y)| y - c[0] * x[0] - c[1] * x[1] - c[2] * x[2])
            .collect();
        let mut abs: Vec<f64> = residuals
            .iter()
            .zip(&keep)
            .filter(|(_, k)| **k)
            .map(|(r, _)| r.abs())
            .collect();
        let mid = abs.len() / 2;
        let robust = 1.4826 * *abs.select_nth_unstable_by(mid, f64::total_cmp).1;
        let kept = keep.iter().filter(|k| **k).count();
        let ss: f64 = residuals
            .iter()
            .zip(&keep)
            .filter(|(_, k)| **k)
            .map(|(r, _)| r * r)
            .sum();
        let var = (ss / (kept as f64 - 3.0)).max(SIGMA_FLOOR_RAD * SIGMA_FLOOR_RAD);
        result = Some((c, inv, var, kept));
        let limit = OUTLIER_SIGMAS * robust.max(SIGMA_FLOOR_RAD);
        let next: Vec<bool> = residuals.iter().map(|r| r.abs() <= limit).collect();
        if next == keep || next.iter().filter(|k| **k).count() < MIN_SAMPLES {
            break;
        }
        keep = next;
    }
    let (c, inv, var, kept) = result?;
    let nominal_j = [-nominal.r_l / nominal.b, nominal.r_r / nominal.b];
    let deviation = [c[0] / nominal_j[0] - 1.0, c[1] / nominal_j[1] - 1.0];
    // Covariance of the deviations: that of (J21, J22) divided by the nominal terms.
    let cov = [
        [
            var * inv[0][0] / (nominal_j[0] * nominal_j[0]),
            var * inv[0][1] / (nominal_j[0] * nominal_j[1]),
        ],
        [
            var * inv[1][0] / (nominal_j[1] * nominal_j[0]),
            var * inv[1][1] / (nominal_j[1] * nominal_j[1]),
        ],
    ];
    let det = cov[0][0] * cov[1][1] - cov[0][1] * cov[1][0];
    if !(det.is_finite() && det > 0.0) {
        return None;
    }
    let chi2 = (cov[1][1] * deviation[0] * deviation[0]
        - 2.0 * cov[0][1] * deviation[0] * deviation[1]
        + cov[0][0] * deviation[1] * deviation[1])
        / det;
    Some(HeadingFit {
        deviation,
        sigma: [cov[0][0].sqrt(), cov[1][1].sqrt()],
        chi2,
        drift: c[2],
        drift_sigma: (var * inv[2][2]).sqrt(),
        samples: kept,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::matching::MatchStats;
    use crate::sync::{ScanPair, WheelMotion};
    use odocal_geom::Pose2;

    /// True wheels 0.0331 / 0.0329 m, b 0.1614 m (a TurtleBot's); nominal 0.033, 0.033,
    /// 0.16.
    const TRUE: [f64; 3] = [0.0331, 0.0329, 0.1614];

    fn nominal() -> Params {
        Params::from_vector([0.033, 0.033, 0.16, 0.0, 0.0, 0.0])
    }

    /// A deterministic uniform number in [-1, 1) per (k, stream).
    fn noise(k: usize, stream: u64) -> f64 {
        let mut x = (k as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ stream;
        x ^= x >> 31;
        x = x.wrapping_mul(0xBF58_476D_1CE4_E5B9);
        x ^= x >> 29;
        (x >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }

    /// `n` pairs of 0.3–0.5 s: straights, arcs, spins both ways and stops, with scan
    /// matching's rotation noise of `sigma` rad (uniform of that σ). With
    /// `gyro_bias = Some(β)`, the odometry's heading is a gyro's (the true rotation plus
    /// β·dt) and its position the wheels' travel with the nominal radii: the wheel
    /// rotations odometry-only mode recovers carry the gyro's rotation.
    fn samples(n: usize, sigma: f64, gyro_bias: Option<f64>) -> Vec<PairSample> {
        let p = nominal();
        (0..n)
            .map(|k| {
                let dt = 0.4 + 0.1 * noise(k, 1);
                let (l, r) = match k % 6 {
                    0 | 1 => (2.4, 2.4 + 0.05 * noise(k, 2)),
                    2 => (1.6, 2.6),
                    3 => (-1.5, 1.5),
                    4 => (1.4, -1.4),
                    _ => (0.0, 0.0),
                };
                let (l, r) = (l * dt / 0.4, r * dt / 0.4);
                let turn = (TRUE[1] * r - TRUE[0] * l) / TRUE[2];
                let (dphi_l, dphi_r) = match gyro_bias {
                    None => (l, r),
                    Some(bias) => {
                        let sum = l + r;
                        let diff = p.b * (turn + bias * dt) / p.r_l;
                        ((sum - diff) / 2.0, (sum + diff) / 2.0)
                    }
                };
                let t0 = k as f64 * 0.5;
                PairSample {
                    pair: ScanPair {
                        first: k,
                        second: k + 1,
                        t0,
                        t1: t0 + dt,
                    },
                    wheel: WheelMotion {
                        t0,
                        dt,
                        dphi_l,
                        dphi_r,
                        profile: Vec::new(),
                    },
                    icp: MatchStats {
                        pose: Pose2 {
                            x: 0.0,
                            y: 0.0,
                            theta: turn + sigma * 3f64.sqrt() * noise(k, 3),
                        },
                        covariance: [[0.0; 3]; 3],
                        iterations: 1,
                        correspondences: 100,
                        mean_residual: 0.0,
                        links: 1,
                        neighbours: 0,
                        free_direction: None,
                    },
                }
            })
            .collect()
    }

    #[test]
    fn wheel_derived_heading_shows_the_wheels_errors_and_is_not_flagged() {
        let fit = fit_heading(&samples(150, 8e-4, None), &nominal()).unwrap();
        // J21 = −r_L/b and J22 = r_R/b of the true wheels against the nominal ones.
        let expected = [
            TRUE[0] / TRUE[2] / (0.033 / 0.16) - 1.0,
            TRUE[1] / TRUE[2] / (0.033 / 0.16) - 1.0,
        ];
        for ((d, e), s) in fit.deviation.iter().zip(expected).zip(fit.sigma) {
            assert!((d - e).abs() < 4.0 * s, "{fit:?}");
        }
        assert!(fit.chi2 > 100.0, "{fit:?}");
        assert!(fit.drift.abs() < 4.0 * fit.drift_sigma, "{fit:?}");
        assert!(!fit.heading_not_from_wheels(), "{fit:?}");
    }

    #[test]
    fn gyro_heading_is_flagged_with_or_without_a_bias() {
        for bias in [0.0, 0.005, -0.002] {
            let fit = fit_heading(&samples(150, 8e-4, Some(bias)), &nominal()).unwrap();
            assert!(fit.chi2 < CHI2_NOMINAL, "bias {bias}: {fit:?}");
            assert!(fit.sigma.iter().all(|s| *s < SIGMA_GATE), "{fit:?}");
            assert!(fit.heading_not_from_wheels(), "bias {bias}: {fit:?}");
            // The bias is the rotation the wheels do not explain, with the sign that
            // scan matching sees it: the odometry turned by it, the scans did not.
            assert!((fit.drift + bias).abs() < 4.0 * fit.drift_sigma, "{fit:?}");
            assert!(fit.cause().starts_with(CAUSE));
        }
    }

    #[test]
    fn a_log_too_noisy_to_tell_is_not_judged() {
        // 30 pairs with 10 mrad of matching noise: σ of the Jacobian terms above the gate,
        // and no bias to show.
        let fit = fit_heading(&samples(30, 1e-2, Some(0.0)), &nominal()).unwrap();
        assert!(fit.sigma.iter().any(|s| *s >= SIGMA_GATE), "{fit:?}");
        assert!(!fit.heading_not_from_wheels(), "{fit:?}");
        assert!(fit_heading(&samples(MIN_SAMPLES - 1, 8e-4, None), &nominal()).is_none());
    }

    #[test]
    fn the_three_by_three_solve_inverts() {
        let a = [[4.0, 1.0, 0.5], [1.0, 3.0, 0.2], [0.5, 0.2, 2.0]];
        let (x, inv) = solve3(&a, &[1.0, 2.0, 3.0]).unwrap();
        for (i, (row, b)) in a.iter().zip([1.0, 2.0, 3.0]).enumerate() {
            let back: f64 = row.iter().zip(x).map(|(r, x)| r * x).sum();
            assert!((back - b).abs() < 1e-12);
            for j in 0..3 {
                let e: f64 = row.iter().zip(&inv).map(|(r, m)| r * m[j]).sum();
                assert!((e - f64::from(u8::from(i == j))).abs() < 1e-12);
            }
        }
        assert!(solve3(
            &[[1.0, 2.0, 3.0], [2.0, 4.0, 6.0], [0.0, 0.0, 1.0]],
            &[0.0; 3]
        )
        .is_none());
    }
}
