//! A published row reproduced in simulation: the row's parameters as the truth of
//! a simulated Khepera III log, and the whole pipeline run on that log.

use crate::table::PublishedRow;
use odocal_log::{read_carmen_from, ReadOptions};
use odocal_pipeline::{calibrate_log, Estimate, NoProgress, Options, PipelineError};
use odocal_sim::{simulate_table_row, RobotParams, SimError};
use odocal_solver::Params;
use serde::Serialize;
use std::time::Instant;

/// One published row reproduced in simulation.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Reproduction {
    /// The published row.
    pub row: PublishedRow,
    /// The simulation's true parameters ([`PublishedRow::truth`]).
    pub truth: Params,
    /// The number of samples asked of the simulation.
    pub target_samples: usize,
    /// The pipeline's result on the simulated log.
    pub estimate: Estimate,
}

/// Simulates a Khepera III with a URG-04LX whose true parameters are `truth`, long
/// enough for about `samples` pipeline samples at the default stride (the simulator's
/// Table I row configuration, `odocal_sim::table_row_config`), and returns the log text.
pub fn simulate_log_text(
    name: &str,
    truth: &Params,
    samples: usize,
    seed: u64,
) -> Result<Vec<u8>, SimError> {
    let robot = RobotParams {
        r_l: truth.r_l,
        r_r: truth.r_r,
        b: truth.b,
        laser: truth.laser,
    };
    simulate_table_row(name, &robot, samples as u64, seed)
}

/// The pipeline options of the reproduction: the defaults with the original
/// package's T-RO trimming rule, as the published results were computed.
pub fn reproduction_options() -> Options {
    let mut opts = Options::default();
    opts.solve.trim = odocal_solver::Trim::TRO;
    opts
}

/// Runs the whole pipeline (read → synchronize → match → solve) on the text of a
/// Carmen log simulated with `row`'s parameters ([`PublishedRow::truth`]) and
/// returns the comparison material. `target_samples` is the number of samples the
/// simulation was sized for. Scan matching runs on rayon's current thread pool.
pub fn reproduce_from_text(
    row: &PublishedRow,
    target_samples: usize,
    log_text: &[u8],
    opts: &Options,
) -> Result<Reproduction, PipelineError> {
    let name = format!("{}.log (simulated)", row.name);
    let t_read = Instant::now();
    let log = read_carmen_from(log_text, &name, &ReadOptions::default())?;
    let parse = t_read.elapsed().as_secs_f64();
    let mut outcome = calibrate_log(&log, opts, &NoProgress)?;
    outcome.timing.parse = parse;
    Ok(Reproduction {
        row: row.clone(),
        truth: row.truth(),
        target_samples,
        estimate: Estimate::of(&outcome),
    })
}

/// The simulation seed of a row: `seed` mixed with a hash (FNV-1a) of the row's
/// name, so a row gets the same log whichever other rows run.
pub fn row_seed(seed: u64, name: &str) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in name.bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    h ^ seed
}
