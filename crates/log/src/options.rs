//! How to read a log: strict or lenient, and command-line overrides of PARAMs.

/// What to do with a malformed line of a known message.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Mode {
    /// Stop at the first malformed line with an error (the default).
    #[default]
    Strict,
    /// Skip malformed lines, counting them and remembering the first few.
    Lenient,
}

/// Reader options. Each `Some` value overrides the PARAM of the same meaning.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ReadOptions {
    /// Strict (default) or lenient.
    pub mode: Mode,
    /// Encoder ticks per wheel revolution (overrides `robot_wheel_ticks_per_revolution`).
    pub ticks_per_revolution: Option<f64>,
    /// Encoder counter modulus (overrides `robot_encoder_modulus`).
    pub encoder_modulus: Option<f64>,
    /// Minimum valid range in metres (overrides `laser_front_laser_min_range`).
    pub min_range: Option<f64>,
    /// Seconds between consecutive rays of a scan (overrides
    /// `laser_front_laser_time_increment` and a bag's `time_increment`).
    pub time_increment: Option<f64>,
}

impl ReadOptions {
    /// Lenient mode, no overrides.
    pub fn lenient() -> Self {
        ReadOptions {
            mode: Mode::Lenient,
            ..ReadOptions::default()
        }
    }

    /// The first option with an impossible value, as (option, what was expected).
    pub(crate) fn invalid(&self) -> Option<(&'static str, &'static str)> {
        if let Some(t) = self.ticks_per_revolution {
            if !(t.is_finite() && t > 0.0) {
                return Some(("ticks per revolution", "a positive finite number"));
            }
        }
        if let Some(m) = self.encoder_modulus {
            if !is_valid_modulus(m) {
                return Some(("encoder modulus", "an integer between 2 and 2^62"));
            }
        }
        if let Some(r) = self.min_range {
            if !(r.is_finite() && r >= 0.0) {
                return Some(("minimum range", "a finite number ≥ 0"));
            }
        }
        if let Some(dt) = self.time_increment {
            if !(dt.is_finite() && dt.abs() < 1.0) {
                return Some(("time increment", "a finite number of seconds, |x| < 1"));
            }
        }
        None
    }
}

/// True when `m` can be a counter modulus: an integer in [2, 2^62].
pub(crate) fn is_valid_modulus(m: f64) -> bool {
    m.fract() == 0.0 && (2.0..=4.611_686_018_427_388e18).contains(&m)
}
