//! The range noise a scan shows itself, on real-sensor quirks: readings repeated over
//! neighbouring rays (a third of the URG-04LX's readings on the MinesRover logs), and
//! scans too cluttered to show their noise at all.

use odocal_geom::Pose2;
use odocal_icp::{IcpError, IcpParams, Matcher, PreparedScan};

/// Deterministic standard normal numbers (xorshift + Box–Muller).
struct Normal(u64);

impl Normal {
    fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        ((self.0 >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    fn sample(&mut self) -> f64 {
        let (u, v) = (self.uniform(), self.uniform());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }
}

/// Plates three rays wide, 20° apart all around (0.5° rays, 42 cm apart at 1.2 m),
/// each tilted ±20° from facing the sensor, with `sigma` (m) of range noise: no run
/// is long enough to show the noise, and no point has four others within 30 cm.
fn plates(sigma: f64, seed: u64) -> (Vec<f32>, Vec<f64>) {
    let angles: Vec<f64> = (0..720).map(|i| (i as f64 * 0.5).to_radians()).collect();
    let mut normal = Normal(seed);
    let ranges = (0..720)
        .map(|i| {
            let k = i / 40;
            if i % 40 >= 3 {
                return 0.0;
            }
            let tilt = if k % 2 == 0 { 0.35 } else { -0.35 };
            let facing = angles[40 * k + 1] + tilt;
            let d = 1.2 + 0.1 * (k % 3) as f64;
            (d / (angles[i] - facing).cos() + sigma * normal.sample()) as f32
        })
        .collect();
    (ranges, angles)
}

#[test]
fn scans_without_straight_stretches_take_the_typical_noise() {
    let params = IcpParams::default();
    let (clean, angles) = plates(0.0, 11);
    let (noisy, _) = plates(0.003, 11);
    let reference = PreparedScan::new(&clean, &angles, 0.02, 5.6, &params).unwrap();
    let current = PreparedScan::new(&noisy, &angles, 0.02, 5.6, &params).unwrap();
    assert_eq!(reference.noise_sigma(), None);
    assert_eq!(current.noise_sigma(), None);
    // Unknown noise taken as none: a right match with 3 mm residuals is refused as a
    // "wrong alignment" (what a fifth of the MinesRover's pairs met).
    let err = Matcher::new(params.clone())
        .match_scans(&reference, &current, Pose2::IDENTITY)
        .unwrap_err();
    assert!(matches!(err, IcpError::ResidualAboveNoise { .. }), "{err}");
    // With the log's typical noise it is accepted, and right.
    let typical = IcpParams {
        typical_noise_sigma: 0.004,
        ..params
    };
    let r = Matcher::new(typical)
        .match_scans(&reference, &current, Pose2::IDENTITY)
        .unwrap();
    assert!(
        r.pose.translation_norm() < 0.003 && r.pose.theta.abs() < 0.003,
        "{}",
        r.pose
    );
}

#[test]
fn scans_without_straight_runs_show_their_noise_through_neighbourhoods() {
    // A cluttered scan: surfaces 5 rays wide at alternating ranges, too short for the
    // windows of consecutive rays to show the noise, but a point's nearest points
    // (whichever rays) lie on a line; the current scan is the same one with 3 mm of
    // range noise.
    let angles: Vec<f64> = (0..200)
        .map(|i| (-50.0 + i as f64 * 0.5).to_radians())
        .collect();
    let clean: Vec<f64> = (0..200)
        .map(|i| if (i / 5) % 2 == 0 { 1.0 } else { 1.6 })
        .collect();
    let mut normal = Normal(11);
    let noisy: Vec<f32> = clean
        .iter()
        .map(|r| (r + 0.003 * normal.sample()) as f32)
        .collect();
    let params = IcpParams::default();
    let current = PreparedScan::new(&noisy, &angles, 0.02, 5.6, &params).unwrap();
    let sigma = current
        .noise_sigma()
        .expect("the noise shown by neighbourhoods");
    assert!((0.002..0.0045).contains(&sigma), "σ {sigma}");
    // The right match is accepted (before the neighbourhoods, it was refused as a
    // wrong alignment with the noise unknown taken as none).
    let clean: Vec<f32> = clean.iter().map(|&r| r as f32).collect();
    let reference = PreparedScan::new(&clean, &angles, 0.02, 5.6, &params).unwrap();
    let r = Matcher::new(params)
        .match_scans(&reference, &current, Pose2::IDENTITY)
        .unwrap();
    assert!(
        r.pose.translation_norm() < 0.002 && r.pose.theta.abs() < 0.002,
        "{}",
        r.pose
    );
}
