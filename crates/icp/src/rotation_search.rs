//! Starting rotations for a pair whose first guess is far off.
//!
//! The direction of a surface's normal does not depend on where the sensor stands,
//! only on how it is turned: the reference scan's histogram of local-line normal
//! directions is the current scan's turned by θ. The rotations whose shifted
//! histograms agree best (circular correlation, 1° bins, linear binning and a
//! [1, 2, 1] blur) within the allowed correction around the guess are the candidates
//! ICP then starts from. Translation plays no part, so a rotation far off is found
//! even when the translation is off too.

use crate::preprocess::PreparedScan;
use std::f64::consts::TAU;

/// Bins of the direction histograms (1° each).
const BINS: usize = 360;

/// Histogram of the directions of a scan's usable local-line normals, linearly
/// binned and blurred by [1, 2, 1].
fn direction_histogram(scan: &PreparedScan) -> [f64; BINS] {
    let mut h = [0.0; BINS];
    let scale = BINS as f64 / TAU;
    for line in scan.segments.iter().flatten() {
        let a = line.normal[1].atan2(line.normal[0]).rem_euclid(TAU) * scale;
        let lo = a.floor();
        let frac = a - lo;
        let lo = lo as usize % BINS;
        h[lo] += 1.0 - frac;
        h[(lo + 1) % BINS] += frac;
    }
    let mut blurred = [0.0; BINS];
    for (i, b) in blurred.iter_mut().enumerate() {
        *b = h[(i + BINS - 1) % BINS] + 2.0 * h[i] + h[(i + 1) % BINS];
    }
    blurred
}

/// Up to `count` rotations (rad) of the current scan in the reference frame, the best
/// first, within `max_correction` of `guess`: the local maxima of the correlation of
/// the two direction histograms, refined by a parabola through the peak.
pub(crate) fn candidate_rotations(
    reference: &PreparedScan,
    current: &PreparedScan,
    guess: f64,
    max_correction: f64,
    count: usize,
) -> Vec<f64> {
    if count == 0 {
        return Vec::new();
    }
    let href = direction_histogram(reference);
    let hcur = direction_histogram(current);
    let step = TAU / BINS as f64;
    let centre = (guess / step).round() as i64;
    let half = (max_correction / step).ceil() as i64 + 1;
    // score[k]: agreement at the shift centre − half + k bins.
    let score: Vec<f64> = (-half..=half)
        .map(|d| {
            let shift = (centre + d).rem_euclid(BINS as i64) as usize;
            hcur.iter()
                .enumerate()
                .map(|(i, &c)| c * href[(i + shift) % BINS])
                .sum()
        })
        .collect();
    let mut peaks: Vec<(f64, f64)> = Vec::new();
    for k in 1..score.len() - 1 {
        let (a, b, c) = (score[k - 1], score[k], score[k + 1]);
        if b > 0.0 && b >= a && b > c {
            let curvature = a - 2.0 * b + c;
            let offset = if curvature < 0.0 {
                (0.5 * (a - c) / curvature).clamp(-0.5, 0.5)
            } else {
                0.0
            };
            let theta = (centre - half + k as i64) as f64 * step + offset * step;
            if (theta - guess).abs() <= max_correction {
                peaks.push((b, theta));
            }
        }
    }
    peaks.sort_by(|x, y| y.0.total_cmp(&x.0));
    peaks.into_iter().take(count).map(|(_, t)| t).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::IcpParams;

    /// A room seen from the origin turned by `theta` (walls x = ±2, y = ±1.5, and a
    /// slanted panel), as URG-04LX-like ranges.
    fn room_scan(theta: f64) -> PreparedScan {
        let angles: Vec<f64> = (0..681)
            .map(|i| (i as f64 - 340.0) * TAU / 1024.0)
            .collect();
        let walls: [([f64; 2], [f64; 2]); 5] = [
            ([-2.0, -1.5], [2.0, -1.5]),
            ([2.0, -1.5], [2.0, 1.5]),
            ([2.0, 1.5], [-2.0, 1.5]),
            ([-2.0, 1.5], [-2.0, -1.5]),
            ([0.5, 1.0], [1.5, 0.3]),
        ];
        let ranges: Vec<f32> = angles
            .iter()
            .map(|a| {
                let u = [(a + theta).cos(), (a + theta).sin()];
                let mut best = f64::INFINITY;
                for (p, q) in walls {
                    let e = [q[0] - p[0], q[1] - p[1]];
                    let den = -u[0] * e[1] + u[1] * e[0];
                    if den.abs() < 1e-12 {
                        continue;
                    }
                    let t = (-p[0] * e[1] + p[1] * e[0]) / den;
                    let s = (u[0] * p[1] - u[1] * p[0]) / den;
                    if t > 0.0 && (0.0..=1.0).contains(&s) {
                        best = best.min(t);
                    }
                }
                best as f32
            })
            .collect();
        PreparedScan::new(&ranges, &angles, 0.02, 4.0, &IcpParams::default()).expect("scan")
    }

    #[test]
    fn finds_a_large_rotation_from_identity() {
        let reference = room_scan(0.0);
        for deg in [-40.0f64, -21.0, 7.5, 33.0] {
            let current = room_scan(deg.to_radians());
            let found = candidate_rotations(&reference, &current, 0.0, 50f64.to_radians(), 3);
            let best = found.first().expect("a candidate").to_degrees();
            assert!((best - deg).abs() < 1.0, "{deg}°: candidates {found:?}");
        }
    }
}
