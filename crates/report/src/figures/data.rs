//! What the figures are drawn from, computed once: per sample its time, residual,
//! whether trimming kept it, its odometry with the calibrated and nominal parameters.

use crate::report::Report;
use odocal_geom::Pose2;
use odocal_pipeline::health::slip::flagged;
use odocal_pipeline::samples::PairSample;
use odocal_pipeline::FindingKind;
use odocal_pipeline::{Options, Outcome};
use odocal_solver::{Params, Predictor, Sample};

/// Per-sample material of the figures.
pub struct FigureData<'a> {
    /// The synchronized samples, in time order.
    pub pairs: &'a [PairSample],
    /// The solver's view of them.
    pub samples: Vec<Sample>,
    /// Seconds since the first sample's first scan.
    pub times: Vec<f64>,
    /// `ŝ_pred − ŝ` with the calibrated parameters (m, m, rad).
    pub residuals: Vec<[f64; 3]>,
    /// Whether the final estimate used the sample (false: trimmed as an outlier).
    pub used: Vec<bool>,
    /// The calibrated parameters.
    pub params: Params,
    /// The nominal parameters and how they were chosen.
    pub nominal: (Params, &'static str),
    /// Encoder profile used in the predictions.
    pub use_profile: bool,
    /// Estimated scan-matching σ (m, m, rad).
    pub sm_sigma: [f64; 3],
    /// Time spans to shade (s since the first sample), with their kind.
    pub spans: Vec<(f64, f64, FindingKind)>,
    /// Kinds of motion nearly absent.
    pub missing: Vec<&'static str>,
    /// Per sample: flagged as slip (wheels and scans disagree).
    pub slipped: Vec<bool>,
}

/// Parameters a user would start from without calibration, when no nominal ones are
/// given: equal radii (the mean of the estimate), the estimated wheel distance, the
/// laser at the robot's origin.
pub fn nominal_params(estimate: &Params) -> Params {
    let r = (estimate.r_l + estimate.r_r) / 2.0;
    Params {
        r_l: r,
        r_r: r,
        b: estimate.b,
        laser: Pose2::IDENTITY,
    }
}

/// The time spans (s since `t0`) of the runs of consecutive flagged samples.
fn slip_spans(pairs: &[PairSample], flagged: &[usize], t0: f64) -> Vec<(f64, f64, FindingKind)> {
    let mut out: Vec<(f64, f64, FindingKind)> = Vec::new();
    let mut last: Option<usize> = None;
    for &k in flagged {
        let Some(p) = pairs.get(k) else { continue };
        let (a, b) = (p.pair.t0 - t0, p.pair.t1 - t0);
        match (last, out.last_mut()) {
            (Some(l), Some(span)) if k == l + 1 => span.1 = b,
            _ => out.push((a, b, FindingKind::Slip)),
        }
        last = Some(k);
    }
    out
}

impl<'a> FigureData<'a> {
    /// Prepares the figures' material.
    pub fn new(opts: &Options, outcome: &'a Outcome, report: &Report) -> FigureData<'a> {
        let c = &outcome.calibration;
        let pairs = &outcome.synced.samples[..];
        let samples: Vec<Sample> = pairs
            .iter()
            .map(|s| s.to_solver(opts.use_profile, opts.use_icp_covariance))
            .collect();
        let predictor = Predictor::new(&c.params, opts.use_profile);
        let residuals = samples.iter().map(|s| predictor.residual(s)).collect();
        let t0 = pairs.first().map_or(0.0, |s| s.pair.t0);
        let times = pairs.iter().map(|s| s.pair.t0 - t0).collect();
        let used = (0..pairs.len())
            .map(|k| c.used.get(k).copied().unwrap_or(false))
            .collect();
        let nominal = match &opts.initial_params {
            Some(p) => (*p, "odometry, nominal parameters"),
            None => (
                nominal_params(&c.params),
                "odometry, equal radii, laser at origin",
            ),
        };
        let mut spans: Vec<(f64, f64, FindingKind)> = report
            .health
            .iter()
            .chain(&report.checks)
            .flat_map(|f| f.spans.iter().map(|s| (s[0] - t0, s[1] - t0, f.kind)))
            .collect();
        let slip_flags = flagged(&outcome.synced);
        let mut slipped = vec![false; pairs.len()];
        for &k in &slip_flags {
            if let Some(s) = slipped.get_mut(k) {
                *s = true;
            }
        }
        if report.health.iter().any(|f| f.kind == FindingKind::Slip) {
            spans.extend(slip_spans(pairs, &slip_flags, t0));
        }
        FigureData {
            pairs,
            samples,
            times,
            residuals,
            used,
            params: c.params,
            nominal,
            use_profile: opts.use_profile,
            sm_sigma: c.sm_sigma,
            spans,
            missing: c.observability.motion.missing(),
            slipped,
        }
    }

    /// The chained positions of the sensor from the displacements `steps`.
    pub fn chain(steps: impl Iterator<Item = Pose2>) -> Vec<(f64, f64)> {
        let mut p = Pose2::IDENTITY;
        let mut out = vec![(0.0, 0.0)];
        for s in steps {
            p = p.compose(&s);
            out.push((p.x, p.y));
        }
        out
    }

    /// The sensor path by odometry with `params`.
    pub fn odometry_path(&self, params: &Params) -> Vec<(f64, f64)> {
        let predictor = Predictor::new(params, self.use_profile);
        Self::chain(
            self.samples
                .iter()
                .map(|s| Pose2::from_array(predictor.predict(s))),
        )
    }

    /// The sensor path by odometry with `params`, except over the samples flagged as
    /// slip, where it follows scan matching: where the wheels slipped no parameters
    /// give the right odometry, so those samples would only blur a comparison.
    pub fn odometry_path_without_slip(&self, params: &Params) -> Vec<(f64, f64)> {
        let predictor = Predictor::new(params, self.use_profile);
        Self::chain(self.samples.iter().zip(&self.slipped).map(|(s, slip)| {
            if *slip {
                s.sm
            } else {
                Pose2::from_array(predictor.predict(s))
            }
        }))
    }

    /// The sensor path by chained scan matching.
    pub fn scan_matching_path(&self) -> Vec<(f64, f64)> {
        Self::chain(self.samples.iter().map(|s| s.sm))
    }
}
