//! Local lines of a sparse scan from metric neighbourhoods: for every point, the total
//! least squares line through its nearest points of the scan (within a radius),
//! whichever rays they come from. A 1° LDS with 75 % of its readings missing has few runs of seven
//! consecutive returns (the windows of `preprocess`), but its returns on one wall are
//! still a few centimetres apart.
//!
//! A neighbourhood is a usable line when it holds enough points, is elongated, and its
//! points scatter about the line no more than the scan's noise allows (a corner or a
//! chair leg among wall points is not a line). The noise is the scan's own: the
//! median scatter of its neighbourhoods.

/// Fewest points of a neighbourhood line.
const MIN_POINTS: usize = 4;
/// A line's points must spread along it at least this many times their scatter across.
const MIN_ELONGATION: f64 = 3.0;
/// A line's scatter across may be at most this many times the scan's noise.
const MAX_SCATTER_TO_NOISE: f64 = 2.5;
/// A neighbourhood: the point and its nearest ones, this many in all, within a radius
/// (m) of [`MATCHING_RADIUS`] or [`NOISE_RADIUS`].
const NEIGHBOURS: usize = 7;
/// The neighbourhoods' radius of the sparse matcher's lines (m). On a 1° LDS with 80 %
/// of its readings missing, consecutive returns on a wall 1.3 m away are about 10 cm
/// apart: within 30 cm, many points have too few neighbours for a line. With 45 cm,
/// on `neato-lds` seeds 1–3 (120 s) the matched share of overlapping pairs went from
/// 48 % to 52 %, the RMS error of the accepted from 16.2 to 13.4 mm, their mean NEES
/// from 13.7 to 8.0; 60 cm matched no more (51 %). A corner or clutter within the
/// radius still fails the scatter test.
pub(crate) const MATCHING_RADIUS: f64 = 0.45;
/// The neighbourhoods' radius of the noise estimate of scans with too few runs of
/// consecutive returns (`preprocess`; m): smaller, so that a wall's curvature or a
/// nearby object does not pass for noise.
pub(crate) const NOISE_RADIUS: f64 = 0.30;
/// Most points whose neighbourhoods are searched: the search compares every pair of
/// points (2048 points: ≈ 10 ms; 16 000 took 0.47 s), and the scans that need it are
/// sparse (a URG-04LX's 682 rays, a Neato's 361). More points get no lines and no
/// noise, whatever a file declares.
pub(crate) const MAX_POINTS: usize = 2048;

/// A local line `normal · p = offset` and where it holds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct NeighbourhoodLine {
    /// Unit normal.
    pub normal: [f64; 2],
    /// Offset along the normal (m).
    pub offset: f64,
    /// Centroid of the neighbourhood.
    pub centroid: [f64; 2],
    /// Largest distance of a neighbourhood point from the centroid along the line (m).
    pub half_length: f64,
}

/// The lines of a scan's points and the noise they show.
#[derive(Debug, Clone)]
pub(crate) struct NeighbourhoodLines {
    /// Per point (same order as given): its neighbourhood's line, if usable.
    pub lines: Vec<Option<NeighbourhoodLine>>,
    /// The scan's range noise (σ, m) from the scatter about the lines; `None` when no
    /// neighbourhood has enough points.
    pub noise_sigma: Option<f64>,
}

/// A total least squares fit: the line and the scatter across it (RMS, corrected for
/// the two fitted parameters).
fn fit(points: &[[f64; 2]], members: &[usize]) -> Option<(NeighbourhoodLine, f64, f64)> {
    let n = members.len() as f64;
    let (mut mx, mut my) = (0.0, 0.0);
    for &k in members {
        mx += points[k][0];
        my += points[k][1];
    }
    (mx, my) = (mx / n, my / n);
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for &k in members {
        let (dx, dy) = (points[k][0] - mx, points[k][1] - my);
        sxx += dx * dx;
        sxy += dx * dy;
        syy += dy * dy;
    }
    let half_trace = 0.5 * (sxx + syy);
    let root = (0.25 * (sxx - syy).powi(2) + sxy * sxy).sqrt();
    let (largest, smallest) = (half_trace + root, (half_trace - root).max(0.0));
    // Direction of the largest eigenvalue: the line.
    let angle = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    let (s, c) = angle.sin_cos();
    let normal = [-s, c];
    let mut half_length: f64 = 0.0;
    for &k in members {
        let along = (points[k][0] - mx) * c + (points[k][1] - my) * s;
        half_length = half_length.max(along.abs());
    }
    let line = NeighbourhoodLine {
        normal,
        offset: normal[0] * mx + normal[1] * my,
        centroid: [mx, my],
        half_length,
    };
    let scatter = (smallest / (n - 2.0)).sqrt();
    let spread = (largest / n).sqrt();
    (scatter.is_finite() && spread.is_finite()).then_some((line, scatter, spread))
}

impl NeighbourhoodLines {
    /// The lines of `points` (sensor frame, all finite) through the neighbourhoods
    /// within `radius` (m); `noise_floor` (m) bounds the noise from below (exact data).
    /// More than [`MAX_POINTS`] points: none.
    pub fn new(points: &[[f64; 2]], radius: f64, noise_floor: f64) -> Self {
        if points.len() > MAX_POINTS {
            return NeighbourhoodLines {
                lines: vec![None; points.len()],
                noise_sigma: None,
            };
        }
        let mut fits = Vec::with_capacity(points.len());
        let mut near: Vec<(f64, usize)> = Vec::new();
        let mut members = Vec::new();
        for p in points {
            near.clear();
            near.extend(points.iter().enumerate().filter_map(|(k, q)| {
                let d2 = (q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2);
                (d2 <= radius * radius).then_some((d2, k))
            }));
            if near.len() > NEIGHBOURS {
                near.select_nth_unstable_by(NEIGHBOURS - 1, |a, b| a.0.total_cmp(&b.0));
                near.truncate(NEIGHBOURS);
            }
            members.clear();
            members.extend(near.iter().map(|&(_, k)| k));
            fits.push(if members.len() >= MIN_POINTS {
                fit(points, &members)
            } else {
                None
            });
        }
        let mut scatters: Vec<f64> = fits.iter().flatten().map(|f| f.1).collect();
        let noise_sigma = (!scatters.is_empty()).then(|| {
            let mid = scatters.len() / 2;
            *scatters.select_nth_unstable_by(mid, f64::total_cmp).1
        });
        let noise = noise_sigma.unwrap_or(0.0).max(noise_floor);
        let lines = fits
            .into_iter()
            .map(|f| {
                let (line, scatter, spread) = f?;
                (scatter <= MAX_SCATTER_TO_NOISE * noise && spread >= MIN_ELONGATION * scatter)
                    .then_some(line)
            })
            .collect();
        NeighbourhoodLines {
            lines,
            noise_sigma: noise_sigma.map(|s| s.max(noise_floor)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wall_points_make_lines_and_a_corner_does_not() {
        // A wall at x = 2 and one at y = 1, points 4 cm apart, meeting at (2, 1).
        let mut points: Vec<[f64; 2]> = (0..30).map(|i| [2.0, -0.2 + 0.04 * i as f64]).collect();
        points.extend((1..30).map(|i| [2.0 - 0.04 * i as f64, 1.0]));
        // Noise-free but for float rounding.
        let lines = NeighbourhoodLines::new(&points, NOISE_RADIUS, 1e-5);
        let mid = lines.lines[10].expect("mid-wall point on a line");
        assert!((mid.normal[0].abs() - 1.0).abs() < 1e-9);
        assert!((mid.offset / mid.normal[0] - 2.0).abs() < 1e-9);
        // (2, 0.96): its neighbourhood spans the corner.
        assert_eq!(lines.lines[29], None);
        assert!(lines.noise_sigma.unwrap() < 1e-3);
    }

    #[test]
    fn more_points_than_the_bound_get_no_lines() {
        // A wall of MAX_POINTS + 1 points 1 mm apart: lines, but not searched.
        let wall = |n: usize| -> Vec<[f64; 2]> { (0..n).map(|i| [2.0, 1e-3 * i as f64]).collect() };
        let within = NeighbourhoodLines::new(&wall(MAX_POINTS), NOISE_RADIUS, 1e-5);
        assert!(within.lines.iter().all(|l| l.is_some()));
        let beyond = NeighbourhoodLines::new(&wall(MAX_POINTS + 1), NOISE_RADIUS, 1e-5);
        assert_eq!(beyond.lines.len(), MAX_POINTS + 1);
        assert!(beyond.lines.iter().all(|l| l.is_none()));
        assert_eq!(beyond.noise_sigma, None);
    }
}
