//! `calibrate` end to end (closed form + T-RO trimming + ML refinement +
//! covariance + observability) on 1k, 10k and 100k synthetic samples with
//! realistic scan-matching noise and 1 % gross outliers.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use odocal_geom::Pose2;
use odocal_solver::{calibrate, Params, Sample, SolveOptions, Trim};

#[path = "../tests/common/mod.rs"]
mod common;

fn samples(n: usize) -> Vec<Sample> {
    let truth = Params {
        r_l: 0.0305,
        r_r: 0.0298,
        b: 0.32,
        laser: Pose2::new(0.08, -0.03, 0.6),
    };
    let mut r = common::rng(7);
    let mut s = common::exact_samples(&mut r, &truth, n, 1);
    common::add_noise(&mut r, &mut s, [0.002, 0.002, 0.004]);
    for x in s.iter_mut().step_by(100) {
        x.sm = Pose2::new(x.sm.x + 0.2, x.sm.y - 0.1, x.sm.theta + 0.3);
    }
    s
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("solve");
    for n in [1_000, 10_000, 100_000] {
        let data = samples(n);
        group.throughput(Throughput::Elements(n as u64));
        if n >= 100_000 {
            group.sample_size(20);
        }
        let full = SolveOptions::default();
        group.bench_with_input(BenchmarkId::new("tro+refine", n), &data, |b, d| {
            b.iter(|| calibrate(d, &full).expect("calibration"))
        });
        let closed = SolveOptions {
            trim: Trim::TRO,
            refine: false,
            ..SolveOptions::default()
        };
        group.bench_with_input(BenchmarkId::new("tro_closed_form", n), &data, |b, d| {
            b.iter(|| calibrate(d, &closed).expect("calibration"))
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
