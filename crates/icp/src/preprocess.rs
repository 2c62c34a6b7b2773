//! A scan made ready for matching, once, whatever role it plays later.
//!
//! Preparation keeps the valid readings (not 0, finite, within range) as Cartesian
//! points, cuts them into runs of consecutive points on one surface (no run crosses
//! a range discontinuity or a far reading; it goes across up to
//! `bridged_missing_rays` readings without a return), and gives every segment
//! between two consecutive points of a run a *local line*: the total-least-squares
//! line of the window of `line_fit_window` consecutive run points containing both
//! ends that fits best. Matching measures point-to-line distances to these lines
//! rather than to the raw segment, whose direction two noisy points barely fix.
//! On noise-free straight walls the local line is the wall itself.

use crate::consistency::EXACT_NOISE_SHARE;
use crate::mixed_pixels::mixed_pixel_readings;
use crate::neighbourhood_lines::{NeighbourhoodLines, MAX_POINTS, NOISE_RADIUS};
use crate::ray_directions::RayDirections;
use crate::{IcpError, IcpParams, NeighbourSearch};
use kiddo::immutable::float::kdtree::ImmutableKdTree;

/// The line `normal · x = offset` of one segment, or nothing when it is not usable.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SegmentLine {
    /// Unit normal, pointing towards the sensor.
    pub normal: [f64; 2],
    /// Signed distance of the line from the sensor along `normal`.
    pub offset: f64,
    /// |cos| of the incidence angle of the reference rays on the line (1 = head-on).
    pub incidence_cos: f64,
    /// Variance of the line's tilt (rad²) per unit variance of the range noise:
    /// `incidence_cos² / S_tt`, `S_tt` the scatter of the window along the line.
    pub tilt_variance: f64,
    /// Position of the window's centroid along the tangent `(−n_y, n_x)` (m).
    pub centroid_along: f64,
}

/// Fewest usable segments for a scan's [`PreparedScan::typical_tilt_sigma`].
const MIN_TILT_SEGMENTS: usize = 10;

/// The k-d tree over a scan's valid points (leaf size 32; items are indices into
/// [`PreparedScan::points`]).
pub(crate) type PointTree = ImmutableKdTree<f64, u32, 2, 32>;

/// One ray with a valid reading: its unit direction and its point, kept
/// together so that the closest-point search reads one cache line per ray.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Ray {
    /// Unit direction `(cos, sin)` in the sensor frame.
    pub dir: [f64; 2],
    /// The measured point in the sensor frame.
    pub point: [f64; 2],
}

/// Unit vectors from a point to its neighbours along usable segments (NaN where the
/// segment is not usable), in `f32`: they only choose a side.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Sides {
    /// Towards the next point.
    pub to_next: [f32; 2],
    /// Towards the previous point.
    pub to_previous: [f32; 2],
}

/// A scan preprocessed once, usable as reference or as current scan any number of times.
///
/// Its valid readings only are kept, in ray order (the arrays below are indexed by
/// them); `original` says which reading of the scan each one is.
#[derive(Debug, Clone)]
pub struct PreparedScan {
    /// Number of readings of the scan, valid or not.
    pub(crate) ray_count: usize,
    /// Angle between neighbouring rays of the scan (rad; the mean over its span when
    /// they are not uniformly spaced).
    pub(crate) ray_step: f64,
    /// `original[k]`: the reading of the scan that kept point `k` is.
    pub(crate) original: Vec<u32>,
    /// Ray angles of the kept readings (rad).
    pub(crate) angles: Vec<f64>,
    /// Ray directions and points.
    pub(crate) rays: Vec<Ray>,
    /// Directions to the neighbours along usable segments.
    pub(crate) sides: Vec<Sides>,
    /// The valid readings' points in the sensor frame.
    pub(crate) points: Vec<[f64; 2]>,
    /// |cos| of the incidence angle of each ray on its own surface (mean over the
    /// usable segments at the point), NaN when the point has no usable segment.
    pub(crate) incidence_cos: Vec<f64>,
    /// Per reading of the scan (not only the kept ones): without a return (zero,
    /// non-finite or below the minimum range: dark, glancing or transparent surfaces),
    /// as opposed to valid ones and to readings beyond the maximum range (a far
    /// surface was seen); all false in a scan where they are rare (see `no_returns`).
    pub(crate) no_return: Vec<bool>,
    /// Valid readings on a usable local line (finite `incidence_cos`): the points a
    /// right match can be expected to explain.
    pub(crate) lined_count: usize,
    /// `segments[i]`: the local line of the segment from point `i` to `i + 1`, if usable.
    pub(crate) segments: Vec<Option<SegmentLine>>,
    /// Angles strictly increasing (required by the angular search).
    pub(crate) angles_increasing: bool,
    /// `Some((first angle, step))` when the angles are uniformly spaced.
    pub(crate) uniform: Option<(f64, f64)>,
    /// Largest valid range (m).
    pub(crate) max_valid_range: f64,
    /// Range-noise variance (m²) that, times a segment's `tilt_variance`, gives the
    /// variance of its line's tilt (rad²), estimated from the scan itself.
    pub(crate) tilt_noise_scale: f64,
    /// Range-noise standard deviation (m) the scan shows itself: the scatter of its
    /// points about their local lines; when it has fewer than 10 usable windows
    /// (most readings missing), about lines through metric neighbourhoods
    /// (`neighbourhood_lines`); `None` when those are fewer than 10 too: unknown,
    /// which is not the same as noise-free.
    pub(crate) noise_sigma: Option<f64>,
    /// k-d tree over the valid points, built when the k-d search is asked for or the
    /// angles do not allow the angular search.
    pub(crate) tree: Option<PointTree>,
    /// The points of several scans placed in one frame ([`PreparedScan::from_points`]),
    /// not one scan's rays: matched by the sparse matcher, whose lines come from
    /// metric neighbourhoods, never from consecutive rays.
    pub(crate) cloud: bool,
    /// Per reading of a cloud: placed from a neighbouring scan, not the anchor scan's
    /// own (empty for a scan). Placed points help the fit; the share of the current
    /// scan a match explains is taken over the own ones.
    pub(crate) placed: Vec<bool>,
}

/// Window statistics of a local line fit.
#[derive(Clone, Copy)]
struct WindowFit {
    /// Centroid, relative to `origin`.
    mx: f64,
    my: f64,
    /// Centred scatter.
    sxx: f64,
    sxy: f64,
    syy: f64,
    /// Smallest eigenvalue of the scatter (sum of squared line residuals).
    smallest: f64,
    origin: [f64; 2],
}

impl PreparedScan {
    /// Prepares a scan: `ranges[i]` (m) measured along `angles[i]` (rad, sensor frame).
    ///
    /// A reading is valid when it is finite, non-zero, above both `min_range` and
    /// `params.min_reading`, and below both `max_range` and `params.max_reading`.
    /// Errors: arrays of different lengths, non-finite angles, invalid parameters, or
    /// fewer than `params.min_valid_points` valid readings.
    ///
    /// Mixed pixels (readings at depth edges on neither surface; see
    /// [`IcpParams::mixed_pixel_sigmas`]) are left out as readings without a return.
    /// They are judged against `params.typical_noise_sigma` when it is given (the
    /// pipeline gives the log's), else against the range noise the scan shows about
    /// its local lines, which takes a first preparation.
    pub fn new(
        ranges: &[f32],
        angles: &[f64],
        min_range: f64,
        max_range: f64,
        params: &IcpParams,
    ) -> Result<PreparedScan, IcpError> {
        Self::new_with(ranges, angles, None, min_range, max_range, params)
    }

    /// [`PreparedScan::new`] along the rays of `rays` (`ranges[i]` measured along
    /// `rays.angles()[i]`), their directions taken from it rather than computed again:
    /// the same scan, for less work when many scans share one angle table.
    pub fn with_rays(
        ranges: &[f32],
        rays: &RayDirections,
        min_range: f64,
        max_range: f64,
        params: &IcpParams,
    ) -> Result<PreparedScan, IcpError> {
        let directions = Some(rays.directions());
        Self::new_with(
            ranges,
            rays.angles(),
            directions,
            min_range,
            max_range,
            params,
        )
    }

    /// [`PreparedScan::new`], with the directions `(cos, sin)` of `angles` when the
    /// caller has them.
    fn new_with(
        ranges: &[f32],
        angles: &[f64],
        directions: Option<&[[f64; 2]]>,
        min_range: f64,
        max_range: f64,
        params: &IcpParams,
    ) -> Result<PreparedScan, IcpError> {
        let directions = directions.filter(|d| d.len() == angles.len());
        // The log's typical noise when the caller knows it (one preparation, and the
        // same judgement whichever way the rays are listed); else the scan's own,
        // which takes a first preparation.
        let typical = Some(params.typical_noise_sigma).filter(|&s| s > 0.0);
        let (first, sigma) = match typical {
            Some(_) => (None, typical),
            None => {
                let scan = Self::prepare(ranges, angles, directions, min_range, max_range, params)?;
                let sigma = scan.noise_sigma;
                (Some(scan), sigma)
            }
        };
        let (lo, hi) = params.reading_bounds(min_range, max_range);
        let mixed = mixed_pixel_readings(ranges, angles, directions, lo, hi, sigma, params);
        if !mixed.contains(&true) {
            return match first {
                Some(scan) => Ok(scan),
                None => Self::prepare(ranges, angles, directions, min_range, max_range, params),
            };
        }
        let cleaned: Vec<f32> = ranges
            .iter()
            .zip(&mixed)
            .map(|(&r, &m)| if m { 0.0 } else { r })
            .collect();
        Self::prepare(&cleaned, angles, directions, min_range, max_range, params)
    }

    /// [`PreparedScan::new`] without judging mixed pixels: every valid reading kept.
    /// `directions`: the `(cos, sin)` of `angles`, when the caller has them.
    fn prepare(
        ranges: &[f32],
        angles: &[f64],
        directions: Option<&[[f64; 2]]>,
        min_range: f64,
        max_range: f64,
        params: &IcpParams,
    ) -> Result<PreparedScan, IcpError> {
        params.validate()?;
        if ranges.len() != angles.len() {
            return Err(IcpError::InvalidScan(format!(
                "{} ranges but {} angles",
                ranges.len(),
                angles.len()
            )));
        }
        if let Some(i) = angles.iter().position(|a| !a.is_finite()) {
            return Err(IcpError::InvalidScan(format!(
                "angle {i} is not finite ({})",
                angles[i]
            )));
        }
        if min_range.is_nan() || max_range.is_nan() {
            return Err(IcpError::InvalidScan(
                "min_range and max_range must not be NaN".to_string(),
            ));
        }
        let ray_count = ranges.len();
        let (lo, hi) = params.reading_bounds(min_range, max_range);
        let ray_step = mean_step(angles);
        let no_return = no_returns(ranges, lo);
        let (original, bridgeable) = kept_readings(ranges, lo, hi, params.bridged_missing_rays);
        let kept_ranges: Vec<f32> = original.iter().map(|&i| ranges[i as usize]).collect();
        let kept_angles: Vec<f64> = original.iter().map(|&i| angles[i as usize]).collect();
        let (ranges, angles) = (&kept_ranges[..], &kept_angles[..]);
        let n = ranges.len();

        let uniform = uniform_spacing(angles);
        let given = directions
            .filter(|d| d.len() == ray_count)
            .map(|d| (d, &original[..]));
        let dirs = ray_directions(angles, uniform, given);
        let points: Vec<[f64; 2]> = ranges
            .iter()
            .zip(&dirs)
            .map(|(&r, &[c, s])| [f64::from(r) * c, f64::from(r) * s])
            .collect();
        let inv_ranges: Vec<f64> = ranges.iter().map(|&r| 1.0 / f64::from(r)).collect();
        let max_valid_range = ranges.iter().fold(0.0, |m: f64, &r| m.max(f64::from(r)));
        if n < params.min_valid_points {
            return Err(IcpError::TooFewValidPoints {
                valid: n,
                total: ray_count,
                needed: params.min_valid_points,
            });
        }

        let angles_increasing = angles.windows(2).all(|w| w[1] > w[0]);
        let connected = connections(ranges, angles, &points, &bridgeable, params);
        let (segments, tilt_noise_scale, noise_sigma) =
            local_lines(&points, &inv_ranges, &connected, params);
        // Too few straight runs of consecutive points (most readings missing): the
        // scatter about lines through metric neighbourhoods, whichever rays they are
        // (their search is quadratic in the points: bounded).
        let noise_sigma = noise_sigma.or_else(|| {
            if n > MAX_NEIGHBOURHOOD_NOISE_POINTS {
                return None;
            }
            let lines =
                NeighbourhoodLines::new(&points, NOISE_RADIUS, EXACT_NOISE_SHARE * max_valid_range);
            let usable = lines.lines.iter().flatten().count();
            lines.noise_sigma.filter(|_| usable >= MIN_NOISE_LINES)
        });
        let incidence_cos = (0..n)
            .map(|i| {
                let before = i.checked_sub(1).and_then(|k| segments[k]);
                match (before, segments[i]) {
                    (Some(a), Some(b)) => 0.5 * (a.incidence_cos + b.incidence_cos),
                    (Some(a), None) | (None, Some(a)) => a.incidence_cos,
                    (None, None) => f64::NAN,
                }
            })
            .collect::<Vec<f64>>();
        let lined_count = incidence_cos.iter().filter(|c| !c.is_nan()).count();
        // The direction between consecutive points of a usable segment is, up to its
        // sign, the tangent of the segment's local line.
        let unit_towards = |line: &SegmentLine, from: usize, to: usize| {
            let t = [-line.normal[1], line.normal[0]];
            let d = [
                points[to][0] - points[from][0],
                points[to][1] - points[from][1],
            ];
            let sign = if t[0] * d[0] + t[1] * d[1] >= 0.0 {
                1.0
            } else {
                -1.0
            };
            [(sign * t[0]) as f32, (sign * t[1]) as f32]
        };
        let sides = (0..n)
            .map(|i| Sides {
                to_next: match &segments[i] {
                    Some(line) => unit_towards(line, i, i + 1),
                    None => [f32::NAN; 2],
                },
                to_previous: match i.checked_sub(1).and_then(|k| segments[k].as_ref()) {
                    Some(line) => unit_towards(line, i, i - 1),
                    None => [f32::NAN; 2],
                },
            })
            .collect();
        let rays = dirs
            .iter()
            .zip(&points)
            .map(|(&dir, &point)| Ray { dir, point })
            .collect();
        let tree = if params.search == NeighbourSearch::KdTree || !angles_increasing {
            Some(PointTree::new_from_slice(&points))
        } else {
            None
        };
        Ok(PreparedScan {
            ray_count,
            ray_step,
            original,
            angles: kept_angles,
            rays,
            sides,
            points,
            no_return,
            incidence_cos,
            lined_count,
            segments,
            angles_increasing,
            uniform,
            max_valid_range,
            tilt_noise_scale,
            noise_sigma,
            tree,
            cloud: false,
            placed: Vec::new(),
        })
    }

    /// Prepares a point cloud (m, in one sensor frame): the points `own` of a scan and
    /// the points `placed` of its neighbours placed in its frame, which a pair of
    /// sparse scans too poor to match alone is matched with. Pairs with a cloud are
    /// matched by the sparse matcher (lines through metric neighbourhoods of the
    /// points; see the crate documentation) when the clouds hold at most 2,048 points
    /// each; the order of the points does not matter (they are taken by bearing).
    /// Both kinds enter the fit; the share of the current cloud a match must explain
    /// ([`IcpParams::min_matched_share`]) is taken over its `own` points: the pair's
    /// overlap is its two scans', and a neighbour's points beyond what the other
    /// cloud saw are no evidence against the match.
    ///
    /// Errors: fewer than `params.min_valid_points` finite points within
    /// `params.min_reading` and `params.max_reading` of the origin, or invalid
    /// parameters.
    pub fn from_points(
        own: &[[f64; 2]],
        placed: &[[f64; 2]],
        params: &IcpParams,
    ) -> Result<PreparedScan, IcpError> {
        let tagged = |points: &'_ [[f64; 2]], placed: bool| {
            points
                .iter()
                .filter(|p| p[0].is_finite() && p[1].is_finite())
                .map(move |p| {
                    let range = (p[0] * p[0] + p[1] * p[1]).sqrt() as f32;
                    (p[1].atan2(p[0]), range, placed)
                })
                .collect::<Vec<_>>()
        };
        let mut polar = tagged(own, false);
        polar.extend(tagged(placed, true));
        polar.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
        let angles: Vec<f64> = polar.iter().map(|p| p.0).collect();
        let ranges: Vec<f32> = polar.iter().map(|p| p.1).collect();
        // A cloud's neighbouring entries are not neighbouring rays: no mixed pixels.
        let mut cloud = PreparedScan::prepare(&ranges, &angles, None, 0.0, f64::INFINITY, params)?;
        cloud.cloud = true;
        cloud.placed = polar.iter().map(|p| p.2).collect();
        Ok(cloud)
    }

    /// Is the kept point `k` of a cloud placed from a neighbouring scan (see
    /// [`PreparedScan::from_points`])? Never for a scan.
    pub(crate) fn is_placed(&self, k: usize) -> bool {
        self.original
            .get(k)
            .and_then(|&i| self.placed.get(i as usize))
            .copied()
            .unwrap_or(false)
    }

    /// Would a pair with this scan be matched by the sparse matcher (coarse rays and
    /// few returns per turn: a 1° LDS), whatever the other scan?
    pub fn is_sparse(&self, params: &IcpParams) -> bool {
        crate::sparse_fallback::sparse_scan(self, params)
    }

    /// The valid readings' points (m, sensor frame), in ray order.
    pub fn points(&self) -> &[[f64; 2]] {
        &self.points
    }

    /// Range noise the scan shows about its own local lines (σ, m; `None` when it has
    /// too few straight stretches to tell).
    pub fn noise_sigma(&self) -> Option<f64> {
        self.noise_sigma
    }

    /// The typical tilt noise of the scan's local lines (σ, rad): the median, over
    /// the segments with a usable line, of the tilt's standard deviation under the
    /// range noise the scan shows itself. What the matcher's errors-in-variables
    /// bias grows with (`odocal_pipeline::matcher_bias`). `None` with fewer than 10
    /// usable segments or no measured noise (sparse scans matched without local
    /// lines).
    pub fn typical_tilt_sigma(&self) -> Option<f64> {
        if !(self.tilt_noise_scale.is_finite() && self.tilt_noise_scale > 0.0) {
            return None;
        }
        let mut tilts: Vec<f64> = self
            .segments
            .iter()
            .flatten()
            .map(|s| (self.tilt_noise_scale * s.tilt_variance).sqrt())
            .filter(|t| t.is_finite())
            .collect();
        if tilts.len() < MIN_TILT_SEGMENTS {
            return None;
        }
        let mid = tilts.len() / 2;
        Some(*tilts.select_nth_unstable_by(mid, f64::total_cmp).1)
    }

    /// Number of readings (valid or not).
    pub fn len(&self) -> usize {
        self.ray_count
    }

    /// True when the scan has no readings (never, for a successfully prepared scan).
    pub fn is_empty(&self) -> bool {
        self.ray_count == 0
    }

    /// Number of valid readings.
    pub fn valid_count(&self) -> usize {
        self.points.len()
    }

    /// Number of segments with a usable local line.
    pub fn usable_segment_count(&self) -> usize {
        self.segments.iter().filter(|s| s.is_some()).count()
    }

    /// Point `i` (the scan's reading `i`) in the sensor frame, `None` when the reading
    /// is invalid.
    pub fn point(&self, i: usize) -> Option<[f64; 2]> {
        let k = self.original.binary_search(&u32::try_from(i).ok()?).ok()?;
        Some(self.points[k])
    }

    /// Run ends where the surface may go on unseen: the reading after kept point `k`
    /// got no return.
    pub(crate) fn no_return_after(&self, k: usize) -> bool {
        let i = self.original[k] as usize;
        self.no_return.get(i + 1).copied().unwrap_or(false)
    }

    /// … or the reading before it got no return (a reading beyond the maximum range
    /// is a far surface: the run's surface ended there).
    pub(crate) fn no_return_before(&self, k: usize) -> bool {
        let i = self.original[k] as usize;
        i > 0 && self.no_return[i - 1]
    }

    /// Index of the ray whose angle is closest to `bearing` (rad, not wrapped).
    pub(crate) fn ray_near_bearing(&self, bearing: f64) -> usize {
        let n = self.angles.len();
        let i = match self.uniform {
            Some((a0, step)) => ((bearing - a0) / step).round(),
            None => self.angles.partition_point(|&a| a < bearing) as f64,
        };
        if i.is_nan() || i <= 0.0 {
            0
        } else {
            (i as usize).min(n - 1)
        }
    }
}

/// `no_return[i]`: reading `i` is zero, non-finite or at most `lo` (m) — in a scan
/// where such readings are common (at least [`SPARSE_SCAN_SHARE`] of them: dark or
/// glancing surfaces, a real URG-04LX on the MinesRover logs has 55 %); elsewhere
/// none is marked and the matches stay exactly what they were (rare dropouts cost a
/// point or two; simulated scans with 15–20 % of their rays beyond the range, also
/// reported as 0, moved a TurtleBot-class verdict from "weak" to "not excited").
fn no_returns(ranges: &[f32], lo: f64) -> Vec<bool> {
    let missing: Vec<bool> = ranges
        .iter()
        .map(|&r| !r.is_finite() || f64::from(r) <= lo)
        .collect();
    let count = missing.iter().filter(|&&m| m).count();
    if (count as f64) < SPARSE_SCAN_SHARE * ranges.len() as f64 {
        return vec![false; ranges.len()];
    }
    missing
}

/// See [`no_returns`].
const SPARSE_SCAN_SHARE: f64 = 0.45;

/// Fewest usable lines that show a scan's noise (windows or metric neighbourhoods).
const MIN_NOISE_LINES: usize = 10;

/// Most valid points whose noise is looked for in metric neighbourhoods
/// ([`MAX_POINTS`]: their search compares every pair). A denser scan without straight
/// runs keeps its noise unknown.
const MAX_NEIGHBOURHOOD_NOISE_POINTS: usize = MAX_POINTS;

/// The readings a scan keeps, valid ones (finite, above `lo` and 0, below `hi`, m), in
/// ray order; and per kept reading, whether it and the next kept one may be
/// consecutive points of a run: neighbouring rays, or at most `bridged` readings
/// between them, all without a return (zero, NaN or at most `lo`: dropouts). A
/// reading at or beyond `hi` between them (a far surface, or none in range) is never
/// bridged.
fn kept_readings(ranges: &[f32], lo: f64, hi: f64, bridged: usize) -> (Vec<u32>, Vec<bool>) {
    let mut kept = Vec::with_capacity(ranges.len());
    let mut bridgeable = Vec::with_capacity(ranges.len());
    // Missing readings since the last kept one; `None` once a far one broke the run.
    let mut missing_since: Option<usize> = Some(0);
    for (i, &r) in ranges.iter().enumerate() {
        let r = f64::from(r);
        if r.is_finite() && r > lo.max(0.0) && r < hi {
            if !kept.is_empty() {
                bridgeable.push(missing_since.is_some_and(|m| m <= bridged));
            }
            kept.push(i as u32);
            missing_since = Some(0);
        } else if r.is_nan() || r <= lo.max(0.0) {
            missing_since = missing_since.map(|m| m + 1);
        } else {
            missing_since = None;
        }
    }
    if !kept.is_empty() {
        bridgeable.push(false);
    }
    (kept, bridgeable)
}

/// Mean angle between neighbouring rays (rad; 0 for fewer than two).
pub(crate) fn mean_step(angles: &[f64]) -> f64 {
    match (angles.first(), angles.last()) {
        (Some(a), Some(b)) if angles.len() > 1 => (b - a).abs() / (angles.len() - 1) as f64,
        _ => 0.0,
    }
}

/// Unit directions of the rays. For uniformly spaced angles (every laser) they are
/// generated by rotating with the step, re-anchored on an exact `sin_cos` every 32
/// rays (error ≲ 1e-15), which is several times cheaper than one `sin_cos` per ray.
/// `uniform`: the spacing found by [`uniform_spacing`]. Otherwise each ray's exact
/// `(cos, sin)`: from `given` (the directions of the scan's every reading, and the
/// reading each of `angles` is) when the caller has them.
fn ray_directions(
    angles: &[f64],
    uniform: Option<(f64, f64)>,
    given: Option<(&[[f64; 2]], &[u32])>,
) -> Vec<[f64; 2]> {
    let Some((a0, step)) = uniform else {
        if let Some((directions, readings)) = given {
            return readings.iter().map(|&i| directions[i as usize]).collect();
        }
        return angles
            .iter()
            .map(|a| {
                let (s, c) = a.sin_cos();
                [c, s]
            })
            .collect();
    };
    let (ss, cs) = step.sin_cos();
    let mut dirs = Vec::with_capacity(angles.len());
    let mut d = [0.0, 0.0];
    for i in 0..angles.len() {
        if i % 32 == 0 {
            let (s, c) = (a0 + i as f64 * step).sin_cos();
            d = [c, s];
        } else {
            d = [d[0] * cs - d[1] * ss, d[0] * ss + d[1] * cs];
        }
        dirs.push(d);
    }
    dirs
}

/// `Some((a0, step))` when `angles[i] = a0 + i·step` to within 1e-9 rad.
fn uniform_spacing(angles: &[f64]) -> Option<(f64, f64)> {
    let n = angles.len();
    if n < 2 {
        return None;
    }
    let step = (angles[n - 1] - angles[0]) / (n - 1) as f64;
    if step <= 0.0 {
        return None;
    }
    let uniform = angles
        .iter()
        .enumerate()
        .all(|(i, &a)| (a - (angles[0] + i as f64 * step)).abs() < 1e-9);
    uniform.then_some((angles[0], step))
}

/// `connected[i]`: kept points `i` and `i + 1` are consecutive points of a run
/// (`bridgeable[i]`) and on one surface (no range jump over the angle between them).
fn connections(
    ranges: &[f32],
    angles: &[f64],
    points: &[[f64; 2]],
    bridgeable: &[bool],
    params: &IcpParams,
) -> Vec<bool> {
    let n = points.len();
    let mut connected = vec![false; n];
    for i in 0..n.saturating_sub(1) {
        if !bridgeable[i] {
            continue;
        }
        let r = f64::from(ranges[i].max(ranges[i + 1]));
        let gap_allowed = params.run_gap(r, angles[i + 1] - angles[i]);
        let (p, q) = (points[i], points[i + 1]);
        let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
        connected[i] = dx * dx + dy * dy <= gap_allowed * gap_allowed;
    }
    connected
}

/// The local line of every segment (see the module documentation).
fn local_lines(
    points: &[[f64; 2]],
    inv_ranges: &[f64],
    connected: &[bool],
    params: &IcpParams,
) -> (Vec<Option<SegmentLine>>, f64, Option<f64>) {
    let n = points.len();
    // Range-noise variance of each disjoint window on a straight surface.
    let mut range_variances: Vec<f64> = Vec::new();
    // (Δφ)² / (u_a + u_b) for pairs of adjacent disjoint windows (see `tilt_scale`).
    let mut tilt_ratios: Vec<f64> = Vec::new();
    let mut segments = vec![None; n];
    let mut fits: Vec<WindowFit> = Vec::with_capacity(n);
    let mut start = 0;
    while start < n {
        if !connected[start] {
            start += 1;
            continue;
        }
        // Run of points start..=end, each connected to the next.
        let mut end = start + 1;
        while end < n && connected[end] {
            end += 1;
        }
        let run_len = end - start + 1;
        let w = params.line_fit_window.min(run_len);
        fits.clear();
        // Sliding moments about the run's first point, recomputed from scratch every
        // 32 windows to bound the rounding drift of the additions and subtractions.
        let origin = points[start];
        let mut moments = Moments::default();
        for s in start..=end + 1 - w {
            if (s - start) % 32 == 0 {
                moments = Moments::default();
                for p in &points[s..s + w] {
                    moments.add(*p, origin, 1.0);
                }
            } else {
                moments.add(points[s - 1], origin, -1.0);
                moments.add(points[s + w - 1], origin, 1.0);
            }
            fits.push(moments.fit(origin, w));
        }
        // Residual sum of squares allowed for a window of w points.
        let max_smallest = params.max_line_fit_rms * params.max_line_fit_rms * w as f64;
        // Tilt noise: disjoint neighbouring windows on one straight surface differ in
        // direction only by their noise.
        if w >= 3 {
            let tilt_unit = |s: usize, line: &SegmentLine| {
                let c = points[s + w / 2];
                let cos = (line.normal[0] * c[0] + line.normal[1] * c[1]) * inv_ranges[s + w / 2];
                cos * cos / (fits[s - start].sxx + fits[s - start].syy - fits[s - start].smallest)
            };
            let mut s = start;
            // The second window's line and tilt unit of one pair are the first
            // window's of the next: computed once.
            let mut carried: Option<(usize, SegmentLine, f64)> = None;
            while s + 2 * w <= end + 1 {
                let (fa, fb) = (&fits[s - start], &fits[s + w - start]);
                if fa.smallest <= max_smallest && fb.smallest <= max_smallest {
                    let (la, unit_a) = match carried {
                        Some((at, line, unit)) if at == s => (line, unit),
                        _ => {
                            let line = fa.line();
                            (line, tilt_unit(s, &line))
                        }
                    };
                    let lb = fb.line();
                    let unit_b = tilt_unit(s + w, &lb);
                    carried = Some((s + w, lb, unit_b));
                    let cross = la.normal[0] * lb.normal[1] - la.normal[1] * lb.normal[0];
                    let units = unit_a + unit_b;
                    if units.is_finite() && units > 0.0 {
                        tilt_ratios.push(cross * cross / units);
                    }
                    // The scatter about the line, back along the ray (range noise
                    // shows only as cos α of it across a line).
                    let c = points[s + w / 2];
                    let cos = (la.normal[0] * c[0] + la.normal[1] * c[1]) * inv_ranges[s + w / 2];
                    let cos2 = (cos * cos).max(MIN_NOISE_COS2);
                    let dof = (w - 2) as f64;
                    // Median of χ²ₖ/k (Wilson–Hilferty): the median of these
                    // variances is then σ² for independent Gaussian noise.
                    let median_ratio = (1.0 - 2.0 / (9.0 * dof)).powi(3);
                    range_variances.push(fa.smallest / (dof * cos2 * median_ratio));
                }
                s += w;
            }
        }
        // Consecutive segments often pick the same window: its line is computed once.
        let mut cached: Option<(usize, SegmentLine)> = None;
        for (i, segment) in segments.iter_mut().enumerate().take(end).skip(start) {
            // Windows s..s+w containing i and i+1: s in [i + 2 - w, i] within the run.
            let s_lo = (i + 2).saturating_sub(w).max(start);
            let s_hi = i.min(end + 1 - w);
            // The first window with the smallest residual (the residuals of a run's
            // windows are finite: its points are valid).
            if s_lo > s_hi {
                continue;
            }
            let mut best = s_lo;
            for s in s_lo + 1..=s_hi {
                if fits[s - start].smallest < fits[best - start].smallest {
                    best = s;
                }
            }
            if fits[best - start].smallest > max_smallest {
                continue;
            }
            let mut line = match cached {
                Some((s, line)) if s == best => line,
                _ => {
                    let line = fits[best - start].line();
                    cached = Some((best, line));
                    line
                }
            };
            if !line.normal[0].is_finite() {
                continue;
            }
            let n = line.normal;
            let cos = |k: usize| (n[0] * points[k][0] + n[1] * points[k][1]) * inv_ranges[k];
            line.incidence_cos = 0.5 * (cos(i) + cos(i + 1)).abs();
            line.tilt_variance *= line.incidence_cos * line.incidence_cos;
            *segment = Some(line);
        }
        start = end + 1;
    }
    (
        segments,
        tilt_scale(&mut tilt_ratios),
        noise_scale(&mut range_variances),
    )
}

/// Floor of cos² α when a window's scatter is turned back into range noise (grazing
/// windows would otherwise blow it up).
const MIN_NOISE_COS2: f64 = 0.04;

/// Range-noise standard deviation from the (median-scaled) variances of disjoint
/// windows: the square root of their median, robust to the windows on bends and
/// corners. Range noise correlated over neighbouring rays partly moves a window as a
/// whole, so that on such sensors it is below the per-ray σ (≈ 0.6 σ for the
/// simulated URG-04LX). `None` (unknown) when fewer than 10 windows.
fn noise_scale(variances: &mut [f64]) -> Option<f64> {
    if variances.len() < MIN_NOISE_LINES {
        return None;
    }
    let mid = variances.len() / 2;
    let (_, median, _) = variances.select_nth_unstable_by(mid, f64::total_cmp);
    Some(median.sqrt())
}

/// Range-noise variance that, times a line's `tilt_variance`, gives the variance of
/// its tilt: estimated from the direction differences of disjoint neighbouring
/// windows (so it includes the effect of noise correlated along the scan, which makes
/// local lines tilt more than independent noise would). The median of the ratios,
/// divided by the median of a χ²₁ variable (0.455), is robust to the pairs that
/// straddle a real bend. 0 when the scan has fewer than 10 such pairs.
fn tilt_scale(ratios: &mut [f64]) -> f64 {
    if ratios.len() < 10 {
        return 0.0;
    }
    let mid = ratios.len() / 2;
    let (_, median, _) = ratios.select_nth_unstable_by(mid, f64::total_cmp);
    // Each ratio is (φ_a − φ_b)² / (u_a + u_b) with var(φ) = scale · u.
    *median / 0.454_936_423_119_572_8
}

/// Sums of a window's coordinates about an origin, and their products.
#[derive(Debug, Clone, Copy, Default)]
struct Moments {
    x: f64,
    y: f64,
    xx: f64,
    xy: f64,
    yy: f64,
}

impl Moments {
    /// Adds (`sign` = 1) or removes (`sign` = −1) point `p`.
    #[inline]
    fn add(&mut self, p: [f64; 2], origin: [f64; 2], sign: f64) {
        let (dx, dy) = (p[0] - origin[0], p[1] - origin[1]);
        self.x += sign * dx;
        self.y += sign * dy;
        self.xx += sign * dx * dx;
        self.xy += sign * dx * dy;
        self.yy += sign * dy * dy;
    }

    /// Centroid, scatter and residual sum of squares of the `count` points summed
    /// (the line itself is computed only for the windows that get used).
    fn fit(&self, origin: [f64; 2], count: usize) -> WindowFit {
        let k = count as f64;
        let (mx, my) = (self.x / k, self.y / k);
        let sxx = (self.xx - mx * self.x).max(0.0);
        let syy = (self.yy - my * self.y).max(0.0);
        let sxy = self.xy - mx * self.y;
        let half_trace = 0.5 * (sxx + syy);
        let half_gap = 0.5 * (sxx - syy);
        let half_diff = (half_gap * half_gap + sxy * sxy).sqrt();
        WindowFit {
            mx,
            my,
            sxx,
            sxy,
            syy,
            smallest: (half_trace - half_diff).max(0.0),
            origin,
        }
    }
}

/// Total-least-squares line through `pts` (at least 2 points) and its RMS residual.
#[cfg(test)]
fn fit_window(pts: &[[f64; 2]]) -> (SegmentLine, f64) {
    let mut m = Moments::default();
    for p in pts {
        m.add(*p, pts[0], 1.0);
    }
    let fit = m.fit(pts[0], pts.len());
    (fit.line(), (fit.smallest / pts.len() as f64).sqrt())
}

impl WindowFit {
    /// The line through the centroid along the major axis of the scatter, its normal
    /// pointing towards the sensor. The normal is the eigenvector of the smallest
    /// eigenvalue, from whichever of two equivalent forms is better conditioned.
    fn line(&self) -> SegmentLine {
        let (sxx, sxy, syy, smallest) = (self.sxx, self.sxy, self.syy, self.smallest);
        let u = [sxy, smallest - sxx];
        let v = [smallest - syy, sxy];
        let (nu, nv) = (u[0] * u[0] + u[1] * u[1], v[0] * v[0] + v[1] * v[1]);
        let (w, nw) = if nu >= nv { (u, nu) } else { (v, nv) };
        let inv = if nw > 0.0 { 1.0 / nw.sqrt() } else { f64::NAN };
        let mut normal = [w[0] * inv, w[1] * inv];
        let centroid = [self.origin[0] + self.mx, self.origin[1] + self.my];
        let mut offset = normal[0] * centroid[0] + normal[1] * centroid[1];
        if offset > 0.0 {
            normal = [-normal[0], -normal[1]];
            offset = -offset;
        }
        let largest = self.sxx + self.syy - self.smallest;
        SegmentLine {
            normal,
            offset,
            incidence_cos: 1.0,
            // Completed with the incidence by the caller.
            tilt_variance: 1.0 / largest,
            centroid_along: -normal[1] * centroid[0] + normal[0] * centroid[1],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fit_window_recovers_an_exact_line() {
        // Points on x·cos(a) + y·sin(a) = d.
        let (a, d) = (0.7_f64, 1.3_f64);
        let n = [a.cos(), a.sin()];
        let t = [-n[1], n[0]];
        let pts: Vec<[f64; 2]> = (0..7)
            .map(|i| {
                let u = 0.01 * i as f64 - 0.02;
                [d * n[0] + u * t[0], d * n[1] + u * t[1]]
            })
            .collect();
        let (line, rms) = fit_window(&pts);
        assert!(rms < 1e-12);
        // Normal towards the sensor: −n, offset −d.
        assert!((line.normal[0] + n[0]).abs() < 1e-12);
        assert!((line.normal[1] + n[1]).abs() < 1e-12);
        assert!((line.offset + d).abs() < 1e-12);
    }

    #[test]
    fn invalid_readings_are_marked() {
        let angles: Vec<f64> = (0..40).map(|i| -0.5 + 0.025 * i as f64).collect();
        let mut ranges: Vec<f32> = angles.iter().map(|a| (1.0 / a.cos()) as f32).collect();
        ranges[3] = 0.0;
        ranges[4] = f32::NAN;
        ranges[5] = f32::INFINITY;
        ranges[6] = 5.0;
        ranges[7] = 0.01;
        let scan = PreparedScan::new(&ranges, &angles, 0.02, 4.0, &IcpParams::default())
            .expect("enough valid points");
        assert_eq!(scan.valid_count(), 35);
        for i in 3..8 {
            assert!(scan.point(i).is_none(), "reading {i} must be invalid");
        }
        // Only the valid readings are kept; no segment crosses the far readings (5:
        // infinite, 6: beyond the maximum range) between rays 2 and 8.
        let kept: Vec<u32> = scan.original.iter().take(4).copied().collect();
        assert_eq!(kept, [0, 1, 2, 8]);
        assert!(scan.segments[2].is_none());
        // The wall x = 1 elsewhere.
        let line = scan.segments[20].expect("segment on the wall");
        assert!(
            (line.normal[0] + 1.0).abs() < 1e-9 && (line.offset + 1.0).abs() < 1e-6,
            "{line:?}"
        );
    }

    #[test]
    fn dropouts_are_bridged_up_to_the_limit() {
        // A wall at x = 1; two readings missing after ray 9, three after ray 19.
        let angles: Vec<f64> = (0..40).map(|i| -0.5 + 0.025 * i as f64).collect();
        let mut ranges: Vec<f32> = angles.iter().map(|a| (1.0 / a.cos()) as f32).collect();
        for i in [10, 11, 20, 21, 22] {
            ranges[i] = 0.0;
        }
        let segment_from = |scan: &PreparedScan, ray: u32| {
            let k = scan.original.binary_search(&ray).expect("a kept reading");
            (scan.original[k + 1], scan.segments[k])
        };
        let scan = PreparedScan::new(&ranges, &angles, 0.02, 4.0, &IcpParams::default())
            .expect("enough valid points");
        let (next, line) = segment_from(&scan, 9);
        assert_eq!(next, 12);
        let line = line.expect("two dropouts bridged");
        assert!((line.normal[0] + 1.0).abs() < 1e-9 && (line.offset + 1.0).abs() < 1e-6);
        assert_eq!(segment_from(&scan, 19), (23, None), "three are not");
        // Not bridging: the run ends at either gap.
        let params = IcpParams {
            bridged_missing_rays: 0,
            ..IcpParams::default()
        };
        let scan = PreparedScan::new(&ranges, &angles, 0.02, 4.0, &params).expect("valid points");
        assert_eq!(segment_from(&scan, 9), (12, None));
        assert!(scan.point(10).is_none() && scan.point(12).is_some());
    }

    #[test]
    fn the_noise_of_scans_without_runs_is_sought_in_neighbourhoods_up_to_a_size() {
        // Cluttered readings (uniform 0.5–3.5 m): no straight window shows the noise.
        use rand::{Rng, SeedableRng};
        let clutter = |n: usize| {
            let angles: Vec<f64> = (0..n).map(|i| -3.1 + 6.2 * i as f64 / n as f64).collect();
            let mut rng = rand::rngs::StdRng::seed_from_u64(5);
            let ranges: Vec<f32> = (0..n).map(|_| rng.random_range(0.5..3.5)).collect();
            PreparedScan::new(&ranges, &angles, 0.02, 5.6, &IcpParams::default()).unwrap()
        };
        assert!(clutter(MAX_NEIGHBOURHOOD_NOISE_POINTS)
            .noise_sigma
            .is_some());
        // Beyond the bound (the search compares every pair of points): unknown.
        assert_eq!(
            clutter(MAX_NEIGHBOURHOOD_NOISE_POINTS + 1).noise_sigma,
            None
        );
    }

    #[test]
    fn range_jumps_split_runs() {
        let angles: Vec<f64> = (0..40).map(|i| -0.5 + 0.025 * i as f64).collect();
        let ranges: Vec<f32> = angles
            .iter()
            .enumerate()
            .map(|(i, a)| ((if i < 20 { 1.0 } else { 2.0 }) / a.cos()) as f32)
            .collect();
        let scan = PreparedScan::new(&ranges, &angles, 0.02, 4.0, &IcpParams::default())
            .expect("enough valid points");
        assert!(scan.segments[19].is_none(), "no segment across the jump");
        assert!(scan.segments[18].is_some() && scan.segments[20].is_some());
        let far = scan.segments[25].expect("far wall");
        assert!((far.offset + 2.0).abs() < 1e-6, "{far:?}");
    }

    #[test]
    fn mixed_pixels_are_left_out_as_readings_without_a_return() {
        // Two walls 1 m and 2 m ahead, rays 0.3° apart, ray 19 a mixed pixel: 4 cm
        // behind the near wall's end, towards the far one.
        let angles: Vec<f64> = (0..40).map(|i| -0.1 + 0.005 * i as f64).collect();
        let mut ranges: Vec<f32> = angles
            .iter()
            .enumerate()
            .map(|(i, a)| ((if i < 20 { 1.0 } else { 2.0 }) / a.cos()) as f32)
            .collect();
        ranges[19] = (1.04 / angles[19].cos()) as f32;
        let scan = PreparedScan::new(&ranges, &angles, 0.02, 4.0, &IcpParams::default())
            .expect("enough valid points");
        assert_eq!(scan.points.len(), 39);
        assert!(!scan.original.contains(&19));
        // The near wall's run ends at ray 18 and is not joined to the far wall.
        let k = scan.original.iter().position(|&i| i == 18).expect("ray 18");
        assert!(scan.segments[k].is_none() && scan.segments[k - 1].is_some());
        // Judged with the log's typical noise instead of the scan's own: the same.
        let typical = IcpParams {
            typical_noise_sigma: 0.005,
            ..IcpParams::default()
        };
        let scan = PreparedScan::new(&ranges, &angles, 0.02, 4.0, &typical).expect("points");
        assert!(!scan.original.contains(&19));
        // Rays 1.4° apart are not judged (mixed_pixels::MAX_RAY_STEP).
        let coarse: Vec<f64> = (0..40).map(|i| -0.5 + 0.025 * i as f64).collect();
        let scan = PreparedScan::new(&ranges, &coarse, 0.02, 4.0, &typical).expect("points");
        assert_eq!(scan.points.len(), 40);
        // Kept when the judgement is switched off; a cloud (entries that are not
        // neighbouring rays) keeps every point.
        let kept = IcpParams {
            mixed_pixel_sigmas: f64::INFINITY,
            ..IcpParams::default()
        };
        let scan = PreparedScan::new(&ranges, &angles, 0.02, 4.0, &kept).expect("valid points");
        assert_eq!(scan.points.len(), 40);
        let points: Vec<[f64; 2]> = ranges
            .iter()
            .zip(&angles)
            .map(|(&r, a)| [f64::from(r) * a.cos(), f64::from(r) * a.sin()])
            .collect();
        let cloud = PreparedScan::from_points(&points, &[], &IcpParams::default()).unwrap();
        assert_eq!(cloud.points.len(), 40);
    }
}
