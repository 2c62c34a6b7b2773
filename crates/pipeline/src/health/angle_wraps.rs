//! Wheel angles a driver wrapped to one turn: ROS drivers often publish the position of
//! a continuous wheel joint in (−π, π] (or [0, 2π)), so the angle jumps back by a whole
//! turn whenever the wheel passes the seam. Read in radians (at
//! [`WHEEL_TICKS_PER_REVOLUTION`] ticks per turn) that is a jump of 2^20 ticks between
//! two messages: a huge spike in the wheel speed. Here each wheel's angles are
//! recognised as wrapped (all within one turn, with steps of more than half a turn) and
//! unwrapped, each step taken as the one within half a turn — exact while a wheel turns
//! less than half a turn between two messages.

use super::since;
use super::wraps::steps;
use crate::finding::{Finding, FindingKind, Severity};
use odocal_log::{EncoderRecord, Origin, Stream, WHEEL_TICKS_PER_REVOLUTION};
use std::f64::consts::TAU;

/// One turn in ticks.
const TURN: i128 = WHEEL_TICKS_PER_REVOLUTION as i128;
/// Slack (ticks) on the one-turn span: rounding at ±π, drivers publishing [−π, π].
const SLACK: i128 = 16;

/// True when every count of both wheels lies within one turn (plus [`SLACK`]).
fn within_one_turn(records: &[EncoderRecord]) -> bool {
    let span = |count: fn(&EncoderRecord) -> i64| {
        let (lo, hi) = records.iter().fold((i64::MAX, i64::MIN), |(lo, hi), r| {
            (lo.min(count(r)), hi.max(count(r)))
        });
        hi as i128 - lo as i128
    };
    span(|r| r.left) <= TURN + SLACK && span(|r| r.right) <= TURN + SLACK
}

/// Unwraps wheel angles (in [`WHEEL_TICKS_PER_REVOLUTION`] ticks, sorted by time) that
/// were wrapped to one turn. A note when they were; a warning when a wheel turned more
/// than a quarter turn between two messages, where the unwrapping may guess wrong.
pub fn unwrap(records: &mut [EncoderRecord], origin: &Origin) -> Option<Finding> {
    let half = TURN / 2;
    let st = steps(records);
    if !st.iter().flatten().any(|d| d.abs() > half) || !within_one_turn(records) {
        return None;
    }
    let mut offset = [0i128; 2];
    let mut wraps = 0u64;
    let mut first: Option<usize> = None;
    let mut largest = 0i128;
    for (k, s) in st.iter().enumerate() {
        for (w, &d) in s.iter().enumerate() {
            let turns = if d > half {
                -1
            } else if d < -half {
                1
            } else {
                0
            };
            if turns != 0 {
                offset[w] += turns * TURN;
                wraps += 1;
                first.get_or_insert(k + 1);
            }
            largest = largest.max((d + turns * TURN).abs());
        }
        let r = &mut records[k + 1];
        // Within one turn plus one turn per record: far inside i64.
        r.left = (r.left as i128 + offset[0]) as i64;
        r.right = (r.right as i128 + offset[1]) as i64;
    }
    let rec = records[first?];
    let largest_rad = largest as f64 / TURN as f64 * TAU;
    let (severity, advice) = if 4 * largest > TURN {
        (
            Severity::Warning,
            "; a wheel turns up to a quarter turn or more between two messages, where the \
             unwrapping may guess wrong: publish the joint states faster",
        )
    } else {
        (Severity::Info, "")
    };
    Some(
        Finding::new(
            FindingKind::WheelAngleWrap,
            severity,
            format!(
                "the wheel angles are wrapped to one turn ((−π, π] or [0, 2π), as drivers \
                 publish continuous joints): {wraps} wrap(s), first at {} ({}); they were \
                 unwrapped into continuous angles, exact while a wheel turns less than half a \
                 turn between messages (here at most {largest_rad:.2} rad){advice}",
                origin.at(Stream::Wheels, rec.line, rec.t),
                since(rec.t, records[0].t)
            ),
        )
        .count(wraps)
        .at(rec.line, rec.t),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use odocal_log::ticks_of_angle;
    use std::f64::consts::PI;

    /// Wheel angles (rad) at 20 Hz as records, each angle mapped by `wrap` first.
    fn recs(angles: &[(f64, f64)], wrap: impl Fn(f64) -> f64) -> Vec<EncoderRecord> {
        angles
            .iter()
            .enumerate()
            .map(|(k, &(l, r))| EncoderRecord {
                t: k as f64 * 0.05,
                left: ticks_of_angle(wrap(l)).unwrap(),
                right: ticks_of_angle(wrap(r)).unwrap(),
                line: k as u64 + 1,
            })
            .collect()
    }

    /// Angles wrapped to (−π, π], as `atan2` gives them.
    fn to_pi(a: f64) -> f64 {
        a.sin().atan2(a.cos())
    }

    fn assert_same_steps(a: &[EncoderRecord], b: &[EncoderRecord]) {
        for (x, y) in a.windows(2).zip(b.windows(2)) {
            assert!((x[1].left - x[0].left - (y[1].left - y[0].left)).abs() <= 1);
            assert!((x[1].right - x[0].right - (y[1].right - y[0].right)).abs() <= 1);
        }
    }

    #[test]
    fn wrapped_joint_positions_are_unwrapped_with_a_note() {
        // Left forward, right backward at 0.4 rad per message: several turns each.
        let angles: Vec<(f64, f64)> = (0..200)
            .map(|k| (0.3 + 0.4 * k as f64, -0.2 - 0.37 * k as f64))
            .collect();
        let truth = recs(&angles, |a| a);
        for wrap in [to_pi as fn(f64) -> f64, |a: f64| a.rem_euclid(2.0 * PI)] {
            let mut r = recs(&angles, wrap);
            let f = unwrap(&mut r, &Origin::Text).expect("a finding");
            assert_eq!(f.kind, FindingKind::WheelAngleWrap);
            assert_eq!(f.severity, Severity::Info);
            // 80 rad and 74 rad: 13 + 12 seams at ±π, 12 + 11 at 0.
            assert!((23..=25).contains(&f.count), "{}", f.count);
            assert_same_steps(&r, &truth);
        }
    }

    #[test]
    fn sparse_messages_are_a_warning() {
        let angles: Vec<(f64, f64)> = (0..100).map(|k| (1.8 * k as f64, 0.1)).collect();
        let mut r = recs(&angles, to_pi);
        let f = unwrap(&mut r, &Origin::Text).expect("a finding");
        assert_eq!(f.severity, Severity::Warning);
        assert_same_steps(&r, &recs(&angles, |a| a));
    }

    #[test]
    fn continuous_angles_are_left_alone() {
        // Continuous, beyond one turn: no step over half a turn.
        let angles: Vec<(f64, f64)> = (0..200).map(|k| (0.4 * k as f64, -3.0)).collect();
        let mut r = recs(&angles, |a| a);
        let before = r.clone();
        assert!(unwrap(&mut r, &Origin::Text).is_none());
        assert_eq!(r, before);
        // Steps over half a turn, but spanning more than one turn: not wrapped.
        let mut r = recs(&[(0.0, 0.0), (0.5, 0.1), (4.0, 0.2), (7.0, 0.3)], |a| a);
        let before = r.clone();
        assert!(unwrap(&mut r, &Origin::Text).is_none());
        assert_eq!(r, before);
    }
}
