//! Laser timestamps that jitter around the laser's regular rate while the wheel counts
//! carry timestamps of their own (e.g. a bag read with `--use-receive-time`: each
//! message stamped when the recorder got it). A scanning laser acquires at a fixed
//! rate, so the second differences of its timestamps are stamping noise, 6σ_t² in
//! variance. Each sample then pairs the scans' motion with the wheels' over a wrong
//! interval; nothing repairs it, so the verdicts cannot be "well determined" (see
//! [`crate::run`]). Scans stamped with the very times of the encoder records (one
//! clock read for both) share the error and are left alone, also when every encoder
//! stamp is moved by one constant (an encoder clock set apart: the clock offset,
//! which is estimated, not the laser's timing).

use super::clock_offset::QUICK_RANGE_S;
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

/// The median of `v`; `None` when it is empty.
pub(crate) fn median(mut v: Vec<f64>) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    let mid = v.len() / 2;
    let (_, m, _) = v.select_nth_unstable_by(mid, f64::total_cmp);
    Some(*m)
}

/// Two timestamps this close (s) are one clock read: a microsecond, far below any
/// jitter that matters, and above the rounding of stamps written to the microsecond
/// and moved by a constant (doubles are 2.4e-7 s apart at Unix-epoch magnitudes).
const SAME_STAMP_S: f64 = 1e-6;
/// Scans whose differences to the encoder stamps propose the shared offset.
const OFFSET_SAMPLES: usize = 200;
/// Offsets tried, the differences most scans of the sample share.
const CANDIDATES: usize = 3;

/// The offset (s, laser clock minus encoder clock) at which most scans carry exactly
/// the timestamp of an encoder record moved by that one constant, among the scans the
/// encoder stream covers there (an encoder record within [`GAP_RATIO`] of its median
/// spacing); `None` when there is none. Searched within ±[`QUICK_RANGE_S`] of
/// `center` (the offset in use), the range of the quick clock-offset check.
///
/// Only the differences between laser and encoder stamps count, so an encoder clock
/// set apart by a constant leaves the answer as it is (on the real MinesRover exp1
/// with every ENCODER record moved by +0.5 s, when only an offset of zero was
/// tried, the scans were taken for stamps of their own and the finding fired at
/// 12.3 ms, as it did not on the log as recorded). A gap in the wheel counts says
/// nothing about the scans' stamps (on exp1 with 63 s of ENCODER records removed, the
/// scans of the gap were otherwise taken for stamps of their own, and the finding
/// fired at 12.3 ms).
///
/// The offsets tried are the differences between a scan's and an encoder record's
/// stamp that most of a sample of scans share (a shared clock read gives one
/// difference for nearly every scan; stamps of their own, differences all apart).
fn shared_stamp_offset(scans: &[ScanMeta], encoders: &[EncoderRecord], center: f64) -> Option<f64> {
    let mut times: Vec<f64> = encoders.iter().map(|e| e.t).collect();
    times.dedup();
    let spacing = median(
        times
            .windows(2)
            .map(|w| w[1] - w[0])
            .filter(|d| *d > 0.0)
            .collect(),
    )?;
    let reach = GAP_RATIO * spacing;
    // Every difference (laser stamp − encoder stamp) within the range, for a sample of
    // the scans.
    let every = scans.len().div_ceil(OFFSET_SAMPLES).max(1);
    let mut differences: Vec<f64> = Vec::new();
    for s in scans.iter().step_by(every) {
        let lo = times.partition_point(|t| *t < s.t - center - QUICK_RANGE_S);
        let hi = times.partition_point(|t| *t <= s.t - center + QUICK_RANGE_S);
        differences.extend(times[lo..hi].iter().map(|t| s.t - t));
    }
    differences.sort_unstable_by(f64::total_cmp);
    // How many differences lie within SAME_STAMP_S above each one.
    let mut end = 0;
    let counts: Vec<usize> = (0..differences.len())
        .map(|i| {
            end = end.max(i);
            while end < differences.len() && differences[end] <= differences[i] + SAME_STAMP_S {
                end += 1;
            }
            end - i
        })
        .collect();
    // Most scans stamped by the encoders' clock moved by `offset`.
    let shared_at = |offset: f64| {
        let (mut shared, mut covered) = (0usize, 0usize);
        for s in scans {
            let t = s.t - offset;
            let i = times.partition_point(|e| *e < t);
            let nearest = [i.checked_sub(1), Some(i)]
                .into_iter()
                .flatten()
                .filter_map(|k| times.get(k))
                .map(|e| (e - t).abs())
                .fold(f64::INFINITY, f64::min);
            if nearest <= reach {
                covered += 1;
                if nearest <= SAME_STAMP_S {
                    shared += 1;
                }
            }
        }
        2 * shared > covered
    };
    // The differences shared by the most scans of the sample, most first.
    let mut order: Vec<usize> = (0..counts.len()).collect();
    order.sort_by_key(|&i| (std::cmp::Reverse(counts[i]), i));
    let mut tried: Vec<f64> = Vec::new();
    for i in order {
        if tried.len() == CANDIDATES {
            break;
        }
        if tried
            .iter()
            .any(|d| (differences[i] - d).abs() <= 2.0 * SAME_STAMP_S)
        {
            continue;
        }
        tried.push(differences[i]);
        let offset = differences[i + counts[i] / 2];
        if shared_at(offset) {
            return Some(offset);
        }
    }
    None
}

/// The jitter of the scan timestamps, when they have stamps of their own; `None`
/// when too few scans or the scans share the encoders' stamps, as they are or moved
/// by one constant within ±[`QUICK_RANGE_S`] of `time_offset` (the offset in use, s,
/// laser clock minus encoder clock).
pub fn estimate(
    scans: &[ScanMeta],
    encoders: &[EncoderRecord],
    time_offset: f64,
) -> Option<ScanJitter> {
    if scans.len() < MIN_SCANS || shared_stamp_offset(scans, encoders, time_offset).is_some() {
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

#[cfg(test)]
mod tests {
    use super::*;
    use odocal_log::ScanKind;

    fn scan(t: f64) -> ScanMeta {
        ScanMeta {
            t,
            geometry: 0,
            offset: 0,
            kind: ScanKind::RawLaser1,
            line: 0,
            remission_offset: 0,
            num_remissions: 0,
        }
    }

    fn encoder(t: f64) -> EncoderRecord {
        EncoderRecord {
            t,
            left: 0,
            right: 0,
            line: 0,
        }
    }

    /// Scans read at irregular times (±16 ms), 10 Hz, each logged with an encoder record
    /// of the same stamp, as the MinesRover logs are.
    fn stamps(n: usize) -> Vec<f64> {
        (0..n)
            .map(|i| {
                let u = ((i as u64 + 1).wrapping_mul(6_364_136_223_846_793_005) >> 40) % 1000;
                0.1 * i as f64 + 0.016 * (u as f64 / 500.0 - 1.0)
            })
            .collect()
    }

    #[test]
    fn scans_sharing_the_encoders_stamps_are_left_alone_across_an_encoder_gap() {
        let t = stamps(1000);
        let scans: Vec<ScanMeta> = t.iter().map(|&t| scan(t)).collect();
        let all: Vec<EncoderRecord> = t.iter().map(|&t| encoder(t)).collect();
        assert_eq!(estimate(&scans, &all, 0.0), None);
        // The encoder records of 60 % of the log removed (a gap of 60 s).
        let gapped: Vec<EncoderRecord> = t
            .iter()
            .enumerate()
            .filter(|(i, _)| !(100..700).contains(i))
            .map(|(_, &t)| encoder(t))
            .collect();
        assert_eq!(estimate(&scans, &gapped, 0.0), None);
        // The same scans beside encoders of their own clock (50 Hz): the jitter shows.
        let own: Vec<EncoderRecord> = (0..5000)
            .map(|k| encoder(0.003 + 0.02 * k as f64))
            .collect();
        let j = estimate(&scans, &own, 0.0).expect("an estimate");
        assert!(j.detected(), "{j:?}");
    }

    /// Every encoder stamp moved by one constant (an encoder clock set apart) leaves
    /// the verdict on the same laser stamps as it is: shared stamps stay shared (also
    /// across a gap, and around an offset in use far from zero), and stamps of their
    /// own give the same estimate.
    #[test]
    fn an_encoder_clock_set_apart_by_a_constant_leaves_the_verdict_alone() {
        let t = stamps(1000);
        let scans: Vec<ScanMeta> = t.iter().map(|&t| scan(t)).collect();
        let own = |shift: f64| -> Vec<EncoderRecord> {
            (0..5000)
                .map(|k| encoder(0.003 + shift + 0.02 * k as f64))
                .collect()
        };
        let reference = estimate(&scans, &own(0.0), 0.0).expect("an estimate");
        for shift in [0.5, -0.5, 1.3, -1.9] {
            let moved: Vec<EncoderRecord> = t.iter().map(|&t| encoder(t + shift)).collect();
            assert_eq!(estimate(&scans, &moved, 0.0), None, "{shift}");
            let gapped: Vec<EncoderRecord> = t
                .iter()
                .enumerate()
                .filter(|(i, _)| !(100..700).contains(i))
                .map(|(_, &t)| encoder(t + shift))
                .collect();
            assert_eq!(estimate(&scans, &gapped, 0.0), None, "{shift}");
            let far: Vec<EncoderRecord> = t.iter().map(|&t| encoder(t - 20.0 + shift)).collect();
            assert_eq!(estimate(&scans, &far, 20.0), None, "{shift}");
            assert_eq!(
                estimate(&scans, &own(shift), 0.0),
                Some(reference),
                "{shift}"
            );
        }
    }
}
