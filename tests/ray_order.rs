//! The order in which a scan lists its rays is a convention, not data: a laser that
//! lists them clockwise (a negative angular step, as ROS drivers of lasers mounted
//! upside down publish) holds the same scans. Listed the other way — each scan's rays
//! reversed, and for a swept scan its timing with them: the increment negated and the
//! stamp moved to the ray that now comes first — a log must calibrate to the same
//! robot. The matching then runs on decreasing angles (its k-d tree instead of the
//! angular walk, which finds the same neighbours) and the sweep's compensation on a
//! negative increment.
//!
//! Not to within rounding today (docs/benchmarks.md, stop 36):
//! - The scans' own noise and tilt estimates lay their disjoint windows from each
//!   run's first point, so they depend on the order (the real exp1 read the other way:
//!   another noise estimate in 161 of 188 scans, by up to 20 %).
//! - The real logs' calibrations are chaotic: ranges changed by two units in the
//!   last place move exp1 by 0.33σ, and by ±1 mm (the URG's quantum) in a fifth of
//!   the readings up to 0.98σ, exp2 up to 1.41σ, and exp2's ℓx then takes one of two
//!   values (stop 42). The bounds on them are that floor, and exp2's ℓx is held to
//!   its two values.
//! - The realistic rover is not chaotic (the same change moves it by less than
//!   0.01σ), and moves 0.13σ with its rays listed the other way: the bound on it.

mod common;

use common::{mines_log, rays_listed_backwards, simulated_120s};
use odocal_log::{Log, ScanStore};
use odocal_pipeline::{calibrate_log, NoProgress, Options};

/// `log` with every scan's rays listed the other way (see the module documentation).
fn rays_reversed(log: &Log) -> Log {
    let mut scans = ScanStore::default();
    for s in log.scans.iter() {
        let (mut geometry, ranges) = rays_listed_backwards(s.geometry, s.ranges);
        // Fired from the ray now listed last: the one listed first was fired last.
        geometry.time_increment = -geometry.time_increment;
        let t = s.t + s.geometry.sweep_duration();
        scans.push(t, &geometry, &ranges, s.kind, s.line);
    }
    Log {
        scans,
        ..log.clone()
    }
}

/// The six parameters and their data σ of `log`'s calibration (weak ones accepted).
fn calibrated(log: &Log) -> ([f64; 6], [f64; 6], usize) {
    let opts = Options {
        accept_weak: true,
        ..Options::default()
    };
    let o = calibrate_log(log, &opts, &NoProgress).unwrap_or_else(|e| panic!("refused: {e}"));
    let c = &o.calibration;
    (
        c.params.to_vector(),
        std::array::from_fn(|i| c.covariance[i][i].sqrt()),
        o.synced.samples.len(),
    )
}

/// `log`'s calibration with its rays listed as they are and the other way: the two
/// estimates, how far each parameter moved (in its data σ), and the two sample
/// counts.
struct BothOrders {
    listed: [f64; 6],
    reversed: [f64; 6],
    moved: [f64; 6],
    samples: (usize, usize),
}

fn both_orders(label: &str, log: &Log) -> BothOrders {
    let (p, sigma, n) = calibrated(log);
    let (q, _, m) = calibrated(&rays_reversed(log));
    println!("{label}: {n} samples, rays listed the other way {m}");
    let moved = std::array::from_fn(|i| (q[i] - p[i]) / sigma[i]);
    for (i, z) in moved.iter().enumerate() {
        println!(
            "{label} parameter {i}: {:.6} and {:.6} ({z:+.3} σ)",
            p[i], q[i]
        );
    }
    BothOrders {
        listed: p,
        reversed: q,
        moved,
        samples: (n, m),
    }
}

/// Asserts that `log` calibrates to the same parameters with its rays listed either
/// way: within `share` of their data σ, with at most `samples` samples more or fewer.
fn same_both_orders(label: &str, log: &Log, share: f64, samples: usize) {
    let b = both_orders(label, log);
    let worst = b.moved.iter().fold(0.0f64, |w, z| w.max(z.abs()));
    let (n, m) = b.samples;
    assert!(n.abs_diff(m) <= samples, "{label}: {n} and {m} samples");
    assert!(worst <= share, "{label}: a parameter moved {worst:.3} σ");
}

#[test]
fn a_swept_log_calibrates_the_same_with_its_rays_listed_the_other_way() {
    // Measured: the same 283 samples, r_L +0.13σ, r_R +0.12σ, b +0.12σ, ℓy +0.09σ.
    same_both_orders("mines-rover", &simulated_120s("mines-rover", 8), 0.25, 0);
}

#[test]
fn the_real_logs_calibrate_the_same_with_their_rays_listed_the_other_way() {
    for name in ["exp1.log", "exp2.log"] {
        let Some(path) = mines_log(name) else {
            continue;
        };
        let log = odocal_log::read_log(&path, &Default::default()).unwrap();
        // Measured (stop 43, the slide weighed in): exp1 160 and 158 samples, ℓθ
        // +0.68σ, ℓx +0.46σ; exp2 120 and 122, r_L −1.43σ, r_R −1.20σ, ℓy −0.96σ, ℓx
        // −0.05σ. The chaos floor is higher than the module documentation's 0.33σ
        // (two units in the last place): with ranges changed by ±1 mm, the URG's
        // quantum, in a fifth of the readings (seven draws, the log itself among
        // them), two draws differ by up to 0.92σ for exp1 (ℓy) and 1.34σ for exp2
        // (ℓθ); 1.13σ and 1.55σ when the driver's repeated scans are redrawn too
        // (they then pair the scans in the other phase of the stride). Until stop 43
        // exp2's ℓx took one of two values 40 mm apart under such changes (the
        // slide switched on at 2σ, its k at 2.1σ): weighed in by its evidence, it
        // moves by 1.02σ at most, and is bounded with the rest.
        // The bounds are the chaos with a margin for what seven draws do not show.
        let bound = if name == "exp2.log" { 1.7 } else { 1.2 };
        let b = both_orders(name, &log);
        let (n, m) = b.samples;
        assert!(n.abs_diff(m) <= 5, "{name}: {n} and {m} samples");
        for i in 0..6 {
            assert!(
                b.moved[i].abs() <= bound,
                "{name}: parameter {i} moved {:.3} σ (listed {}, reversed {})",
                b.moved[i],
                b.listed[i],
                b.reversed[i]
            );
        }
    }
}
