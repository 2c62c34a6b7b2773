//! `odocal calibrate LOG`: raw log in, calibrated robot out.

use anyhow::Context;
use odocal_log::{read_log, Mode, ReadOptions};
use odocal_pipeline::{build_report, calibrate_log, write_outputs, Options, Progress, Trim};
use odocal_solver::Params;
use std::path::PathBuf;
use std::time::Instant;

/// The outlier-trimming rule, as named on the command line.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum TrimArg {
    /// ICRA 2008: drop the worst 5 %, three times.
    Icra,
    /// The original package (T-RO 2013): p = 1 %, 4 rounds, xy or θ threshold.
    Tro,
    /// No trimming.
    None,
}

impl From<TrimArg> for Trim {
    fn from(t: TrimArg) -> Trim {
        match t {
            TrimArg::Icra => Trim::ICRA,
            TrimArg::Tro => Trim::TRO,
            TrimArg::None => Trim::None,
        }
    }
}

/// Arguments of `odocal calibrate`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The log (Carmen-style text with ENCODER lines, or the original package's JSON log).
    pub log: PathBuf,
    /// Encoder ticks per wheel revolution (overrides the log's PARAM).
    #[arg(long, value_name = "X")]
    pub ticks_per_rev: Option<f64>,
    /// Pair scans K apart (default: about 0.4 s apart at the log's scan rate).
    #[arg(long, value_name = "K")]
    pub stride: Option<usize>,
    /// Outlier trimming rule.
    #[arg(long, value_enum, default_value = "tro")]
    pub trim: TrimArg,
    /// Skip the maximum-likelihood refinement (closed form only).
    #[arg(long)]
    pub no_refine: bool,
    /// Use the constant-speed formulas instead of the encoder profile.
    #[arg(long)]
    pub constant_speed: bool,
    /// Weight each sample by the scan matcher's covariance of ŝ (default: noise
    /// estimated from the residuals, which is what the reported σ assume).
    #[arg(long)]
    pub icp_covariance: bool,
    /// Estimate a constant clock offset between laser and encoders (within ±0.5 s).
    #[arg(long)]
    pub estimate_time_offset: bool,
    /// Known clock offset (s): laser clock minus encoder clock.
    #[arg(
        long,
        value_name = "S",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    pub time_offset: f64,
    /// Nominal parameters "r_L,r_R,b" or "r_L,r_R,b,l_x,l_y,l_theta" (m, rad): first
    /// guesses for scan matching come from odometry with them, and the figures
    /// compare them with the calibrated ones.
    #[arg(
        long,
        value_name = "LIST",
        value_delimiter = ',',
        allow_negative_numbers = true
    )]
    pub nominal: Option<Vec<f64>>,
    /// Identity first guesses for every scan pair (default: odometry with a rough
    /// estimate from 300 evenly spread pairs, when the log has at least 600).
    #[arg(long)]
    pub identity_guess: bool,
    /// Match the scans a second time, with first guesses from the first estimate.
    #[arg(long)]
    pub second_pass: bool,
    /// Print the numbers even when some parameters are only weakly determined.
    #[arg(long)]
    pub accept_weak: bool,
    /// Threads for scan matching (default: all cores).
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
    /// Skip malformed lines (counted and reported) instead of stopping at the first.
    #[arg(long)]
    pub lenient: bool,
    /// Write results.json, samples.tuple (and figures with --plots) into DIR.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// With --out: also write SVG figures.
    #[arg(long, requires = "out")]
    pub plots: bool,
    /// Print one JSON object instead of the human summary.
    #[arg(long)]
    pub json: bool,
}

/// A progress bar on stderr, shown only when stderr is a terminal.
pub struct Bar(Option<indicatif::ProgressBar>);

impl Bar {
    /// A bar when stderr is a terminal, nothing otherwise.
    pub fn for_stderr() -> Bar {
        use std::io::IsTerminal;
        Bar(std::io::stderr()
            .is_terminal()
            .then(indicatif::ProgressBar::hidden))
    }
}

impl Progress for Bar {
    fn start(&self, stage: &str, total: usize) {
        if let Some(b) = &self.0 {
            b.set_draw_target(indicatif::ProgressDrawTarget::stderr());
            b.reset();
            b.set_length(total as u64);
            b.set_position(0);
            b.set_message(stage.to_string());
            if let Ok(style) =
                indicatif::ProgressStyle::with_template("{msg:>24} [{bar:40}] {pos}/{len} ({eta})")
            {
                b.set_style(style.progress_chars("=> "));
            }
        }
    }
    fn advance(&self) {
        if let Some(b) = &self.0 {
            b.inc(1);
        }
    }
    fn finish(&self) {
        if let Some(b) = &self.0 {
            b.finish_and_clear();
        }
    }
}

/// A rayon pool with `threads` threads (all cores when `None`).
pub fn thread_pool(threads: Option<usize>) -> anyhow::Result<rayon::ThreadPool> {
    if threads == Some(0) {
        anyhow::bail!("--threads must be at least 1");
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .context("cannot start the scan-matching threads")
}

/// Reads the log named on the command line, strict unless `lenient`, with an optional
/// `--ticks-per-rev` override (shared by `calibrate` and `match`).
pub fn read_input_log(
    path: &std::path::Path,
    lenient: bool,
    ticks_per_rev: Option<f64>,
) -> anyhow::Result<odocal_log::Log> {
    let opts = ReadOptions {
        mode: if lenient { Mode::Lenient } else { Mode::Strict },
        ticks_per_revolution: ticks_per_rev,
        ..ReadOptions::default()
    };
    // The reader's message already says everything (file, line, cause).
    read_log(path, &opts).map_err(|e| anyhow::anyhow!("{e}"))
}

/// Parameters from `--nominal`: three values (r_L, r_R, b; laser at the origin) or six.
fn nominal_params(v: &[f64]) -> anyhow::Result<Params> {
    let full = match v.len() {
        3 => [v[0], v[1], v[2], 0.0, 0.0, 0.0],
        6 => [v[0], v[1], v[2], v[3], v[4], v[5]],
        n => anyhow::bail!(
            "--nominal takes 3 values (r_L,r_R,b) or 6 (r_L,r_R,b,l_x,l_y,l_theta), got {n}"
        ),
    };
    if !(full.iter().all(|x| x.is_finite()) && full[..3].iter().all(|x| *x > 0.0)) {
        anyhow::bail!("--nominal needs positive radii and wheel distance and finite values");
    }
    Ok(Params::from_vector(full))
}

/// Runs `odocal calibrate`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let pool = thread_pool(args.threads)?;
    let t_parse = Instant::now();
    let log = read_input_log(&args.log, args.lenient, args.ticks_per_rev)?;
    let parse_s = t_parse.elapsed().as_secs_f64();

    let initial_params = args.nominal.as_deref().map(nominal_params).transpose()?;
    let mut opts = Options {
        initial_params,
        ticks_per_revolution: args.ticks_per_rev,
        stride: args.stride,
        use_profile: !args.constant_speed,
        use_icp_covariance: args.icp_covariance,
        time_offset: args.time_offset,
        estimate_time_offset: args.estimate_time_offset.then_some(0.5),
        second_pass: args.second_pass,
        bootstrap_guesses: !args.identity_guess,
        accept_weak: args.accept_weak,
        ..Options::default()
    };
    opts.solve.trim = args.trim.into();
    opts.solve.refine = !args.no_refine;

    let bar = Bar::for_stderr();
    let mut outcome = pool.install(|| calibrate_log(&log, &opts, &bar))?;
    outcome.timing.parse = parse_s;
    let report = build_report(&args.log, &log, &opts, &outcome);

    if let Some(dir) = &args.out {
        write_outputs(dir, &opts, &outcome, &report, args.plots)
            .with_context(|| format!("cannot write the results into {}", dir.display()))?;
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print!("{report}");
        if let Some(dir) = &args.out {
            println!("results written to {}", dir.display());
        }
    }
    Ok(())
}
