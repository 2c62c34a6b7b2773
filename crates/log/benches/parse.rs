//! Parse speed of the Carmen reader on a generated log: 2,000 URG-04LX RAWLASER1 scans
//! (681 rays, 1 mm quantization) at 10 Hz and 50 Hz ENCODER records, written in memory
//! by our writer. Throughput is reported in bytes of log text per second.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use odocal_log::{read_carmen_from, LogWriter, ReadOptions, ScanGeometry};
use std::hint::black_box;

/// A deterministic log text of `scans` scans with encoders at 5 per scan.
fn generated_log(scans: usize) -> Vec<u8> {
    let geometry = ScanGeometry::urg_04lx();
    let mut w = LogWriter::new(Vec::new(), "khepera");
    w.comment("CARMEN Logfile (benchmark)").unwrap();
    w.param("robot_wheel_ticks_per_revolution", 2764.8).unwrap();
    let mut seed: u64 = 0x2545_f491_4f6c_dd1d;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed
    };
    let mut ranges = vec![0f32; geometry.num_readings()];
    let t0 = 1_190_000_000.0;
    let (mut left, mut right) = (0i64, 0i64);
    for k in 0..scans {
        for j in 0..5 {
            let t = t0 + (k * 5 + j) as f64 * 0.02 + (next() % 1000) as f64 * 1e-6;
            left += 20 + (next() % 5) as i64;
            right += 18 + (next() % 5) as i64;
            w.encoder(t, left, right).unwrap();
        }
        for r in ranges.iter_mut() {
            // Millimetre-quantized ranges between 0.1 and 4 m, with some failures (0).
            let mm = next() % 4000;
            *r = if mm < 100 { 0.0 } else { mm as f32 / 1000.0 };
        }
        w.rawlaser1(t0 + k as f64 * 0.1 + 0.05, &geometry, &ranges)
            .unwrap();
    }
    w.into_inner()
}

fn parse(c: &mut Criterion) {
    let text = generated_log(2000);
    eprintln!(
        "generated log: {} bytes, {} lines",
        text.len(),
        text.iter().filter(|&&b| b == b'\n').count()
    );
    let mut group = c.benchmark_group("carmen");
    group.throughput(Throughput::Bytes(text.len() as u64));
    group.sample_size(10);
    group.bench_function("rawlaser1_urg_2000_scans_50hz_encoders", |b| {
        b.iter(|| {
            let log = read_carmen_from(black_box(&text[..]), "bench", &ReadOptions::default())
                .expect("generated log parses");
            assert_eq!(log.scans.len(), 2000);
            log
        })
    });
    group.finish();
}

criterion_group!(benches, parse);
criterion_main!(benches);
