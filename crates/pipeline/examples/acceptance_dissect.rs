//! Are the pairs the matcher refuses on a log right matches with heavy-tailed
//! residuals, or wrong ones? Every pair `stride` scans apart is matched twice from the
//! odometry guess (sweep compensated): with the default consistency test and without
//! it. For each, the relaxed result is judged without ground truth by
//! - re-matching from perturbed starts (±3 cm along x and y, ±2°): a right match
//!   comes back to the same pose,
//! - the closure with the two half-stride matches `(i, i+s/2) ⊕ (i+s/2, i+s)`, both
//!   accepted by the default test (no figure when either is refused),
//!
//! and the figures are tallied separately for the pairs the test accepts and each
//! reason it refuses.
//!
//! `cargo run --release -p odocal-pipeline --example acceptance_dissect -- LOG STRIDE OFFSET r_l r_r b l_x l_y l_theta`
//!
//! Environment: `DUMP` prints every pair. The measured figures of the two real
//! MinesRover logs are in docs/benchmarks.md ("Why real pairs are refused").

use odocal_geom::{wrap_angle, Pose2};
use odocal_icp::{IcpParams, IcpResult, Matcher, PreparedScan};
use odocal_pipeline::matching::{typical_noise_sigma, with_typical_noise};
use odocal_pipeline::rejection::Rejection;
use odocal_pipeline::sweep::compensated_pairs;
use odocal_pipeline::sync::{EncoderTrack, SyncLimits};
use std::collections::BTreeMap;

mod common;

/// The pose difference as (mm, °).
fn apart(a: &Pose2, b: &Pose2) -> (f64, f64) {
    let d = a.between(b);
    (
        d.translation_norm() * 1e3,
        wrap_angle(d.theta).abs().to_degrees(),
    )
}

fn percentile(v: &mut [f64], q: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * q).round() as usize]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a: Vec<String> = std::env::args().collect();
    let setup = common::Setup::from_args(&a)?;
    let (log, stride, offset, params) = (&setup.log, setup.stride, setup.offset, &setup.params);
    let half = (stride / 2).max(1);
    let track = EncoderTrack::new(&log.encoders, setup.ticks);
    let limits = SyncLimits::from_streams(&setup.encoder_times(), &setup.times, stride);
    let guess = |i: usize, j: usize| setup.guess(&track, i, j);
    let mut all_pairs = Vec::new();
    for i in 0..log.scans.len().saturating_sub(stride) {
        all_pairs.extend([(i, i + stride), (i, i + half), (i + half, i + stride)]);
    }
    let (store, _) = compensated_pairs(&log.scans, &all_pairs, &track, &limits, params, offset);
    let strict = with_typical_noise(
        &IcpParams::default(),
        typical_noise_sigma(&store, &IcpParams::default()),
    );
    let relaxed = IcpParams {
        max_residual_to_noise: f64::INFINITY,
        min_matched_share: 0.0,
        ..strict.clone()
    };
    let prepared: Vec<Option<PreparedScan>> = (0..store.len())
        .map(|i| {
            let s = store.get(i)?;
            PreparedScan::new(
                s.ranges,
                &s.geometry.angles,
                s.geometry.min_range,
                s.geometry.max_range,
                &strict,
            )
            .ok()
        })
        .collect();
    let mut strict_m = Matcher::new(strict.clone());
    let mut relaxed_m = Matcher::new(relaxed.clone());
    let one = |m: &mut Matcher, i: usize, j: usize, g: Pose2| -> Result<IcpResult, String> {
        let (Some(r), Some(c)) = (&prepared[i], &prepared[j]) else {
            return Err("scan".into());
        };
        match m.match_scans(r, c, g) {
            Ok(res) if res.ill_conditioned => Err("conditioning".into()),
            Ok(res) => Ok(res),
            Err(e) => Err(Rejection::of(&e).key().to_string()),
        }
    };
    // category -> (turn °, restart mm, restart deg, closure mm, closure deg, spread/noise, share)
    let mut table: BTreeMap<String, Vec<[f64; 7]>> = BTreeMap::new();
    let dump = std::env::var("DUMP").is_ok();
    let moving = 0.05;
    for i in 0..log.scans.len().saturating_sub(stride) {
        let j = i + stride;
        let Some(g) = guess(i, j) else { continue };
        if g.translation_norm() < moving && g.theta.abs() < 0.05 {
            continue;
        }
        let category = match one(&mut strict_m, i, j, g) {
            Ok(_) => "accepted".to_string(),
            Err(e) => e,
        };
        let Ok(r) = one(&mut relaxed_m, i, j, g) else {
            table
                .entry(format!("{category} (relaxed fails too)"))
                .or_default();
            continue;
        };
        let mut worst = (0.0f64, 0.0f64);
        for (dx, dy, dt) in [
            (0.03, 0.0, 0.0),
            (-0.03, 0.0, 0.0),
            (0.0, 0.03, 0.0),
            (0.0, -0.03, 0.0),
            (0.0, 0.0, 0.035),
            (0.0, 0.0, -0.035),
        ] {
            let start = Pose2::new(r.pose.x + dx, r.pose.y + dy, r.pose.theta + dt);
            let (mm, deg) = match one(&mut relaxed_m, i, j, start) {
                Ok(p) => apart(&p.pose, &r.pose),
                Err(_) => (f64::INFINITY, f64::INFINITY),
            };
            worst = (worst.0.max(mm), worst.1.max(deg));
        }
        let closure = match (guess(i, i + half), guess(i + half, j)) {
            (Some(g1), Some(g2)) => match (
                one(&mut strict_m, i, i + half, g1),
                one(&mut strict_m, i + half, j, g2),
            ) {
                (Ok(a1), Ok(a2)) => apart(&a1.pose.compose(&a2.pose), &r.pose),
                _ => (f64::NAN, f64::NAN),
            },
            _ => (f64::NAN, f64::NAN),
        };
        let row = [
            r.pose.theta.abs().to_degrees(),
            worst.0,
            worst.1,
            closure.0,
            closure.1,
            r.residual_spread / r.noise_sigma,
            r.matched_share,
        ];
        if dump {
            println!(
                "{i:4} {j:4} {category:14} restart {:7.1} mm {:5.2}°  closure {:7.1} mm {:5.2}°  spread/noise {:5.1}  share {:.2}  guess-off {:.0} mm {:.1}°  motion {:.0} mm {:.1}°",
                row[1], row[2], row[3], row[4], row[5], row[6],
                apart(&g, &r.pose).0, apart(&g, &r.pose).1,
                r.pose.translation_norm() * 1e3, r.pose.theta.abs().to_degrees()
            );
        }
        table.entry(category).or_default().push(row);
    }
    println!("category: n | restart max mm/° (median, p90) | closure mm/° (median, p90) | spread/noise median | share median | turn per pair median °");
    for (k, rows) in &table {
        let col = |c: usize, q: f64| {
            let mut v: Vec<f64> = rows.iter().map(|r| r[c]).filter(|x| !x.is_nan()).collect();
            percentile(&mut v, q)
        };
        println!(
            "{k:32} {:4} | {:6.1} {:5.2}° ({:6.1} {:5.2}°) | {:6.1} {:5.2}° ({:6.1} {:5.2}°) | {:5.1} | {:.2} | {:.1}",
            rows.len(),
            col(1, 0.5),
            col(2, 0.5),
            col(1, 0.9),
            col(2, 0.9),
            col(3, 0.5),
            col(4, 0.5),
            col(3, 0.9),
            col(4, 0.9),
            col(5, 0.5),
            col(6, 0.5),
            col(0, 0.5)
        );
    }
    Ok(())
}
