//! Every scan pair a log holds: its phases, for `--all-pairs`.
//!
//! A log is paired at a stride `k`: scans 0 and k, k and 2k, … — one chain, so that
//! consecutive samples share a scan, which the closure of scan triples, the
//! bootstrap's chains, the matches through the scans between and the shared-scan
//! noise all rely on. The pairs `k` apart that start at scans 1, 2, …, k − 1 are left
//! unused: three quarters of a log at stride 4. They are fresh draws of the matching
//! error, which dominates the laser pose's σ on most logs: on the simulated rover and
//! TurtleBot 4 the mean of the four phases' estimates has 60–73 % less mean squared
//! error in ℓx, ℓy and ℓθ than one phase, on the Neato 40–47 % (30 seeds;
//! `docs/benchmarks.md`, stop 43).
//!
//! The phase `j` of a log is the log without its first `j` scans: its own chain of
//! pairs, with everything else (encoders, odometry, the other scans) as it is. The
//! `k` phases are calibrated together as several logs of one laser are
//! ([`crate::calibrate_logs`]): each alone first, then one joint solve that treats
//! them as independent logs and compares each with it. They share the wheels'
//! readings over the same stretches of driving: on the simulated presets their errors
//! are small beside the matching's and the joint σ stay as honest as one phase's (RMS
//! error/σ 0.47–1.40); on the real MinesRover logs they are not (residuals of
//! overlapping pairs correlated by 0.46–0.83), and the joint σ are scaled by what the
//! phases share ([`crate::phase_correlation`]).

use crate::error::PipelineError;
use crate::options::Options;
use crate::sync::chosen_stride;
use odocal_log::Log;

/// Phases at the most: a log is held once per phase in memory, and matched once.
pub const MAX_PHASES: usize = 8;

/// The stride `log`'s scans are paired at with `opts` (the one the pipeline takes).
pub fn stride(log: &Log, opts: &Options) -> Result<usize, PipelineError> {
    chosen_stride(opts.stride, &crate::run::reference_times(log))
}

/// The phases of `log` paired at `stride`: phase `j` is the log without its first
/// `j` scans (`j` = 0 … stride − 1), as many as hold a pair (at least the log as it
/// is). Refused beyond [`MAX_PHASES`], which would hold the log that many times.
pub fn phases(log: &Log, stride: usize) -> Result<Vec<Log>, PipelineError> {
    if stride > MAX_PHASES {
        return Err(PipelineError::InvalidSetting(format!(
            "--all-pairs calibrates one phase of the pairing per scan of the stride, at \
             most {MAX_PHASES} (each holds the log in memory and matches it again); this \
             log is paired {stride} scans apart: give `--stride {MAX_PHASES}` or less"
        )));
    }
    // Phase j's first pair is scans j and j + stride.
    let count = stride.min(log.scans.len().saturating_sub(stride)).max(1);
    Ok((0..count)
        .map(|j| {
            let mut phase = log.clone();
            phase.scans.scans.drain(..j);
            phase
        })
        .collect())
}

/// The name of phase `j` of the log named `name`: "exp1.log, pairs from scan 2".
pub fn phase_name(name: &str, j: usize) -> String {
    format!("{name}, pairs from scan {}", j + 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn log_of(scans: usize) -> Log {
        let mut log = Log::default();
        for i in 0..scans {
            log.scans.scans.push(odocal_log::ScanMeta {
                t: 0.1 * i as f64,
                geometry: 0,
                offset: 0,
                kind: odocal_log::ScanKind::RawLaser1,
                line: i as u64 + 1,
                remission_offset: 0,
                num_remissions: 0,
            });
        }
        log
    }

    #[test]
    fn phase_j_starts_at_scan_j_and_keeps_the_rest() {
        let log = log_of(10);
        let p = phases(&log, 4).unwrap();
        assert_eq!(p.len(), 4);
        for (j, phase) in p.iter().enumerate() {
            assert_eq!(phase.scans.scans.len(), 10 - j);
            assert_eq!(phase.scans.scans[0].line, j as u64 + 1);
        }
        assert_eq!(phase_name("a.log", 2), "a.log, pairs from scan 3");
    }

    #[test]
    fn too_many_phases_are_refused_with_the_way_out() {
        let err = phases(&log_of(100), MAX_PHASES + 1)
            .unwrap_err()
            .to_string();
        assert!(err.contains("--stride 8"), "{err}");
        // A stride of 1 is one phase: the log as it is.
        assert_eq!(phases(&log_of(3), 1).unwrap().len(), 1);
        // Only phases that hold a pair: 6 scans at stride 4 pair 0–4 and 1–5.
        assert_eq!(phases(&log_of(6), 4).unwrap().len(), 2);
        assert_eq!(phases(&log_of(3), 4).unwrap().len(), 1);
    }
}
