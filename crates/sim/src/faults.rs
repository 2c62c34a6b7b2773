//! Faults injected on request: wheel slip, a laser–encoder clock offset, dropped
//! messages and garbage lines.

use crate::error::SimError;
use rand::Rng;
use serde::{Deserialize, Serialize};

/// Which faults to inject, and how much.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FaultConfig {
    /// Laser clock minus encoder clock (s): every scan's logged timestamp is its true
    /// acquisition time plus this (rounded to the microsecond).
    pub clock_offset: f64,
    /// Wheel-slip episodes per minute of simulation (the count is rounded).
    pub slip_per_minute: f64,
    /// Range `[min, max]` of an episode's length (s).
    pub slip_duration: [f64; 2],
    /// Range `[min, max]` of the factor scaling each wheel's ground speed while slipping
    /// (drawn independently per wheel: the robot moves less, and differently).
    pub slip_factor: [f64; 2],
    /// Fraction of ENCODER / RAWLASER1 messages left out of the log.
    pub drop_fraction: f64,
    /// Probability, per written message, of a malformed line being inserted after it.
    pub garbage_fraction: f64,
}

impl Default for FaultConfig {
    /// No faults at all (slip episodes, when requested, last 0.5–1 s at factors 0.3–0.9).
    fn default() -> Self {
        FaultConfig {
            clock_offset: 0.0,
            slip_per_minute: 0.0,
            slip_duration: [0.5, 1.0],
            slip_factor: [0.3, 0.9],
            drop_fraction: 0.0,
            garbage_fraction: 0.0,
        }
    }
}

/// One wheel-slip episode: during `[start, end)` (s since the start of the
/// simulation, encoder clock) each wheel's ground speed is its rotation speed times
/// `factors` (`[left, right]`), while the encoders count the full rotation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SlipEpisode {
    /// Start (s since the simulation start).
    pub start: f64,
    /// End (s since the simulation start).
    pub end: f64,
    /// Ground-speed factors `[left, right]`.
    pub factors: [f64; 2],
}

impl FaultConfig {
    /// Checks that every setting is meaningful.
    pub fn validate(&self) -> Result<(), SimError> {
        let bad = |field, value: f64, expected| {
            Err(SimError::InvalidConfig {
                field,
                value: value.to_string(),
                expected,
            })
        };
        if !(self.clock_offset.is_finite() && self.clock_offset.abs() <= 10.0) {
            return bad(
                "faults.clock_offset",
                self.clock_offset,
                "an offset within ±10 s",
            );
        }
        if !(self.slip_per_minute.is_finite() && (0.0..=30.0).contains(&self.slip_per_minute)) {
            return bad(
                "faults.slip_per_minute",
                self.slip_per_minute,
                "0 to 30 episodes per minute",
            );
        }
        let [d0, d1] = self.slip_duration;
        if !(d0.is_finite() && d1.is_finite() && 0.0 < d0 && d0 <= d1 && d1 <= 10.0) {
            return bad("faults.slip_duration", d0, "0 < min ≤ max ≤ 10 s");
        }
        let [f0, f1] = self.slip_factor;
        if !(f0.is_finite() && f1.is_finite() && 0.0 <= f0 && f0 <= f1) {
            return bad("faults.slip_factor", f0, "0 ≤ min ≤ max");
        }
        for (field, p) in [
            ("faults.drop_fraction", self.drop_fraction),
            ("faults.garbage_fraction", self.garbage_fraction),
        ] {
            if !(0.0..1.0).contains(&p) {
                return bad(field, p, "a fraction in [0, 1)");
            }
        }
        Ok(())
    }

    /// Draws the slip episodes for a run of `duration` s: non-overlapping intervals
    /// whose ends are multiples of `grid` s (the integration sub-step), sorted by time.
    pub fn slip_episodes<R: Rng + ?Sized>(
        &self,
        duration: f64,
        grid: f64,
        rng: &mut R,
    ) -> Vec<SlipEpisode> {
        let count = (self.slip_per_minute * duration / 60.0).round() as usize;
        let snap = |t: f64| (t / grid).round() * grid;
        let mut out: Vec<SlipEpisode> = Vec::with_capacity(count);
        let mut attempts = 0;
        while out.len() < count && attempts < 100 * (count + 1) {
            attempts += 1;
            let len = rng.random_range(self.slip_duration[0]..=self.slip_duration[1]);
            if len >= duration {
                break;
            }
            let start = snap(rng.random_range(0.0..duration - len));
            let end = snap(start + len);
            let factors = [
                rng.random_range(self.slip_factor[0]..=self.slip_factor[1]),
                rng.random_range(self.slip_factor[0]..=self.slip_factor[1]),
            ];
            if end > start && out.iter().all(|e| end <= e.start || start >= e.end) {
                out.push(SlipEpisode {
                    start,
                    end,
                    factors,
                });
            }
        }
        out.sort_by(|a, b| a.start.total_cmp(&b.start));
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn slip_episodes_are_disjoint_and_on_the_grid() {
        let f = FaultConfig {
            slip_per_minute: 6.0,
            ..FaultConfig::default()
        };
        let eps = f.slip_episodes(120.0, 0.001, &mut ChaCha8Rng::seed_from_u64(1));
        assert_eq!(eps.len(), 12);
        for w in eps.windows(2) {
            assert!(w[0].end <= w[1].start);
        }
        for e in &eps {
            let len = e.end - e.start;
            assert!((0.499..=1.001).contains(&len), "{len}");
            assert!(((e.start * 1000.0) - (e.start * 1000.0).round()).abs() < 1e-6);
            assert!(e.factors.iter().all(|f| (0.3..=0.9).contains(f)));
        }
    }
}
