//! Test-only scan simulator: a few segments, exact ray casting, URG-04LX geometry,
//! optional Gaussian range noise and 1 mm quantisation.
#![allow(dead_code)]

use odocal_geom::Pose2;
use rand::Rng;
use rand_distr::{Distribution, Normal};
use std::f64::consts::TAU;

/// URG-04LX ray angles: 681 rays, step 2π/1024, starting at −340 steps.
pub fn urg_angles() -> Vec<f64> {
    let step = TAU / 1024.0;
    (0..681).map(|i| (i as f64 - 340.0) * step).collect()
}

/// A world made of line segments.
pub struct World {
    pub segments: Vec<([f64; 2], [f64; 2])>,
}

fn rect(segs: &mut Vec<([f64; 2], [f64; 2])>, x0: f64, y0: f64, x1: f64, y1: f64) {
    segs.push(([x0, y0], [x1, y0]));
    segs.push(([x1, y0], [x1, y1]));
    segs.push(([x1, y1], [x0, y1]));
    segs.push(([x0, y1], [x0, y0]));
}

impl World {
    /// A 4 m × 3 m room with two boxes and a slanted panel.
    pub fn room() -> World {
        let mut segments = Vec::new();
        rect(&mut segments, -2.0, -1.5, 2.0, 1.5);
        rect(&mut segments, 0.8, 0.4, 1.2, 0.9);
        rect(&mut segments, -1.3, -1.1, -0.9, -0.6);
        segments.push(([-1.5, 0.6], [-0.7, 1.2]));
        World { segments }
    }

    /// A long corridor, 1.2 m wide, far longer than the sensor range.
    pub fn corridor() -> World {
        World {
            segments: vec![([-50.0, -0.6], [50.0, -0.6]), ([-50.0, 0.6], [50.0, 0.6])],
        }
    }

    /// Exact range along the ray from `o` in direction `u` (unit), if any.
    pub fn cast(&self, o: [f64; 2], u: [f64; 2]) -> Option<f64> {
        let mut best: Option<f64> = None;
        for &(a, b) in &self.segments {
            let e = [b[0] - a[0], b[1] - a[1]];
            let den = u[0] * (-e[1]) - u[1] * (-e[0]);
            if den.abs() < 1e-15 {
                continue;
            }
            let w = [a[0] - o[0], a[1] - o[1]];
            // o + t u = a + s e  →  t u − s e = w.
            let t = (w[0] * (-e[1]) - w[1] * (-e[0])) / den;
            let s = (u[0] * w[1] - u[1] * w[0]) / den;
            if t > 1e-9 && (0.0..=1.0).contains(&s) && best.is_none_or(|b| t < b) {
                best = Some(t);
            }
        }
        best
    }

    /// Scan from sensor pose `pose`; readings ≥ 4 m or missing are 0 (invalid).
    pub fn scan(&self, pose: &Pose2, angles: &[f64]) -> Vec<f64> {
        angles
            .iter()
            .map(|&a| {
                let th = pose.theta + a;
                match self.cast([pose.x, pose.y], [th.cos(), th.sin()]) {
                    Some(r) if r < 4.0 => r,
                    _ => 0.0,
                }
            })
            .collect()
    }
}

/// Noise-free ranges as f32.
pub fn exact(ranges: &[f64]) -> Vec<f32> {
    ranges.iter().map(|&r| r as f32).collect()
}

/// Ranges with Gaussian noise of `sigma` (m) and 1 mm quantisation; 0 stays 0.
pub fn noisy<R: Rng>(ranges: &[f64], sigma: f64, rng: &mut R) -> Vec<f32> {
    let normal = Normal::new(0.0, sigma).expect("valid sigma");
    ranges
        .iter()
        .map(|&r| {
            if r == 0.0 {
                0.0
            } else {
                ((r + normal.sample(rng)) * 1000.0).round() as f32 / 1000.0
            }
        })
        .collect()
}
