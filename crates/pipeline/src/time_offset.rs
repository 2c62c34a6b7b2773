//! Estimating a constant offset between the laser clock and the encoder clock.
//!
//! Shifting the scan timestamps by δ changes only the encoder half of each sample
//! (the wheel rotations over `[t0 + δ, t1 + δ]`); the scan-matching results do not
//! depend on δ and are reused. For each δ the samples are rebuilt, the closed form
//! (with the configured trimming) is solved, and the cost is the mean truncated
//! squared residual of *all* samples, normalized by the residual scale found at the
//! starting offset — the truncation keeps outliers (slip, bad matches) from steering
//! the search. A grid (10 ms steps, on at most [`GRID_SAMPLES`] evenly spread samples) finds
//! the basin; golden-section search on all samples refines it.

use crate::error::PipelineError;
use crate::options::Options;
use crate::sync::EncoderTrack;
use crate::synchronized::Synchronized;
use odocal_log::Log;
use odocal_solver::{Calibration, Params, Predictor, Sample};
use rayon::prelude::*;
use serde::Serialize;

/// Grid spacing of the coarse search (s).
pub const GRID_STEP_S: f64 = 0.01;
/// At most about this many samples enter each cost of the coarse grid.
pub const GRID_SAMPLES: usize = 1500;
/// Tolerance of the golden-section refinement (s).
pub const TOLERANCE_S: f64 = 1e-4;
/// At most this many grid steps on each side of the start: a wide range is searched
/// with coarser steps, so the search costs at most `2 · MAX_GRID_STEPS + 1` solves on
/// [`GRID_SAMPLES`] samples whatever the range.
pub const MAX_GRID_STEPS: usize = 500;
/// The range may reach at most this fraction of the scans' time span: beyond it, fewer
/// than half of the scan pairs still have encoder records at the shifted times.
pub const MAX_RANGE_OF_SPAN: f64 = 0.5;
/// Squared normalized residuals are capped at this value.
const CAP: f64 = 25.0;
/// Half-width (s) of the three-point curvature of the cost at the estimate.
pub const CURVATURE_STEP_S: f64 = 0.005;

/// The result of the search.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OffsetEstimate {
    /// The offset (s): laser clock minus encoder clock.
    pub offset: f64,
    /// Cost at the estimate.
    pub cost: f64,
    /// Cost at the starting offset (on the coarse grid's samples).
    pub cost_at_start: f64,
    /// Standard deviation of the offset (s) from the curvature of the profile cost
    /// (the parameters re-solved at each offset), taking the samples as independent;
    /// `None` when the cost is not convex there.
    pub sigma: Option<f64>,
    /// The coarse grid: (offset s, cost on its subsample of the samples).
    pub grid: Vec<(f64, f64)>,
    /// How far the parameters (r_L, r_R, b, ℓx, ℓy, ℓθ) move when the offset moves by
    /// its σ: half the difference of the estimates solved at `offset ± sigma`. Their
    /// covariance includes it (`shift · shiftᵀ`); `None` when not measured (no σ, or
    /// an estimate failed there).
    pub parameter_shift: Option<[f64; 6]>,
}

/// The grid step (s) of a search over `start ± range`: [`GRID_STEP_S`], coarser when
/// the range would need more than [`MAX_GRID_STEPS`] steps on each side (at least 5).
pub fn grid_step(range: f64) -> f64 {
    range / grid_steps(range) as f64
}

/// The number of grid steps on each side of the start.
fn grid_steps(range: f64) -> usize {
    (range / GRID_STEP_S)
        .round()
        .clamp(5.0, MAX_GRID_STEPS as f64) as usize
}

/// The search range to use: `range` checked against the scans' time span. A range
/// asked for on the command line (`asked`) is refused, naming the value and the
/// largest the log supports, when it is not a positive number or exceeds
/// [`MAX_RANGE_OF_SPAN`] of the span; a range the pipeline chose is clamped to it.
pub fn checked_range(range: f64, scan_span: f64, asked: bool) -> Result<f64, PipelineError> {
    if !(range.is_finite() && range > 0.0) {
        return Err(PipelineError::InvalidSetting(format!(
            "the clock-offset search range must be a positive number of seconds, got {range}"
        )));
    }
    let largest = MAX_RANGE_OF_SPAN * scan_span.max(0.0);
    if range <= largest {
        return Ok(range);
    }
    if asked {
        return Err(PipelineError::InvalidSetting(format!(
            "--time-offset-range {range} s is more than the log can support: the scans span \
             {scan_span:.1} s, and an offset beyond ±{largest:.1} s leaves fewer than half of \
             the scan pairs with encoder records; use at most --time-offset-range {:.1}",
            (largest * 10.0).floor() / 10.0
        )));
    }
    Ok(largest)
}

/// Robust scale (1.4826 · median absolute value) of each residual component.
fn residual_scale(residuals: &[[f64; 3]]) -> [f64; 3] {
    let mut out = [1.0; 3];
    for (c, o) in out.iter_mut().enumerate() {
        let mut a: Vec<f64> = residuals.iter().map(|r| r[c].abs()).collect();
        if a.is_empty() {
            continue;
        }
        let mid = a.len() / 2;
        let (_, m, _) = a.select_nth_unstable_by(mid, f64::total_cmp);
        *o = (1.4826 * *m).max(1e-12);
    }
    out
}

struct Problem<'a> {
    log: &'a Log,
    synced: &'a Synchronized,
    opts: &'a Options,
    scale: [f64; 3],
}

impl Problem<'_> {
    /// The samples rebuilt at `offset`; `every` > 1 keeps one sample in `every`.
    fn samples_at(&self, offset: f64, every: usize) -> Vec<Sample> {
        let track = EncoderTrack::new(&self.log.encoders, self.synced.ticks_per_revolution);
        self.synced
            .samples
            .iter()
            .step_by(every.max(1))
            .filter_map(|s| {
                let wheel = track
                    .motion(s.pair.t0 - offset, s.pair.t1 - offset, &self.synced.limits)
                    .ok()?;
                let shifted = crate::samples::PairSample { wheel, ..s.clone() };
                Some(shifted.to_solver(self.opts.use_profile, self.opts.use_icp_covariance))
            })
            .collect()
    }

    fn cost_with(&self, params: &Params, samples: &[Sample]) -> f64 {
        let predictor = Predictor::new(params, self.opts.use_profile);
        let total: f64 = samples
            .iter()
            .map(|s| {
                // Along a free direction ŝ is odometry's guess, not a measurement.
                let r = s.measured_part(predictor.residual(s));
                let q: f64 = (0..3).map(|c| (r[c] / self.scale[c]).powi(2)).sum();
                q.min(CAP)
            })
            .sum();
        total / samples.len().max(1) as f64
    }

    fn cost(&self, offset: f64, every: usize) -> f64 {
        let samples = self.samples_at(offset, every);
        let mut solve = self.opts.solve_options();
        solve.refine = false;
        // Every trial offset is solved, weak or not: a refusal would make its cost
        // infinite and move the estimate depending on --accept-weak.
        solve.accept_weak = true;
        match odocal_solver::calibrate(&samples, &solve) {
            Ok(c) => self.cost_with(&c.params, &samples),
            Err(_) => f64::INFINITY,
        }
    }
}

impl Problem<'_> {
    /// σ of the offset from the cost's curvature at `offset`. The cost is the mean of
    /// the N samples' normalized squared residuals (≈ χ² with 3 degrees of freedom
    /// each), so the negative log-likelihood is N·cost/2 and the offset's variance
    /// 2 / (N·cost''), the parameters being re-solved at each offset (profile).
    fn sigma_at(&self, offset: f64, cost: f64) -> Option<f64> {
        let h = CURVATURE_STEP_S;
        let n = self.samples_at(offset, 1).len() as f64;
        let second = (self.cost(offset - h, 1) - 2.0 * cost + self.cost(offset + h, 1)) / (h * h);
        (second.is_finite() && second > 0.0 && n > 0.0).then(|| (2.0 / (n * second)).sqrt())
    }
}

/// Searches the offset within `start ± range` (s).
pub fn estimate_time_offset(
    log: &Log,
    synced: &Synchronized,
    opts: &Options,
    start: f64,
    range: f64,
    base: &Calibration,
) -> Result<OffsetEstimate, PipelineError> {
    let mut problem = Problem {
        log,
        synced,
        opts,
        scale: [1.0; 3],
    };
    let samples = problem.samples_at(start, 1);
    let predictor = Predictor::new(&base.params, opts.use_profile);
    let residuals: Vec<[f64; 3]> = samples
        .iter()
        .map(|s| s.measured_part(predictor.residual(s)))
        .collect();
    problem.scale = residual_scale(&residuals);

    // The coarse grid only has to find the basin: a subsample keeps it fast on long
    // logs; the refinement uses every sample.
    let coarse_every = synced.samples.len().div_ceil(GRID_SAMPLES).max(1);
    let n = grid_steps(range) as i64;
    let step = grid_step(range);
    let grid: Vec<(f64, f64)> = (-n..=n)
        .into_par_iter()
        .map(|i| {
            let d = start + i as f64 * step;
            (d, problem.cost(d, coarse_every))
        })
        .collect();
    let (best, best_cost) = grid
        .iter()
        .copied()
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or((start, f64::INFINITY));
    if !best_cost.is_finite() {
        return Err(PipelineError::InvalidSetting(
            "the clock-offset search found no offset at which the samples can be solved".into(),
        ));
    }

    // Golden-section search on [best − step, best + step].
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let (mut a, mut b) = (best - step, best + step);
    let mut c = b - g * (b - a);
    let mut d = a + g * (b - a);
    let (mut fc, mut fd) = (problem.cost(c, 1), problem.cost(d, 1));
    while b - a > TOLERANCE_S {
        if fc <= fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = problem.cost(c, 1);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = problem.cost(d, 1);
        }
    }
    let (mut offset, mut cost) = if fc <= fd { (c, fc) } else { (d, fd) };
    let best_full = if coarse_every == 1 {
        best_cost
    } else {
        problem.cost(best, 1)
    };
    if best_full < cost {
        (offset, cost) = (best, best_full);
    }
    let sigma = problem.sigma_at(offset, cost);
    let cost_at_start = grid
        .iter()
        .find(|(d, _)| (*d - start).abs() < 1e-12)
        .map(|p| p.1)
        .unwrap_or(f64::NAN);
    Ok(OffsetEstimate {
        offset,
        cost,
        cost_at_start,
        sigma,
        grid,
        parameter_shift: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_beyond_the_log_are_refused_and_the_grid_is_bounded() {
        assert_eq!(checked_range(1.0, 60.0, true).unwrap(), 1.0);
        let e = checked_range(1e9, 60.0, true).unwrap_err().to_string();
        assert!(
            e.contains("1000000000") && e.contains("at most --time-offset-range 30"),
            "{e}"
        );
        assert!(checked_range(f64::NAN, 60.0, true).is_err());
        assert!(checked_range(-1.0, 60.0, false).is_err());
        assert_eq!(checked_range(45.0, 60.0, false).unwrap(), 30.0);
        assert_eq!(grid_steps(0.5), 50);
        assert!((grid_step(0.5) - GRID_STEP_S).abs() < 1e-12);
        assert_eq!(grid_steps(1e9), MAX_GRID_STEPS);
        assert_eq!(grid_steps(1e300), MAX_GRID_STEPS);
    }

    #[test]
    fn scale_is_robust() {
        let mut r: Vec<[f64; 3]> = (0..1000)
            .map(|i| {
                let u = (i as f64 + 0.5) / 1000.0 * 2.0 - 1.0;
                [u, 2.0 * u, 0.0]
            })
            .collect();
        r.push([1e6, 1e6, 1e6]);
        let s = residual_scale(&r);
        assert!((s[0] - 1.4826 * 0.5).abs() < 0.01);
        assert!((s[1] - 1.4826).abs() < 0.02);
        assert!(s[2] > 0.0);
    }
}
