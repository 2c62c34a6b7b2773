//! Wheel encoders: integer cumulative ticks sampled at about 50 Hz with timing jitter,
//! optionally wrapping modulo a counter size.

use crate::error::SimError;
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;

/// The encoders' resolution, rate and counter behaviour.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct EncoderConfig {
    /// Ticks per wheel revolution (Khepera III: 2764.8); may be fractional.
    pub ticks_per_revolution: f64,
    /// Records per second.
    pub rate_hz: f64,
    /// Timing jitter: each record time is moved by a uniform amount in ±jitter (s).
    pub jitter_s: f64,
    /// Counters wrap modulo this value (written as PARAM `robot_encoder_modulus`);
    /// `None` = no wrapping.
    pub modulus: Option<u64>,
    /// Counter values `[left, right]` when the wheels are at their start angle.
    pub initial_ticks: [i64; 2],
    /// One record per scan instead of `rate_hz`: the counts read when the laser clock
    /// shows the scan's timestamp, and written with that timestamp (a log that stores
    /// the encoder counts with each scan; with a clock offset, the counts are read
    /// that much after the scan's first ray). `jitter_s` then moves the time the
    /// counts are read, not their timestamp.
    /// (Left out of the JSON when off, so configurations written before it read and
    /// write back the same.)
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub with_scans: bool,
}

impl Default for EncoderConfig {
    /// Khepera III: 2764.8 ticks/rev, 50 Hz ± 2 ms, no wrapping, counters from 0.
    fn default() -> Self {
        EncoderConfig {
            ticks_per_revolution: 2764.8,
            rate_hz: 50.0,
            jitter_s: 0.002,
            modulus: None,
            initial_ticks: [0, 0],
            with_scans: false,
        }
    }
}

impl EncoderConfig {
    /// The cumulative (unwrapped) counts for cumulative wheel rotations `[left, right]`
    /// (rad): `initial + floor(angle · ticks_per_revolution / 2π)`, the same rounding
    /// for both signs.
    pub fn ticks(&self, wheel_angles: [f64; 2]) -> [i64; 2] {
        let k = self.ticks_per_revolution / TAU;
        [
            self.initial_ticks[0] + (wheel_angles[0] * k).floor() as i64,
            self.initial_ticks[1] + (wheel_angles[1] * k).floor() as i64,
        ]
    }

    /// The value a counter shows for cumulative count `ticks`: `ticks` itself, or
    /// `ticks mod modulus` in `[0, modulus)` when the counter wraps.
    pub fn counter_value(&self, ticks: i64) -> i64 {
        match self.modulus {
            Some(m) => ticks.rem_euclid(m as i64),
            None => ticks,
        }
    }

    /// Wheel rotation (rad) for a number of ticks.
    pub fn ticks_to_radians(&self, ticks: i64) -> f64 {
        ticks as f64 * TAU / self.ticks_per_revolution
    }

    /// Checks that every setting is meaningful.
    pub fn validate(&self) -> Result<(), SimError> {
        let bad = |field, value: String, expected| {
            Err(SimError::InvalidConfig {
                field,
                value,
                expected,
            })
        };
        let tpr = self.ticks_per_revolution;
        if !(tpr.is_finite() && tpr > 0.0) {
            return bad(
                "encoder.ticks_per_revolution",
                tpr.to_string(),
                "a positive number",
            );
        }
        if !(self.rate_hz.is_finite() && self.rate_hz > 0.0 && self.rate_hz <= 10_000.0) {
            return bad(
                "encoder.rate_hz",
                self.rate_hz.to_string(),
                "a rate in (0, 10000] Hz",
            );
        }
        if !(self.jitter_s.is_finite()
            && self.jitter_s >= 0.0
            && self.jitter_s < 0.5 / self.rate_hz)
        {
            return bad(
                "encoder.jitter_s",
                self.jitter_s.to_string(),
                "≥ 0 and below half the encoder period",
            );
        }
        if let Some(m) = self.modulus {
            if !(2..=(1u64 << 62)).contains(&m) {
                return bad(
                    "encoder.modulus",
                    m.to_string(),
                    "a counter size between 2 and 2^62",
                );
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_floor_consistently() {
        let e = EncoderConfig::default();
        let per_tick = TAU / 2764.8;
        assert_eq!(e.ticks([0.0, 0.5 * per_tick]), [0, 0]);
        assert_eq!(e.ticks([-0.5 * per_tick, 1.5 * per_tick]), [-1, 1]);
        assert_eq!(e.ticks([TAU, -TAU]), [2764, -2765]);
    }

    #[test]
    fn counters_wrap() {
        let e = EncoderConfig {
            modulus: Some(65536),
            ..EncoderConfig::default()
        };
        assert_eq!(e.counter_value(65537), 1);
        assert_eq!(e.counter_value(-1), 65535);
        assert_eq!(EncoderConfig::default().counter_value(-1), -1);
    }
}
