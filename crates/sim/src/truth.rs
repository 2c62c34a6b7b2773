//! The ground-truth file written next to a simulated log.

use crate::config::SimConfig;
use crate::output::LogSummary;
use crate::simulation::SimRun;
use crate::world::Segment;
use odocal_geom::FlatParams;
use serde::{Deserialize, Serialize};

/// Identifies the format of the truth JSON.
pub const TRUTH_FORMAT: &str = "odocal-sim-truth/1";

/// A wheel-slip episode on the log's (encoder) clock.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TruthSlip {
    /// Start (s, encoder clock, as logged).
    pub t_start: f64,
    /// End (s, encoder clock, as logged).
    pub t_end: f64,
    /// Ground-speed factor of the left wheel.
    pub factor_l: f64,
    /// Ground-speed factor of the right wheel.
    pub factor_r: f64,
}

/// The faults injected.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TruthFaults {
    /// Laser clock minus encoder clock (s), as applied (to the microsecond).
    pub clock_offset: f64,
    /// Wheel-slip episodes.
    pub slip_intervals: Vec<TruthSlip>,
    /// Timestamps of the ENCODER records left out.
    pub dropped_encoder_times: Vec<f64>,
    /// Logged timestamps of the scans left out.
    pub dropped_scan_times: Vec<f64>,
    /// 1-based line numbers of the malformed lines injected.
    pub garbage_lines: Vec<u64>,
}

/// The truth at one logged scan.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TruthScan {
    /// Timestamp as logged (s, laser clock).
    pub t: f64,
    /// True acquisition time on the encoder clock (s) = `t − clock_offset`.
    pub t_encoder: f64,
    /// True robot pose `[x, y, theta]` in the world.
    pub robot: [f64; 3],
    /// True sensor pose `[x, y, theta]` in the world (`robot ⊕ laser`).
    pub sensor: [f64; 3],
    /// True cumulative wheel rotations `[left, right]` (rad) since the start.
    pub wheel_angles: [f64; 2],
}

/// Everything about a simulated log that a calibration should recover or cope with.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GroundTruth {
    /// [`TRUTH_FORMAT`].
    pub format: String,
    /// The generator and its version.
    pub generator: String,
    /// The preset the configuration started from.
    pub preset: String,
    /// The seed.
    pub seed: u64,
    /// The true parameters.
    pub params: FlatParams,
    /// The nominal parameters the ODOM messages were computed with.
    pub nominal: FlatParams,
    /// Encoder ticks per wheel revolution.
    pub ticks_per_revolution: f64,
    /// Counter modulus, when the counters wrap.
    pub encoder_modulus: Option<u64>,
    /// Encoder counts at wheel angle 0 `[left, right]`.
    pub initial_ticks: [i64; 2],
    /// The world's name.
    pub world: String,
    /// The world's walls.
    pub segments: Vec<Segment>,
    /// The trajectory kind.
    pub trajectory: String,
    /// The faults injected.
    pub faults: TruthFaults,
    /// Counts of what the log holds.
    pub log: LogSummary,
    /// The complete configuration (reproduces the run).
    pub config: SimConfig,
    /// One entry per scan in the log, in log order.
    pub scans: Vec<TruthScan>,
}

impl GroundTruth {
    /// The truth of `run` as written with `summary`.
    pub fn new(run: &SimRun, summary: &LogSummary) -> Self {
        let c = &run.config;
        let start = (c.start_time * 1e6).round() * 1e-6;
        let slip_intervals = run
            .slips
            .iter()
            .map(|e| TruthSlip {
                t_start: start + e.start,
                t_end: start + e.end,
                factor_l: e.factors[0],
                factor_r: e.factors[1],
            })
            .collect();
        let mut scans: Vec<TruthScan> = run
            .logged_scans()
            .map(|s| TruthScan {
                t: s.t,
                t_encoder: s.t_true,
                robot: s.robot.to_array(),
                sensor: s.sensor.to_array(),
                wheel_angles: s.wheel_angles,
            })
            .collect();
        scans.sort_by(|a, b| a.t.total_cmp(&b.t));
        GroundTruth {
            format: TRUTH_FORMAT.into(),
            generator: format!("odocal-sim {}", env!("CARGO_PKG_VERSION")),
            preset: c.preset.clone(),
            seed: c.seed,
            params: c.robot.into(),
            nominal: c.nominal.into(),
            ticks_per_revolution: c.encoder.ticks_per_revolution,
            encoder_modulus: c.encoder.modulus,
            initial_ticks: c.encoder.initial_ticks,
            world: run.world.name().to_string(),
            segments: run.world.segments().to_vec(),
            trajectory: c.trajectory.name().to_string(),
            faults: TruthFaults {
                clock_offset: (c.faults.clock_offset * 1e6).round() * 1e-6,
                slip_intervals,
                dropped_encoder_times: run
                    .encoders
                    .iter()
                    .filter(|e| e.dropped)
                    .map(|e| e.t)
                    .collect(),
                dropped_scan_times: run
                    .scans
                    .iter()
                    .filter(|s| s.dropped)
                    .map(|s| s.t)
                    .collect(),
                garbage_lines: summary.garbage_lines.clone(),
            },
            log: summary.clone(),
            config: c.clone(),
            scans,
        }
    }
}
