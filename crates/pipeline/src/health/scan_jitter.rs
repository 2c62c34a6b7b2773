//! Laser timestamps that jitter around the laser's regular rate while the wheel counts
//! carry timestamps of their own (e.g. a bag read with `--use-receive-time`: each
//! message stamped when the recorder got it). A scanning laser acquires at a fixed
//! rate, so the second differences of its timestamps are stamping noise, 6σ_t² in
//! variance. Each sample then pairs the scans' motion with the wheels' over a wrong
//! interval; nothing repairs it, so the verdicts cannot be "well determined" (see
//! [`crate::run`]). Scans stamped with the very times of the encoder records (one
//! clock read for both) share the error and are left alone.

use crate::finding::{Finding, FindingKind};
use odocal_log::{EncoderRecord, ScanMeta};

/// Jitter (σ_t, s) above which the laser timestamps are reported.
pub const WARN_SIGMA_S: f64 = 0.0025;
/// Scans needed for an estimate.
pub const MIN_SCANS: usize = 50;
/// Consecutive spacings beyond this multiple of the median (a dropped scan) are skipped.
const GAP_RATIO: f64 = 1.5;

/// The jitter of the laser timestamps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScanJitter {
    /// Standard deviation (s) of the timestamps around a regular rate.
    pub sigma_t: f64,
    /// Second differences it was estimated from.
    pub differences: usize,
}

fn median(mut v: Vec<f64>) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    let mid = v.len() / 2;
    let (_, m, _) = v.select_nth_unstable_by(mid, f64::total_cmp);
    Some(*m)
}

/// True when most scans carry exactly the timestamp of an encoder record.
fn shares_encoder_stamps(scans: &[ScanMeta], encoders: &[EncoderRecord]) -> bool {
    let times: Vec<f64> = encoders.iter().map(|e| e.t).collect();
    let shared = scans
        .iter()
        .filter(|s| {
            let i = times.partition_point(|t| *t < s.t - 1e-7);
            times.get(i).is_some_and(|t| (t - s.t).abs() <= 1e-7)
        })
        .count();
    2 * shared > scans.len()
}

/// The jitter of the scan timestamps, when they have stamps of their own; `None`
/// when too few scans or the scans share the encoders' stamps.
pub fn estimate(scans: &[ScanMeta], encoders: &[EncoderRecord]) -> Option<ScanJitter> {
    if scans.len() < MIN_SCANS || shares_encoder_stamps(scans, encoders) {
        return None;
    }
    let dt: Vec<f64> = scans.windows(2).map(|w| w[1].t - w[0].t).collect();
    let spacing = median(dt.clone())?;
    let d2: Vec<f64> = dt
        .windows(2)
        .filter(|w| w.iter().all(|d| *d > 0.0 && *d < GAP_RATIO * spacing))
        .map(|w| (w[1] - w[0]).abs())
        .collect();
    if d2.len() < MIN_SCANS {
        return None;
    }
    let differences = d2.len();
    let sigma_t = 1.4826 * median(d2)? / 6f64.sqrt();
    Some(ScanJitter {
        sigma_t,
        differences,
    })
}

impl ScanJitter {
    /// Large enough to matter.
    pub fn detected(&self) -> bool {
        self.sigma_t > WARN_SIGMA_S
    }

    /// The cause in words, for the finding and the verdicts.
    pub fn cause(&self) -> String {
        format!(
            "the laser timestamps jitter by σ_t ≈ {:.1} ms around the laser's regular rate \
             (from {} second differences), on a clock of their own: each scan's motion is \
             paired with the wheels' over a wrong interval and nothing repairs it, so no \
             parameter is judged well determined; use the times the scans were acquired \
             (a bag's header stamps: leave out --use-receive-time)",
            1e3 * self.sigma_t,
            self.differences
        )
    }

    /// The warning.
    pub fn finding(&self) -> Finding {
        Finding::warning(FindingKind::ReadJitter, self.cause()).count(self.differences as u64)
    }
}
