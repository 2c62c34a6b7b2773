//! The realistic laser mode: what a real range finder does to a scan besides white
//! noise, for tests that need real-looking scans with ground truth.
//!
//! - Sparse returns: each surface returns a ray with its own probability (dark
//!   surfaces absorb, glass lets most rays through to what lies behind; see
//!   [`crate::Surface`]), returns fade with range and at grazing incidence, and open
//!   space beyond the maximum range returns nothing.
//! - Mixed pixels: a ray at a depth edge may return a range between the two surfaces.
//! - A range bias rising with range (`offset + quadratic · r²`: a rectangular room
//!   looks slightly curved) and a slow drift of every reading (warm-up).
//! - Noise growing with range (`σ = range_sigma + sigma_per_metre · r`).
//! - People walking about ([`crate::Walker`]), frozen during one sweep.
//!
//! Off by default ([`LaserConfig::realism`] `None`): the plain laser model and its
//! random draws are unchanged.

use crate::error::SimError;
use crate::laser::LaserConfig;
use crate::surfaces::Scene;
use crate::world::World;
use odocal_geom::Pose2;
use rand::Rng;
use serde::{Deserialize, Serialize};

/// The realistic error model's settings (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RealisticLaser {
    /// Range (m) at which half the rays hitting a matte surface squarely return: the
    /// return probability is `1 / (1 + (r / half_return_range)⁴)`.
    pub half_return_range: f64,
    /// Angle of incidence (rad from the surface normal) beyond which returns fade,
    /// linearly in its cosine, to none at grazing incidence (90°).
    pub grazing_angle: f64,
    /// Probability that a ray at a depth edge (its neighbour's range differs by more
    /// than [`RealisticLaser::depth_edge`]) returns a mixed pixel, a range drawn
    /// uniformly between the two.
    pub mixed_pixel_probability: f64,
    /// Range jump (m) between neighbouring rays that makes a depth edge.
    pub depth_edge: f64,
    /// Constant part of the range bias (m).
    pub bias_offset: f64,
    /// Range bias growing with the square of the range (m per m²).
    pub bias_quadratic: f64,
    /// Drift of every reading (m) reached after warm-up.
    pub drift: f64,
    /// Time constant (s) of the drift: `drift · (1 − exp(−t / drift_time))` at `t` s
    /// into the run.
    pub drift_time: f64,
    /// Noise growing with range: `σ(r) = range_sigma + sigma_per_metre · r` (m per m).
    pub sigma_per_metre: f64,
}

impl RealisticLaser {
    /// Checks that every setting is meaningful.
    pub fn validate(&self, range_sigma: f64) -> Result<(), SimError> {
        let bad = |field, value: f64, expected| {
            Err(SimError::InvalidConfig {
                field,
                value: value.to_string(),
                expected,
            })
        };
        let positive = [
            ("laser.realism.half_return_range", self.half_return_range),
            ("laser.realism.drift_time", self.drift_time),
        ];
        for (field, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return bad(field, v, "a positive, finite value");
            }
        }
        if !(self.grazing_angle.is_finite()
            && self.grazing_angle >= 0.0
            && self.grazing_angle < std::f64::consts::FRAC_PI_2)
        {
            return bad(
                "laser.realism.grazing_angle",
                self.grazing_angle,
                "an angle in [0, π/2) rad",
            );
        }
        if !(0.0..=1.0).contains(&self.mixed_pixel_probability) {
            return bad(
                "laser.realism.mixed_pixel_probability",
                self.mixed_pixel_probability,
                "a probability in [0, 1]",
            );
        }
        let non_negative = [
            ("laser.realism.depth_edge", self.depth_edge),
            ("laser.realism.sigma_per_metre", self.sigma_per_metre),
        ];
        for (field, v) in non_negative {
            if !(v.is_finite() && v >= 0.0) {
                return bad(field, v, "a finite value ≥ 0");
            }
        }
        for (field, v) in [
            ("laser.realism.bias_offset", self.bias_offset),
            ("laser.realism.bias_quadratic", self.bias_quadratic),
            ("laser.realism.drift", self.drift),
        ] {
            if !(v.is_finite() && v.abs() < 1.0) {
                return bad(field, v, "a finite value within ±1");
            }
        }
        if self.sigma_per_metre > 0.0 && range_sigma <= 0.0 {
            return bad(
                "laser.range_sigma",
                range_sigma,
                "> 0 when laser.realism.sigma_per_metre is set",
            );
        }
        Ok(())
    }

    /// Probability that a ray returns from a surface that returns everything, at
    /// `range` (m) and `cos_incidence`.
    pub fn return_probability(&self, range: f64, cos_incidence: f64) -> f64 {
        let by_range = 1.0 / (1.0 + (range / self.half_return_range).powi(4));
        let cos_grazing = self.grazing_angle.cos();
        let by_incidence = if cos_incidence >= cos_grazing {
            1.0
        } else {
            cos_incidence / cos_grazing
        };
        by_range * by_incidence
    }

    /// The systematic error (m) of a reading of `range` taken `elapsed` s into the
    /// run: the bias plus the drift.
    pub fn systematic_error(&self, range: f64, elapsed: f64) -> f64 {
        self.bias_offset
            + self.bias_quadratic * range * range
            + self.drift * (1.0 - (-elapsed / self.drift_time).exp())
    }
}

impl LaserConfig {
    /// One scan with the realistic error model `realism`: ray `i` from
    /// `sensor_poses[i]` (the last pose for the rays beyond the list: one pose for an
    /// instantaneous scan), into `world` as it is `elapsed` s into the run.
    pub fn realistic_scan<R: Rng + ?Sized>(
        &self,
        realism: &RealisticLaser,
        world: &World,
        sensor_poses: &[Pose2],
        elapsed: f64,
        rng: &mut R,
    ) -> Vec<f32> {
        let Some(first) = sensor_poses.first() else {
            return vec![0.0; self.num_rays];
        };
        let last = sensor_poses[sensor_poses.len() - 1];
        // Reach: the range plus how far the sensor moves during the sweep.
        let moved = (last.x - first.x).hypot(last.y - first.y);
        let scene = Scene::new(world, [first.x, first.y], self.max_range + moved, elapsed);
        let mut truth: Vec<f64> = self
            .angles()
            .iter()
            .enumerate()
            .map(|(i, a)| {
                let p = sensor_poses.get(i).unwrap_or(&last);
                first_return(&scene, realism, p, a, self.max_range, rng)
            })
            .collect();
        mix_edges(&mut truth, realism, rng);
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
                let scale = if self.range_sigma > 0.0 {
                    1.0 + realism.sigma_per_metre * r / self.range_sigma
                } else {
                    0.0
                };
                let mut m = r + realism.systematic_error(r, elapsed) + e * scale;
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
}

/// The exact range of the surface that returns the ray at `angle` (sensor frame) from
/// `pose`, or infinity when none does (open space, absorbed, faded).
fn first_return<R: Rng + ?Sized>(
    scene: &Scene,
    realism: &RealisticLaser,
    pose: &Pose2,
    angle: &f64,
    max_range: f64,
    rng: &mut R,
) -> f64 {
    let (s, c) = (pose.theta + angle).sin_cos();
    let origin = [pose.x, pose.y];
    let mut after = 0.0;
    // A ray passes through a few panes at most.
    for _ in 0..8 {
        let Some(hit) = scene.first_hit(origin, [c, s], after, max_range) else {
            return f64::INFINITY;
        };
        let p = hit.surface.return_probability
            * realism.return_probability(hit.range, hit.cos_incidence);
        if rng.random::<f64>() < p {
            return hit.range;
        }
        if !hit.surface.see_through {
            return f64::INFINITY;
        }
        after = hit.range + 1e-9;
    }
    f64::INFINITY
}

/// Mixed pixels: at each depth edge between returning neighbours, the first ray of
/// the two may return a range drawn between them.
fn mix_edges<R: Rng + ?Sized>(ranges: &mut [f64], realism: &RealisticLaser, rng: &mut R) {
    if realism.mixed_pixel_probability == 0.0 {
        return;
    }
    let exact = ranges.to_vec();
    for (i, w) in exact.windows(2).enumerate() {
        let (a, b) = (w[0], w[1]);
        if a.is_finite()
            && b.is_finite()
            && (a - b).abs() > realism.depth_edge
            && rng.random::<f64>() < realism.mixed_pixel_probability
        {
            ranges[i] = a + rng.random::<f64>() * (b - a);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surfaces::Surface;
    use crate::world::Segment;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    fn realism() -> RealisticLaser {
        RealisticLaser {
            half_return_range: 1e6,
            grazing_angle: 1.5,
            mixed_pixel_probability: 0.0,
            depth_edge: 0.1,
            bias_offset: 0.0,
            bias_quadratic: 0.0,
            drift: 0.0,
            drift_time: 1.0,
            sigma_per_metre: 0.0,
        }
    }

    /// A wall 2 m ahead across the whole field of view, a glass pane 1 m ahead.
    fn glass_world(pane: Surface) -> World {
        World::new(
            "glass",
            vec![
                Segment::new([1.0, -10.0], [1.0, 10.0]),
                Segment::new([2.0, -20.0], [2.0, 20.0]),
            ],
        )
        .with_surfaces(vec![pane])
    }

    fn scan(laser: &LaserConfig, r: &RealisticLaser, world: &World, seed: u64) -> Vec<f32> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        laser.realistic_scan(r, world, &[Pose2::IDENTITY], 0.0, &mut rng)
    }

    #[test]
    fn glass_returns_itself_or_the_wall_behind() {
        let laser = LaserConfig::noise_free();
        let ranges = scan(&laser, &realism(), &glass_world(Surface::GLASS), 1);
        // Rays within ±60° (where the pane is squarely enough ahead): 1 m·/cos or 2 m/cos.
        let angles = laser.angles();
        let (mut pane, mut behind) = (0, 0);
        for (r, a) in ranges.iter().zip(&angles) {
            if a.abs() < 1.0 {
                let k = *r as f64 * a.cos();
                if (k - 1.0).abs() < 1e-5 {
                    pane += 1;
                } else if (k - 2.0).abs() < 1e-5 {
                    behind += 1;
                } else {
                    panic!("range {r} at {a}");
                }
            }
        }
        let share = pane as f64 / (pane + behind) as f64;
        assert!((0.05..0.16).contains(&share), "pane share {share}");
        // A dark pane absorbs what it does not return.
        let ranges = scan(&laser, &realism(), &glass_world(Surface::DARK), 2);
        let near: Vec<_> = ranges
            .iter()
            .zip(&angles)
            .filter(|(_, a)| a.abs() < 1.0)
            .map(|(r, a)| *r as f64 * a.cos())
            .collect();
        let returned = near.iter().filter(|&&x| x > 0.0).count() as f64 / near.len() as f64;
        assert!((0.22..0.38).contains(&returned), "dark returns {returned}");
        assert!(near.iter().all(|&x| x == 0.0 || (x - 1.0).abs() < 1e-5));
    }

    #[test]
    fn returns_fade_with_range_and_incidence() {
        let r = RealisticLaser {
            half_return_range: 3.0,
            grazing_angle: 1.0,
            ..realism()
        };
        assert!((r.return_probability(3.0, 1.0) - 0.5).abs() < 1e-12);
        assert!(r.return_probability(1.0, 1.0) > 0.98);
        assert!(r.return_probability(6.0, 1.0) < 0.06);
        let cos_g = 1f64.cos();
        assert_eq!(r.return_probability(0.0, cos_g + 0.01), 1.0);
        assert!((r.return_probability(0.0, cos_g / 2.0) - 0.5).abs() < 1e-12);
    }

    #[test]
    fn bias_curves_a_flat_wall_and_drift_grows() {
        let r = RealisticLaser {
            bias_offset: 0.003,
            bias_quadratic: 0.005,
            drift: 0.02,
            drift_time: 100.0,
            ..realism()
        };
        let laser = LaserConfig::noise_free();
        let world = glass_world(Surface::MATTE);
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let ranges = laser.realistic_scan(&r, &world, &[Pose2::IDENTITY], 0.0, &mut rng);
        // The wall at x = 1: measured x = r·cos(a) rises away from the centre ray.
        let angles = laser.angles();
        let x = |i: usize| ranges[i] as f64 * angles[i].cos();
        assert!((x(340) - 1.008).abs() < 1e-6, "{}", x(340));
        let at_45 = 340 + 128;
        let expected = (2f64.sqrt() + 0.003 + 0.005 * 2.0) / 2f64.sqrt();
        assert!((x(at_45) - expected).abs() < 1e-6, "{}", x(at_45));
        let late = laser.realistic_scan(&r, &world, &[Pose2::IDENTITY], 1e4, &mut rng);
        assert!((late[340] - ranges[340] - 0.02).abs() < 1e-5);
    }

    #[test]
    fn mixed_pixels_fall_between_the_surfaces() {
        // A box corner in front of a far wall: the ray at its edge straddles both.
        let world = World::new(
            "edge",
            vec![
                Segment::new([1.0, 0.0], [1.0, 1.0]),
                Segment::new([3.0, -5.0], [3.0, 5.0]),
            ],
        );
        let r = RealisticLaser {
            mixed_pixel_probability: 1.0,
            ..realism()
        };
        let laser = LaserConfig::noise_free();
        let ranges = scan(&laser, &r, &world, 4);
        let angles = laser.angles();
        let between = ranges
            .iter()
            .zip(&angles)
            .filter(|(&r, &a)| {
                let x = r as f64 * a.cos();
                r > 0.0 && x > 1.01 && x < 2.99
            })
            .count();
        assert!(between >= 1, "no mixed pixel");
        let plain = scan(&laser, &realism(), &world, 4);
        assert!(plain.iter().zip(&angles).all(|(&r, &a)| {
            let x = r as f64 * a.cos();
            r == 0.0 || (x - 1.0).abs() < 1e-5 || (x - 3.0).abs() < 1e-5
        }));
    }

    #[test]
    fn noise_grows_with_range() {
        let r = RealisticLaser {
            sigma_per_metre: 0.01,
            ..realism()
        };
        let laser = LaserConfig {
            quantization: 0.0,
            dropout_probability: 0.0,
            correlation_rays: 1,
            ..LaserConfig::default()
        };
        let spread = |d: f64| {
            let world = World::new("wall", vec![Segment::new([d, -50.0], [d, 50.0])]);
            let mut rng = ChaCha8Rng::seed_from_u64(5);
            let mut s2 = 0.0;
            let mut n = 0.0;
            for _ in 0..20 {
                let ranges = laser.realistic_scan(&r, &world, &[Pose2::IDENTITY], 0.0, &mut rng);
                for (r, a) in ranges.iter().zip(laser.angles()).skip(330).take(20) {
                    let e = *r as f64 - d / a.cos();
                    s2 += e * e;
                    n += 1.0;
                }
            }
            (s2 / n).sqrt()
        };
        let (near, far) = (spread(0.5), spread(3.0));
        assert!((near - 0.008).abs() < 0.0015, "{near}");
        assert!((far - 0.033).abs() < 0.005, "{far}");
    }
}
