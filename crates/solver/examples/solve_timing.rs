//! Fastest and median wall time of single `calibrate` calls on the same synthetic
//! data as the `solve` bench — a load-robust complement to criterion's mean on a
//! shared machine. Run: `cargo run --release -p odocal-solver --example solve_timing`.

use odocal_geom::Pose2;
use odocal_solver::{calibrate, Params, SolveOptions};
use std::time::Instant;

#[path = "../tests/common/mod.rs"]
mod common;

fn main() {
    let truth = Params {
        r_l: 0.0305,
        r_r: 0.0298,
        b: 0.32,
        laser: Pose2::new(0.08, -0.03, 0.6),
    };
    for n in [1_000_usize, 10_000, 100_000] {
        let mut r = common::rng(7);
        let mut samples = common::exact_samples(&mut r, &truth, n, 1);
        common::add_noise(&mut r, &mut samples, [0.002, 0.002, 0.004]);
        for s in samples.iter_mut().step_by(100) {
            s.sm = Pose2::new(s.sm.x + 0.2, s.sm.y - 0.1, s.sm.theta + 0.3);
        }
        for refine in [true, false] {
            let options = SolveOptions {
                refine,
                ..SolveOptions::default()
            };
            let calls = (400_000 / n).max(10);
            let mut times: Vec<f64> = (0..calls)
                .map(|_| {
                    let t = Instant::now();
                    std::hint::black_box(calibrate(&samples, &options).expect("calibration"));
                    t.elapsed().as_secs_f64() * 1e3
                })
                .collect();
            times.sort_by(f64::total_cmp);
            println!(
                "{n:>7} samples, {}: min {:.3} ms, median {:.3} ms ({calls} calls)",
                if refine {
                    "T-RO + refinement"
                } else {
                    "T-RO closed form "
                },
                times[0],
                times[calls / 2]
            );
        }
    }
}
