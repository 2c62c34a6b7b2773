//! `odocal solve TUPLES [--trim chi2|icra|tro|none] [--icp-covariance] [--no-refine] [--json]`: the six
//! parameters, their covariance and the observability report from a tuple file
//! (the original package's `{T, phi_l, phi_r, sm}` stream, or ours with `sm_cov`
//! and wheel-speed profiles).

use crate::calibrate::TrimArg;
use crate::partial_args::PartialArgs;
use crate::terminal::{write_json_stdout, write_stdout};
use anyhow::Context;
use odocal_geom::{FlatParams, Pose2};
use odocal_log::{read_tuples, TupleRecord};
use odocal_solver::{
    calibrate, Calibration, Constraint, Constraints, ProfileSegment, Sample, SigmaEstimate,
    SolveOptions, Trim, Verdict, PARAMETER_NAMES,
};
use serde::Serialize;
use std::path::PathBuf;

/// Where the scan-matching σ's are estimated (command line).
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum SigmaFrom {
    /// As the original package.
    FirstRound,
    /// From the final samples.
    Final,
}

/// Arguments of `odocal solve`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Tuple file: a stream of JSON objects {"T", "phi_l", "phi_r", "sm"[, "sm_cov", "profile"]}.
    pub tuples: PathBuf,
    /// Outlier trimming between closed-form solves (the same rules and default as
    /// `calibrate`).
    #[arg(long, value_enum, default_value = "chi2")]
    pub trim: TrimArg,
    /// Weight each sample by its `sm_cov` (the scan matcher's covariance of ŝ) when
    /// every sample has one. Off by default, as in `calibrate` (`--icp-covariance`
    /// there), so the two give the same numbers on the same samples: the noise level
    /// estimated from the residuals, shaped per sample by its `sm_cov` relative to the
    /// typical sample's.
    #[arg(long)]
    pub icp_covariance: bool,
    /// Return the closed form without maximum-likelihood refinement.
    #[arg(long)]
    pub no_refine: bool,
    /// Ignore wheel-speed profiles (use the constant-speed formulas).
    #[arg(long)]
    pub no_profile: bool,
    /// Residuals the scan-matching σ's come from: `first-round` (the original
    /// package: untrimmed estimate, samples kept after the first trimming round) or
    /// `final` (final estimate and samples; tighter when outliers survive round 1).
    #[arg(long, value_enum, default_value = "first-round")]
    pub sigma: SigmaFrom,
    /// The scan matcher's bias on rotations as a systematic part of σ: standard
    /// deviations "X,Y,THETA" of a bias β·θ common to every ŝ (m/rad, m/rad, rad/rad).
    /// `calibrate` derives it from the log's range noise and ray spacing
    /// (`match_self_check` in results.json; `odocal_pipeline::matcher_bias`); a tuple
    /// file does not hold them, so by default there is none here.
    #[arg(long, value_name = "X,Y,THETA", value_parser = parse_matcher_bias)]
    pub matcher_bias: Option<[f64; 3]>,
    #[command(flatten)]
    pub partial: PartialArgs,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

/// `"X,Y,THETA"` as three finite non-negative numbers.
fn parse_matcher_bias(text: &str) -> Result<[f64; 3], String> {
    let values: Vec<f64> = text
        .split(',')
        .map(|v| v.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("expected three numbers X,Y,THETA: {e}"))?;
    match values[..] {
        [x, y, t] if values.iter().all(|v| v.is_finite() && *v >= 0.0) => Ok([x, y, t]),
        _ => Err(format!(
            "expected three finite non-negative numbers X,Y,THETA, got {text:?}"
        )),
    }
}

/// A tuple record as a solver sample.
pub fn sample_from_record(rec: &TupleRecord) -> Sample {
    let mut s = Sample::from_speeds(rec.t, rec.phi_l, rec.phi_r, Pose2::from_array(rec.sm));
    s.sm_cov = rec.sm_cov;
    s.free_direction = rec.free_direction;
    s.scan_times = rec.t0.zip(rec.t1).map(|(t0, t1)| [t0, t1]);
    s.profile = rec.profile.as_ref().map(|pieces| {
        pieces
            .iter()
            .map(|p| ProfileSegment {
                duration: p[0],
                dphi_l: p[1],
                dphi_r: p[2],
            })
            .collect()
    });
    s
}

/// The JSON printed by `--json`.
#[derive(Serialize)]
struct JsonOutput<'a> {
    #[serde(flatten)]
    params: FlatParams,
    covariance: [[f64; 6]; 6],
    j: [[f64; 2]; 2],
    samples_used: usize,
    samples_total: usize,
    samples_per_round: &'a [usize],
    trim: Trim,
    refined: bool,
    closed_form: &'a odocal_solver::Params,
    sm_sigma: [f64; 3],
    noise_source: odocal_solver::NoiseSource,
    cost_before: f64,
    cost_after: f64,
    reduced_chi2: f64,
    observability: &'a odocal_solver::Observability,
    /// Per parameter (r_L, r_R, b, l_x, l_y, l_theta): "free", {"held": v} or
    /// {"prior": {"mean", "sigma"}}.
    constraints: Constraints,
}

/// Runs `odocal solve`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let records = read_tuples(&args.tuples)?;
    let samples: Vec<Sample> = records
        .iter()
        .map(|r| {
            let s = sample_from_record(r);
            // Without --icp-covariance, `sm_cov` only shapes the residuals' noise level
            // per sample, as in `calibrate`.
            let (sm_cov, matcher_cov) = match args.icp_covariance {
                true => (s.sm_cov, None),
                false => (None, s.sm_cov),
            };
            Sample {
                sm_cov,
                matcher_cov,
                ..s
            }
        })
        .collect();
    let options = SolveOptions {
        trim: args.trim.into(),
        refine: !args.no_refine,
        use_profile: !args.no_profile,
        sigma_from: match args.sigma {
            SigmaFrom::FirstRound => SigmaEstimate::FirstRound,
            SigmaFrom::Final => SigmaEstimate::FinalSet,
        },
        constraints: args.partial.constraints()?,
        accept_weak: args.partial.accept_weak,
        matcher_bias: args.matcher_bias.unwrap_or([0.0; 3]),
        ..SolveOptions::default()
    };
    let cal = calibrate(&samples, &options)
        .with_context(|| format!("{}: calibration failed", args.tuples.display()))?;
    if args.json {
        let out = JsonOutput {
            params: cal.params.into(),
            covariance: cal.covariance,
            j: cal.j,
            samples_used: cal.samples_used,
            samples_total: samples.len(),
            samples_per_round: &cal.samples_per_round,
            trim: options.trim,
            refined: cal.refinement.is_some(),
            closed_form: &cal.closed_form,
            sm_sigma: cal.sm_sigma,
            noise_source: cal.noise_source,
            cost_before: cal.cost_before,
            cost_after: cal.cost_after,
            reduced_chi2: cal.reduced_chi2,
            observability: &cal.observability,
            constraints: options.constraints,
        };
        let text = serde_json::to_string_pretty(&out).context("serializing the result")?;
        write_json_stdout(&text)
    } else {
        write_stdout(&summary(&args, &cal, samples.len()))
    }
}

/// The human-readable summary.
fn summary(args: &Args, cal: &Calibration, total: usize) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let rounds: Vec<String> = cal
        .samples_per_round
        .iter()
        .map(|n| n.to_string())
        .collect();
    let _ = writeln!(
        s,
        "{}: {} of {} samples used (trimming {}: {})",
        args.tuples.display(),
        cal.samples_used,
        total,
        args.trim.name(),
        rounds.join(" → ")
    );
    let units = ["m", "m", "m", "m", "m", "rad"];
    for (i, rep) in cal.observability.parameters.iter().enumerate() {
        let mark = match (rep.verdict, rep.constraint) {
            (_, Constraint::Held(_)) | (Verdict::WellDetermined, _) => "",
            (Verdict::Weak | Verdict::NotExcited, _) => "  <--",
        };
        let status = match rep.constraint {
            Constraint::Free => rep.verdict.as_str().to_string(),
            Constraint::Held(_) => "held (--fix)".to_string(),
            Constraint::Prior { mean, sigma } => {
                format!("{} (prior {mean} ± {sigma})", rep.verdict.as_str())
            }
        };
        let _ = writeln!(
            s,
            "  {:<8} = {:>13.8} {:<3} ± {:.2e}  {}{}",
            PARAMETER_NAMES[i], rep.value, units[i], rep.sigma, status, mark
        );
    }
    let _ = writeln!(
        s,
        "  ℓθ = {:.4}° ± {:.4}°",
        cal.params.laser.theta.to_degrees(),
        cal.observability.parameters[5].sigma.to_degrees()
    );
    let j = cal.j;
    let _ = writeln!(
        s,
        "  J = [[{:.6e}, {:.6e}], [{:.6e}, {:.6e}]]",
        j[0][0], j[0][1], j[1][0], j[1][1]
    );
    let _ = writeln!(
        s,
        "  scan-matching noise σ = ({:.3} mm, {:.3} mm, {:.4}°) from the residuals; weights: {}",
        cal.sm_sigma[0] * 1e3,
        cal.sm_sigma[1] * 1e3,
        cal.sm_sigma[2].to_degrees(),
        match cal.noise_source {
            odocal_solver::NoiseSource::Estimated => "these σ",
            odocal_solver::NoiseSource::SampleCovariance => "each sample's sm_cov",
            odocal_solver::NoiseSource::Shaped =>
                "these σ shaped by each sample's matcher covariance",
        }
    );
    match &cal.refinement {
        Some(r) => {
            let _ = writeln!(
                s,
                "  ML refinement: cost {:.6e} → {:.6e} in {} iterations{}",
                r.cost_before,
                r.cost_after,
                r.iterations,
                if r.converged { "" } else { " (not converged)" }
            );
        }
        None => {
            let _ = writeln!(s, "  closed form only: cost {:.6e}", cal.cost_before);
        }
    }
    let _ = writeln!(
        s,
        "  reduced χ² {:.3}{}",
        cal.reduced_chi2,
        if cal.reduced_chi2 < 0.5 {
            " (< 1: the σ's, hence the covariance, are conservative; try --sigma final)"
        } else if cal.reduced_chi2 > 2.0 {
            " (> 1: the noise model underestimates the residuals; the covariance is optimistic)"
        } else {
            ""
        }
    );
    let o = &cal.observability;
    let _ = writeln!(
        s,
        "  condition numbers: step 1 {:.1}, A {:.3e} (unit-diagonal {:.1})",
        o.step1_condition, o.a_condition, o.a_condition_scaled
    );
    let _ = writeln!(s, "  {}", o.sentence);
    if let Some(w) = &o.wheel_signs {
        let _ = writeln!(s, "  warning: {w}");
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn record_to_sample_keeps_every_field() {
        let mut rec = TupleRecord::new(0.5, 2.0, -1.0, [0.01, -0.02, 0.3]);
        rec.sm_cov = Some([[1e-6, 0.0, 0.0], [0.0, 1e-6, 0.0], [0.0, 0.0, 1e-5]]);
        rec.profile = Some(vec![[0.25, 0.4, -0.1], [0.25, 0.6, -0.4]]);
        let s = sample_from_record(&rec);
        assert_eq!((s.t, s.dphi_l, s.dphi_r), (0.5, 1.0, -0.5));
        assert_eq!(s.sm.to_array(), [0.01, -0.02, 0.3]);
        assert_eq!(s.sm_cov, rec.sm_cov);
        let p = s.profile.as_ref().unwrap();
        assert_eq!((p[1].duration, p[1].dphi_l, p[1].dphi_r), (0.25, 0.6, -0.4));
        assert!(s.check(0).is_ok());
    }
}
