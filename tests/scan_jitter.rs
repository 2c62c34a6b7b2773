//! Laser timestamps that jitter on a clock of their own (a bag read with
//! `--use-receive-time`) are named, and no parameter is then "well determined": a
//! refusal names the jitter; with --accept-weak the numbers come as "weak". Clean
//! logs, and logs whose scans share the encoders' stamps, are not flagged.

use odocal_log::{read_carmen_from, Log, ReadOptions};
use odocal_pipeline::{calibrate_log, FindingKind, NoProgress, Options, PipelineError};
use odocal_sim::{simulate, SimConfig};
use odocal_solver::Verdict;

fn khepera_log(seed: u64) -> Log {
    let mut config = SimConfig::preset("khepera").expect("preset");
    config.duration = 60.0;
    config.seed = seed;
    let run = simulate(&config).expect("simulation runs");
    let mut bytes = Vec::new();
    run.write_log(&mut bytes, &[]).expect("log written");
    read_carmen_from(&bytes[..], "jitter.log", &ReadOptions::default()).expect("reads")
}

/// Shifts every scan timestamp by a uniform error in ±`half` s (a fixed sequence).
fn jitter_scan_stamps(log: &mut Log, half: f64) {
    let mut state: u64 = 0x9e37_79b9_7f4a_7c15;
    for s in log.scans.scans.iter_mut() {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let u = (state >> 11) as f64 / (1u64 << 53) as f64;
        s.t += half * (2.0 * u - 1.0);
    }
}

fn jitter_findings(out: &odocal_pipeline::Outcome) -> usize {
    out.health
        .iter()
        .filter(|f| f.kind == FindingKind::ReadJitter)
        .count()
}

#[test]
fn jittery_laser_stamps_are_named_and_never_well_determined() {
    let clean = khepera_log(8);
    let out = calibrate_log(&clean, &Options::default(), &NoProgress).expect("calibrates");
    assert_eq!(jitter_findings(&out), 0, "{:?}", out.health);

    let mut log = clean.clone();
    jitter_scan_stamps(&mut log, 0.010);
    match calibrate_log(&log, &Options::default(), &NoProgress) {
        Err(e @ PipelineError::NotDetermined { .. }) => {
            let text = e.to_string();
            assert!(
                text.contains("because the laser timestamps jitter"),
                "{text}"
            );
            assert!(e.holds().is_empty(), "{text}");
        }
        other => panic!("not refused for the jitter: {other:?}"),
    }
    let opts = Options {
        accept_weak: true,
        ..Options::default()
    };
    let out = calibrate_log(&log, &opts, &NoProgress).expect("numbers with --accept-weak");
    assert_eq!(jitter_findings(&out), 1, "{:?}", out.health);
    let obs = &out.calibration.observability;
    assert!(
        obs.parameters
            .iter()
            .all(|p| p.verdict != Verdict::WellDetermined),
        "{obs:?}"
    );
    assert!(
        obs.sentence.contains("laser timestamps jitter"),
        "{}",
        obs.sentence
    );
}
