//! End to end on the bundled demo log (`fixtures/demo.log`: 60 s of a simulated
//! Khepera III with a URG-04LX): reading the file, synchronization + scan matching,
//! solving (closed form, T-RO trimming, ML refinement, covariance) on the samples,
//! and the whole `read → match → solve`, on every core; and the reading and the
//! writing of `samples.tuple` on one thread (`*_1_thread`: the reader parses scan
//! readings ahead, and the tuples are rendered, on every thread of the pool it runs
//! in, so the difference is what the threads gain).

use criterion::{criterion_group, criterion_main, Criterion};
use odocal_log::{read_log, ReadOptions};
use odocal_pipeline::{
    calibrate_log, synchronize_and_match, write_tuples, NoProgress, Options, Timing,
};
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
    let one_thread = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("thread pool");
    group.bench_function("read", |b| b.iter(|| black_box(read().scans.len())));
    group.bench_function("read_1_thread", |b| {
        b.iter(|| black_box(one_thread.install(read).scans.len()))
    });
    let tuples = std::env::temp_dir().join(format!("odocal-bench-{}.tuple", std::process::id()));
    group.bench_function("write_tuples", |b| {
        b.iter(|| write_tuples(&tuples, &synced.samples).expect("writes"))
    });
    group.bench_function("write_tuples_1_thread", |b| {
        b.iter(|| {
            one_thread
                .install(|| write_tuples(&tuples, &synced.samples))
                .expect("writes")
        })
    });
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
    let _ = std::fs::remove_file(&tuples);
}

criterion_group!(benches, bench);
criterion_main!(benches);
