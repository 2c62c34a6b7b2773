//! Wheel angles in radians as encoder ticks, and wheel rotations recovered from
//! integrated odometry poses: how inputs without encoder counters (ROS joint states,
//! ROS odometry, Carmen `ODOM` lines) enter the same calibration as `ENCODER` lines.
//!
//! Convention: an angle of `a` radians is `round(a / 2π · 2^20)` ticks, so one tick is
//! 6 µrad — far below any encoder's resolution, and exact enough that the calibrated
//! radii are the same as from the angles themselves.

use crate::model::{EncoderRecord, OdomRecord};
use std::f64::consts::TAU;

/// Ticks per wheel revolution used for wheel angles given in radians: 2^20.
pub const WHEEL_TICKS_PER_REVOLUTION: f64 = 1_048_576.0;

/// A wheel angle (rad) as ticks; `None` when not finite or beyond ±2^62 ticks.
pub fn ticks_of_angle(angle: f64) -> Option<i64> {
    let t = (angle / TAU * WHEEL_TICKS_PER_REVOLUTION).round();
    (t.is_finite() && t.abs() < 4.6e18).then_some(t as i64)
}

/// The nominal wheel radii and wheel distance a robot integrated its odometry with.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NominalWheels {
    /// Left wheel radius (m).
    pub r_l: f64,
    /// Right wheel radius (m).
    pub r_r: f64,
    /// Distance between the wheels (m).
    pub b: f64,
}

/// The wheel rotations (rad, left and right) that move a differential-drive robot with
/// `nominal` parameters from `from` to `to`: the pose increment in the robot frame is an
/// arc of length `s` turning by `Δθ` (its chord is `s · sin(Δθ/2)/(Δθ/2)`, backwards when
/// the increment points backwards), and `φ_L = (s − bΔθ/2)/r_L`, `φ_R = (s + bΔθ/2)/r_R`.
/// Exact for odometry integrated along arcs; for Euler or midpoint integration the
/// error is of order Δθ²/24 of `s` per interval.
pub fn wheel_rotations(
    from: &odocal_geom::Pose2,
    to: &odocal_geom::Pose2,
    nominal: NominalWheels,
) -> (f64, f64) {
    let (dx_w, dy_w) = (to.x - from.x, to.y - from.y);
    let (s0, c0) = from.theta.sin_cos();
    let dx = c0 * dx_w + s0 * dy_w;
    let dy = -s0 * dx_w + c0 * dy_w;
    let dtheta =
        (to.theta - from.theta + std::f64::consts::PI).rem_euclid(TAU) - std::f64::consts::PI;
    let chord = dx.hypot(dy);
    let half = dtheta / 2.0;
    let arc_per_chord = if half.abs() < 1e-9 {
        1.0
    } else {
        half / half.sin()
    };
    let s = chord * arc_per_chord * if dx < 0.0 { -1.0 } else { 1.0 };
    let left = (s - nominal.b * half) / nominal.r_l;
    let right = (s + nominal.b * half) / nominal.r_r;
    (left, right)
}

/// Encoder records (in [`WHEEL_TICKS_PER_REVOLUTION`] ticks) recovered from odometry
/// poses integrated with `nominal`: one record per odometry record, starting at 0.
/// Returns `None` when a pose is not finite.
pub fn encoders_from_odometry(
    odom: &[OdomRecord],
    nominal: NominalWheels,
) -> Option<Vec<EncoderRecord>> {
    let mut out = Vec::with_capacity(odom.len());
    let (mut left, mut right) = (0.0, 0.0);
    for (k, o) in odom.iter().enumerate() {
        if k > 0 {
            let (l, r) = wheel_rotations(&odom[k - 1].pose, &o.pose, nominal);
            left += l;
            right += r;
        }
        out.push(EncoderRecord {
            t: o.t,
            left: ticks_of_angle(left)?,
            right: ticks_of_angle(right)?,
            line: o.line,
        });
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use odocal_geom::Pose2;

    /// Integrates wheel rotations along an arc, the inverse of `wheel_rotations`.
    fn integrate(p: Pose2, l: f64, r: f64, n: NominalWheels) -> Pose2 {
        let s = (n.r_l * l + n.r_r * r) / 2.0;
        let dth = (n.r_r * r - n.r_l * l) / n.b;
        let chord = if dth.abs() < 1e-12 {
            s
        } else {
            s * (dth / 2.0).sin() / (dth / 2.0)
        };
        let heading = p.theta + dth / 2.0;
        Pose2 {
            x: p.x + chord * heading.cos(),
            y: p.y + chord * heading.sin(),
            theta: p.theta + dth,
        }
    }

    #[test]
    fn rotations_are_recovered_exactly_from_arc_integrated_poses() {
        let n = NominalWheels {
            r_l: 0.033,
            r_r: 0.034,
            b: 0.16,
        };
        let mut p = Pose2 {
            x: 1.0,
            y: -2.0,
            theta: 3.0,
        };
        for (l, r) in [
            (0.3, 0.3),
            (0.2, 0.5),
            (-0.4, 0.4),
            (-0.3, -0.1),
            (0.0, 0.0),
        ] {
            let q = integrate(p, l, r, n);
            let (el, er) = wheel_rotations(&p, &q, n);
            assert!(
                (el - l).abs() < 1e-9 && (er - r).abs() < 1e-9,
                "{l} {r}: {el} {er}"
            );
            p = q;
        }
    }

    #[test]
    fn angles_become_ticks_at_the_fixed_scale() {
        assert_eq!(ticks_of_angle(TAU), Some(1 << 20));
        assert_eq!(ticks_of_angle(-TAU / 2.0), Some(-(1 << 19)));
        assert_eq!(ticks_of_angle(f64::NAN), None);
    }
}
