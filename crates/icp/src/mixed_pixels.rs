//! Mixed pixels: readings at a depth edge that lie on neither surface, left out of a
//! scan before matching.
//!
//! Where one ray hits a near surface and its neighbour a far one, real range finders
//! often return a range between the two (the beam's footprint straddles the edge;
//! the "trails" of an RPLIDAR). Such a point sits on the ray through the edge, so it
//! moves with the sensor, not with the world, and always on the same side of the
//! surface it is matched to: the ones that survive the trimming pull every match of a
//! place the same way. On the realistic TurtleBot 4 preset that pull made ℓθ's error
//! common to a whole log, 1.39 times its σ over 30 seeds (0.88 without mixed pixels;
//! docs/benchmarks.md, "Stop 41").
//!
//! A mixed pixel that lands far from both surfaces is a point alone, which no local
//! line goes through and which the trimming drops. The ones that pull are those a
//! few centimetres off a surface: close enough to be joined to its run, so that
//! lines are fitted through them and they pass the trimming. So a reading is judged
//! where a run ends at a depth edge: the run's last readings before it (up to
//! [`RUN_POINTS`] on the run) give a line, continued to its ray. The reading is a
//! mixed pixel when it lies off that continuation towards the surface across the
//! edge by more than [`crate::IcpParams::mixed_pixel_sigmas`] times the noise of that
//! prediction, the range noise being the scans' (see [`mixed_pixel_readings`]) or
//! the run's own scatter about its line, whichever is larger (a far wall's, when the
//! noise grows with range). The true end of a surface lies on its own continuation and is kept:
//! corners and the ends of walls stay in the scan, however clean it is (leaving
//! every reading at an edge out cost clean scans their corners; "Stop 41" in
//! docs/benchmarks.md). A reading joined to no run (a surface only one ray hits, or a
//! mixed pixel far from both surfaces) is left as it is, and so is one whose run is
//! too short or too steep to the rays to be continued. Scans of coarse rays are not
//! judged ([`MAX_RAY_STEP`]).

use crate::params::IcpParams;

/// The most readings of a run that its continuation is fitted to; their scatter
/// about it is the run's own noise.
const RUN_POINTS: usize = 5;

/// Scans whose rays are farther apart on average (rad; 0.6°) are not judged: the
/// URG-04LX (0.35°) and the RPLIDAR (0.5°) are, 1° lasers are not. On those, a run's
/// last readings span degrees and their continuation is no sharp test, and judging
/// them gained nothing: the simulated Neato's RMS error/σ moved by +0.01 to +0.03
/// (30 seeds), the simulated two-lidar TurtleBot's front laser kept its ℓθ and
/// widened its σ by 2 %.
const MAX_RAY_STEP: f64 = 0.6 * std::f64::consts::PI / 180.0;

/// A reading whose ray meets its run's line at a larger incidence (|cos| below this)
/// is not judged: the continuation's range is too uncertain there.
const MIN_JUDGING_COS: f64 = 0.2;

/// The least range noise (m) a reading is judged with: quantisation (1 mm on most
/// lasers) and curved surfaces (a continuation of a few rays along a round pillar
/// misses by a fraction of a millimetre) are not mixed pixels on noise-free scans.
const MIN_SIGMA: f64 = 1e-3;

/// `mixed[i]`: reading `i` is a mixed pixel (see the module documentation), judged
/// with `sigma` the scan's range noise (m; at least [`MIN_SIGMA`]). Readings are valid
/// when finite, above `lo` and below `hi`; `angles` in rad, `directions` their
/// `(cos, sin)` when the caller has them (one per angle). All false when the noise
/// is unknown (`None`, or NaN), `params.mixed_pixel_sigmas` is infinite, or the rays
/// are more than [`MAX_RAY_STEP`] apart on average.
///
/// The noise is the one scans show about their local lines (the log's typical one,
/// or the scan's own): on real URG-04LX scans, whose noise is correlated over
/// neighbouring rays, the second differences of consecutive ranges show only 0.65 of
/// it, and flagged 4.7 readings per scan of the real MinesRover log exp1 instead of
/// 2.6.
pub(crate) fn mixed_pixel_readings(
    ranges: &[f32],
    angles: &[f64],
    directions: Option<&[[f64; 2]]>,
    lo: f64,
    hi: f64,
    sigma: Option<f64>,
    params: &IcpParams,
) -> Vec<bool> {
    let n = ranges.len().min(angles.len());
    let mut mixed = vec![false; ranges.len()];
    let Some(sigma) = sigma.filter(|s| !s.is_nan()) else {
        return mixed;
    };
    if !params.mixed_pixel_sigmas.is_finite() {
        return mixed;
    }
    let sigma = sigma.max(MIN_SIGMA);
    let span = angles
        .first()
        .zip(angles.last())
        .map(|(a, b)| (b - a).abs());
    // NaN angles make no span: not judged.
    let fine = |span: f64| span <= MAX_RAY_STEP * n.saturating_sub(1) as f64;
    if !span.is_some_and(fine) {
        return mixed;
    }
    let range = |i: usize| {
        let r = f64::from(ranges[i]);
        (r.is_finite() && r > lo.max(0.0) && r < hi).then_some(r)
    };
    // joined[i]: readings i and i + 1 both valid, and consecutive points of one run
    // (closer than the gap `PreparedScan` joins runs across).
    let joined: Vec<bool> = (0..n.saturating_sub(1))
        .map(|i| match (range(i), range(i + 1)) {
            (Some(a), Some(b)) => {
                (a - b).abs() <= params.run_gap(a.max(b), angles[i + 1] - angles[i])
            }
            _ => false,
        })
        .collect();
    for i in 1..n.saturating_sub(1) {
        let Some(r) = range(i) else { continue };
        // At a depth edge on one side only: joined to the other.
        let own: isize = match (joined[i - 1], joined[i]) {
            (true, false) => -1,
            (false, true) => 1,
            _ => continue,
        };
        // The surface across the edge (a reading without a return there is no edge).
        let Some(r_across) = range((i as isize - own) as usize) else {
            continue;
        };
        let point = |k: usize, r: f64| {
            let (sin, cos) = match directions {
                Some(d) => (d[k][1], d[k][0]),
                None => angles[k].sin_cos(),
            };
            [r * cos, r * sin]
        };
        let p = point(i, r);
        // Its run's readings before it: i ± 1, i ± 2, … while on one surface.
        let mut run = Vec::with_capacity(RUN_POINTS);
        let mut k = i as isize + own;
        while run.len() < RUN_POINTS && (0..n as isize).contains(&k) {
            let ku = k as usize;
            let Some(rk) = range(ku) else { break };
            if !run.is_empty() && !joined[ku.min((ku as isize - own) as usize)] {
                break;
            }
            run.push(point(ku, rk));
            k += own;
        }
        // Off its run's continuation, towards the surface across the edge, by more
        // than the noise: the log's, or the run's own where that is larger (a far
        // wall's, when the range noise grows with range).
        if let Some(c) = Continuation::of(&run, p) {
            let towards = c.along * (r_across - r).signum();
            if towards > params.mixed_pixel_sigmas * sigma.max(c.scatter) * c.spread {
                mixed[i] = true;
            }
        }
    }
    mixed
}

/// A reading against the line through its run's readings before it.
struct Continuation {
    /// How far the reading lies off the line, along its own ray (m; positive beyond
    /// the line).
    along: f64,
    /// The standard deviation of `along` per unit range noise were the reading on
    /// the line: its own noise and the line's at that distance from the run.
    spread: f64,
    /// The range noise the run's readings show about their line (m, along the
    /// reading's ray; 0 from fewer than four readings).
    scatter: f64,
}

impl Continuation {
    /// The reading `p` against the line through `points`; `None` with fewer than two
    /// points, or when `p`'s ray meets the line at grazing incidence.
    fn of(points: &[[f64; 2]], p: [f64; 2]) -> Option<Continuation> {
        let m = points.len();
        if m < 2 {
            return None;
        }
        let mf = m as f64;
        let c = points
            .iter()
            .fold([0.0, 0.0], |a, q| [a[0] + q[0] / mf, a[1] + q[1] / mf]);
        let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
        for q in points {
            let (dx, dy) = (q[0] - c[0], q[1] - c[1]);
            sxx += dx * dx;
            sxy += dx * dy;
            syy += dy * dy;
        }
        // The line's direction: the scatter's principal axis.
        let angle = 0.5 * (2.0 * sxy).atan2(sxx - syy);
        let tangent = [angle.cos(), angle.sin()];
        let normal = [-tangent[1], tangent[0]];
        let s_tt = sxx * tangent[0] * tangent[0]
            + 2.0 * sxy * tangent[0] * tangent[1]
            + syy * tangent[1] * tangent[1];
        if s_tt.is_nan() || s_tt <= 0.0 {
            return None;
        }
        let r = (p[0] * p[0] + p[1] * p[1]).sqrt();
        let dir = [p[0] / r, p[1] / r];
        let cos = normal[0] * dir[0] + normal[1] * dir[1];
        if cos.abs() < MIN_JUDGING_COS {
            return None;
        }
        // Distance of p from the line, then along its ray.
        let off = normal[0] * (p[0] - c[0]) + normal[1] * (p[1] - c[1]);
        let t = tangent[0] * (p[0] - c[0]) + tangent[1] * (p[1] - c[1]);
        // Perpendicular noise of each reading ≈ σ·|cos|; the line's error at `t`
        // (1/m + t²/S_tt) and p's own add up; along the ray, divided by |cos| again.
        let spread = (1.0 + 1.0 / mf + t * t / s_tt).sqrt();
        // The points' own scatter about the line (m − 2 degrees of freedom), along the
        // ray; from four points on.
        let s_nn = sxx * normal[0] * normal[0]
            + 2.0 * sxy * normal[0] * normal[1]
            + syy * normal[1] * normal[1];
        let scatter = if m >= 4 {
            (s_nn / (mf - 2.0)).sqrt() / cos.abs()
        } else {
            0.0
        };
        Some(Continuation {
            along: off / cos,
            spread,
            scatter,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};

    const STEP: f64 = 0.5 * std::f64::consts::PI / 180.0;

    fn angles(n: usize) -> Vec<f64> {
        (0..n).map(|i| i as f64 * STEP).collect()
    }

    /// Ranges to the line x = d (a wall in front) along `angles`.
    fn wall(d: f64, angles: &[f64]) -> Vec<f32> {
        angles.iter().map(|a| (d / a.cos()) as f32).collect()
    }

    /// A box 1 m away over rays 0-19, the wall 2 m away over rays 20-39, noise-free.
    fn box_before_wall() -> (Vec<f32>, Vec<f64>) {
        let a = angles(40);
        let mut r = wall(2.0, &a);
        for v in r.iter_mut().take(20) {
            *v = 1.0;
        }
        (r, a)
    }

    /// The readings flagged with range noise `sigma` (m; `None`: unknown).
    fn flagged(
        ranges: &[f32],
        angles: &[f64],
        sigma: Option<f64>,
        params: &IcpParams,
    ) -> Vec<usize> {
        let mixed = mixed_pixel_readings(ranges, angles, None, 0.02, 5.6, sigma, params);
        (0..ranges.len()).filter(|&i| mixed[i]).collect()
    }

    #[test]
    fn a_reading_in_a_run_off_its_continuation_is_a_mixed_pixel() {
        let params = IcpParams::default();
        let (mut r, a) = box_before_wall();
        // Joined to the box's run, 4 cm behind its end towards the wall.
        r[19] = 1.04;
        assert_eq!(flagged(&r, &a, Some(0.0), &params), vec![19]);
        // Joined to the wall's run, 10 cm in front of it towards the box.
        let (mut r, _) = box_before_wall();
        r[19] = (2.0 / a[19].cos() - 0.1) as f32;
        assert_eq!(flagged(&r, &a, Some(0.0), &params), vec![19]);
        // Joined to neither run (40 cm from both): a point alone, left as it is.
        let (mut r, _) = box_before_wall();
        r[19] = 1.4;
        assert!(flagged(&r, &a, Some(0.0), &params).is_empty());
    }

    #[test]
    fn the_true_ends_of_both_surfaces_are_kept() {
        let params = IcpParams::default();
        let (mut r, a) = box_before_wall();
        assert!(flagged(&r, &a, Some(0.0), &params).is_empty());
        // Within the noise of the continuation (3 σ · 1.83 at the floor σ = 1 mm):
        // it cannot be told from the surface's own end.
        r[19] = 1.003;
        assert!(flagged(&r, &a, Some(0.0), &params).is_empty());
        // Off the continuation away from the surface across the edge: not between
        // the two surfaces, no mixed pixel.
        r[19] = 0.97;
        assert!(flagged(&r, &a, Some(0.0), &params).is_empty());
        // 4 mm in front of the far wall.
        r[19] = (2.0 / a[19].cos() - 0.004) as f32;
        assert!(flagged(&r, &a, Some(0.0), &params).is_empty());
    }

    #[test]
    fn the_tolerance_follows_the_noise_of_the_scans() {
        // The same edge on readings with 5 mm of white noise: a reading 1 cm behind
        // the box's last one is within it, 6 cm is not.
        let mut rng = rand::rngs::StdRng::seed_from_u64(3);
        let noise = Normal::new(0.0, 0.005).expect("σ > 0");
        let (clean, a) = box_before_wall();
        let noisy: Vec<f32> = clean
            .iter()
            .map(|&r| (f64::from(r) + noise.sample(&mut rng)) as f32)
            .collect();
        let params = IcpParams::default();
        let mut r = noisy.clone();
        r[19] = r[18] + 0.01;
        assert!(flagged(&r, &a, Some(0.005), &params).is_empty());
        // Judged with a noise five times too small, it (and the noisy first reading
        // of the far wall) is.
        assert!(flagged(&r, &a, Some(0.0), &params).contains(&19));
        r[19] = r[18] + 0.06;
        assert_eq!(flagged(&r, &a, Some(0.005), &params), vec![19]);
    }

    #[test]
    fn a_run_too_short_or_an_edge_without_a_return_is_not_judged() {
        let params = IcpParams::default();
        let (mut r, a) = box_before_wall();
        r[19] = 1.04;
        // The box's run reduced to one reading (ray 18; 17 has no return).
        r[17] = 0.0;
        assert!(flagged(&r, &a, Some(0.0), &params).is_empty());
        // No return across the edge: no surface to lie towards.
        let (mut r, _) = box_before_wall();
        r[19] = 1.04;
        r[20] = 0.0;
        assert!(flagged(&r, &a, Some(0.0), &params).is_empty());
    }

    #[test]
    fn switched_off_by_infinite_sigmas_unknown_noise_or_coarse_rays() {
        let (mut r, a) = box_before_wall();
        r[19] = 1.04;
        let off = IcpParams {
            mixed_pixel_sigmas: f64::INFINITY,
            ..IcpParams::default()
        };
        assert!(flagged(&r, &a, Some(0.0), &off).is_empty());
        // The noise unknown: nothing is judged.
        assert!(flagged(&r, &a, None, &IcpParams::default()).is_empty());
        assert!(flagged(&r, &a, Some(f64::NAN), &IcpParams::default()).is_empty());
        // Rays 1° apart are not judged.
        let coarse: Vec<f64> = (0..40).map(|i| (i as f64).to_radians()).collect();
        assert!(flagged(&r, &coarse, Some(0.0), &IcpParams::default()).is_empty());
    }
}
