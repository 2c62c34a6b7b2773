//! Angle wrapping and the small-angle-safe functions used by the kinematics.

use std::f64::consts::{PI, TAU};

/// Wraps an angle (rad) to the interval (−π, π].
///
/// Non-finite input is returned unchanged so that callers can detect it.
pub fn wrap_angle(a: f64) -> f64 {
    if !a.is_finite() {
        return a;
    }
    if a > -PI && a <= PI {
        return a;
    }
    let mut w = a.rem_euclid(TAU); // [0, 2π)
    if w > PI {
        w -= TAU;
    }
    w
}

/// `sin(x)/x`, with its Taylor series near 0 to avoid cancellation (limit 1).
pub fn sin_over_x(x: f64) -> f64 {
    if x.abs() < 1e-3 {
        let x2 = x * x;
        1.0 - x2 / 6.0 * (1.0 - x2 / 20.0)
    } else {
        x.sin() / x
    }
}

/// `(1 − cos x)/x`, with its Taylor series near 0 to avoid cancellation (limit 0).
pub fn one_minus_cos_over_x(x: f64) -> f64 {
    if x.abs() < 1e-3 {
        let x2 = x * x;
        x / 2.0 * (1.0 - x2 / 12.0 * (1.0 - x2 / 30.0))
    } else {
        (1.0 - x.cos()) / x
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_keeps_range() {
        assert_eq!(wrap_angle(PI), PI);
        assert!((wrap_angle(-PI) - PI).abs() < 1e-15);
        assert!((wrap_angle(3.0 * PI) - PI).abs() < 1e-12);
        assert!((wrap_angle(0.5 + 4.0 * TAU) - 0.5).abs() < 1e-12);
        assert!((wrap_angle(-0.5 - 4.0 * TAU) + 0.5).abs() < 1e-12);
        assert!(wrap_angle(f64::NAN).is_nan());
    }

    #[test]
    fn series_match_closed_forms_at_the_switch() {
        for &x in &[1e-3_f64, -1e-3, 0.999e-3, 2e-3] {
            assert!((sin_over_x(x) - x.sin() / x).abs() < 1e-15);
            assert!((one_minus_cos_over_x(x) - (1.0 - x.cos()) / x).abs() < 1e-12);
        }
        assert_eq!(sin_over_x(0.0), 1.0);
        assert_eq!(one_minus_cos_over_x(0.0), 0.0);
    }
}
