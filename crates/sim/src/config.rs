//! The complete description of one simulation run.

use crate::drive::MotorConfig;
use crate::encoder::EncoderConfig;
use crate::error::SimError;
use crate::faults::FaultConfig;
use crate::kinematics::RobotParams;
use crate::laser::LaserConfig;
use crate::planner::{MotionLimits, TrajectoryKind};
use serde::{Deserialize, Serialize};

/// Everything that defines a simulation: with the same `SimConfig` (seed included) the
/// simulator produces the same bytes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SimConfig {
    /// Name of the preset this configuration started from (informational).
    pub preset: String,
    /// Seed of every random choice (trajectory, timing, noise, faults).
    pub seed: u64,
    /// Length of the run (s).
    pub duration: f64,
    /// Encoder-clock time of the start of the run (s); timestamps are written to the
    /// microsecond, and this is rounded to the microsecond.
    pub start_time: f64,
    /// Host name written on every log line.
    pub hostname: String,
    /// Name of the world (see [`crate::World::preset`]).
    pub world: String,
    /// Kind of trajectory.
    pub trajectory: TrajectoryKind,
    /// The robot's true parameters.
    pub robot: RobotParams,
    /// The nominal parameters the robot's firmware uses for its ODOM messages.
    pub nominal: RobotParams,
    /// Speed limits and wall clearance of the planner.
    pub motion: MotionLimits,
    /// Motor lag and integration sub-step.
    pub motors: MotorConfig,
    /// Wheel encoders.
    pub encoder: EncoderConfig,
    /// Range finder.
    pub laser: LaserConfig,
    /// Faults to inject.
    pub faults: FaultConfig,
    /// Whether to write ODOM messages (firmware odometry from the nominal parameters)
    /// after the ENCODER messages.
    pub write_odom: bool,
}

impl Default for SimConfig {
    /// The `khepera` preset: a Khepera III with a URG-04LX in the Khepera arena, mixed
    /// trajectory, 60 s, seed 1, no faults.
    fn default() -> Self {
        SimConfig {
            preset: "khepera".into(),
            seed: 1,
            duration: 60.0,
            start_time: 1_190_000_000.0,
            hostname: "khepera".into(),
            world: "khepera-arena".into(),
            trajectory: TrajectoryKind::Mixed,
            robot: RobotParams::khepera_iii(),
            nominal: RobotParams::khepera_iii_nominal(),
            motion: MotionLimits::default(),
            motors: MotorConfig::default(),
            encoder: EncoderConfig::default(),
            laser: LaserConfig::default(),
            faults: FaultConfig::default(),
            write_odom: true,
        }
    }
}

impl SimConfig {
    /// Checks every part of the configuration; the error names the bad setting.
    pub fn validate(&self) -> Result<(), SimError> {
        if !(self.duration.is_finite() && self.duration > 0.0 && self.duration <= 86_400.0) {
            return Err(SimError::InvalidConfig {
                field: "duration",
                value: self.duration.to_string(),
                expected: "a duration in (0, 86400] s",
            });
        }
        if !(self.start_time.is_finite() && self.start_time.abs() < 1e11) {
            return Err(SimError::InvalidConfig {
                field: "start_time",
                value: self.start_time.to_string(),
                expected: "a finite time below 1e11 s",
            });
        }
        if self.hostname.is_empty() || self.hostname.contains(char::is_whitespace) {
            return Err(SimError::InvalidConfig {
                field: "hostname",
                value: format!("{:?}", self.hostname),
                expected: "one non-empty token",
            });
        }
        if self.motors.substep_us == 0
            || !(self.motors.time_constant >= 0.0 && self.motors.time_constant <= 10.0)
            || !(self.motors.lateral_slip >= 0.0 && self.motors.lateral_slip <= 1.0)
        {
            return Err(SimError::InvalidConfig {
                field: "motors",
                value: format!("{:?}", self.motors),
                expected:
                    "substep_us ≥ 1, a time constant in [0, 10] s and a lateral slip in [0, 1] s",
            });
        }
        self.robot.validate()?;
        self.nominal.validate()?;
        self.motion.validate()?;
        self.encoder.validate()?;
        self.laser.validate()?;
        self.faults.validate()?;
        Ok(())
    }
}
