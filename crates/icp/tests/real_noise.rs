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

#[test]
fn scans_without_straight_stretches_take_the_typical_noise() {
    // A cluttered scan: surfaces 5 rays wide at alternating ranges, too short to show
    // the noise; the current scan is the same one with 3 mm of range noise.
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
    let clean: Vec<f32> = clean.iter().map(|&r| r as f32).collect();
    let params = IcpParams::default();
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
        r.pose.translation_norm() < 0.002 && r.pose.theta.abs() < 0.002,
        "{}",
        r.pose
    );
}
