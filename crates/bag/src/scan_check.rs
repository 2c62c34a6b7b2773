//! Whether a decoded `sensor_msgs/LaserScan` describes a usable scan: the same bounds
//! the Carmen reader puts on its laser parameters (finite angles and ranges, a time
//! between rays under a second), and a ray count that agrees with the angle fields.

use crate::messages::ScanFields;

/// Largest |angle| accepted for `angle_min`/`angle_max` (rad): two turns.
const MAX_ANGLE: f32 = 4.0 * std::f32::consts::PI;

/// Longest sweep accepted (s): rays spread over more than this are not one 2-D scan.
const MAX_SWEEP_S: f64 = 1.0;

/// What is wrong with a scan of `len` rays with these fields, `None` when usable.
/// `own_time_increment`: whether the message's `time_increment` is used (not
/// overridden by `--time-increment`).
pub(crate) fn scan_problem(f: &ScanFields, len: usize, own_time_increment: bool) -> Option<String> {
    let angles_ok = [f.angle_min, f.angle_max]
        .iter()
        .all(|a| a.is_finite() && a.abs() <= MAX_ANGLE)
        && f.angle_increment.is_finite()
        && f.angle_increment != 0.0;
    if !angles_ok {
        return Some(format!(
            "angle_min {}, angle_max {}, angle_increment {} are not finite angles (|a| ≤ 4π) \
             with a nonzero increment",
            f.angle_min, f.angle_max, f.angle_increment
        ));
    }
    let span_rays = ((f.angle_max - f.angle_min) / f.angle_increment) as f64 + 1.0;
    if len < 2 || (span_rays - len as f64).abs() > 1.5 {
        return Some(format!(
            "{len} ranges, but angle_min {} to angle_max {} by angle_increment {} make {:.0} \
             rays",
            f.angle_min, f.angle_max, f.angle_increment, span_rays
        ));
    }
    if !(f.range_max.is_finite() && f.range_max > 0.0) {
        return Some(format!(
            "range_max {} is not a positive finite range (m)",
            f.range_max
        ));
    }
    if !(f.range_min.is_finite() && f.range_min >= 0.0 && f.range_min < f.range_max) {
        return Some(format!(
            "range_min {} is not a finite range in [0, range_max {}) (m)",
            f.range_min, f.range_max
        ));
    }
    let sweep = f.time_increment as f64 * (len - 1) as f64;
    if own_time_increment && !(f.time_increment.is_finite() && sweep.abs() <= MAX_SWEEP_S) {
        return Some(format!(
            "time_increment {} s over {len} rays is not a sweep of at most {MAX_SWEEP_S} s \
             (give the true value with --time-increment)",
            f.time_increment
        ));
    }
    if !(f.scan_time.is_finite() && (0.0..=60.0).contains(&f.scan_time)) {
        return Some(format!(
            "scan_time {} is not a time between scans in [0, 60] s",
            f.scan_time
        ));
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fields() -> ScanFields {
        ScanFields {
            stamp_ns: 0,
            angle_min: -1.0,
            angle_max: 1.0,
            angle_increment: 0.5,
            time_increment: 0.001,
            scan_time: 0.1,
            range_min: 0.02,
            range_max: 4.0,
        }
    }

    #[test]
    fn a_plausible_scan_passes() {
        assert_eq!(scan_problem(&fields(), 5, true), None);
    }

    /// Spoils one field of a scan.
    type Spoil = fn(&mut ScanFields);

    #[test]
    fn each_absurd_field_is_named() {
        let cases: [(Spoil, &str); 7] = [
            (|f| f.time_increment = f32::NAN, "time_increment"),
            (|f| f.time_increment = 1e6, "time_increment"),
            (|f| f.range_min = f32::INFINITY, "range_min"),
            (|f| f.range_min = 5.0, "range_min"),
            (|f| f.range_max = f32::NAN, "range_max"),
            (|f| f.angle_increment = f32::NAN, "angle_increment"),
            (|f| f.angle_max = 1e9, "angle_max"),
        ];
        for (set, name) in cases {
            let mut f = fields();
            set(&mut f);
            let why = scan_problem(&f, 5, true).expect("refused");
            assert!(why.contains(name), "{why}");
        }
    }

    #[test]
    fn a_count_that_disagrees_with_the_angles_is_named() {
        let why = scan_problem(&fields(), 36, true).expect("refused");
        assert!(why.contains("36 ranges"), "{why}");
    }

    #[test]
    fn an_overridden_time_increment_is_not_checked() {
        let mut f = fields();
        f.time_increment = f32::NAN;
        assert_eq!(scan_problem(&f, 5, false), None);
    }
}
