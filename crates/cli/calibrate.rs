//! `odocal calibrate LOG [LOG …]`: raw logs in, calibrated robot out (several logs of
//! one robot are calibrated jointly).

use crate::hashing_thread::Checksum;
use crate::heading_refusal::with_joint_states_command;
use crate::input::InputArgs;
use crate::nominal::{describe, odometry_only_mode};
use crate::output_paths::{check_dir_output, check_file_output};
use crate::partial_args::PartialArgs;
use crate::progress_bar::Bar;
use crate::terminal::{errln, out, outln, write_json_stdout};
use anyhow::Context;
use odocal_log::Log;
use odocal_pipeline::{
    calibrate_log, calibrate_logs_with_lasers, laser_indices, LaserSetup, Options, SlideModel, Trim,
};
use odocal_report::{
    build_joint_report, build_report, sha256_of_input, write_html, write_outputs, NominalLaserPose,
    Provenance,
};
use std::path::PathBuf;
use std::time::Instant;

/// The outlier-trimming rule, as named on the command line (`calibrate` and `solve`).
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum TrimArg {
    /// χ² on the residuals whitened by their robust scale, iterated (the default;
    /// works at any sample count).
    Chi2,
    /// ICRA 2008: drop the worst 5 %, three times.
    Icra,
    /// The original package (T-RO 2013): p = 1 %, 4 rounds, xy or θ threshold.
    Tro,
    /// No trimming.
    None,
}

impl TrimArg {
    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            TrimArg::Chi2 => "chi2",
            TrimArg::Icra => "icra",
            TrimArg::Tro => "tro",
            TrimArg::None => "none",
        }
    }
}

impl From<TrimArg> for Trim {
    fn from(t: TrimArg) -> Trim {
        match t {
            TrimArg::Chi2 => Trim::CHI2,
            TrimArg::Icra => Trim::ICRA,
            TrimArg::Tro => Trim::TRO,
            TrimArg::None => Trim::None,
        }
    }
}

/// The odometry model of `--lateral-slip` / `--no-lateral-slip`.
fn slide_model(args: &Args) -> SlideModel {
    match (args.lateral_slip, args.no_lateral_slip) {
        (true, _) => SlideModel::Estimate,
        (_, true) => SlideModel::Off,
        _ => SlideModel::Auto,
    }
}

/// Arguments of `odocal calibrate`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub input: InputArgs,
    /// Outlier trimming rule.
    #[arg(long, value_enum, default_value = "chi2")]
    pub trim: TrimArg,
    /// Skip the maximum-likelihood refinement (closed form only).
    #[arg(long)]
    pub no_refine: bool,
    /// Use the constant-speed formulas instead of the encoder profile.
    #[arg(long)]
    pub constant_speed: bool,
    /// Weight each sample by the scan matcher's covariance of ŝ as it is (default: the
    /// noise level estimated from the residuals, shaped per sample by the matcher's
    /// covariance relative to the typical match's; the reported σ take as much of the
    /// shapes as the residuals follow).
    #[arg(long)]
    pub icp_covariance: bool,
    /// Use every scan pair the log holds: the scans STRIDE apart from every scan, not
    /// from every STRIDE-th (all phases of the pairing, calibrated together as
    /// several logs of one laser). STRIDE times the matching (at most 8 phases), for
    /// a laser pose whose σ is up to 2–3× smaller; one laser only.
    #[arg(long)]
    pub all_pairs: bool,
    /// Skid-steer robot: estimate the sideways slide in turns (v_y = −k·v·ω) as a
    /// seventh parameter in full, always (by default it is weighed in by the evidence
    /// for it). Several logs of one laser share one slide; not with several lasers.
    #[arg(long, conflicts_with = "no_lateral_slip")]
    pub lateral_slip: bool,
    /// Differential drive only: neither check for the sideways slide in turns nor
    /// estimate it.
    #[arg(long)]
    pub no_lateral_slip: bool,
    /// Estimate a constant clock offset between laser and encoders (within
    /// ±0.5 s of --time-offset, or ±--time-offset-range), before observability is judged.
    #[arg(long)]
    pub estimate_time_offset: bool,
    /// Half-width (s) of the clock-offset search, at most half the log's span;
    /// implies --estimate-time-offset.
    #[arg(long, value_name = "S", value_parser = positive_seconds)]
    pub time_offset_range: Option<f64>,
    /// Identity first guesses for every scan pair (default: odometry with a rough
    /// estimate from 300 evenly spread pairs, when the log has at least 600, or from
    /// every pair, each pair of those guessed by the motion the pair before it
    /// measured).
    #[arg(long)]
    pub identity_guess: bool,
    /// Match the scans a second time, with first guesses from the first estimate.
    #[arg(long)]
    pub second_pass: bool,
    #[command(flatten)]
    pub partial: PartialArgs,
    /// The laser's range-scale uncertainty in per cent (one σ): every calibrated
    /// distance (r_L, r_R, b, ℓx, ℓy) scales with the laser's ranges, and the data
    /// cannot tell that scale. Default: the data sheet's range accuracy of the range
    /// finder recognised from the scans (URG-04LX 1 %, RPLIDAR A1 1 %, LDS-01 5 %, …),
    /// none when it is not recognised. 0: the ranges' scale is known exact.
    #[arg(
        long,
        value_name = "PCT",
        value_parser = range_scale_percent,
        allow_negative_numbers = true
    )]
    pub laser_range_scale: Option<f64>,
    /// Scan matching uses the readings below this range (m). Default: the range the
    /// laser's data sheet states its accuracy for when the range finder is recognised
    /// (a URG-04LX reporting to 5.6 m: 4 m; an RPLIDAR A1: 12 m), else the maximum its
    /// scans declare, 4 m when they declare none. results.json: settings.matching_range_m.
    #[arg(
        long,
        value_name = "METRES",
        value_parser = positive_metres,
        allow_negative_numbers = true
    )]
    pub matching_range: Option<f64>,
    /// Give log N (its position among the LOGs, from 1) a laser of its own: its own ℓ,
    /// the wheels shared with the other logs (a laser re-mounted between recordings, or
    /// another laser of the robot logged separately). Repeatable; logs not named share
    /// the first log's laser.
    #[arg(long, value_name = "N")]
    pub own_laser: Vec<usize>,
    /// Write results.json, samples.tuple, results.html (and figures with --plots) into DIR.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// With --out: also write each figure as an SVG file.
    #[arg(long, requires = "out")]
    pub plots: bool,
    /// Write the one-page report (self-contained HTML: tables and figures) to FILE.
    #[arg(long, value_name = "FILE.html")]
    pub report: Option<PathBuf>,
    /// Print one JSON object instead of the human summary.
    #[arg(long)]
    pub json: bool,
}

/// `--own-laser` positions: each names one of the `logs` LOGs (from 1), and there are
/// at least two logs (one log has one laser).
fn check_own_laser(own: &[usize], logs: usize) -> anyhow::Result<()> {
    if let Some(&n) = own.iter().find(|&&n| n == 0 || n > logs) {
        anyhow::bail!(
            "--own-laser {n}: N is a log's position among the {logs} LOG(s) given, from 1 \
             (e.g. `odocal calibrate A.log B.log --own-laser 2` gives B.log its own laser)"
        );
    }
    if !own.is_empty() && logs < 2 {
        anyhow::bail!(
            "--own-laser gives one of several logs a laser of its own; with one log there \
             is one laser (a bag with two lasers: repeat --scan-topic)"
        );
    }
    Ok(())
}

/// A positive, finite number of seconds (for `--time-offset-range`).
fn positive_seconds(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!(
            "expected a positive number of seconds, got '{text}'"
        )),
    }
}

/// A positive, finite number of metres (for `--matching-range`).
fn positive_metres(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!(
            "expected a positive number of metres (e.g. 5.6), got '{text}'"
        )),
    }
}

/// A range-scale uncertainty in per cent (`--laser-range-scale`), as a fraction: a
/// finite number from 0 to 50.
fn range_scale_percent(text: &str) -> Result<f64, String> {
    match text.trim().trim_end_matches('%').parse::<f64>() {
        Ok(v) if v.is_finite() && (0.0..=50.0).contains(&v) => Ok(v / 100.0),
        _ => Err(format!(
            "expected the laser's range-scale uncertainty in per cent, from 0 to 50 \
             (e.g. 1 for a data sheet's ±1 % of the range), got '{text}'"
        )),
    }
}

/// A bag's nominal laser pose as the report shows it.
fn nominal_pose(l: odocal_bag::NominalLaser) -> NominalLaserPose {
    NominalLaserPose {
        source: l.source,
        base_frame: l.base_frame,
        laser_frame: l.laser_frame,
        l_x: l.x,
        l_y: l.y,
        l_theta: l.theta,
    }
}

/// The logs to calibrate, one entry per laser's log, with the path each was read
/// from, the name the messages give it, its scan topic and its input checksum.
struct LogInputs<'a> {
    logs: Vec<Log>,
    paths: Vec<&'a std::path::Path>,
    names: Vec<String>,
    topics: Vec<Option<String>>,
    checksums: Vec<Option<Checksum>>,
    /// With `--all-pairs`: which of `logs` are the phases of which log given.
    groups: Vec<odocal_pipeline::LogPhases>,
}

impl<'a> LogInputs<'a> {
    /// `--all-pairs`: every log replaced by its phases ([`odocal_pipeline::phases`]),
    /// each named by the scan its pairs start from, with its log's path, topic and
    /// checksum.
    fn into_phases(self, opts: &Options) -> anyhow::Result<Self> {
        let mut out = LogInputs {
            logs: Vec::new(),
            paths: Vec::new(),
            names: Vec::new(),
            topics: Vec::new(),
            checksums: Vec::new(),
            groups: Vec::new(),
        };
        for ((((log, path), name), topic), checksum) in self
            .logs
            .iter()
            .zip(self.paths)
            .zip(&self.names)
            .zip(&self.topics)
            .zip(&self.checksums)
        {
            let stride = odocal_pipeline::phases::stride(log, opts)?;
            let first = out.logs.len();
            for (j, phase) in odocal_pipeline::phases::phases(log, stride)?
                .into_iter()
                .enumerate()
            {
                out.logs.push(phase);
                out.paths.push(path);
                out.names.push(odocal_pipeline::phases::phase_name(name, j));
                out.topics.push(topic.clone());
                out.checksums.push(checksum.clone());
            }
            out.groups.push(odocal_pipeline::LogPhases {
                name: name.clone(),
                logs: (first..out.logs.len()).collect(),
            });
        }
        Ok(out)
    }
}

/// Runs `odocal calibrate`.
pub fn run(mut args: Args) -> anyhow::Result<()> {
    let started = Instant::now();
    // The inputs' checksums go only into the outputs that record provenance: without
    // them the summary alone is printed, and hashing would only take a core.
    let provenance = args.out.is_some() || args.report.is_some() || args.json;
    args.input.read.checksum = provenance;
    let input = &args.input;
    let pool = input.thread_pool()?;
    for log_path in input.paths() {
        if let Some(path) = &args.report {
            check_file_output(path, log_path)
                .with_context(|| format!("cannot write the report {}", path.display()))?;
        }
        if let Some(dir) = &args.out {
            check_dir_output(dir, log_path)
                .with_context(|| format!("cannot write the results into {}", dir.display()))?;
        }
    }
    let t_parse = Instant::now();
    let files = input.paths();
    check_own_laser(&args.own_laser, files.len())?;
    if args.lateral_slip && (input.read.scan_topic.len() > 1 || !args.own_laser.is_empty()) {
        anyhow::bail!(
            "--lateral-slip estimates the slide with one laser's six parameters (several \
             logs of one laser share it); several lasers are calibrated with the \
             six-parameter model only: calibrate each laser's log alone (`odocal calibrate \
             {} --lateral-slip`)",
            files
                .first()
                .map_or_else(|| "LOG".into(), |p| p.display().to_string())
        );
    }
    // On the pool's threads: the reader parses scan readings ahead on them.
    let inputs = pool.install(|| input.read_lasers())?;
    let parse_s = t_parse.elapsed().as_secs_f64();
    // One entry per laser's log: a bag read for several scan topics is one per topic.
    let several_topics = input.read.scan_topic.len() > 1;
    let log_index: Vec<usize> = inputs.iter().map(|(i, _)| *i).collect();
    let paths: Vec<&std::path::Path> = log_index.iter().map(|&i| files[i]).collect();
    let topics: Vec<Option<String>> = inputs.iter().map(|(_, r)| r.scan_topic.clone()).collect();
    let names: Vec<String> = paths
        .iter()
        .zip(&topics)
        .map(|(p, t)| match t {
            Some(t) if several_topics => format!("{} {t}", p.display()),
            _ => p.display().to_string(),
        })
        .collect();
    // A log's laser: its own with --own-laser, else its topic's with several topics.
    let laser_keys: Vec<(Option<usize>, Option<&str>)> = log_index
        .iter()
        .zip(&topics)
        .map(|(&i, t)| {
            (
                args.own_laser.contains(&(i + 1)).then_some(i),
                t.as_deref().filter(|_| several_topics),
            )
        })
        .collect();
    let laser_of_log = laser_indices(&laser_keys);
    let lasers = laser_of_log.iter().max().map_or(1, |m| m + 1);
    let constraints = args.partial.laser_constraints()?;
    if constraints.more.len() >= lasers {
        anyhow::bail!(
            "--fix/--prior NAME@{}: this calibration has {lasers} laser(s); a laser's \
             number counts from 1 in the order of the --scan-topic given, or of the logs \
             given --own-laser after the first log's laser",
            constraints.more.len() + 1
        );
    }
    // Each laser's nominal pose from its first bag with static transforms (the
    // first laser's is the one `--nominal` with three values completes).
    let nominal_of = |k: usize| {
        inputs
            .iter()
            .zip(&laser_of_log)
            .filter(|(_, &l)| l == k)
            .find_map(|((_, r), _)| r.nominal_laser.clone())
    };
    let laser = nominal_of(0);
    let other_nominal: Vec<Option<odocal_bag::NominalLaser>> =
        (1..lasers).map(nominal_of).collect();
    // The bag's wheel joint states and IMU topics, for a gyro-heading refusal.
    let heading_sources = inputs.iter().find_map(|(_, r)| r.heading_sources.clone());
    let refused = |e| match with_joint_states_command(e, heading_sources.as_ref()) {
        Ok(heading) => anyhow::Error::from(heading),
        Err(e) => crate::partial_args::with_hold_command(e),
    };
    let (mut logs, checksums): (Vec<Log>, Vec<Option<Checksum>>) =
        inputs.into_iter().map(|(_, r)| (r.log, r.checksum)).unzip();

    let initial_params = input.nominal_with_laser(laser.as_ref())?;
    let mut odometry_only = None;
    for (path, log) in paths.iter().zip(logs.iter_mut()) {
        let mode = odometry_only_mode(path, log, initial_params.as_ref())?;
        odometry_only = odometry_only.or(mode);
    }
    let mut opts = Options {
        initial_params,
        ticks_per_revolution: input.read.ticks_per_rev,
        stride: input.stride,
        use_profile: !args.constant_speed,
        use_icp_covariance: args.icp_covariance,
        time_offset: input.time_offset.unwrap_or(0.0),
        estimate_found_time_offset: input.time_offset.is_none(),
        estimate_time_offset: (args.estimate_time_offset || args.time_offset_range.is_some())
            .then_some(args.time_offset_range.unwrap_or(0.5)),
        second_pass: args.second_pass,
        bootstrap_guesses: !args.identity_guess,
        accept_weak: args.partial.accept_weak,
        odometry_only: odometry_only.is_some(),
        laser_range_scale: args.laser_range_scale,
        matching_range: args.matching_range,
        // The frame of the one laser read (several lasers' frames differ).
        laser_frame: laser
            .as_ref()
            .filter(|_| logs.len() == 1)
            .map(|l| l.laser_frame.clone()),
        lateral_slip: slide_model(&args),
        ..Options::default()
    };
    opts.solve.trim = args.trim.into();
    opts.solve.refine = !args.no_refine;
    opts.solve.constraints = constraints.shared;
    let setup = LaserSetup {
        of_log: laser_of_log.clone(),
        nominal: other_nominal
            .iter()
            .map(|n| {
                n.as_ref()
                    .map(|l| odocal_geom::Pose2::new(l.x, l.y, l.theta))
            })
            .collect(),
        constraints: constraints.more.clone(),
    };
    if opts.initial_params.is_some() {
        for (k, n) in other_nominal.iter().enumerate() {
            if let Some(l) = n {
                errln!(
                    "laser {}: nominal pose from the bag's {} ({} -> {}): l_x = {:.4} m, \
                     l_y = {:.4} m, l_theta = {:.4} rad",
                    k + 2,
                    l.source,
                    l.base_frame,
                    l.laser_frame,
                    l.x,
                    l.y,
                    l.theta
                );
            }
        }
    }

    let mut inputs = LogInputs {
        logs,
        paths,
        names,
        topics,
        checksums,
        groups: Vec::new(),
    };
    if args.all_pairs {
        if lasers > 1 {
            anyhow::bail!(
                "--all-pairs calibrates the phases of one laser's logs together; with \
                 several lasers (--own-laser, several --scan-topic) calibrate each laser's \
                 logs on their own"
            );
        }
        // Its phases are one laser's logs (`calibrate_log_phases`): `setup` is not used.
        inputs = inputs.into_phases(&opts)?;
    }
    let LogInputs {
        logs,
        paths,
        names,
        topics,
        mut checksums,
        groups,
    } = inputs;

    let bar = Bar::for_stderr();
    let (mut outcome, mut report) = if let [log] = &logs[..] {
        let outcome = pool
            .install(|| calibrate_log(log, &opts, &bar))
            .map_err(refused)?;
        let report = build_report(paths[0], log, &opts, &outcome);
        (outcome, report)
    } else {
        let named: Vec<(&str, &Log)> = names.iter().map(String::as_str).zip(&logs).collect();
        let joint = pool
            .install(|| {
                if groups.is_empty() {
                    calibrate_logs_with_lasers(&named, &setup, &opts, &bar)
                } else {
                    odocal_pipeline::calibrate_log_phases(&named, &groups, &opts, &bar)
                }
            })
            .map_err(|e| {
                let what = match &groups[..] {
                    [one] => format!("every scan pair of {} (its phases together)", one.name),
                    _ => "the joint calibration of the logs".to_string(),
                };
                match e {
                    // One laser's joint estimate refused for parameters it leaves weak:
                    // the exact command that holds them, as for one log (several
                    // lasers' holds name the first laser's parameters only: left as the
                    // refusal says).
                    odocal_pipeline::JointError::Joint(refusal)
                        if lasers == 1 && !refusal.holds().is_empty() =>
                    {
                        refused(refusal).context(what)
                    }
                    odocal_pipeline::JointError::Joint(refusal) => {
                        anyhow::Error::from(refusal).context(what)
                    }
                    // The log's own failure under its name, said once (the error's
                    // message and its source would each say it).
                    odocal_pipeline::JointError::Log { name, source, .. } => {
                        anyhow::Error::from(source).context(name)
                    }
                    e => e.into(),
                }
            })?;
        let all: Vec<&Log> = logs.iter().collect();
        let mut report = build_joint_report(&paths, &names, &topics, &all, &opts, &joint);
        for (row, n) in report
            .lasers
            .iter_mut()
            .zip(std::iter::once(&laser).chain(&other_nominal))
        {
            row.nominal = n.clone().map(nominal_pose);
        }
        if provenance {
            for ((row, path), checksum) in report.logs.iter_mut().zip(&paths).zip(&mut checksums) {
                let (sha256, bytes) = match checksum.take() {
                    Some(c) => c,
                    None => sha256_of_input(path).with_context(|| {
                        format!("cannot read {} for its checksum", path.display())
                    })?,
                };
                row.sha256 = Some(sha256.clone());
                *checksum = Some((sha256, bytes));
            }
        }
        // A log given in phases: its file's checksum, as its phases have.
        for (row, group) in report.logs_given.iter_mut().zip(&groups) {
            row.sha256 = group
                .logs
                .first()
                .and_then(|&i| checksums.get(i))
                .and_then(|c| c.as_ref().map(|(sha256, _)| sha256.clone()));
        }
        (joint.joint, report)
    };
    outcome.timing.parse = parse_s;
    report.timing_s.parse = parse_s;
    report.odometry_only = odometry_only.is_some();
    report.nominal_laser = laser.map(nominal_pose);
    if provenance {
        let (input_sha256, input_bytes) = match checksums[0].take() {
            Some(c) => c,
            None => sha256_of_input(paths[0])
                .with_context(|| format!("cannot read {} for its checksum", paths[0].display()))?,
        };
        report.provenance = Some(Provenance {
            command_line: std::env::args().collect::<Vec<_>>().join(" "),
            version: env!("CARGO_PKG_VERSION").to_string(),
            input_sha256,
            input_bytes,
            wall_time_s: started.elapsed().as_secs_f64(),
        });
    }

    // The results are printed whatever happens to --out and --report, so they are never lost.
    // On the pool's threads: the figures are drawn on them.
    let written_report = args.report.as_ref().map(|path| {
        pool.install(|| write_html(path, &opts, &outcome, &report))
            .with_context(|| format!("cannot write the report {}", path.display()))
    });
    let written = args.out.as_ref().map(|dir| {
        pool.install(|| write_outputs(dir, &opts, &outcome, &report, args.plots))
            .with_context(|| format!("cannot write the results into {}", dir.display()))
    });
    if args.json {
        let mut value = serde_json::to_value(&report)?;
        if let (Some(nominal), Some(obj)) = (&odometry_only, value.as_object_mut()) {
            obj.insert(
                "odometry_only".into(),
                serde_json::json!({
                    "nominal": {"r_l": nominal.r_l, "r_r": nominal.r_r, "b": nominal.b},
                    "note": crate::nominal::ODOMETRY_ONLY_CAVEAT,
                    "correction_factors": {
                        "r_l": report.params.r_l / nominal.r_l,
                        "r_r": report.params.r_r / nominal.r_r,
                        "b": report.params.b / nominal.b,
                    },
                }),
            );
        }
        write_json_stdout(&serde_json::to_string_pretty(&value)?)?;
    } else {
        out!("{report}")?;
        if let Some(n) = &odometry_only {
            outln!(
                "{}\ncorrection factors of the nominal: r_L x{:.5}, r_R x{:.5}, b x{:.5}",
                describe(n),
                report.params.r_l / n.r_l,
                report.params.r_r / n.r_r,
                report.params.b / n.b
            )?;
        }
    }
    match (written, &args.out) {
        (Some(Err(e)), _) => return Err(e.context("the results above were printed only")),
        (Some(Ok(())), Some(dir)) if !args.json => outln!("results written to {}", dir.display())?,
        _ => {}
    }
    match (written_report, &args.report) {
        (Some(Err(e)), _) => return Err(e.context("the results above were printed only")),
        (Some(Ok(())), Some(path)) if !args.json => outln!("report written to {}", path.display())?,
        _ => {}
    }
    Ok(())
}
