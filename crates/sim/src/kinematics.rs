//! Differential-drive kinematics: robot parameters, wheel ↔ body velocities and the
//! exact displacement of a constant-velocity motion (a circular arc).
//!
//! Conventions (as in `docs/method.md`): `v = (r_L ω_L + r_R ω_R)/2`,
//! `ω = (r_R ω_R − r_L ω_L)/b`, positive wheel speed drives the robot forward, the
//! robot frame has x forward and y to the left.

use crate::error::SimError;
use odocal_geom::{one_minus_cos_over_x, sin_over_x, FlatParams, Pose2};
use serde::{Deserialize, Serialize};

/// The six calibration parameters of a differential-drive robot with a laser.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RobotParams {
    /// Left wheel radius (m).
    pub r_l: f64,
    /// Right wheel radius (m).
    pub r_r: f64,
    /// Distance between the wheels' contact points (m).
    pub b: f64,
    /// Pose of the laser in the robot frame (m, m, rad).
    pub laser: Pose2,
}

impl From<RobotParams> for FlatParams {
    fn from(p: RobotParams) -> Self {
        FlatParams::new(p.r_l, p.r_r, p.b, &p.laser)
    }
}

impl From<FlatParams> for RobotParams {
    /// ℓθ is wrapped.
    fn from(p: FlatParams) -> Self {
        RobotParams {
            r_l: p.r_l,
            r_r: p.r_r,
            b: p.b,
            laser: p.laser(),
        }
    }
}

impl RobotParams {
    /// A Khepera III as calibrated by the original package on its `lstraight` log
    /// (rounded): b = 0.0890 m, r_L = 0.02088 m, r_R = 0.02095 m, laser at
    /// (−0.0058 m, 0.0002 m, 0.0095 rad).
    pub fn khepera_iii() -> Self {
        RobotParams {
            r_l: 0.02088,
            r_r: 0.02095,
            b: 0.0890,
            laser: Pose2::new(-0.0058, 0.0002, 0.0095),
        }
    }

    /// The Khepera III's nominal (data-sheet-like) parameters, as a firmware would use
    /// them for its own odometry: equal radii 0.021 m, b = 0.0884 m, laser at the origin.
    pub fn khepera_iii_nominal() -> Self {
        RobotParams {
            r_l: 0.021,
            r_r: 0.021,
            b: 0.0884,
            laser: Pose2::IDENTITY,
        }
    }

    /// Body velocities `(v, ω)` (m/s, rad/s) from wheel speeds `[ω_L, ω_R]` (rad/s).
    pub fn body_velocity(&self, wheel_speeds: [f64; 2]) -> (f64, f64) {
        let sl = self.r_l * wheel_speeds[0];
        let sr = self.r_r * wheel_speeds[1];
        (0.5 * (sl + sr), (sr - sl) / self.b)
    }

    /// Wheel speeds `[ω_L, ω_R]` (rad/s) that produce body velocities `(v, ω)`.
    pub fn wheel_speeds(&self, v: f64, omega: f64) -> [f64; 2] {
        let half = 0.5 * self.b * omega;
        [(v - half) / self.r_l, (v + half) / self.r_r]
    }

    /// Checks that the radii and wheel distance are positive and finite and the laser
    /// pose finite.
    pub fn validate(&self) -> Result<(), SimError> {
        for (field, value) in [("r_l", self.r_l), ("r_r", self.r_r), ("b", self.b)] {
            if !(value.is_finite() && value > 0.0) {
                return Err(SimError::InvalidConfig {
                    field,
                    value: value.to_string(),
                    expected: "a positive length in metres",
                });
            }
        }
        if !self.laser.is_finite() {
            return Err(SimError::InvalidConfig {
                field: "laser",
                value: self.laser.to_string(),
                expected: "a finite pose",
            });
        }
        Ok(())
    }
}

/// The exact displacement, in the robot's starting frame, of a motion at constant
/// forward speed `v` (m/s) and turn rate `omega` (rad/s) during `dt` seconds: an arc
/// of a circle (a straight segment when `omega` is 0).
pub fn arc_motion(v: f64, omega: f64, dt: f64) -> Pose2 {
    let dtheta = omega * dt;
    let dist = v * dt;
    Pose2::new(
        dist * sin_over_x(dtheta),
        dist * one_minus_cos_over_x(dtheta),
        dtheta,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wheel_and_body_velocities_are_inverse() {
        let p = RobotParams::khepera_iii();
        let w = p.wheel_speeds(0.07, -0.6);
        let (v, om) = p.body_velocity(w);
        assert!((v - 0.07).abs() < 1e-15 && (om + 0.6).abs() < 1e-14);
        // Pure spin: the wheels turn in opposite directions.
        let w = p.wheel_speeds(0.0, 1.0);
        assert!(w[0] < 0.0 && w[1] > 0.0);
        assert!(p.body_velocity(w).0.abs() < 1e-16);
    }

    #[test]
    fn arc_is_on_the_circle() {
        // Quarter circle of radius 0.5 turning left: ends at (0.5, 0.5), heading π/2.
        let r = 0.5;
        let omega = 0.8;
        let t = std::f64::consts::FRAC_PI_2 / omega;
        let d = arc_motion(r * omega, omega, t);
        assert!((d.x - 0.5).abs() < 1e-14 && (d.y - 0.5).abs() < 1e-14);
        assert!((d.theta - std::f64::consts::FRAC_PI_2).abs() < 1e-14);
        // Straight and reverse.
        let s = arc_motion(-0.1, 0.0, 2.0);
        assert_eq!(s, Pose2::new(-0.2, 0.0, 0.0));
        // Two half-arcs compose into the whole arc.
        let half = arc_motion(0.1, 0.9, 0.7);
        let whole = arc_motion(0.1, 0.9, 1.4);
        let c = half.compose(&half);
        assert!((c.x - whole.x).abs() < 1e-15 && (c.y - whole.y).abs() < 1e-15);
    }

    #[test]
    fn validation_rejects_nonsense() {
        let mut p = RobotParams::khepera_iii();
        assert!(p.validate().is_ok());
        p.b = 0.0;
        assert!(p.validate().is_err());
        p = RobotParams::khepera_iii();
        p.r_l = f64::NAN;
        assert!(p.validate().is_err());
    }
}
