//! The Cramér–Rao bound (CRB) of the displacement between two simulated scans, with
//! the walls unknown: the least covariance any unbiased estimator of the relative
//! pose can reach from the two scans' ranges on the simulator's sensor model.
//!
//! Model, in the frame of the first sensor pose: the unknowns are the relative pose
//! `s = (x, y, θ)` of the second scan and every wall line `n·p = d`,
//! `n = (cos α, sin α)` (collinear segments of the world are one line). A ray from
//! `o` in unit direction `u` reads `r = (d − n·o) / (n·u)` plus noise; scan 1 has
//! `o = 0`, scan 2 has `o = (x, y)` and its ray directions turned by `θ`. The noise
//! of a scan is Gaussian with the simulator's covariance: σ² times the correlation of
//! a normalised moving sum of `correlation_rays` white values (`1 − lag/w` up to lag
//! `w − 1`), restricted to the rays used (the correlation between them kept), plus
//! the variance `q²/12` of the rounding to `q` on the diagonal; scans are
//! independent. Fisher information `F = Σ_scans Jᵀ Σ⁻¹ J`; the bound on `s` is the
//! 3×3 block of `F⁻¹`, i.e. the inverse of the Schur complement of the wall block.
//! The rounding is taken as independent Gaussian noise of its variance (with
//! σ = 3 mm ≫ 1 mm the rounding errors are close to independent and uniform); on the
//! correlated model it is the only noise at the frequencies where the moving sum's
//! spectrum vanishes, so the bound depends on it (see `tests/cramer_rao.rs`).
//!
//! Include with `#[path = "common/cramer_rao_bound.rs"] mod cramer_rao_bound;`.
#![allow(dead_code)]

use nalgebra::{DMatrix, Matrix3};
use odocal_geom::Pose2;
use odocal_sim::{LaserConfig, World};

/// Two segments are on the same line when both ends of one are this close (m) to
/// the other's line.
const COLLINEAR_TOLERANCE: f64 = 1e-9;

/// The range noise of one scan (Gaussian approximation of the simulator's model).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RangeNoise {
    /// Standard deviation of each reading before rounding (m).
    pub sigma: f64,
    /// Length of the moving sum the noise is made of (1 = independent).
    pub correlation_rays: usize,
    /// Rounding step (m), 0 for none.
    pub quantization: f64,
}

impl RangeNoise {
    /// The noise model of a simulated laser.
    pub fn of(laser: &LaserConfig) -> Self {
        RangeNoise {
            sigma: laser.range_sigma,
            correlation_rays: laser.correlation_rays.max(1),
            quantization: laser.quantization,
        }
    }

    /// Covariance (m²) of the readings of two rays `lag` indices apart: the moving
    /// sum's `σ² (w − lag) / w` below `w`, plus the rounding's `q²/12` at lag 0.
    pub fn covariance(&self, lag: usize) -> f64 {
        let w = self.correlation_rays;
        let mut c = if lag < w {
            self.sigma * self.sigma * (w - lag) as f64 / w as f64
        } else {
            0.0
        };
        if lag == 0 {
            c += self.quantization * self.quantization / 12.0;
        }
        c
    }

    /// Number of neighbours on each side a reading is correlated with.
    pub fn bandwidth(&self) -> usize {
        self.correlation_rays - 1
    }

    /// `Σ m` for the covariance `Σ` of readings `rays` (increasing ray indices) and
    /// `m` with one row per reading.
    pub fn covariance_times(&self, rays: &[usize], m: &DMatrix<f64>) -> DMatrix<f64> {
        let b = self.bandwidth();
        let n = rays.len();
        let mut out = DMatrix::zeros(n, m.ncols());
        for i in 0..n {
            for j in i.saturating_sub(b)..(i + b + 1).min(n) {
                let c = self.covariance(rays[i].abs_diff(rays[j]));
                if c != 0.0 {
                    for k in 0..m.ncols() {
                        out[(i, k)] += c * m[(j, k)];
                    }
                }
            }
        }
        out
    }
}

/// The covariance of readings `rays` (increasing ray indices) as the Cholesky factor
/// `L` (`Σ = L Lᵀ`), stored by band. The restriction of a banded Toeplitz matrix to
/// increasing indices is banded with the same width (indices `k` apart in the list
/// are at least `k` rays apart), so the factor has that band too: `O(n b²)` instead
/// of the dense `O(n³)` (tested against nalgebra's dense Cholesky).
#[derive(Debug, Clone)]
pub struct BandedCholesky {
    /// Band width `b`: `L[i][j] = 0` for `i − j > b`.
    bandwidth: usize,
    /// Row `i` holds `L[i][i − b ..= i]` at `i (b + 1) ..`, left-padded with zeros.
    factor: Vec<f64>,
}

impl BandedCholesky {
    /// The factor of the noise covariance of readings `rays`, or `None` when it is not
    /// positive definite.
    pub fn of_rays(noise: &RangeNoise, rays: &[usize]) -> Option<Self> {
        let b = noise.bandwidth();
        let n = rays.len();
        let w = b + 1;
        let mut factor = vec![0.0; n * w];
        for i in 0..n {
            for j in i.saturating_sub(b)..=i {
                // Entries of L at (i, k) live at factor[i w + b − (i − k)].
                let at = |r: usize, k: usize| r * w + b - (r - k);
                let mut s = noise.covariance(rays[i] - rays[j]);
                for k in i.saturating_sub(b)..j {
                    s -= factor[at(i, k)] * factor[at(j, k)];
                }
                if i == j {
                    if s <= 0.0 || !s.is_finite() {
                        return None;
                    }
                    factor[at(i, i)] = s.sqrt();
                } else {
                    factor[at(i, j)] = s / factor[at(j, j)];
                }
            }
        }
        Some(BandedCholesky {
            bandwidth: b,
            factor,
        })
    }

    /// Replaces `m` (one row per reading) by `L⁻¹ m`, so that `mᵀ Σ⁻¹ m` becomes
    /// `(L⁻¹m)ᵀ (L⁻¹m)`.
    pub fn whiten(&self, m: &mut DMatrix<f64>) {
        let b = self.bandwidth;
        let w = b + 1;
        for i in 0..m.nrows() {
            for k in i.saturating_sub(b)..i {
                let l = self.factor[i * w + b - (i - k)];
                for c in 0..m.ncols() {
                    let v = m[(k, c)];
                    m[(i, c)] -= l * v;
                }
            }
            let d = self.factor[i * w + b];
            for c in 0..m.ncols() {
                m[(i, c)] /= d;
            }
        }
    }
}

/// The infinite lines of a world's walls: collinear segments share one line.
#[derive(Debug, Clone)]
pub struct WallLines {
    /// Per line: unit normal `n` and offset `d` of `n·p = d` (world frame).
    lines: Vec<([f64; 2], f64)>,
    /// Per segment of the world (same order): its line.
    line_of_segment: Vec<usize>,
}

impl WallLines {
    /// The lines of `world`'s segments (degenerate, zero-length segments are left out
    /// and never hit).
    pub fn of(world: &World) -> Self {
        let mut lines: Vec<([f64; 2], f64)> = vec![];
        let mut line_of_segment = vec![];
        for s in world.segments() {
            let e = [s.b[0] - s.a[0], s.b[1] - s.a[1]];
            let len = e[0].hypot(e[1]);
            let n = [-e[1] / len, e[0] / len];
            let on = |(m, d): &([f64; 2], f64), p: [f64; 2]| {
                (m[0] * p[0] + m[1] * p[1] - d).abs() < COLLINEAR_TOLERANCE
            };
            let found = lines.iter().position(|l| on(l, s.a) && on(l, s.b));
            let id = found.unwrap_or_else(|| {
                lines.push((n, n[0] * s.a[0] + n[1] * s.a[1]));
                lines.len() - 1
            });
            line_of_segment.push(id);
        }
        WallLines {
            lines,
            line_of_segment,
        }
    }

    /// Number of distinct lines.
    pub fn len(&self) -> usize {
        self.lines.len()
    }

    /// Line `id` as `(α, d)` in the frame of `frame` (a pose in the world frame).
    pub fn in_frame(&self, id: usize, frame: &Pose2) -> [f64; 2] {
        let (n, d) = self.lines[id];
        [
            n[1].atan2(n[0]) - frame.theta,
            d - n[0] * frame.x - n[1] * frame.y,
        ]
    }
}

/// A ray of a scan that reads a wall: its index, the wall's line, the true range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WallHit {
    /// Ray index in the scan.
    pub ray: usize,
    /// Line of the wall hit (see [`WallLines`]).
    pub line: usize,
    /// True range (m).
    pub range: f64,
    /// Cosine of the angle between the ray and the wall's normal (1 = head-on).
    pub incidence_cos: f64,
}

/// The rays of a scan taken from `sensor` (world frame) that carry information: the
/// true ray hits a wall strictly between the laser's minimum and maximum range, and
/// the scan reports a reading (`reported[i] != 0`: random dropouts carry nothing).
pub fn wall_hits(
    world: &World,
    lines: &WallLines,
    laser: &LaserConfig,
    sensor: &Pose2,
    reported: &[f32],
) -> Vec<WallHit> {
    let origin = [sensor.x, sensor.y];
    laser
        .angles()
        .iter()
        .enumerate()
        .filter(|&(i, _)| reported[i] != 0.0)
        .filter_map(|(i, a)| {
            let (sn, cs) = (sensor.theta + a).sin_cos();
            let (range, segment) = world
                .segments()
                .iter()
                .enumerate()
                .filter_map(|(k, s)| s.ray_hit(origin, [cs, sn]).map(|t| (t, k)))
                .min_by(|x, y| x.0.total_cmp(&y.0))?;
            let line = lines.line_of_segment[segment];
            let n = lines.lines[line].0;
            (range > laser.min_range && range < laser.max_range).then_some(WallHit {
                ray: i,
                line,
                range,
                incidence_cos: dot(n, [cs, sn]).abs(),
            })
        })
        .collect()
}

/// Range read along the ray at angle `angle` (sensor frame) of a sensor at `pose`
/// (frame 1) on the line `(α, d)` (frame 1): `(d − n·o) / (n·u)`.
pub fn range_to_line(pose: [f64; 3], line: [f64; 2], angle: f64) -> f64 {
    let (n, u) = (unit(line[0]), unit(pose[2] + angle));
    (line[1] - n[0] * pose[0] - n[1] * pose[1]) / dot(n, u)
}

/// Gradient of [`range_to_line`]: with respect to the pose `(x, y, θ)` and to the
/// line `(α, d)`.
pub fn range_gradient(pose: [f64; 3], line: [f64; 2], angle: f64) -> ([f64; 3], [f64; 2]) {
    let (n, u) = (unit(line[0]), unit(pose[2] + angle));
    let n_turned = [-n[1], n[0]];
    let u_turned = [-u[1], u[0]];
    let nu = dot(n, u);
    let r = range_to_line(pose, line, angle);
    let o = [pose[0], pose[1]];
    (
        [-n[0] / nu, -n[1] / nu, -r * dot(n, u_turned) / nu],
        [-(dot(n_turned, o) + r * dot(n_turned, u)) / nu, 1.0 / nu],
    )
}

/// The bound for one pair, and what it was computed from.
#[derive(Debug, Clone)]
pub struct PairBound {
    /// CRB of `(x, y, θ)` (m², rad²).
    pub covariance: Matrix3<f64>,
    /// Its inverse: the pose information left once the walls are estimated.
    pub information: Matrix3<f64>,
    /// Covariance of `(x, y, θ)` estimated by ordinary least squares on the same
    /// rays and model (walls unknown), i.e. with the noise taken as independent, under
    /// the true noise: the floor of a matcher that does not model the correlation
    /// (equal to `covariance` for independent noise).
    pub least_squares_covariance: Matrix3<f64>,
    /// Lines read by both scans (the pose information comes from them; a line read
    /// by one scan only tells nothing about the pose, except, with correlated noise,
    /// through what its rays reveal of their neighbours' noise).
    pub shared_lines: usize,
    /// Rays used, per scan.
    pub rays: [usize; 2],
    /// Largest difference (m) between a true range and [`range_to_line`] at the
    /// truth: a check of the frames and of the ray-to-line association.
    pub max_range_mismatch: f64,
}

/// The unknowns of a pair and the rays that inform them. A line read by fewer than
/// three rays of the pair is left out with its rays: its two parameters absorb them
/// exactly, which is the same as not having them (the noise of the others is then
/// that of the restricted covariance).
struct PairModel<'a> {
    /// Per line: the column of its `α` (`d` is next), `usize::MAX` when left out.
    column: Vec<usize>,
    /// Number of unknowns: the pose, then two per line kept.
    params: usize,
    /// Per scan: the rays used.
    used: [Vec<&'a WallHit>; 2],
    /// Lines read by both scans.
    shared_lines: usize,
}

impl<'a> PairModel<'a> {
    fn new(lines: &WallLines, hits: [&'a [WallHit]; 2]) -> Self {
        let mut per_line = vec![[0usize; 2]; lines.len()];
        for (scan, hits) in hits.iter().enumerate() {
            for h in hits.iter() {
                per_line[h.line][scan] += 1;
            }
        }
        let mut column = vec![usize::MAX; lines.len()];
        let mut params = 3;
        for (id, c) in per_line.iter().enumerate() {
            if c[0] + c[1] >= 3 {
                column[id] = params;
                params += 2;
            }
        }
        let shared_lines = per_line
            .iter()
            .filter(|c| c[0] > 0 && c[1] > 0 && c[0] + c[1] >= 3)
            .count();
        let used = hits.map(|h| h.iter().filter(|h| column[h.line] != usize::MAX).collect());
        PairModel {
            column,
            params,
            used,
            shared_lines,
        }
    }

    /// The unknowns at the truth: the relative pose, and every kept line in the
    /// first scan's frame.
    fn truth(&self, lines: &WallLines, first: &Pose2, second: &Pose2) -> Vec<f64> {
        let relative = first.between(second);
        let mut x = vec![0.0; self.params];
        x[..3].copy_from_slice(&[relative.x, relative.y, relative.theta]);
        for (id, &c) in self.column.iter().enumerate() {
            if c != usize::MAX {
                x[c..c + 2].copy_from_slice(&lines.in_frame(id, first));
            }
        }
        x
    }

    /// Predicted ranges of the rays of `scan` and their Jacobian at the unknowns `x`.
    fn ranges(&self, scan: usize, x: &[f64], angles: &[f64]) -> (Vec<f64>, DMatrix<f64>) {
        let at = if scan == 0 {
            [0.0; 3]
        } else {
            [x[0], x[1], x[2]]
        };
        let used = &self.used[scan];
        let mut jacobian = DMatrix::<f64>::zeros(used.len(), self.params);
        let mut predicted = Vec::with_capacity(used.len());
        for (row, h) in used.iter().enumerate() {
            let c = self.column[h.line];
            let line = [x[c], x[c + 1]];
            let angle = angles[h.ray];
            predicted.push(range_to_line(at, line, angle));
            let (d_pose, d_line) = range_gradient(at, line, angle);
            if scan == 1 {
                for (k, v) in d_pose.iter().enumerate() {
                    jacobian[(row, k)] = *v;
                }
            }
            jacobian[(row, c)] = d_line[0];
            jacobian[(row, c + 1)] = d_line[1];
        }
        (predicted, jacobian)
    }

    /// Ray indices of the rays of `scan`.
    fn rays(&self, scan: usize) -> Vec<usize> {
        self.used[scan].iter().map(|h| h.ray).collect()
    }
}

/// The 3×3 pose block of the inverse of `m` (pose first): the inverse of the Schur
/// complement of the rest.
fn pose_information(m: &DMatrix<f64>) -> Option<Matrix3<f64>> {
    let rest = m.nrows() - 3;
    let pose_block = m.view((0, 0), (3, 3)).into_owned();
    let schur = if rest == 0 {
        pose_block
    } else {
        let cross = m.view((0, 3), (3, rest)).into_owned();
        let solved = m
            .view((3, 3), (rest, rest))
            .into_owned()
            .cholesky()?
            .solve(&cross.transpose());
        pose_block - &cross * solved
    };
    let information = Matrix3::from_iterator(schur.iter().copied());
    Some(0.5 * (information + information.transpose()))
}

/// The CRB of the displacement from the scan at `first` (world frame) to the scan at
/// `second`, given their readable rays (see [`wall_hits`]); `None` when the
/// information is singular.
pub fn pair_bound(
    lines: &WallLines,
    noise: &RangeNoise,
    angles: &[f64],
    first: (&Pose2, &[WallHit]),
    second: (&Pose2, &[WallHit]),
) -> Option<PairBound> {
    let model = PairModel::new(lines, [first.1, second.1]);
    let truth = model.truth(lines, first.0, second.0);
    let n = model.params;
    let (mut fisher, mut normal, mut meat) = (
        DMatrix::<f64>::zeros(n, n),
        DMatrix::<f64>::zeros(n, n),
        DMatrix::<f64>::zeros(n, n),
    );
    let mut max_range_mismatch = 0.0f64;
    for scan in 0..2 {
        if model.used[scan].is_empty() {
            continue;
        }
        let (predicted, mut jacobian) = model.ranges(scan, &truth, angles);
        for (p, h) in predicted.iter().zip(&model.used[scan]) {
            max_range_mismatch = max_range_mismatch.max((p - h.range).abs());
        }
        let rays = model.rays(scan);
        normal += jacobian.transpose() * &jacobian;
        meat += jacobian.transpose() * noise.covariance_times(&rays, &jacobian);
        BandedCholesky::of_rays(noise, &rays)?.whiten(&mut jacobian);
        fisher += jacobian.transpose() * &jacobian;
    }
    let information = pose_information(&fisher)?;
    let covariance = information.cholesky()?.inverse();
    let normal = normal.cholesky()?;
    let sandwich = normal.solve(&normal.solve(&meat).transpose());
    Some(PairBound {
        covariance,
        least_squares_covariance: sandwich.fixed_view::<3, 3>(0, 0).into_owned(),
        information,
        shared_lines: model.shared_lines,
        rays: [model.used[0].len(), model.used[1].len()],
        max_range_mismatch,
    })
}

/// How an [`oracle_estimate`] weighs the ranges.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Weighting {
    /// By the inverse noise covariance (generalised least squares: maximum
    /// likelihood under the Gaussian model).
    Covariance,
    /// Equally (ordinary least squares: the noise taken as independent).
    Equal,
}

/// The displacement estimated from the readings (`ranges` of each scan, m) by an
/// oracle that knows which wall line each ray reads and that walls are straight, but
/// neither the pose nor the lines: Gauss–Newton on all the unknowns from the truth,
/// to convergence. It shows what the bound's model lets an estimator reach on the
/// simulated data (rounding and all). `None` when a system is singular.
pub fn oracle_estimate(
    lines: &WallLines,
    noise: &RangeNoise,
    angles: &[f64],
    first: (&Pose2, &[WallHit], &[f32]),
    second: (&Pose2, &[WallHit], &[f32]),
    weighting: Weighting,
) -> Option<Pose2> {
    let model = PairModel::new(lines, [first.1, second.1]);
    let mut x = model.truth(lines, first.0, second.0);
    let readings = [first.2, second.2];
    let factors = [0, 1].map(|scan| BandedCholesky::of_rays(noise, &model.rays(scan)));
    for _ in 0..10 {
        let mut normal = DMatrix::<f64>::zeros(model.params, model.params);
        let mut gradient = DMatrix::<f64>::zeros(model.params, 1);
        for scan in 0..2 {
            if model.used[scan].is_empty() {
                continue;
            }
            let (predicted, mut jacobian) = model.ranges(scan, &x, angles);
            let mut residual = DMatrix::from_iterator(
                predicted.len(),
                1,
                model.used[scan]
                    .iter()
                    .zip(&predicted)
                    .map(|(h, p)| readings[scan][h.ray] as f64 - p),
            );
            if weighting == Weighting::Covariance {
                let factor = factors[scan].as_ref()?;
                factor.whiten(&mut jacobian);
                factor.whiten(&mut residual);
            }
            normal += jacobian.transpose() * &jacobian;
            gradient += jacobian.transpose() * residual;
        }
        let step = normal.cholesky()?.solve(&gradient);
        for (v, d) in x.iter_mut().zip(step.iter()) {
            *v += d;
        }
        if step.rows(0, 3).norm() < 1e-12 {
            break;
        }
    }
    Some(Pose2::new(x[0], x[1], x[2]))
}

fn unit(angle: f64) -> [f64; 2] {
    let (s, c) = angle.sin_cos();
    [c, s]
}

fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

#[cfg(test)]
mod helper_tests {
    use super::*;
    use odocal_sim::Segment;

    /// The analytic gradient against central differences.
    #[test]
    fn range_gradient_matches_finite_differences() {
        let cases = [
            ([0.0, 0.0, 0.0], [0.3, 1.7], 0.2),
            ([0.05, -0.02, 0.1], [0.3, 1.7], -0.1),
            ([0.3, 0.1, -0.4], [2.5, -1.2], -0.6),
            ([-0.2, 0.4, 2.0], [-1.0, 0.8], -2.1),
        ];
        for (pose, line, angle) in cases {
            let r = range_to_line(pose, line, angle);
            assert!(r > 0.0, "case must read the line in front: {r}");
            let (d_pose, d_line) = range_gradient(pose, line, angle);
            let h = 1e-6;
            for k in 0..3 {
                let (mut p, mut m) = (pose, pose);
                p[k] += h;
                m[k] -= h;
                let fd =
                    (range_to_line(p, line, angle) - range_to_line(m, line, angle)) / (2.0 * h);
                assert!(
                    (fd - d_pose[k]).abs() < 1e-6 * (1.0 + fd.abs()),
                    "pose {k}: {fd} vs {}",
                    d_pose[k]
                );
            }
            for k in 0..2 {
                let (mut p, mut m) = (line, line);
                p[k] += h;
                m[k] -= h;
                let fd =
                    (range_to_line(pose, p, angle) - range_to_line(pose, m, angle)) / (2.0 * h);
                assert!(
                    (fd - d_line[k]).abs() < 1e-6 * (1.0 + fd.abs()),
                    "line {k}: {fd} vs {}",
                    d_line[k]
                );
            }
        }
    }

    /// `Jᵀ Σ⁻¹ J` through the banded factor equals nalgebra's dense Cholesky solve,
    /// on rays with gaps (dropouts and a run out of range), correlated or not.
    #[test]
    fn banded_factor_agrees_with_dense_cholesky() {
        let rays: Vec<usize> = (0..300)
            .filter(|i| i % 37 != 5 && i % 53 != 0 && !(120..126).contains(i))
            .collect();
        for noise in [
            RangeNoise {
                sigma: 0.003,
                correlation_rays: 4,
                quantization: 0.001,
            },
            RangeNoise {
                sigma: 0.003,
                correlation_rays: 1,
                quantization: 0.001,
            },
            RangeNoise {
                sigma: 0.003,
                correlation_rays: 6,
                quantization: 0.0,
            },
        ] {
            let n = rays.len();
            let j = DMatrix::from_fn(n, 4, |r, c| {
                ((r * 7 + c * 13) % 11) as f64 - 5.0 + 0.1 * c as f64
            });
            let mut white = j.clone();
            BandedCholesky::of_rays(&noise, &rays)
                .expect("positive definite")
                .whiten(&mut white);
            let banded = white.transpose() * &white;
            let sigma = DMatrix::from_fn(n, n, |a, b| noise.covariance(rays[a].abs_diff(rays[b])));
            let dense = j.transpose() * sigma.cholesky().expect("positive definite").solve(&j);
            let err = (&banded - &dense).norm() / dense.norm();
            assert!(err < 1e-10, "{noise:?}: relative difference {err}");
        }
    }

    fn room() -> World {
        let s = |a, b| Segment::new(a, b);
        World::new(
            "room",
            vec![
                s([0.0, 0.0], [3.0, 0.0]),
                s([3.0, 0.0], [3.0, 2.0]),
                s([3.0, 2.0], [1.0, 2.0]),
                s([1.0, 2.0], [0.0, 2.0]), // collinear with the previous one
                s([0.0, 2.0], [0.0, 0.0]),
                s([1.2, 0.6], [1.6, 1.1]), // a slanted panel
            ],
        )
    }

    /// Collinear segments are one line; ranges from the lines match the ray casts.
    #[test]
    fn lines_and_hits_reproduce_the_ray_casts() {
        let world = room();
        let lines = WallLines::of(&world);
        assert_eq!(lines.len(), 5);
        let laser = LaserConfig::default();
        let angles = laser.angles();
        let (p1, p2) = (Pose2::new(0.5, 0.4, 0.3), Pose2::new(0.56, 0.43, 0.35));
        let readings = vec![1.0f32; laser.num_rays];
        let h1 = wall_hits(&world, &lines, &laser, &p1, &readings);
        let h2 = wall_hits(&world, &lines, &laser, &p2, &readings);
        assert!(h1.len() > 600 && h2.len() > 600);
        let bound = pair_bound(
            &lines,
            &RangeNoise::of(&laser),
            &angles,
            (&p1, &h1[..]),
            (&p2, &h2[..]),
        )
        .expect("bound");
        assert!(
            bound.max_range_mismatch < 1e-9,
            "{}",
            bound.max_range_mismatch
        );
        assert!(bound.shared_lines >= 4);
    }

    /// A wall read by one scan only carries no pose information: with independent
    /// noise the bound is the same with and without its rays. With correlated noise
    /// its rays still tell something about the noise of their neighbours, so they
    /// may only help (information with ≥ without), never hurt.
    #[test]
    fn a_wall_seen_by_one_scan_only_carries_no_pose_information() {
        let world = room();
        let lines = WallLines::of(&world);
        let correlated = LaserConfig::default();
        let angles = correlated.angles();
        let (p1, p2) = (Pose2::new(0.5, 0.4, 0.3), Pose2::new(0.56, 0.43, 0.35));
        let readings = vec![1.0f32; correlated.num_rays];
        let h1 = wall_hits(&world, &lines, &correlated, &p1, &readings);
        let h2 = wall_hits(&world, &lines, &correlated, &p2, &readings);
        // Hide the slanted panel's line from the first scan: only the second reads it.
        let panel = lines.line_of_segment[5];
        let without_panel = |h: &[WallHit]| -> Vec<WallHit> {
            h.iter().filter(|h| h.line != panel).copied().collect()
        };
        let (h1_without, h2_without) = (without_panel(&h1), without_panel(&h2));
        assert!(
            h2.len() - h2_without.len() >= 10,
            "the panel must be in view"
        );
        let white = LaserConfig {
            correlation_rays: 1,
            ..correlated.clone()
        };
        for laser in [&white, &correlated] {
            let noise = RangeNoise::of(laser);
            let bound = |h2: &[WallHit]| {
                pair_bound(&lines, &noise, &angles, (&p1, &h1_without[..]), (&p2, h2))
                    .expect("bound")
            };
            let (with, without) = (bound(&h2), bound(&h2_without));
            let gain = with.information - without.information;
            let scale = without.information.norm();
            if laser.correlation_rays == 1 {
                assert!(gain.norm() < 1e-9 * scale, "gain {gain}");
            } else {
                let least = gain.symmetric_eigen().eigenvalues.min();
                assert!(least > -1e-9 * scale, "information lost: {gain}");
            }
            // And a wall seen by both scans does help.
            let both =
                pair_bound(&lines, &noise, &angles, (&p1, &h1[..]), (&p2, &h2[..])).expect("bound");
            assert!(both.covariance.trace() < 0.99 * without.covariance.trace());
        }
    }

    /// With independent noise, ordinary least squares is the efficient estimator:
    /// its covariance is the bound.
    #[test]
    fn least_squares_is_efficient_with_independent_noise() {
        let world = room();
        let lines = WallLines::of(&world);
        let laser = LaserConfig {
            correlation_rays: 1,
            ..LaserConfig::default()
        };
        let angles = laser.angles();
        let (p1, p2) = (Pose2::new(0.5, 0.4, 0.3), Pose2::new(0.56, 0.43, 0.35));
        let readings = vec![1.0f32; laser.num_rays];
        let h1 = wall_hits(&world, &lines, &laser, &p1, &readings);
        let h2 = wall_hits(&world, &lines, &laser, &p2, &readings);
        for l in [&laser, &LaserConfig::default()] {
            let b = pair_bound(
                &lines,
                &RangeNoise::of(l),
                &angles,
                (&p1, &h1[..]),
                (&p2, &h2[..]),
            )
            .expect("bound");
            let excess = b.least_squares_covariance - b.covariance;
            let least = excess.symmetric_eigen().eigenvalues.min();
            if l.correlation_rays == 1 {
                assert!(excess.norm() < 1e-9 * b.covariance.norm(), "{excess}");
            } else {
                // Never better than the bound.
                assert!(least > -1e-9 * b.covariance.norm(), "{excess}");
            }
        }
    }
}
