//! A sample (the papers' "measurement tuple"): the wheel rotations over one scan
//! interval and the sensor displacement scan matching estimated over it.

use crate::error::SolveError;
use odocal_geom::Pose2;
use serde::{Deserialize, Serialize};

/// One piece of an interval during which both wheels turned at constant speed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ProfileSegment {
    /// Length of the piece (s).
    pub duration: f64,
    /// Left wheel rotation over the piece (rad).
    pub dphi_l: f64,
    /// Right wheel rotation over the piece (rad).
    pub dphi_r: f64,
}

/// One sample: interval, wheel rotations, and scan-matching displacement `ŝ`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Sample {
    /// Length of the interval (s).
    pub t: f64,
    /// Left wheel rotation over the interval (rad).
    pub dphi_l: f64,
    /// Right wheel rotation over the interval (rad).
    pub dphi_r: f64,
    /// Sensor displacement `ŝ` estimated by scan matching (m, m, rad).
    pub sm: Pose2,
    /// Covariance of `ŝ` (order x, y, θ), when scan matching provides it.
    pub sm_cov: Option<[[f64; 3]; 3]>,
    /// Wheel rotations piece by piece inside the interval, when the speeds were not
    /// constant. Its rotations must add up to `dphi_l`, `dphi_r`.
    pub profile: Option<Vec<ProfileSegment>>,
    /// Timestamps of the interval's two scans (s, any clock), when known. Samples
    /// that share a scan (one ends where the next starts) share that scan's
    /// matching error and its encoder reading: with these times the covariance of
    /// the estimate accounts for it (see [`crate::calibrate`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scan_times: Option<[f64; 2]>,
    /// Standard deviation (s) of the error in the times the encoder readings at the
    /// two scans were taken, when the counts were read at jittery times (what is
    /// left after smoothing them). Each scan's wheel angles then carry an error
    /// `φ̇·δ` shared by the two samples that use the scan, which the covariance of
    /// the estimate accounts for (needs `scan_times`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub read_time_sigma: Option<f64>,
    /// A motion `(x, y, θ)` along which `ŝ` says nothing (a match along a corridor,
    /// whose scans fix the displacement across it and the rotation only), when there
    /// is one. The residual's component along it gets no weight: the weights are the
    /// limit of a covariance infinitely wide along it, whatever the noise model.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub free_direction: Option<[f64; 3]>,
    /// The scan matcher's covariance of `ŝ` when it is not the noise the samples
    /// are weighted by (`sm_cov` absent): only its shape and its size relative to
    /// the other samples' count. The residuals give the noise's level; each sample
    /// is weighted by that level shaped as the matcher's covariance of it says
    /// (see [`crate::calibrate`]). `None`: the residuals' level alone.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub matcher_cov: Option<[[f64; 3]; 3]>,
}

/// `e` without its component along `free` (orthogonal projection in `(x, y, θ)`;
/// see [`Sample::measured_part`]).
pub(crate) fn measured_part(e: [f64; 3], free: Option<[f64; 3]>) -> [f64; 3] {
    let Some(d) = free else { return e };
    let dd: f64 = d.iter().map(|v| v * v).sum();
    if dd.is_nan() || dd <= 0.0 {
        return e;
    }
    let along = (0..3).map(|c| d[c] * e[c]).sum::<f64>() / dd;
    std::array::from_fn(|c| e[c] - along * d[c])
}

/// Relative tolerance for a profile's rotations to add up to the sample's totals.
const PROFILE_SUM_TOLERANCE: f64 = 1e-6;

impl Sample {
    /// A sample from the interval length and the wheel rotations over it.
    pub fn from_rotations(t: f64, dphi_l: f64, dphi_r: f64, sm: Pose2) -> Self {
        Sample {
            t,
            dphi_l,
            dphi_r,
            sm,
            sm_cov: None,
            profile: None,
            scan_times: None,
            read_time_sigma: None,
            free_direction: None,
            matcher_cov: None,
        }
    }

    /// A sample from the interval length and the average wheel speeds (rad/s), as in
    /// the original package's tuple files (`T`, `phi_l`, `phi_r`, `sm`).
    pub fn from_speeds(t: f64, phi_l: f64, phi_r: f64, sm: Pose2) -> Self {
        Sample::from_rotations(t, phi_l * t, phi_r * t, sm)
    }

    /// A sample whose interval and totals are those of a piecewise-constant profile.
    pub fn from_profile(profile: Vec<ProfileSegment>, sm: Pose2) -> Self {
        let t = profile.iter().map(|p| p.duration).sum();
        let dphi_l = profile.iter().map(|p| p.dphi_l).sum();
        let dphi_r = profile.iter().map(|p| p.dphi_r).sum();
        Sample {
            t,
            dphi_l,
            dphi_r,
            sm,
            sm_cov: None,
            profile: Some(profile),
            scan_times: None,
            read_time_sigma: None,
            free_direction: None,
            matcher_cov: None,
        }
    }

    /// The same sample with the covariance of `ŝ` attached.
    pub fn with_covariance(mut self, cov: [[f64; 3]; 3]) -> Self {
        self.sm_cov = Some(cov);
        self
    }

    /// The same sample with the timestamps of its two scans attached.
    pub fn with_scan_times(mut self, t0: f64, t1: f64) -> Self {
        self.scan_times = Some([t0, t1]);
        self
    }

    /// The same sample with a direction `ŝ` does not determine (see
    /// [`Sample::free_direction`]).
    pub fn with_free_direction(mut self, motion: [f64; 3]) -> Self {
        self.free_direction = Some(motion);
        self
    }

    /// The same sample with a wheel-speed profile attached (totals unchanged).
    pub fn with_profile(mut self, profile: Vec<ProfileSegment>) -> Self {
        self.profile = Some(profile);
        self
    }

    /// `e` (a residual `ŝ_pred − ŝ` of this sample, or any error of its ŝ) without
    /// its component along [`Sample::free_direction`] (orthogonal projection in
    /// `(x, y, θ)`): the part ŝ measured. `e` itself for a sample that fixes every
    /// direction.
    pub fn measured_part(&self, e: [f64; 3]) -> [f64; 3] {
        measured_part(e, self.free_direction)
    }

    /// Average left wheel speed over the interval (rad/s).
    pub fn phi_l(&self) -> f64 {
        self.dphi_l / self.t
    }

    /// Average right wheel speed over the interval (rad/s).
    pub fn phi_r(&self) -> f64 {
        self.dphi_r / self.t
    }

    /// Checks that every field is finite and consistent; `index` names the sample in
    /// the error.
    pub fn check(&self, index: usize) -> Result<(), SolveError> {
        let non_finite = |field: &str, value: f64| SolveError::NonFinite {
            index,
            field: field.to_string(),
            value,
        };
        let scalars = [
            ("T", self.t),
            ("dphi_l", self.dphi_l),
            ("dphi_r", self.dphi_r),
            ("sm.x", self.sm.x),
            ("sm.y", self.sm.y),
            ("sm.theta", self.sm.theta),
        ];
        for (field, value) in scalars {
            if !value.is_finite() {
                return Err(non_finite(field, value));
            }
        }
        if self.t <= 0.0 {
            return Err(SolveError::InvalidSample {
                index,
                reason: format!("the interval T must be positive, found {} s", self.t),
            });
        }
        if let Some(cov) = &self.sm_cov {
            for (i, row) in cov.iter().enumerate() {
                for (j, &v) in row.iter().enumerate() {
                    if !v.is_finite() {
                        return Err(non_finite(&format!("sm_cov[{i}][{j}]"), v));
                    }
                }
            }
            if crate::linalg::information_from_covariance(cov).is_none() {
                return Err(SolveError::InvalidSample {
                    index,
                    reason: "sm_cov must be a symmetric positive definite 3×3 matrix".into(),
                });
            }
        }
        if let Some(motion) = &self.free_direction {
            for (k, &v) in motion.iter().enumerate() {
                if !v.is_finite() {
                    return Err(non_finite(&format!("free_direction[{k}]"), v));
                }
            }
            if motion.iter().all(|&v| v == 0.0) {
                return Err(SolveError::InvalidSample {
                    index,
                    reason: "free_direction must not be zero".into(),
                });
            }
        }
        if let Some(profile) = &self.profile {
            let (mut sum_l, mut sum_r) = (0.0, 0.0);
            for (k, p) in profile.iter().enumerate() {
                for (field, value) in [
                    ("duration", p.duration),
                    ("dphi_l", p.dphi_l),
                    ("dphi_r", p.dphi_r),
                ] {
                    if !value.is_finite() {
                        return Err(non_finite(&format!("profile[{k}].{field}"), value));
                    }
                }
                if p.duration < 0.0 {
                    return Err(SolveError::InvalidSample {
                        index,
                        reason: format!(
                            "profile piece {k} has a negative duration ({} s)",
                            p.duration
                        ),
                    });
                }
                sum_l += p.dphi_l;
                sum_r += p.dphi_r;
            }
            let close = |a: f64, b: f64| {
                (a - b).abs() <= PROFILE_SUM_TOLERANCE * a.abs().max(b.abs()).max(1e-3)
            };
            if !close(sum_l, self.dphi_l) || !close(sum_r, self.dphi_r) {
                return Err(SolveError::InvalidSample {
                    index,
                    reason: format!(
                        "the profile's wheel rotations add up to ({sum_l}, {sum_r}) rad but the \
                         sample's totals are ({}, {}) rad",
                        self.dphi_l, self.dphi_r
                    ),
                });
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn speeds_and_rotations_agree() {
        let s = Sample::from_speeds(0.5, 2.0, -4.0, Pose2::IDENTITY);
        assert_eq!((s.dphi_l, s.dphi_r), (1.0, -2.0));
        assert_eq!((s.phi_l(), s.phi_r()), (2.0, -4.0));
    }

    #[test]
    fn check_names_the_bad_field() {
        let s = Sample::from_speeds(0.5, 2.0, 1.0, Pose2::new(0.0, f64::NAN, 0.0));
        match s.check(7) {
            Err(SolveError::NonFinite { index, field, .. }) => {
                assert_eq!(index, 7);
                assert_eq!(field, "sm.y");
            }
            other => panic!("unexpected {other:?}"),
        }
        let s = Sample::from_speeds(0.0, 2.0, 1.0, Pose2::IDENTITY);
        assert!(matches!(s.check(0), Err(SolveError::InvalidSample { .. })));
        let bad_cov = [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]];
        let s = Sample::from_speeds(1.0, 2.0, 1.0, Pose2::IDENTITY).with_covariance(bad_cov);
        assert!(matches!(s.check(0), Err(SolveError::InvalidSample { .. })));
    }

    #[test]
    fn profile_must_match_totals() {
        let seg = |l, r| ProfileSegment {
            duration: 0.1,
            dphi_l: l,
            dphi_r: r,
        };
        let s = Sample::from_profile(vec![seg(0.1, 0.2), seg(0.3, 0.1)], Pose2::IDENTITY);
        assert!(s.check(0).is_ok());
        assert!((s.t - 0.2).abs() < 1e-15);
        let s = Sample::from_rotations(0.2, 0.4, 0.4, Pose2::IDENTITY)
            .with_profile(vec![seg(0.1, 0.2), seg(0.3, 0.1)]);
        assert!(matches!(
            s.check(3),
            Err(SolveError::InvalidSample { index: 3, .. })
        ));
    }
}
