//! Time per 681-ray URG-04LX pair: preparing a scan, and matching a prepared pair,
//! with the angular search and with the kiddo k-d tree. Pairs are consecutive 10 Hz
//! scans of the simulated Khepera arena, office and realistic MinesRover (sparse
//! returns, millimetre ranges; crates/sim), first guess off by ~2 mm / 0.3°.

use criterion::{criterion_group, criterion_main, Criterion};
use odocal_geom::Pose2;
use odocal_icp::{IcpParams, Matcher, NeighbourSearch, PreparedScan};
use odocal_sim::{simulate, PresetRegistry, SimRun};
use std::hint::black_box;

fn sim(preset: &str) -> SimRun {
    let mut config = PresetRegistry::builtin().get(preset).expect("preset");
    config.duration = 5.0;
    simulate(&config).expect("simulation")
}

fn guesses(run: &SimRun) -> Vec<Pose2> {
    (0..run.scans.len() - 1)
        .map(|k| {
            let t = run.scans[k].sensor.between(&run.scans[k + 1].sensor);
            // Deterministic odometry-like error.
            let s = if k % 2 == 0 { 1.0 } else { -1.0 };
            Pose2::new(t.x + 0.002 * s, t.y - 0.0015 * s, t.theta + 0.005 * s)
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    for (world, preset) in [
        ("arena", "khepera"),
        ("office", "office"),
        ("rover", "mines-rover"),
    ] {
        let run = sim(preset);
        let angles = run.config.laser.angles();
        let guesses = guesses(&run);
        for search in [NeighbourSearch::Angular, NeighbourSearch::KdTree] {
            let params = IcpParams {
                search,
                ..IcpParams::default()
            };
            let scans: Vec<PreparedScan> = run
                .scans
                .iter()
                .map(|s| PreparedScan::new(&s.ranges, &angles, 0.02, 4.0, &params).expect("scan"))
                .collect();
            let mut matcher = Matcher::new(params.clone());
            let n = guesses.len();
            let mut k = 0;
            c.bench_function(&format!("icp_pair/match/{world}/{search:?}"), |b| {
                b.iter(|| {
                    k = (k + 1) % n;
                    black_box(matcher.match_scans(&scans[k], &scans[k + 1], guesses[k]))
                })
            });
            let mut k = 0;
            c.bench_function(&format!("icp_pair/prepare/{world}/{search:?}"), |b| {
                b.iter(|| {
                    k = (k + 1) % run.scans.len();
                    black_box(PreparedScan::new(
                        &run.scans[k].ranges,
                        &angles,
                        0.02,
                        4.0,
                        &params,
                    ))
                })
            });
        }
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30).measurement_time(std::time::Duration::from_secs(3));
    targets = bench
}
criterion_main!(benches);
