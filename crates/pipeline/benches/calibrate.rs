//! Pipeline speed on a simulated 2-minute Khepera log (1,200 URG-04LX scans, 300
//! samples at the default stride): synchronization alone, synchronization + matching,
//! the bootstrap's matching of every pair without a nominal (runs guessed by the
//! motion before, against every pair from the identity), and the whole calibration
//! (sync, matching, trimming, refinement, covariance), on rayon's default pool. The one-hour-log figure in docs/benchmarks.md is measured
//! with the binary (see there).

use criterion::{criterion_group, criterion_main, Criterion};
use odocal_geom::Pose2;
use odocal_log::{read_carmen_from, Log, ReadOptions};
use odocal_pipeline::bootstrap_runs::{match_runs, BootstrapPair};
use odocal_pipeline::matching::{match_pairs, typical_noise_sigma, with_typical_noise};
use odocal_pipeline::sync::{default_stride, scan_pairs, EncoderTrack, SyncLimits};
use odocal_pipeline::{calibrate_log, synchronize_and_match, NoProgress, Options, Timing};
use odocal_sim::{simulate, SimConfig};
use std::hint::black_box;

fn simulated_log() -> Log {
    let mut config = SimConfig::preset("khepera-displaced").expect("preset");
    config.duration = 120.0;
    let run = simulate(&config).expect("simulation");
    let mut text = Vec::new();
    run.write_log(&mut text, &[]).expect("log text");
    read_carmen_from(&text[..], "bench", &ReadOptions::default()).expect("log reads")
}

fn pipeline(c: &mut Criterion) {
    let log = simulated_log();
    let opts = Options::default();
    let mut group = c.benchmark_group("pipeline_2min");
    group.sample_size(10);
    group.bench_function("sync", |b| {
        let times: Vec<f64> = log.scans.scans.iter().map(|s| s.t).collect();
        let enc: Vec<f64> = log.encoders.iter().map(|e| e.t).collect();
        let stride = default_stride(&times);
        let limits = SyncLimits::from_streams(&enc, &times, stride);
        let track = EncoderTrack::new(&log.encoders, 2764.8);
        b.iter(|| {
            let pairs = scan_pairs(&times, stride);
            let n = pairs
                .iter()
                .filter_map(|p| track.motion(p.t0, p.t1, &limits).ok())
                .count();
            black_box(n)
        })
    });
    group.bench_function("sync_and_match", |b| {
        b.iter(|| {
            let mut timing = Timing::default();
            let s = synchronize_and_match(&log, &opts, &NoProgress, &mut timing).expect("ok");
            black_box(s.samples.len())
        })
    });
    let mut timing = Timing::default();
    let synced = synchronize_and_match(&log, &opts, &NoProgress, &mut timing).expect("ok");
    let pairs = BootstrapPair::of_samples(&synced.samples);
    let ends: Vec<(usize, usize)> = pairs.iter().map(|p| (p.first, p.second)).collect();
    let matcher = opts.icp_for(&log);
    let icp = with_typical_noise(&matcher, typical_noise_sigma(&log.scans, &matcher));
    group.bench_function("bootstrap_runs", |b| {
        b.iter(|| black_box(match_runs(&log.scans, &pairs, &icp, || ()).len()))
    });
    group.bench_function("bootstrap_identity", |b| {
        let identity = vec![Pose2::IDENTITY; ends.len()];
        b.iter(|| black_box(match_pairs(&log.scans, &ends, &identity, &icp, || ()).len()))
    });
    group.bench_function("calibrate", |b| {
        b.iter(|| {
            let o = calibrate_log(&log, &opts, &NoProgress).expect("ok");
            black_box(o.calibration.params)
        })
    });
    group.finish();
}

criterion_group!(benches, pipeline);
criterion_main!(benches);
