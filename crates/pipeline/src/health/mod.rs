//! The data-health stage, between reading and solving: faults real logs have, each
//! found, repaired where that is safe, and named in a [`Finding`] that says what was
//! done and what the user can do.
//!
//! Before synchronization ([`check_log`], on the log): clock jumps and records out of
//! order ([`clock`]), duplicated records and colliding timestamps ([`duplicates`]),
//! frozen scans ([`frozen`]), wheel angles wrapped to one turn ([`angle_wraps`]),
//! encoder counter wraps without a modulus ([`wraps`]),
//! physically impossible encoder jumps ([`spikes`]), gaps ([`gaps`]), counts read at
//! times that vary around their timestamps ([`read_jitter`]); timestamps or counts
//! that cannot be a real robot's are refused ([`plausibility`]). After matching
//! ([`after_matching`], on the samples): a large laser–encoder clock offset
//! ([`clock_offset`]) and wheel-slip episodes ([`slip`]); in odometry-only mode, an
//! odometry heading that does not come from the wheels ([`gyro_heading`]).

pub mod angle_wraps;
pub mod clock;
pub mod clock_offset;
pub mod duplicates;
pub mod frozen;
pub mod gaps;
pub mod gyro_heading;
pub mod plausibility;
pub mod read_jitter;
pub mod scan_jitter;
pub mod slip;
pub mod spikes;
pub mod wraps;

use crate::finding::Finding;
use crate::options::Options;
use crate::synchronized::Synchronized;
use odocal_log::{
    EncoderRecord, Log, ScanMeta, ScanStore, Stream, ValueSource, WHEEL_TICKS_PER_REVOLUTION,
};
use std::borrow::Cow;

/// The encoder records and scans in the order they appear in the file (by line; the
/// reader sorts each stream by timestamp).
pub(crate) fn in_file_order<T: Copy>(items: &[T], line: impl Fn(&T) -> u64) -> Vec<T> {
    let mut v = items.to_vec();
    v.sort_by_key(|x| line(x));
    v
}

/// Seconds from `t0` to `t`, for messages ("12.4 s into the log").
pub(crate) fn since(t: f64, t0: f64) -> String {
    format!("{:.2} s into the log", t - t0)
}

/// True when the log's counts are wheel angles read in radians (ROS joint states,
/// odometry), at [`WHEEL_TICKS_PER_REVOLUTION`] ticks per turn by convention.
fn angles_in_radians(log: &Log) -> bool {
    matches!(
        log.params.ticks_per_revolution,
        Some((t, ValueSource::Convention)) if t == WHEEL_TICKS_PER_REVOLUTION
    )
}

/// Checks the log before synchronization and repairs what is safe to repair. Returns
/// the log to use (borrowed when nothing changed) and the findings.
pub fn check_log<'a>(log: &'a Log, opts: &Options) -> (Cow<'a, Log>, Vec<Finding>) {
    let (log, findings, _) = check_log_and_read_times(log, opts);
    (log, findings)
}

/// [`check_log`], plus the standard deviation (s) of the read-time error left in
/// the counts when they were read at jittery times and smoothed (`None` when no
/// jitter was detected).
pub fn check_log_and_read_times<'a>(
    log: &'a Log,
    opts: &Options,
) -> (Cow<'a, Log>, Vec<Finding>, Option<f64>) {
    let mut findings = Vec::new();
    let mut read_time_sigma = None;
    let ticks = opts
        .ticks_per_revolution
        .or(log.params.ticks_per_revolution.as_ref().map(|t| t.0));

    let mut encoders: Vec<EncoderRecord> = log.encoders.clone();
    let mut scans: Vec<ScanMeta> = log.scans.scans.clone();
    let origin = &log.stats.origin;
    findings.extend(clock::keep_longest_run(
        &mut encoders,
        origin,
        Stream::Wheels,
        |r| r.t,
        |r| r.line,
    ));
    findings.extend(clock::keep_longest_run(
        &mut scans,
        origin,
        Stream::Scans,
        |s| s.t,
        |s| s.line,
    ));
    findings.extend(duplicates::encoders(&mut encoders, origin));
    findings.extend(duplicates::scans(&mut scans, &log.scans, origin));
    findings.extend(frozen::scans(&mut scans, &log.scans, origin));
    if angles_in_radians(log) {
        findings.extend(angle_wraps::unwrap(&mut encoders, origin));
    }
    if log.params.encoder_modulus.is_none() {
        findings.extend(wraps::unwrap(&mut encoders, origin));
    }
    findings.extend(spikes::repair(&mut encoders, ticks, origin));
    let (t, line) = (|r: &EncoderRecord| r.t, |r: &EncoderRecord| r.line);
    findings.extend(gaps::find(&encoders, origin, Stream::Wheels, t, line));
    findings.extend(gaps::find(
        &scans,
        origin,
        Stream::Scans,
        |s| s.t,
        |s| s.line,
    ));
    if let Some(j) = read_jitter::estimate(&encoders) {
        let half =
            read_jitter::smoothing_half_width(j.sigma_t, read_jitter::median_spacing(&encoders));
        if j.detected() {
            read_jitter::smooth(&mut encoders, half);
            read_time_sigma = Some(read_jitter::left_after_smoothing(j.sigma_t, half));
        }
        findings.extend(read_jitter::finding(&j, half));
    }

    let changed = encoders != log.encoders || scans != log.scans.scans;
    let log = if changed {
        Cow::Owned(Log {
            params: log.params.clone(),
            encoders,
            odom: log.odom.clone(),
            scans: ScanStore {
                geometries: log.scans.geometries.clone(),
                scans,
                ranges: log.scans.ranges.clone(),
                remissions: log.scans.remissions.clone(),
            },
            stats: log.stats.clone(),
        })
    } else {
        Cow::Borrowed(log)
    };
    (log, findings, read_time_sigma)
}

/// Checks the matched samples: a large clock offset (a quick check on every run) and
/// slip episodes.
pub fn after_matching(log: &Log, synced: &Synchronized, opts: &Options) -> Vec<Finding> {
    let mut findings = Vec::new();
    findings.extend(
        clock_offset::found_offset(log, synced, opts)
            .map(|q| clock_offset::found_offset_finding(&q, synced.time_offset, false)),
    );
    findings.extend(slip::episodes(log, synced));
    findings
}
