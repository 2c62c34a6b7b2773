//! Scan matching of a whole simulated log (crates/sim Khepera arena, URG-04LX, 681
//! rays at 10 Hz) with the pipeline's `match_pairs`, on a local rayon pool:
//!
//! - `match_log/every_pair/{1,N}_threads`: all 1,999 consecutive pairs of a 2,000-scan
//!   log, on 1 thread and on every core;
//! - `match_log/length/{2000,4000,8000}_scans`: the pairs the pipeline matches at its
//!   default stride (≈ 0.4 s apart, non-overlapping) for logs of 2k, 4k and 8k scans,
//!   on every core — how time grows with the log's length.
//!
//! First guesses are the identity (the pipeline's `--identity-guess` mode; by default it
//! matches a few hundred pairs from the identity and predicts the rest by odometry).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use odocal_geom::Pose2;
use odocal_icp::IcpParams;
use odocal_log::{read_carmen_from, Log, ReadOptions};
use odocal_pipeline::matching::match_pairs;
use odocal_pipeline::sync::{default_stride, scan_pairs};
use odocal_sim::{simulate, PresetRegistry};
use std::hint::black_box;

/// A simulated Khepera log of `scans` scans, read back from its text.
fn simulated_log(scans: usize) -> Log {
    let mut config = PresetRegistry::builtin().get("khepera").expect("preset");
    config.seed = 7;
    config.duration = (scans as f64 - 0.5) / config.laser.rate_hz;
    let run = simulate(&config).expect("simulation");
    let mut text = Vec::new();
    run.write_log(&mut text, &[]).expect("log text");
    let log = read_carmen_from(&text[..], "bench", &ReadOptions::default()).expect("log reads");
    assert_eq!(log.scans.len(), scans, "scans in the simulated log");
    log
}

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool")
}

fn match_all(log: &Log, pairs: &[(usize, usize)], params: &IcpParams) -> usize {
    let guesses = vec![Pose2::IDENTITY; pairs.len()];
    match_pairs(&log.scans, pairs, &guesses, params, || {})
        .iter()
        .filter(|r| r.is_ok())
        .count()
}

fn bench(c: &mut Criterion) {
    let params = IcpParams::default();
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());

    let log = simulated_log(2000);
    let every: Vec<(usize, usize)> = (0..log.scans.len() - 1).map(|i| (i, i + 1)).collect();
    let mut group = c.benchmark_group("match_log/every_pair");
    group.sample_size(10);
    group.throughput(Throughput::Elements(every.len() as u64));
    for threads in [1, cores] {
        let p = pool(threads);
        group.bench_function(
            BenchmarkId::from_parameter(format!("{threads}_threads")),
            |b| b.iter(|| p.install(|| black_box(match_all(&log, &every, &params)))),
        );
    }
    group.finish();

    let mut group = c.benchmark_group("match_log/length");
    group.sample_size(10);
    let p = pool(cores);
    for scans in [2000, 4000, 8000] {
        let log = simulated_log(scans);
        let times: Vec<f64> = log.scans.scans.iter().map(|s| s.t).collect();
        let pairs: Vec<(usize, usize)> = scan_pairs(&times, default_stride(&times))
            .iter()
            .map(|p| (p.first, p.second))
            .collect();
        group.throughput(Throughput::Elements(scans as u64));
        group.bench_function(BenchmarkId::from_parameter(format!("{scans}_scans")), |b| {
            b.iter(|| p.install(|| black_box(match_all(&log, &pairs, &params))))
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
