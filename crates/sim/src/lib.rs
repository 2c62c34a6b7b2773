//! Simulator of a differential-drive robot with wheel encoders and a laser range finder
//! (sweeping its rays or not), producing Carmen-style logs with exact ground truth.
//!
//! The pieces, each usable on its own:
//! - [`World`]: line-segment worlds (presets [`World::khepera_arena`],
//!   [`World::office`], [`World::corridor`], [`World::hall`]) with ray casting and clearance queries.
//! - [`LaserConfig`]: the range finder's geometry, error model and sweep (named
//!   models: [`LaserConfig::model`], [`LASER_MODELS`]);
//!   [`LaserConfig::scan`] simulates one scan from a sensor pose (noise-free with
//!   [`LaserConfig::noise_free`]), [`LaserConfig::true_ranges`] gives exact ranges.
//! - [`RobotParams`], [`arc_motion`], [`Drive`]: kinematics and the motor model,
//!   integrated exactly (circular arcs over piecewise-constant wheel speeds).
//! - [`Planner`] / [`TrajectoryKind`]: mixed and degenerate trajectories.
//! - [`EncoderConfig`], [`FaultConfig`]: encoder counts and injected faults.
//! - The realistic mode, off by default: [`RealisticLaser`] (sparse returns, mixed
//!   pixels, range bias and drift, noise growing with range), [`Surface`]s (dark,
//!   glass) and [`Walker`]s in the cluttered worlds ([`World::office_cluttered`],
//!   [`World::hall_cluttered`]), and the presets of real sensor classes
//!   ([`REALISTIC_PRESETS`]; docs/realistic-presets.md).
//!
//! And the whole: [`SimConfig`] (or [`SimConfig::preset`]) → [`simulate`] →
//! [`SimRun`] (every record with its truth, in memory) → [`SimRun::write_log`] and
//! [`SimRun::write_truth`] (or [`SimRun::to_log`] for the reader's data model without
//! text). Everything is deterministic from [`SimConfig::seed`]
//! (ChaCha8 streams, one per purpose).
//!
//! ```
//! use odocal_sim::{simulate, SimConfig};
//! let mut config = SimConfig::preset("khepera").unwrap();
//! config.duration = 2.0;
//! let run = simulate(&config).unwrap();
//! assert_eq!(run.scans.len(), 20);
//! let mut log = Vec::new();
//! let summary = run.write_log(&mut log, &[]).unwrap();
//! assert_eq!(summary.scans, 20);
//! ```

#![deny(missing_docs)]

mod config;
mod drive;
mod encoder;
mod error;
mod faults;
mod in_memory;
mod kinematics;
mod laser;
mod laser_models;
mod output;
mod planner;
mod presets;
mod realistic_laser;
mod realistic_presets;
mod realistic_worlds;
mod robot_classes;
mod simulation;
mod surfaces;
mod truth;
mod world;
mod world_presets;

pub use config::SimConfig;
pub use drive::{Drive, DriveState, MotorConfig};
pub use encoder::EncoderConfig;
pub use error::SimError;
pub use faults::{FaultConfig, SlipEpisode};
pub use kinematics::{arc_motion, RobotParams};
pub use laser::LaserConfig;
pub use laser_models::LASER_MODELS;
pub use output::LogSummary;
pub use planner::{MotionLimits, Planner, TrajectoryKind, TRAJECTORY_NAMES};
pub use presets::{
    simulate_table_row, table_row_config, PresetRegistry, TableRow, BUILTIN_PRESETS,
    SECONDS_PER_SAMPLE,
};
pub use realistic_laser::RealisticLaser;
pub use realistic_presets::REALISTIC_PRESETS;
pub use simulation::{simulate, simulate_in, SimEncoderRecord, SimRun, SimScan};
pub use surfaces::{Hit, Scene, Surface, Walker};
pub use truth::{GroundTruth, TruthFaults, TruthScan, TruthSlip, TRUTH_FORMAT};
pub use world::{Segment, World};
pub use world_presets::WORLD_NAMES;
