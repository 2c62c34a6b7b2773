//! Wheel-slip episodes: samples where scan matching and odometry disagree in
//! rotation or in translation. The sensor turns exactly as the robot does, so
//! ŝθ = J21·Δφ_L + J22·Δφ_R whatever the laser pose; a robust straight-line fit of
//! that relation flags the samples far from it. On samples that hardly turn the sensor
//! travels as far as the robot, |ŝxy| = J11·Δφ_L + J12·Δφ_R in magnitude, whatever
//! the laser pose; a robust fit of that flags wheels that turned while the scans saw
//! less (or no) motion. Consecutive flagged samples form an episode.

use super::since;
use crate::finding::{Finding, FindingKind, Severity};
use crate::synchronized::Synchronized;
use odocal_log::Log;

/// A sample whose rotation residual exceeds this many robust σ is flagged.
pub const FLAG_SIGMAS: f64 = 5.0;
/// The robust σ is at least this (rad): below it, residuals are numerical noise.
pub const SIGMA_FLOOR_RAD: f64 = 2e-4;
/// The robust σ of the translation residual is at least this (m).
pub const SIGMA_FLOOR_M: f64 = 1e-3;
/// Samples turning less than this (rad, scan matching) enter the translation check.
pub const STRAIGHT_TURN_RAD: f64 = 0.05;
/// Flagged samples above this share of all samples make the finding a warning.
pub const WARN_SHARE: f64 = 0.05;

/// Least squares of θ on (Δφ_L, Δφ_R) over the samples not excluded.
fn fit(x: &[[f64; 2]], y: &[f64], out: &[bool]) -> Option<[f64; 2]> {
    let (mut a, mut b, mut c, mut p, mut q) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for ((xi, yi), o) in x.iter().zip(y).zip(out) {
        if *o {
            continue;
        }
        a += xi[0] * xi[0];
        b += xi[0] * xi[1];
        c += xi[1] * xi[1];
        p += xi[0] * yi;
        q += xi[1] * yi;
    }
    let det = a * c - b * b;
    (det.abs() > 1e-12 * (a * c).max(f64::MIN_POSITIVE))
        .then(|| [(c * p - b * q) / det, (a * q - b * p) / det])
}

/// Indices of the samples flagged as slipping, in rotation or in translation.
pub fn flagged(synced: &Synchronized) -> Vec<usize> {
    let mut out = flagged_in_rotation(synced);
    out.extend(flagged_in_translation(synced));
    out.sort_unstable();
    out.dedup();
    out
}

/// Flags outliers of the robust fit of `y` on `x` (samples listed in `rows`): residuals
/// beyond [`FLAG_SIGMAS`] robust σ (at least `floor`), iterated; returns indices into
/// `rows`.
fn outliers(x: &[[f64; 2]], y: &[f64], floor: f64) -> Vec<usize> {
    let n = y.len();
    if n < 20 {
        return Vec::new();
    }
    let mut out = vec![false; n];
    for _ in 0..4 {
        let Some(j) = fit(x, y, &out) else {
            return Vec::new();
        };
        let res: Vec<f64> = x
            .iter()
            .zip(y)
            .map(|(xi, yi)| yi - j[0] * xi[0] - j[1] * xi[1])
            .collect();
        let mut a: Vec<f64> = res.iter().map(|r| r.abs()).collect();
        let mid = a.len() / 2;
        let (_, med, _) = a.select_nth_unstable_by(mid, f64::total_cmp);
        let sigma = (1.4826 * *med).max(floor);
        let next: Vec<bool> = res.iter().map(|r| r.abs() > FLAG_SIGMAS * sigma).collect();
        if next == out {
            break;
        }
        out = next;
    }
    (0..n).filter(|&k| out[k]).collect()
}

/// Samples that hardly turn whose scan-matched travel disagrees with the wheels'.
/// The wheel rotations enter with the sign of the travel, so |ŝxy| is fitted on
/// (|Δφ_L|, |Δφ_R|) of samples whose wheels turn the same way.
pub fn flagged_in_translation(synced: &Synchronized) -> Vec<usize> {
    let rows: Vec<usize> = synced
        .samples
        .iter()
        .enumerate()
        .filter(|(_, s)| {
            s.icp.pose.theta.abs() < STRAIGHT_TURN_RAD && s.wheel.dphi_l * s.wheel.dphi_r > 0.0
        })
        .map(|(k, _)| k)
        .collect();
    let x: Vec<[f64; 2]> = rows
        .iter()
        .map(|&k| {
            let w = &synced.samples[k].wheel;
            [w.dphi_l.abs(), w.dphi_r.abs()]
        })
        .collect();
    let y: Vec<f64> = rows
        .iter()
        .map(|&k| {
            let p = &synced.samples[k].icp.pose;
            p.x.hypot(p.y)
        })
        .collect();
    outliers(&x, &y, SIGMA_FLOOR_M)
        .into_iter()
        .map(|i| rows[i])
        .collect()
}

/// Samples whose scan-matched rotation disagrees with the wheels'.
pub fn flagged_in_rotation(synced: &Synchronized) -> Vec<usize> {
    let x: Vec<[f64; 2]> = synced
        .samples
        .iter()
        .map(|s| [s.wheel.dphi_l, s.wheel.dphi_r])
        .collect();
    let y: Vec<f64> = synced.samples.iter().map(|s| s.icp.pose.theta).collect();
    outliers(&x, &y, SIGMA_FLOOR_RAD)
}

/// The slip episodes of the samples, with their times.
pub fn episodes(log: &Log, synced: &Synchronized) -> Option<Finding> {
    let flags = flagged(synced);
    let first_k = *flags.first()?;
    let in_translation = flagged_in_translation(synced).len();
    let s = &synced.samples;
    // Consecutive samples (pairs chain: one's end is the next one's start) join.
    let mut eps: Vec<(usize, usize)> = Vec::new();
    for &k in &flags {
        match eps.last_mut() {
            Some(e) if s[k].pair.first <= s[e.1].pair.second => e.1 = k,
            _ => eps.push((k, k)),
        }
    }
    let t_start = log.scans.scans.first().map_or(0.0, |m| m.t);
    let listed: Vec<String> = eps
        .iter()
        .take(8)
        .map(|&(a, b)| {
            format!(
                "{:.1}–{:.1} s",
                s[a].pair.t0 - t_start,
                s[b].pair.t1 - t_start
            )
        })
        .collect();
    let more = if eps.len() > 8 { ", …" } else { "" };
    let share = flags.len() as f64 / s.len() as f64;
    let line = log.scans.scans.get(s[first_k].pair.first).map(|m| m.line);
    Some(
        Finding::new(
            FindingKind::Slip,
            if share > WARN_SHARE {
                Severity::Warning
            } else {
                Severity::Info
            },
            format!(
                "scan matching and odometry disagree in rotation or translation in {} \
                 episode(s) ({} of {} samples, {:.1} %, {in_translation} of them in \
                 translation: the wheels travelled other than the scans saw the robot move; \
                 wheel slip or bad scan matches) at {}{more} (times into the log, first {}); \
                 the outlier rejection leaves such samples out; if there are many, drive \
                 slower, with gentler accelerations, on a floor with more grip",
                eps.len(),
                flags.len(),
                s.len(),
                100.0 * share,
                listed.join(", "),
                since(s[first_k].pair.t0, t_start)
            ),
        )
        .count(eps.len() as u64)
        .at(line, s[first_k].pair.t0),
    )
}
