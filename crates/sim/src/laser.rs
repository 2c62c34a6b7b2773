//! The range finder: a Hokuyo URG-04LX by default (681 rays, 2π/1024 rad apart,
//! ±120°, 4 m), with correlated Gaussian range noise, quantization and failures
//! reported as 0. The rays are fired one after another when
//! [`LaserConfig::time_increment`] is set (the sweep; see [`crate::laser_models`]).

use crate::error::SimError;
use crate::realistic_laser::RealisticLaser;
use crate::world::World;
use odocal_geom::Pose2;
use odocal_log::{LaserFields, ScanGeometry};
use rand::Rng;
use rand_distr::StandardNormal;
use serde::{Deserialize, Serialize};

/// Geometry, rate and error model of the simulated laser.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LaserConfig {
    /// Number of rays per scan.
    pub num_rays: usize,
    /// Angle of ray 0 in the sensor frame (rad).
    pub start_angle: f64,
    /// Angle between consecutive rays (rad); negative for a clockwise scanner.
    pub resolution: f64,
    /// Maximum range (m): farther walls, and readings at or above it, give 0.
    pub max_range: f64,
    /// Minimum range (m): readings at or below it give 0.
    pub min_range: f64,
    /// Scans per second.
    pub rate_hz: f64,
    /// Scan timing jitter: each scan time is moved by a uniform amount in ±jitter (s).
    pub jitter_s: f64,
    /// Standard deviation of the range noise of each reading (m); 0 = noise-free.
    pub range_sigma: f64,
    /// Number of neighbouring rays the noise is correlated over: the noise of ray `i`
    /// is the normalised sum of `correlation_rays` consecutive white-noise values, so
    /// neighbours closer than that share part of their error (1 = independent).
    pub correlation_rays: usize,
    /// Ranges are rounded to a multiple of this (m); 0 = no rounding.
    pub quantization: f64,
    /// Probability that a reading fails at random (reported as 0).
    pub dropout_probability: f64,
    /// Seconds between two consecutive rays (the sweep): ray `i` is taken at the scan's
    /// timestamp plus `i · time_increment`, from the pose the sensor has then. 0 = every
    /// ray at the timestamp (the instantaneous scans of the Khepera presets).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub time_increment: f64,
    /// Carmen laser type written in RAWLASER1 lines (0 SICK LMS, 2 Hokuyo URG, 99
    /// other).
    #[serde(default = "hokuyo_urg_type", skip_serializing_if = "is_hokuyo_urg")]
    pub laser_type: i32,
    /// The realistic error model (sparse returns, mixed pixels, bias and drift, noise
    /// growing with range; see [`RealisticLaser`]); `None` (the default) for the plain
    /// model above.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub realism: Option<RealisticLaser>,
}

// The two settings are left out of the configuration JSON at their defaults, so that
// the truth files of instantaneous URG-04LX runs stay as they were.
fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

fn is_hokuyo_urg(t: &i32) -> bool {
    *t == hokuyo_urg_type()
}

/// The Carmen laser type of a Hokuyo URG.
fn hokuyo_urg_type() -> i32 {
    2
}

impl Default for LaserConfig {
    /// The URG-04LX: 681 rays, 2π/1024 rad apart from −340·2π/1024, 0.02–4 m, 10 Hz,
    /// σ = 3 mm correlated over 4 rays, 1 mm quantization, 0.1 % random failures.
    fn default() -> Self {
        let res = std::f64::consts::TAU / 1024.0;
        LaserConfig {
            num_rays: 681,
            start_angle: -340.0 * res,
            resolution: res,
            max_range: 4.0,
            min_range: 0.02,
            rate_hz: 10.0,
            jitter_s: 0.0,
            range_sigma: 0.003,
            correlation_rays: 4,
            quantization: 0.001,
            dropout_probability: 0.001,
            time_increment: 0.0,
            laser_type: hokuyo_urg_type(),
            realism: None,
        }
    }
}

impl LaserConfig {
    /// The same sensor without any error: exact ranges (up to `f32` rounding), no
    /// quantization, no random failures.
    pub fn noise_free() -> Self {
        LaserConfig {
            range_sigma: 0.0,
            quantization: 0.0,
            dropout_probability: 0.0,
            ..LaserConfig::default()
        }
    }

    /// The scan geometry as written to the log, with its `time_increment` (and an
    /// unknown `scan_time`, as a Carmen reader sees it).
    pub fn geometry(&self) -> ScanGeometry {
        let fields = LaserFields {
            laser_type: self.laser_type,
            start_angle: self.start_angle,
            fov: (self.num_rays.saturating_sub(1)) as f64 * self.resolution,
            resolution: self.resolution,
            max_range: self.max_range,
            min_range: self.min_range,
            accuracy: self.range_sigma,
            remission_mode: 0,
        };
        ScanGeometry::new(fields, self.num_rays).with_timing(self.time_increment, 0.0)
    }

    /// Duration (s) of one sweep, first ray to last.
    pub fn sweep_duration(&self) -> f64 {
        self.num_rays.saturating_sub(1) as f64 * self.time_increment
    }

    /// Ray angles in the sensor frame (rad).
    pub fn angles(&self) -> Vec<f64> {
        (0..self.num_rays)
            .map(|i| self.start_angle + i as f64 * self.resolution)
            .collect()
    }

    /// Checks that every setting is meaningful.
    pub fn validate(&self) -> Result<(), SimError> {
        let bad = |field, value: f64, expected| {
            Err(SimError::InvalidConfig {
                field,
                value: value.to_string(),
                expected,
            })
        };
        if self.num_rays == 0 {
            return bad("laser.num_rays", 0.0, "at least one ray");
        }
        if !(self.resolution.is_finite() && self.resolution != 0.0) {
            return bad(
                "laser.resolution",
                self.resolution,
                "a non-zero angle (rad; negative for a clockwise scanner)",
            );
        }
        if !self.start_angle.is_finite() {
            return bad(
                "laser.start_angle",
                self.start_angle,
                "a finite angle (rad)",
            );
        }
        if !(self.max_range.is_finite() && self.max_range > self.min_range && self.min_range >= 0.0)
        {
            return bad(
                "laser.max_range",
                self.max_range,
                "finite, above min_range ≥ 0",
            );
        }
        if !(self.rate_hz.is_finite() && self.rate_hz > 0.0 && self.rate_hz <= 1000.0) {
            return bad("laser.rate_hz", self.rate_hz, "a rate in (0, 1000] Hz");
        }
        if !(self.jitter_s.is_finite()
            && self.jitter_s >= 0.0
            && self.jitter_s < 0.5 / self.rate_hz)
        {
            return bad(
                "laser.jitter_s",
                self.jitter_s,
                "≥ 0 and below half the scan period",
            );
        }
        if !(self.range_sigma.is_finite() && self.range_sigma >= 0.0) {
            return bad(
                "laser.range_sigma",
                self.range_sigma,
                "a standard deviation ≥ 0 (m)",
            );
        }
        if self.correlation_rays == 0 {
            return bad("laser.correlation_rays", 0.0, "at least 1 ray");
        }
        if !(self.quantization.is_finite() && self.quantization >= 0.0) {
            return bad("laser.quantization", self.quantization, "a step ≥ 0 (m)");
        }
        if !(self.time_increment.is_finite()
            && self.time_increment >= 0.0
            && self.sweep_duration() < 1.0 / self.rate_hz)
        {
            return bad(
                "laser.time_increment",
                self.time_increment,
                "≥ 0 s, the sweep shorter than the scan period",
            );
        }
        if !(0.0..=1.0).contains(&self.dropout_probability) {
            return bad(
                "laser.dropout_probability",
                self.dropout_probability,
                "a probability in [0, 1]",
            );
        }
        if let Some(r) = &self.realism {
            r.validate(self.range_sigma)?;
        }
        Ok(())
    }

    /// The exact ranges (m) seen from `sensor_pose` (world frame): `f64::INFINITY`
    /// where no wall is within `max_range`.
    pub fn true_ranges(&self, world: &World, sensor_pose: &Pose2) -> Vec<f64> {
        world.cast_fan(
            [sensor_pose.x, sensor_pose.y],
            sensor_pose.theta,
            &self.angles(),
            self.max_range,
        )
    }

    /// One scan as the sensor reports it from `sensor_pose`: the true ranges plus
    /// correlated noise, quantized, with failures (nothing within range, reading out
    /// of `(min_range, max_range)`, random dropout) reported as 0.
    ///
    /// With [`LaserConfig::noise_free`] this uses no randomness at all.
    pub fn scan<R: Rng + ?Sized>(
        &self,
        world: &World,
        sensor_pose: &Pose2,
        rng: &mut R,
    ) -> Vec<f32> {
        let truth = self.true_ranges(world, sensor_pose);
        self.measure(&truth, rng)
    }

    /// One swept scan: ray `i` cast from `sensor_poses[i]` (the sensor's pose when it
    /// fired that ray), with the error model of [`LaserConfig::scan`].
    pub fn swept_scan<R: Rng + ?Sized>(
        &self,
        world: &World,
        sensor_poses: &[Pose2],
        rng: &mut R,
    ) -> Vec<f32> {
        debug_assert_eq!(sensor_poses.len(), self.num_rays);
        let truth: Vec<f64> = self
            .angles()
            .iter()
            .zip(sensor_poses)
            .map(|(&a, p)| {
                world
                    .cast_ray([p.x, p.y], p.theta + a, self.max_range)
                    .unwrap_or(f64::INFINITY)
            })
            .collect();
        self.measure(&truth, rng)
    }

    /// The readings reported for the exact ranges `truth` (see [`LaserConfig::scan`]).
    fn measure<R: Rng + ?Sized>(&self, truth: &[f64], rng: &mut R) -> Vec<f32> {
        let noise = self.correlated_noise(rng);
        truth
            .iter()
            .zip(&noise)
            .map(|(&r, &e)| {
                let failed = self.dropout_probability > 0.0
                    && rng.random::<f64>() < self.dropout_probability;
                if !r.is_finite() || failed {
                    return 0.0;
                }
                let mut m = r + e;
                if self.quantization > 0.0 {
                    m = (m / self.quantization).round() * self.quantization;
                }
                if m <= self.min_range || m >= self.max_range {
                    0.0
                } else {
                    m as f32
                }
            })
            .collect()
    }

    /// Per-ray noise (m): a moving sum of `correlation_rays` white Gaussian values,
    /// scaled so that each ray's standard deviation is `range_sigma`.
    pub(crate) fn correlated_noise<R: Rng + ?Sized>(&self, rng: &mut R) -> Vec<f64> {
        if self.range_sigma == 0.0 {
            return vec![0.0; self.num_rays];
        }
        let w = self.correlation_rays;
        let white: Vec<f64> = (0..self.num_rays + w - 1)
            .map(|_| rng.sample::<f64, _>(StandardNormal))
            .collect();
        let scale = self.range_sigma / (w as f64).sqrt();
        let mut sum: f64 = white[..w].iter().sum();
        let mut out = Vec::with_capacity(self.num_rays);
        for i in 0..self.num_rays {
            if i > 0 {
                sum += white[i + w - 1] - white[i - 1];
            }
            out.push(sum * scale);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn geometry_is_the_urg_04lx() {
        let g = LaserConfig::default().geometry();
        let urg = ScanGeometry::urg_04lx();
        assert!(g.same_rays(&urg));
        assert!((g.angles[0] + 2.0 * std::f64::consts::PI / 3.0).abs() < 0.01);
        assert!((g.angles[680] - 2.0 * std::f64::consts::PI / 3.0).abs() < 0.01);
    }

    #[test]
    fn noise_has_the_announced_spread_and_correlation() {
        let cfg = LaserConfig::default();
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut n = 0.0;
        let (mut s2, mut c1, mut c4) = (0.0, 0.0, 0.0);
        for _ in 0..300 {
            let e = cfg.correlated_noise(&mut rng);
            for i in 0..e.len() - 4 {
                s2 += e[i] * e[i];
                c1 += e[i] * e[i + 1];
                c4 += e[i] * e[i + 4];
                n += 1.0;
            }
        }
        let sigma = (s2 / n).sqrt();
        assert!((sigma - 0.003).abs() < 0.0001, "sigma {sigma}");
        // Moving sum over 4: neighbour correlation 3/4, none at lag 4.
        assert!((c1 / s2 - 0.75).abs() < 0.02, "rho1 {}", c1 / s2);
        assert!((c4 / s2).abs() < 0.02, "rho4 {}", c4 / s2);
    }

    #[test]
    fn failures_are_zero_and_readings_quantized() {
        let world = World::corridor();
        let cfg = LaserConfig {
            dropout_probability: 0.05,
            ..LaserConfig::default()
        };
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        // Looking along the corridor: the far end is beyond 4 m.
        let scan = cfg.scan(&world, &Pose2::new(20.0, 1.0, 0.0), &mut rng);
        let zeros = scan.iter().filter(|&&r| r == 0.0).count();
        assert!(zeros > 20);
        for &r in &scan {
            if r != 0.0 {
                let mm = r as f64 * 1000.0;
                assert!((mm - mm.round()).abs() < 1e-3, "{r}");
                assert!(r > 0.02 && r < 4.0);
            }
        }
        // The ray straight ahead (index 340) never reaches the end wall.
        assert_eq!(
            LaserConfig::noise_free().scan(&world, &Pose2::new(20.0, 1.0, 0.0), &mut rng)[340],
            0.0
        );
    }
}
