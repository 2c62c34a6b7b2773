//! Named range-finder models, each sweeping its rays one after another as the real
//! sensor does: a Hokuyo URG-04LX, a 360° LDS-like lidar of a TurtleBot-class robot and
//! a 180° SICK-like scanner that sweeps clockwise.

use crate::error::SimError;
use crate::laser::LaserConfig;
use std::f64::consts::{FRAC_PI_2, TAU};

/// Names accepted by [`LaserConfig::model`].
pub const LASER_MODELS: [&str; 6] = [
    "urg-04lx",
    "lds",
    "sick",
    "urg-04lx-realistic",
    "neato-lds",
    "rplidar",
];

impl LaserConfig {
    /// A laser model by name (see [`LASER_MODELS`]), sweeping (`time_increment` set);
    /// [`LaserConfig::instantaneous`] takes the sweep out.
    pub fn model(name: &str) -> Result<LaserConfig, SimError> {
        match name {
            "urg-04lx" | "urg" | "hokuyo" => Ok(LaserConfig::urg_04lx()),
            "lds" => Ok(LaserConfig::lds()),
            "sick" | "sick-lms" => Ok(LaserConfig::sick()),
            "urg-04lx-realistic" => Ok(LaserConfig::urg_04lx_realistic()),
            "neato-lds" => Ok(LaserConfig::neato_lds()),
            "rplidar" => Ok(LaserConfig::rplidar()),
            _ => Err(SimError::UnknownName {
                what: "laser model",
                name: name.to_string(),
                known: LASER_MODELS.join(", "),
            }),
        }
    }

    /// The Hokuyo URG-04LX as it really scans: the [`LaserConfig::default`] geometry and
    /// noise, 10 Hz, its mirror turning 1024 steps in 0.1 s, so consecutive rays are
    /// 0.1/1024 s apart and the 240° sweep takes 66.4 ms.
    pub fn urg_04lx() -> Self {
        LaserConfig {
            time_increment: 0.1 / 1024.0,
            ..LaserConfig::default()
        }
    }

    /// A 360° lidar like the LDS of a TurtleBot-class robot: 360 rays 1° apart from 0°
    /// (counter-clockwise), one turn in 0.2 s (5 Hz), 0.12–3.5 m, σ = 10 mm
    /// independent per ray, 1 mm quantization, 1 % random failures.
    pub fn lds() -> Self {
        LaserConfig {
            num_rays: 360,
            start_angle: 0.0,
            resolution: TAU / 360.0,
            max_range: 3.5,
            min_range: 0.12,
            rate_hz: 5.0,
            jitter_s: 0.0,
            range_sigma: 0.010,
            correlation_rays: 1,
            quantization: 0.001,
            dropout_probability: 0.01,
            time_increment: 0.2 / 360.0,
            laser_type: 99,
            realism: None,
        }
    }

    /// A SICK-LMS-like scanner: 181 rays 1° apart over 180°, swept clockwise (from
    /// +90° to −90°: a negative angle increment), mirror at 75 Hz so consecutive rays
    /// are 1/(75·360) s apart, 37.5 scans per second, 0.05–8 m, σ = 5 mm, 1 mm
    /// quantization, 0.1 % random failures.
    pub fn sick() -> Self {
        LaserConfig {
            num_rays: 181,
            start_angle: FRAC_PI_2,
            resolution: -TAU / 360.0,
            max_range: 8.0,
            min_range: 0.05,
            rate_hz: 37.5,
            jitter_s: 0.0,
            range_sigma: 0.005,
            correlation_rays: 1,
            quantization: 0.001,
            dropout_probability: 0.001,
            time_increment: 1.0 / (75.0 * 360.0),
            laser_type: 0,
            realism: None,
        }
    }

    /// The same sensor with every ray taken at the scan's timestamp (no sweep).
    pub fn instantaneous(self) -> Self {
        LaserConfig {
            time_increment: 0.0,
            ..self
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn models_are_valid_and_sweep_as_announced() {
        for name in LASER_MODELS {
            let l = LaserConfig::model(name).unwrap();
            l.validate().unwrap();
            assert!(l.time_increment > 0.0);
            assert_eq!(l.geometry().time_increment, l.time_increment);
        }
        let urg = LaserConfig::urg_04lx();
        assert!((urg.sweep_duration() - 0.0664).abs() < 1e-4);
        let lds = LaserConfig::lds();
        assert!((lds.sweep_duration() - 0.2 * 359.0 / 360.0).abs() < 1e-12);
        let sick = LaserConfig::sick();
        let a = sick.angles();
        assert_eq!(a.len(), 181);
        assert!((a[0] - FRAC_PI_2).abs() < 1e-12 && (a[180] + FRAC_PI_2).abs() < 1e-12);
        assert!(sick.geometry().resolution < 0.0);
        assert_eq!(sick.clone().instantaneous().time_increment, 0.0);
        assert!(LaserConfig::model("velodyne").is_err());
    }
}
