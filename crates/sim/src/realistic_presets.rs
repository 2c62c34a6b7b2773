//! Presets for the three real sensor classes whose scans odocal must match, with the
//! realistic laser ([`crate::RealisticLaser`]) in the cluttered worlds: a fast
//! six-wheel rover with a URG-04LX, a Neato-class robot with its 1° LDS and a
//! TurtleBot 4 with an RPLIDAR. What each models, and what not, is in
//! `docs/realistic-presets.md`.

use crate::config::SimConfig;
use crate::drive::MotorConfig;
use crate::encoder::EncoderConfig;
use crate::faults::FaultConfig;
use crate::kinematics::RobotParams;
use crate::laser::LaserConfig;
use crate::planner::MotionLimits;
use crate::realistic_laser::RealisticLaser;
use odocal_geom::Pose2;
use std::f64::consts::TAU;

/// The realistic preset names (also in [`crate::BUILTIN_PRESETS`]).
pub const REALISTIC_PRESETS: [&str; 3] = ["mines-rover", "neato-lds", "turtlebot4-rplidar"];

impl LaserConfig {
    /// A real Hokuyo URG-04LX as on the MinesRover logs: 682 rays 2π/1024 apart over
    /// 240°, 10 Hz, swept, 0.02–5.6 m; σ = 5 mm + 0.25 % of the range (the data
    /// sheet's ±10 mm up to 1 m, ±1 % beyond, as about ±2σ), correlated over 2 rays; 1 % random failures; returns fading beyond 4 m and past 70° incidence;
    /// mixed pixels at half the depth edges; a bias of 3 mm + 4 mm/m² · r² (1.6 % at
    /// 4 m) and a 20 mm warm-up drift (time constant 3 min).
    pub fn urg_04lx_realistic() -> Self {
        let res = TAU / 1024.0;
        LaserConfig {
            num_rays: 682,
            start_angle: -340.5 * res,
            resolution: res,
            max_range: 5.6,
            min_range: 0.02,
            rate_hz: 10.0,
            jitter_s: 0.0,
            range_sigma: 0.005,
            correlation_rays: 2,
            quantization: 0.001,
            dropout_probability: 0.01,
            time_increment: 0.1 / 1024.0,
            laser_type: 2,
            realism: Some(RealisticLaser {
                half_return_range: 4.0,
                grazing_angle: 70f64.to_radians(),
                mixed_pixel_probability: 0.5,
                depth_edge: 0.1,
                bias_offset: 0.003,
                bias_quadratic: 0.004,
                drift: 0.02,
                drift_time: 180.0,
                sigma_per_metre: 0.0025,
            }),
        }
    }

    /// A Neato-class 360° LDS: 361 rays 1° apart from 0°, 5 Hz, swept, 0.06–5 m;
    /// σ = 6 mm + 0.4 % of the range; a weak receiver: half the returns lost at
    /// 1.3 m, fading past 55° incidence, 2 % random failures (about 80 % of the
    /// readings invalid in an office, 40–110 returns per scan); mixed pixels; a bias
    /// of 2 mm/m² · r² and a 10 mm drift.
    pub fn neato_lds() -> Self {
        LaserConfig {
            num_rays: 361,
            start_angle: 0.0,
            resolution: TAU / 360.0,
            max_range: 5.0,
            min_range: 0.06,
            rate_hz: 5.0,
            jitter_s: 0.0,
            range_sigma: 0.006,
            correlation_rays: 1,
            quantization: 0.001,
            dropout_probability: 0.02,
            time_increment: 0.2 / 361.0,
            laser_type: 99,
            realism: Some(RealisticLaser {
                half_return_range: 1.3,
                grazing_angle: 55f64.to_radians(),
                mixed_pixel_probability: 0.5,
                depth_edge: 0.1,
                bias_offset: 0.0,
                bias_quadratic: 0.002,
                drift: 0.01,
                drift_time: 120.0,
                sigma_per_metre: 0.004,
            }),
        }
    }

    /// An RPLIDAR A1 as on a TurtleBot 4: 720 rays 0.5° apart from −180°, 7.7 Hz,
    /// swept, 0.15–12 m; σ = 3 mm + 0.5 % of the range (the data sheet's 1 % up to
    /// 3 m, 2 % to 5 m, as about ±2σ); 5 % random failures; returns
    /// fading beyond 6 m and past 75° incidence; mixed pixels at 70 % of the depth
    /// edges (its well-known trails); a bias of 2 mm + 1 mm/m² · r² and a 5 mm drift.
    pub fn rplidar() -> Self {
        LaserConfig {
            num_rays: 720,
            start_angle: -TAU / 2.0,
            resolution: TAU / 720.0,
            max_range: 12.0,
            min_range: 0.15,
            rate_hz: 7.7,
            jitter_s: 0.0,
            range_sigma: 0.003,
            correlation_rays: 1,
            quantization: 0.001,
            dropout_probability: 0.05,
            time_increment: 1.0 / (7.7 * 720.0),
            laser_type: 99,
            realism: Some(RealisticLaser {
                half_return_range: 6.0,
                grazing_angle: 75f64.to_radians(),
                mixed_pixel_probability: 0.7,
                depth_edge: 0.08,
                bias_offset: 0.002,
                bias_quadratic: 0.001,
                drift: 0.005,
                drift_time: 120.0,
                sigma_per_metre: 0.005,
            }),
        }
    }
}

/// The realistic preset `name` built on `base` (the default configuration renamed),
/// `None` for another name.
pub(crate) fn preset(name: &str, base: SimConfig) -> Option<SimConfig> {
    match name {
        "mines-rover" => Some(mines_rover(base)),
        "neato-lds" => Some(neato_lds(base)),
        "turtlebot4-rplidar" => Some(turtlebot4_rplidar(base)),
        _ => None,
    }
}

/// A six-wheel skid-steer rover like the MinesRover, with about what odocal finds on
/// its real logs (docs/benchmarks.md): wheel radii 74.6 / 74.1 mm, an effective wheel
/// distance of 305 mm (nominal 77 mm and 330 mm), the URG-04LX 94 mm ahead, 6 mm to
/// the left, turned by −0.033 rad (nominal 145 mm ahead); up to 0.6 m/s and 1 rad/s;
/// sliding outward in turns (lateral slip 0.05 s: 3° at 1 rad/s); 2000-tick encoders
/// read with each scan; three short slip episodes a minute; in the cluttered hall,
/// 120 s.
fn mines_rover(base: SimConfig) -> SimConfig {
    SimConfig {
        duration: 120.0,
        hostname: "minesrover".into(),
        world: "hall-cluttered".into(),
        robot: RobotParams {
            r_l: 0.0746,
            r_r: 0.0741,
            b: 0.305,
            laser: Pose2::new(0.094, 0.006, -0.033),
        },
        nominal: RobotParams {
            r_l: 0.077,
            r_r: 0.077,
            b: 0.330,
            laser: Pose2::new(0.145, 0.0, 0.0),
        },
        motion: MotionLimits {
            max_speed: 0.6,
            max_turn_rate: 1.0,
            clearance: 0.5,
            turn_radius: 1.0,
        },
        motors: MotorConfig {
            time_constant: 0.3,
            lateral_slip: 0.05,
            ..MotorConfig::default()
        },
        encoder: EncoderConfig {
            ticks_per_revolution: 2000.0,
            with_scans: true,
            ..base.encoder
        },
        laser: LaserConfig::urg_04lx_realistic(),
        faults: FaultConfig {
            slip_per_minute: 3.0,
            slip_duration: [0.3, 0.8],
            slip_factor: [0.8, 0.97],
            ..FaultConfig::default()
        },
        ..base
    }
}

/// A Neato-class vacuum robot: wheel radii 38.4 / 38.6 mm, wheel distance 247 mm, the
/// LDS 90 mm behind the axle centre; up to 0.3 m/s and 1.5 rad/s; 1000-tick encoders
/// at 20 Hz; in the cluttered office, 120 s.
fn neato_lds(base: SimConfig) -> SimConfig {
    SimConfig {
        duration: 120.0,
        hostname: "neato".into(),
        world: "office-cluttered".into(),
        robot: RobotParams {
            r_l: 0.0384,
            r_r: 0.0386,
            b: 0.247,
            laser: Pose2::new(-0.09, 0.003, 0.015),
        },
        nominal: RobotParams {
            r_l: 0.0385,
            r_r: 0.0385,
            b: 0.248,
            laser: Pose2::new(-0.09, 0.0, 0.0),
        },
        motion: MotionLimits {
            max_speed: 0.3,
            max_turn_rate: 1.5,
            clearance: 0.3,
            turn_radius: 0.5,
        },
        motors: MotorConfig {
            time_constant: 0.1,
            ..MotorConfig::default()
        },
        encoder: EncoderConfig {
            ticks_per_revolution: 1000.0,
            rate_hz: 20.0,
            ..base.encoder
        },
        laser: LaserConfig::neato_lds(),
        ..base
    }
}

/// A TurtleBot 4 (iRobot Create 3 base): wheel radii 35.7 / 35.8 mm, wheel distance
/// 235 mm, the RPLIDAR 45 mm behind the axle centre; up to 0.3 m/s and 1.9 rad/s;
/// 508.8-tick encoders at 20 Hz; in the cluttered office, 120 s.
fn turtlebot4_rplidar(base: SimConfig) -> SimConfig {
    SimConfig {
        duration: 120.0,
        hostname: "turtlebot4".into(),
        world: "office-cluttered".into(),
        robot: RobotParams {
            r_l: 0.0357,
            r_r: 0.0358,
            b: 0.2352,
            laser: Pose2::new(-0.045, 0.004, 0.02),
        },
        nominal: RobotParams {
            r_l: 0.03575,
            r_r: 0.03575,
            b: 0.235,
            laser: Pose2::new(-0.04, 0.0, 0.0),
        },
        motion: MotionLimits {
            max_speed: 0.3,
            max_turn_rate: 1.9,
            clearance: 0.3,
            turn_radius: 0.5,
        },
        motors: MotorConfig {
            time_constant: 0.1,
            ..MotorConfig::default()
        },
        encoder: EncoderConfig {
            ticks_per_revolution: 508.8,
            rate_hz: 20.0,
            ..base.encoder
        },
        laser: LaserConfig::rplidar(),
        ..base
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simulation::simulate;

    /// Valid returns per scan over a short run of `name`.
    fn returns_per_scan(name: &str) -> (f64, usize, usize, f64) {
        let mut c = SimConfig::preset(name).unwrap();
        c.duration = 8.0;
        let run = simulate(&c).unwrap();
        let n: Vec<usize> = run
            .scans
            .iter()
            .map(|s| s.ranges.iter().filter(|&&r| r > 0.0).count())
            .collect();
        let mean = n.iter().sum::<usize>() as f64 / n.len() as f64;
        let rays = c.laser.num_rays as f64;
        (
            mean,
            *n.iter().min().unwrap(),
            *n.iter().max().unwrap(),
            1.0 - mean / rays,
        )
    }

    #[test]
    fn realistic_presets_are_valid_and_realistic() {
        for name in REALISTIC_PRESETS {
            let c = SimConfig::preset(name).unwrap();
            c.validate().unwrap();
            assert!(c.laser.realism.is_some(), "{name}");
            assert!(crate::World::preset(&c.world).unwrap().is_realistic());
        }
    }

    #[test]
    fn returns_are_as_sparse_as_the_real_sensors() {
        let (mean, lo, hi, invalid) = returns_per_scan("neato-lds");
        println!("neato-lds: {mean:.0} returns per scan ({lo}–{hi}), {invalid:.2} invalid");
        assert!((40.0..=80.0).contains(&mean), "{mean}");
        assert!((0.7..=0.9).contains(&invalid), "{invalid}");
        let (mean, lo, hi, invalid) = returns_per_scan("mines-rover");
        println!("mines-rover: {mean:.0} returns per scan ({lo}–{hi}), {invalid:.2} invalid");
        assert!((0.4..=0.7).contains(&invalid), "{invalid}");
        let (mean, lo, hi, invalid) = returns_per_scan("turtlebot4-rplidar");
        println!(
            "turtlebot4-rplidar: {mean:.0} returns per scan ({lo}–{hi}), {invalid:.2} invalid"
        );
        assert!((0.25..=0.6).contains(&invalid), "{invalid}");
    }
}
