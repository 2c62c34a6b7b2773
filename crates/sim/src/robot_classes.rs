//! Robot classes besides the Khepera III: a TurtleBot-class robot with a 360° LDS-like
//! lidar and a Pioneer-class robot with a URG-04LX, both faster than a Khepera and with
//! lasers that sweep (see [`crate::laser_models`]).

use crate::config::SimConfig;
use crate::drive::MotorConfig;
use crate::encoder::EncoderConfig;
use crate::kinematics::RobotParams;
use crate::laser::LaserConfig;
use crate::planner::MotionLimits;
use odocal_geom::Pose2;

impl RobotParams {
    /// A TurtleBot-class robot (true values): wheel radii 33.1 / 32.9 mm, wheel
    /// distance 161.4 mm, lidar 32 mm behind the axle centre, 4.5 mm to the left,
    /// turned by 0.012 rad.
    pub fn turtlebot_class() -> Self {
        RobotParams {
            r_l: 0.0331,
            r_r: 0.0329,
            b: 0.1614,
            laser: Pose2::new(-0.032, 0.0045, 0.012),
        }
    }

    /// The TurtleBot-class data-sheet values: radii 33 mm, wheel distance 160 mm,
    /// lidar at (−32 mm, 0, 0).
    pub fn turtlebot_class_nominal() -> Self {
        RobotParams {
            r_l: 0.033,
            r_r: 0.033,
            b: 0.160,
            laser: Pose2::new(-0.032, 0.0, 0.0),
        }
    }

    /// A Pioneer-class robot (true values): wheel radii 95.2 / 94.9 mm, wheel distance
    /// 331.2 mm, laser 160 mm ahead of the axle centre, 12 mm to the right, turned by
    /// −0.025 rad.
    pub fn pioneer_class() -> Self {
        RobotParams {
            r_l: 0.0952,
            r_r: 0.0949,
            b: 0.3312,
            laser: Pose2::new(0.16, -0.012, -0.025),
        }
    }

    /// The Pioneer-class data-sheet values: radii 97.5 mm, wheel distance 330 mm, laser
    /// at (160 mm, 0, 0).
    pub fn pioneer_class_nominal() -> Self {
        RobotParams {
            r_l: 0.0975,
            r_r: 0.0975,
            b: 0.330,
            laser: Pose2::new(0.16, 0.0, 0.0),
        }
    }
}

/// The `turtlebot` preset: a TurtleBot-class robot with the LDS-like lidar (5 Hz,
/// sweeping) in the office, up to 0.2 m/s and 1.5 rad/s, motors with a 0.1 s lag
/// (2 m/s² at most), 4096-tick encoders at 50 Hz, 120 s.
pub(crate) fn turtlebot(base: SimConfig) -> SimConfig {
    SimConfig {
        duration: 120.0,
        hostname: "turtlebot".into(),
        world: "office".into(),
        robot: RobotParams::turtlebot_class(),
        nominal: RobotParams::turtlebot_class_nominal(),
        motion: MotionLimits {
            max_speed: 0.2,
            max_turn_rate: 1.5,
            clearance: 0.3,
            turn_radius: 0.5,
        },
        motors: MotorConfig {
            time_constant: 0.1,
            ..MotorConfig::default()
        },
        encoder: EncoderConfig {
            ticks_per_revolution: 4096.0,
            rate_hz: 50.0,
            ..base.encoder
        },
        laser: LaserConfig::lds(),
        ..base
    }
}

/// The `pioneer` preset: a Pioneer-class robot with a URG-04LX (10 Hz, sweeping) in the
/// hall, up to 0.5 m/s and 1 rad/s, motors with a 0.4 s lag (1.25 m/s² at most),
/// 76 400-tick encoders at 50 Hz, 120 s.
pub(crate) fn pioneer(base: SimConfig) -> SimConfig {
    SimConfig {
        duration: 120.0,
        hostname: "pioneer".into(),
        world: "hall".into(),
        robot: RobotParams::pioneer_class(),
        nominal: RobotParams::pioneer_class_nominal(),
        motion: MotionLimits {
            max_speed: 0.5,
            max_turn_rate: 1.0,
            clearance: 0.5,
            turn_radius: 1.0,
        },
        motors: MotorConfig {
            time_constant: 0.4,
            ..MotorConfig::default()
        },
        encoder: EncoderConfig {
            ticks_per_revolution: 76_400.0,
            rate_hz: 50.0,
            ..base.encoder
        },
        laser: LaserConfig::urg_04lx(),
        ..base
    }
}
