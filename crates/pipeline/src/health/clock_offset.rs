//! A quick check of the laser–encoder clock offset on every run: the robot's rotation
//! over each pair seen by scan matching is compared with the wheels' rotation
//! difference over the same interval shifted by δ; the δ at which they correlate best
//! is where the clocks agree. It costs a few interpolations per sample and grid point,
//! not a solve.

use crate::finding::{Finding, FindingKind};
use crate::options::Options;
use crate::sync::EncoderTrack;
use crate::synchronized::Synchronized;
use odocal_log::Log;
use rayon::prelude::*;

/// Half-width (s) of the quick check's search around the offset in use.
pub const QUICK_RANGE_S: f64 = 2.0;
/// Grid step (s) of the quick check.
pub const QUICK_STEP_S: f64 = 0.01;
/// An offset further than this (s) from the one in use is reported.
pub const LARGE_OFFSET_S: f64 = 0.05;
/// At most this many samples enter the quick check.
const MAX_SAMPLES: usize = 1000;

/// The quick check's answer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QuickOffset {
    /// The offset (s, laser clock minus encoder clock) of best agreement.
    pub offset: f64,
    /// Correlation of the two rotations there.
    pub correlation: f64,
    /// Correlation at the offset in use.
    pub correlation_in_use: f64,
}

fn correlation(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len() as f64;
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        sab += (x - ma) * (y - mb);
        saa += (x - ma) * (x - ma);
        sbb += (y - mb) * (y - mb);
    }
    let d = (saa * sbb).sqrt();
    if d > 0.0 {
        sab / d
    } else {
        f64::NAN
    }
}

/// The scan-matching rotations must spread over at least this many times their own
/// σ (the median of the matches' covariances) for the quick check to correlate
/// them with the wheels'. Below, they are the matcher's noise: on simulated 20 s
/// Khepera logs that only drive straight or only along arcs (spread 1–3 times the
/// σ; 100–280 times on logs with spins) the best of the check's 400 offsets
/// correlated 0.5–0.6 by chance, an offset of 0.4–1.9 s was "found", and the
/// refusal named it as its cause.
pub const MIN_ROTATION_SPREAD: f64 = 10.0;

/// Whether the rotations `theta` of the matches `used` vary beyond their noise
/// ([`MIN_ROTATION_SPREAD`]).
fn rotations_vary(used: &[&crate::samples::PairSample], theta: &[f64]) -> bool {
    let n = theta.len() as f64;
    let mean = theta.iter().sum::<f64>() / n;
    let spread = (theta.iter().map(|t| (t - mean).powi(2)).sum::<f64>() / n).sqrt();
    let sigmas: Vec<f64> = used
        .iter()
        .map(|s| s.icp.covariance[2][2].sqrt())
        .filter(|s| s.is_finite())
        .collect();
    super::scan_jitter::median(sigmas).is_none_or(|median| spread >= MIN_ROTATION_SPREAD * median)
}

/// The offset within `center ± range` at which scan-matching rotations and wheel
/// rotation differences correlate best; `None` with too few samples.
pub fn quick_estimate(
    log: &Log,
    synced: &Synchronized,
    center: f64,
    range: f64,
) -> Option<QuickOffset> {
    let (first, last) = (log.encoders.first()?.t, log.encoders.last()?.t);
    let every = synced.samples.len().div_ceil(MAX_SAMPLES).max(1);
    // Samples whose shifted intervals stay inside the encoder stream at every δ.
    let used: Vec<_> = synced
        .samples
        .iter()
        .step_by(every)
        .filter(|s| s.pair.t0 - center - range > first && s.pair.t1 - center + range < last)
        .collect();
    if used.len() < 20 {
        return None;
    }
    let theta: Vec<f64> = used.iter().map(|s| s.icp.pose.theta).collect();
    if !rotations_vary(&used, &theta) {
        return None;
    }
    let track = EncoderTrack::new(&log.encoders, synced.ticks_per_revolution);
    let rotation_at = |delta: f64| -> Option<Vec<f64>> {
        used.iter()
            .map(|s| {
                let (l0, r0) = track.ticks_at(s.pair.t0 - delta, f64::INFINITY).ok()?;
                let (l1, r1) = track.ticks_at(s.pair.t1 - delta, f64::INFINITY).ok()?;
                Some((r1 - r0) - (l1 - l0))
            })
            .collect()
    };
    let n = (range / QUICK_STEP_S).round() as i64;
    let deltas: Vec<f64> = (-n..=n).map(|i| center + i as f64 * QUICK_STEP_S).collect();
    // Per sample (in parallel), its wheel rotation at every grid offset: the instants
    // move one step at a time, so each is found next to the last one's records.
    let per_sample: Vec<Vec<Option<f64>>> = used
        .par_iter()
        .map(|s| {
            let (mut h0, mut h1) = (0, 0);
            deltas
                .iter()
                .map(|&d| {
                    let (l0, r0) = track
                        .ticks_at_near(s.pair.t0 - d, f64::INFINITY, &mut h0)
                        .ok()?;
                    let (l1, r1) = track
                        .ticks_at_near(s.pair.t1 - d, f64::INFINITY, &mut h1)
                        .ok()?;
                    Some((r1 - r0) - (l1 - l0))
                })
                .collect()
        })
        .collect();
    // A grid point counts when every sample has its rotation there.
    let grid: Vec<(f64, f64)> = (0..deltas.len())
        .into_par_iter()
        .filter_map(|k| {
            let rotation: Vec<f64> = per_sample.iter().map(|r| r[k]).collect::<Option<_>>()?;
            let c = correlation(&theta, &rotation);
            c.is_finite().then_some((deltas[k], c))
        })
        .collect();
    let (k, &(best, corr)) = grid
        .iter()
        .enumerate()
        .max_by(|a, b| a.1 .1.total_cmp(&b.1 .1))?;
    // Parabola through the best grid point and its neighbours.
    let offset = match (k.checked_sub(1).and_then(|j| grid.get(j)), grid.get(k + 1)) {
        (Some(&(_, a)), Some(&(_, c))) if a - 2.0 * corr + c < 0.0 => {
            best + 0.5 * QUICK_STEP_S * (a - c) / (a - 2.0 * corr + c)
        }
        _ => best,
    };
    let in_use = correlation(&theta, &rotation_at(center)?);
    Some(QuickOffset {
        offset,
        correlation: corr,
        correlation_in_use: in_use,
    })
}

/// The disagreement `1 − correlation` at the offset in use must be at least this many
/// times that at the best offset for the offset to be reported (outliers such as slip
/// move the best offset a little without such a gain). Measured on 60 s Khepera,
/// TurtleBot and Pioneer logs with and without slip (36 logs, clocks in agreement):
/// best offsets within 23 ms, gains ≤ 1.01; on the fast-robot stand-in with a 0.15 s
/// offset and turns no tighter than 10 m, gains 1.45–1.5 (they were missed at 1.5).
pub const MIN_GAIN: f64 = 1.2;

/// True when the quick estimate says the clocks are clearly offset from `in_use`.
pub fn is_large(q: &QuickOffset, in_use: f64) -> bool {
    (q.offset - in_use).abs() > LARGE_OFFSET_S
        && q.correlation > 0.5
        && (1.0 - q.correlation_in_use) >= MIN_GAIN * (1.0 - q.correlation)
}

/// The quick check's answer when the clocks look clearly offset from the offset in
/// use and no estimate was asked for; `None` otherwise.
pub fn found_offset(log: &Log, synced: &Synchronized, opts: &Options) -> Option<QuickOffset> {
    if opts.estimate_time_offset.is_some() {
        return None;
    }
    let used = synced.time_offset;
    let q = quick_estimate(log, synced, used, QUICK_RANGE_S)?;
    is_large(&q, used).then_some(q)
}

/// The warning about an offset `q` found by the quick check with `used` in use:
/// `estimated` says whether the pipeline estimates it (the offset was not given as
/// known) or only reports it.
pub fn found_offset_finding(q: &QuickOffset, used: f64, estimated: bool) -> Finding {
    let found = format!(
        "the laser clock looks offset from the encoder clock by about {:+.2} s \
         (rotations from scan matching and from the wheels agree best there: \
         correlation {:.3} against {:.3} at the {used:+.2} s used)",
        q.offset, q.correlation, q.correlation_in_use
    );
    let range = suggested_range(q.offset - used);
    let advice = if estimated {
        format!(
            "the offset was estimated with the calibration (as with \
             `--estimate-time-offset --time-offset-range {range}`; see the clock offset \
             reported); synchronize the clocks when recording, or give the offset as known \
             with `--time-offset`"
        )
    } else {
        format!(
            "the results are biased unless the offset is applied: pass `--time-offset {:.2}`, \
             or have it estimated with `odocal calibrate … --estimate-time-offset \
             --time-offset-range {range}`",
            q.offset
        )
    };
    Finding::warning(FindingKind::ClockOffset, format!("{found}; {advice}"))
}

/// Whether the clock offset estimated with the calibration, `est`, agrees with the
/// offset `used`: within three of its σ. The quick check correlates rotations over
/// a few dozen samples and, on short logs with a few spins, finds a best
/// correlation 0.05–0.23 s away by chance (simulated 20 s Khepera logs, clocks in
/// agreement: 13 of 200, 0.993 against 0.989 in use); the estimate then puts the
/// offset at 0.0002–0.0005 s ± 0.0007 s.
pub fn estimate_agrees(est: &crate::time_offset::OffsetEstimate, used: f64) -> bool {
    est.sigma
        .is_some_and(|sigma| (est.offset - used).abs() <= 3.0 * sigma)
}

/// The note when the offset `q` found by the quick check with `used` in use was
/// estimated with the calibration and the estimate `est` agrees with `used`.
pub fn unconfirmed_finding(
    q: &QuickOffset,
    used: f64,
    est: &crate::time_offset::OffsetEstimate,
) -> Finding {
    let sigma = est.sigma.unwrap_or(f64::NAN);
    Finding::note(
        FindingKind::ClockOffset,
        format!(
            "the quick check of the clocks suggested an offset of about {:+.2} s \
             (correlation {:.3} against {:.3} at the {used:+.2} s used); estimated with the \
             calibration it is {:+.4} s ± {sigma:.4} s, within 3σ of the {used:+.2} s used: \
             the clocks agree, and the log is calibrated at {used:+.2} s",
            q.offset, q.correlation, q.correlation_in_use, est.offset
        ),
    )
}

/// A search half-width (s) that comfortably holds an offset `d` from the start.
pub fn suggested_range(d: f64) -> f64 {
    ((d.abs() * 1.5 + 0.1) * 10.0).ceil() / 10.0
}
