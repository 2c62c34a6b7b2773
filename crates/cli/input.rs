//! The arguments `calibrate` and `match` share: the log and how to read it, the
//! robot's nominal parameters, how to pair its scans, and how many threads match them.

use crate::nominal::nominal_params;
use crate::read_args::{ReadArgs, ReadInput};
use crate::terminal::errln;
use anyhow::Context;
use odocal_bag::NominalLaser;
use odocal_solver::Params;
use std::path::{Path, PathBuf};

/// The input log and the options of reading, pairing and matching it.
#[derive(clap::Args, Debug)]
pub struct InputArgs {
    /// The log and how to read it.
    #[command(flatten)]
    pub read: ReadArgs,
    /// Further logs of the same robot (any mix of Carmen logs, JSON logs and bags, read
    /// with the same options), calibrated jointly with the first: each keeps its own
    /// clock offset, health findings and scan pairs; the parameters are shared.
    #[arg(value_name = "LOG")]
    pub more_logs: Vec<PathBuf>,
    /// Pair scans K apart (default: about 0.4 s apart at the log's scan rate).
    #[arg(long, value_name = "K")]
    pub stride: Option<usize>,
    /// Known clock offset (s): laser clock minus encoder clock. Without it the clocks
    /// are taken as recorded (offset 0), and `calibrate` estimates the offset when its
    /// check on every run finds the clocks clearly offset.
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub time_offset: Option<f64>,
    /// Threads for scan matching (calibrate: also for reading the log's scans and
    /// drawing the report; default: all cores).
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
    /// Nominal parameters "r_L,r_R,b" or "r_L,r_R,b,l_x,l_y,l_theta" (m, rad): first
    /// guesses for scan matching come from odometry with them; odometry-only inputs
    /// (odometry poses, no wheel encoders) need them to recover the wheel rotations;
    /// calibrate's figures compare them with the calibrated ones.
    #[arg(
        long,
        value_name = "LIST",
        value_delimiter = ',',
        allow_negative_numbers = true
    )]
    pub nominal: Option<Vec<f64>>,
}

impl InputArgs {
    /// A rayon pool with `--threads` threads (all cores when not given).
    pub fn thread_pool(&self) -> anyhow::Result<rayon::ThreadPool> {
        thread_pool(self.threads)
    }

    /// The parameters given with `--nominal`, checked.
    pub fn nominal(&self) -> anyhow::Result<Option<Params>> {
        self.nominal.as_deref().map(nominal_params).transpose()
    }

    /// Every log given, the first first.
    pub fn paths(&self) -> Vec<&Path> {
        std::iter::once(self.read.log.as_path())
            .chain(self.more_logs.iter().map(PathBuf::as_path))
            .collect()
    }

    /// Every log given, read once per laser ([`ReadArgs::read_input_lasers`]: a bag
    /// with several `--scan-topic` gives one input per topic), each with the position
    /// (from 0) of its log among [`InputArgs::paths`].
    pub fn read_lasers(&self) -> anyhow::Result<Vec<(usize, ReadInput)>> {
        let mut out = Vec::new();
        for (index, path) in self.paths().into_iter().enumerate() {
            let inputs = ReadArgs {
                log: path.to_path_buf(),
                ..self.read.clone()
            }
            .read_input_lasers()?;
            out.extend(inputs.into_iter().map(|i| (index, i)));
        }
        Ok(out)
    }

    /// The parameters given with `--nominal`; when they are the wheels only (three
    /// values), the laser pose is the bag's static transforms' `laser`, if any.
    /// Six values override the bag's pose.
    pub fn nominal_with_laser(
        &self,
        laser: Option<&NominalLaser>,
    ) -> anyhow::Result<Option<Params>> {
        let mut params = self.nominal()?;
        if let (Some(p), Some(l), Some(3)) =
            (&mut params, laser, self.nominal.as_ref().map(Vec::len))
        {
            *p = Params::from_vector([p.r_l, p.r_r, p.b, l.x, l.y, l.theta]);
            errln!(
                "nominal laser pose from the bag's {} ({} -> {}): \
                 l_x = {:.4} m, l_y = {:.4} m, l_theta = {:.4} rad",
                l.source,
                l.base_frame,
                l.laser_frame,
                l.x,
                l.y,
                l.theta
            );
        }
        Ok(params)
    }
}

/// Threads per core beyond which `--threads` is capped: more only adds overhead.
pub const MAX_THREADS_PER_CORE: usize = 4;

/// A rayon pool with `threads` threads (all cores when `None`); 0 is an error, and more
/// than [`MAX_THREADS_PER_CORE`] per core are capped, with a message.
pub fn thread_pool(threads: Option<usize>) -> anyhow::Result<rayon::ThreadPool> {
    if threads == Some(0) {
        anyhow::bail!("--threads must be at least 1");
    }
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let cap = MAX_THREADS_PER_CORE * cores;
    let threads = match threads {
        Some(n) if n > cap => {
            errln!(
                "note: --threads {n} capped at {cap} ({MAX_THREADS_PER_CORE} per core, {cores} \
                 core(s)); more threads than that only add overhead"
            );
            Some(cap)
        }
        t => t,
    };
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .context("cannot start the scan-matching threads")
}
