//! End to end on the bundled demo log (`fixtures/demo.log`: 60 s of a simulated
//! Khepera III with a URG-04LX): reading the file, synchronization + scan matching,
//! solving (closed form, T-RO trimming, ML refinement, covariance) on the samples,
//! and the whole `read → match → solve`, on every core.

use criterion::{criterion_group, criterion_main, Criterion};
use odocal_log::{read_log, ReadOptions};
use odocal_pipeline::{calibrate_log, synchronize_and_match, NoProgress, Options, Timing};
use std::hint::black_box;
use std::path::Path;

fn bench(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/demo.log");
    if !path.exists() {
        println!(
            "notice: {} is missing; the calibrate bench is skipped",
            path.display()
        );
        return;
    }
    let read = || read_log(&path, &ReadOptions::default()).expect("the demo log reads");
    let opts = Options::default();
    let log = read();
    let synced = synchronize_and_match(&log, &opts, &NoProgress, &mut Timing::default())
        .expect("the demo log synchronizes");
    let samples: Vec<_> = synced
        .samples
        .iter()
        .map(|s| s.to_solver(opts.use_profile, opts.use_icp_covariance))
        .collect();
    println!(
        "demo log: {} scans, {} scan pairs, {} samples",
        log.scans.len(),
        synced.pairs,
        samples.len()
    );

    let mut group = c.benchmark_group("calibrate/demo");
    group.sample_size(10);
    group.bench_function("read", |b| b.iter(|| black_box(read().scans.len())));
    group.bench_function("sync_and_match", |b| {
        b.iter(|| {
            let s = synchronize_and_match(&log, &opts, &NoProgress, &mut Timing::default())
                .expect("ok");
            black_box(s.samples.len())
        })
    });
    group.bench_function("solve", |b| {
        b.iter(|| black_box(odocal_solver::calibrate(&samples, &opts.solve).expect("solves")))
    });
    group.bench_function("read_match_solve", |b| {
        b.iter(|| {
            let log = read();
            let o = calibrate_log(&log, &opts, &NoProgress).expect("calibrates");
            black_box(o.calibration.params)
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
