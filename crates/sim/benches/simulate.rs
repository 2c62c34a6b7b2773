//! Simulation speed: a 60 s Khepera run (3000 encoder records, 600 scans of 681 rays)
//! in the arena and in the office, and writing its log to memory.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use odocal_sim::{simulate, SimConfig};

fn config(preset: &str) -> SimConfig {
    let mut c = SimConfig::preset(preset).expect("preset");
    c.duration = 60.0;
    c
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("simulate_60s");
    g.sample_size(10);
    g.throughput(Throughput::Elements(600));
    for preset in ["khepera", "office", "corridor"] {
        let cfg = config(preset);
        g.bench_function(preset, |b| b.iter(|| simulate(&cfg).expect("simulation")));
    }
    let run = simulate(&config("khepera")).expect("simulation");
    g.bench_function("write_log_khepera", |b| {
        b.iter(|| {
            let mut out = Vec::with_capacity(3 << 20);
            run.write_log(&mut out, &[]).expect("write");
            out
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
