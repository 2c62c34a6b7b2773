//! Numbers that cannot be those of a real robot, refused before synchronization:
//! timestamps in another unit than seconds (ROS stamps are nanoseconds, many loggers
//! write microseconds) and encoder counts that would turn a wheel impossibly fast (a
//! wrong ticks-per-revolution, or counts in another scale). Either would give wrong
//! numbers that look confident, and the time unit also makes the synchronization cut
//! intervals of 10⁸ "seconds". FLASER scans whose field of view no PARAM gives are
//! refused too: the reader assumes π to show them, but a wrong field of view scales
//! every bearing and biases the laser pose and the wheel radii, with σ that look
//! small.

use crate::error::PipelineError;
use crate::sync::median_period;
use odocal_log::{EncoderRecord, Log, ScanKind, Stream};

/// Longest plausible median time between two scans, or two encoder records (s).
pub const MAX_PERIOD_S: f64 = 10.0;
/// Fastest plausible median wheel speed while the wheels turn (revolutions per second:
/// 6,000 rpm, a 10 cm wheel at 60 m/s).
pub const MAX_WHEEL_REV_PER_S: f64 = 100.0;

/// The unit the timestamps were probably written in, when a period of `period` "s"
/// is one of 1 ms – [`MAX_PERIOD_S`] in that unit.
fn likely_unit(period: f64) -> Option<(&'static str, f64)> {
    [
        (1e3, "milliseconds"),
        (1e6, "microseconds"),
        (1e9, "nanoseconds"),
    ]
    .into_iter()
    .find(|(per_s, _)| (1e-3..=MAX_PERIOD_S).contains(&(period / per_s)))
    .map(|(per_s, name)| (name, per_s))
}

/// An error when the median period of a stream is implausibly long.
fn check_period(what: &str, times: &[f64], first: &str) -> Result<(), PipelineError> {
    let Some(period) = median_period(times) else {
        return Ok(());
    };
    if period <= MAX_PERIOD_S {
        return Ok(());
    }
    let cause = match likely_unit(period) {
        Some((unit, per_s)) => format!(
            "timestamps look like {unit}: the {what} are {period:.3e} s apart (median), where \
             one every 1 ms to {MAX_PERIOD_S} s is plausible; write the timestamps in seconds \
             (divide them by {per_s:e})"
        ),
        None => format!(
            "the {what} are {period:.3e} s apart (median), where one every 1 ms to \
             {MAX_PERIOD_S} s is plausible; the timestamps are not seconds — write the \
             timestamps in seconds"
        ),
    };
    Err(PipelineError::Implausible(format!(
        "{cause} (first at {first})"
    )))
}

/// The median wheel speed (revolutions per second, the faster wheel) between
/// consecutive records where a wheel turned, with the record where it was first that
/// fast; `None` when the wheels never turn.
fn median_wheel_speed(
    encoders: &[EncoderRecord],
    ticks_per_rev: f64,
) -> Option<(f64, EncoderRecord)> {
    let mut speeds: Vec<(f64, EncoderRecord)> = encoders
        .windows(2)
        .filter_map(|w| {
            let dt = w[1].t - w[0].t;
            let dl = (i128::from(w[1].left) - i128::from(w[0].left)).unsigned_abs();
            let dr = (i128::from(w[1].right) - i128::from(w[0].right)).unsigned_abs();
            let ticks = dl.max(dr) as f64;
            (dt > 0.0 && ticks > 0.0).then(|| (ticks / dt / ticks_per_rev, w[1]))
        })
        .collect();
    if speeds.is_empty() {
        return None;
    }
    let mid = speeds.len() / 2;
    let (_, m, _) = speeds.select_nth_unstable_by(mid, |a, b| a.0.total_cmp(&b.0));
    Some(*m)
}

/// An error when the log has FLASER scans and no PARAM gives their geometry.
fn check_flaser_geometry(log: &Log) -> Result<(), PipelineError> {
    let params = &log.params;
    if params.flaser_fov.is_some() || params.flaser_resolution.is_some() {
        return Ok(());
    }
    let Some(first) = log.scans.scans.iter().find(|s| s.kind == ScanKind::FLaser) else {
        return Ok(());
    };
    Err(PipelineError::Implausible(format!(
        "the FLASER scans (first at line {}) carry no field of view and no PARAM gives it: the reader assumed π rad, and a wrong field of view biases every parameter; add the laser's value before the first FLASER line, e.g. `PARAM laser_front_laser_fov 3.14159265` (rad, first to last ray) or `PARAM laser_front_laser_resolution 0.01745329` (rad between rays)",
        first.line
    )))
}

/// Refuses a log whose timestamps, encoder counts or scan geometry cannot be right,
/// naming the value and what to fix; `ticks_per_rev` is the one the calibration would
/// use.
pub fn check(log: &Log, ticks_per_rev: f64) -> Result<(), PipelineError> {
    check_flaser_geometry(log)?;
    let scan_times: Vec<f64> = log.scans.scans.iter().map(|s| s.t).collect();
    let origin = &log.stats.origin;
    let first_scan = log.scans.scans.first().map_or((0, 0.0), |s| (s.line, s.t));
    let first_scan = origin.at(Stream::Scans, first_scan.0, first_scan.1);
    check_period(&origin.records(Stream::Scans), &scan_times, &first_scan)?;
    let encoder_times: Vec<f64> = log.encoders.iter().map(|e| e.t).collect();
    let first_encoder = log.encoders.first().map_or((0, 0.0), |e| (e.line, e.t));
    let first_encoder = origin.at(Stream::Wheels, first_encoder.0, first_encoder.1);
    check_period(
        &origin.records(Stream::Wheels),
        &encoder_times,
        &first_encoder,
    )?;
    if let Some((speed, rec)) = median_wheel_speed(&log.encoders, ticks_per_rev) {
        let line = origin.at(Stream::Wheels, rec.line, rec.t);
        if speed > MAX_WHEEL_REV_PER_S {
            return Err(PipelineError::Implausible(format!(
                "with {ticks_per_rev} ticks per revolution the encoder counts turn a wheel at \
                 {speed:.3e} revolutions per second (median while moving, e.g. up to {line}), \
                 where no robot wheel turns faster than {MAX_WHEEL_REV_PER_S}: the \
                 counts are in another scale or the ticks per revolution are wrong — give \
                 the right value with --ticks-per-rev or PARAM robot_wheel_ticks_per_revolution"
            )));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use odocal_log::EncoderRecord;

    fn encoders(dt: f64, ticks_per_record: i64) -> Vec<EncoderRecord> {
        (0..200)
            .map(|k| EncoderRecord {
                t: 1e3 + k as f64 * dt,
                left: k * ticks_per_record,
                right: k * ticks_per_record / 2,
                line: k as u64 + 1,
            })
            .collect()
    }

    #[test]
    fn time_units_are_named() {
        let secs: Vec<f64> = (0..50).map(|k| k as f64 * 0.1).collect();
        assert!(check_period("scans", &secs, "line 1").is_ok());
        for (per_s, unit) in [(1e3, "milli"), (1e6, "micro"), (1e9, "nano")] {
            let t: Vec<f64> = secs.iter().map(|s| s * per_s + 1.7e9 * per_s).collect();
            let e = check_period("scans", &t, "line 7").unwrap_err().to_string();
            assert!(e.contains(&format!("{unit}seconds")), "{e}");
            assert!(e.contains("line 7"), "{e}");
        }
        let absurd: Vec<f64> = (0..50).map(|k| k as f64 * 1e298).collect();
        let e = check_period("scans", &absurd, "line 1")
            .unwrap_err()
            .to_string();
        assert!(e.contains("not seconds"), "{e}");
    }

    #[test]
    fn impossible_wheel_speeds_are_refused() {
        // 20 ticks per 10 ms at 2764.8 ticks/rev: 0.72 rev/s, a Khepera.
        let ok = encoders(0.01, 20);
        assert!(median_wheel_speed(&ok, 2764.8).unwrap().0 < 1.0);
        let scaled = encoders(0.01, 20_000_000_000_000);
        let (speed, _) = median_wheel_speed(&scaled, 2764.8).unwrap();
        assert!(speed > 1e11, "{speed}");
        assert!(median_wheel_speed(&encoders(0.01, 0), 2764.8).is_none());
    }
}
