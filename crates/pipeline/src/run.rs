//! The whole pipeline: synchronize, match, (estimate the clock offset,) solve.

use crate::bootstrap_runs::{match_runs, BootstrapPair};
use crate::chained::{rescue_refused, LinkSource};
use crate::consistency::{check_halves, Consistency};
use crate::error::PipelineError;
use crate::finding::{Finding, FindingKind};
use crate::health;
use crate::local_map::rescue_with_neighbours;
use crate::matching::{
    match_pairs, typical_noise_sigma, typical_scan_noise, with_typical_noise, MatchStats,
};
use crate::options::{Options, BOOTSTRAP_PAIRS, BOOTSTRAP_RUN, MIN_SAMPLES};
use crate::progress::Progress;
use crate::refusal;
use crate::rejection::{MatchFailure, Rejection, RejectionCounts};
use crate::samples::PairSample;
use crate::sweep::{compensated_pairs, has_sweep, reference_time};
use crate::sync::{
    chosen_stride, scan_pairs, DiscardCounts, DiscardReason, EncoderTrack, ScanPair, SyncLimits,
    WheelMotion,
};
use crate::synchronized::Synchronized;
use crate::time_offset::{estimate_time_offset, OffsetEstimate};
use odocal_geom::Pose2;
use odocal_icp::IcpParams;
use odocal_log::{Log, ScanStore};
use odocal_solver::{Calibration, Constraint, Params, Predictor, SolveOptions, Verdict};
use std::borrow::Cow;
use std::time::Instant;

/// Half-width (s) of the second clock-offset search of a swept log, around the first
/// estimate, once the sweep is compensated at it.
pub const REESTIMATE_RANGE_S: f64 = 0.05;

/// Wall time per stage (s).
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct Timing {
    /// Reading the log (filled by the caller that read it).
    pub parse: f64,
    /// Synchronization (encoder interpolation, profiles).
    pub sync: f64,
    /// Scan matching (all passes).
    pub r#match: f64,
    /// Clock-offset search (0 when not asked).
    pub time_offset: f64,
    /// Solving (closed form, trimming, refinement, covariance).
    pub solve: f64,
}

/// The result of [`calibrate_log`].
#[derive(Debug, Clone)]
pub struct Outcome {
    /// What the data-health stage found (and did), in the order found.
    pub health: Vec<Finding>,
    /// Samples and discards.
    pub synced: Synchronized,
    /// The solver's output.
    pub calibration: Calibration,
    /// The clock-offset search, when asked.
    pub offset: Option<OffsetEstimate>,
    /// Wall time per stage.
    pub timing: Timing,
    /// The two halves of the samples calibrated separately and compared.
    pub consistency: Consistency,
    /// The laser's range-scale σ that the distances carry (stated, or from the data
    /// sheet of the range finder recognised in the log); the calibration's covariance
    /// is the data's alone, [`crate::Estimate`] gives both.
    pub range_scale: crate::RangeScale,
}

/// The indices of the pairs the bootstrap matches without odometry, of `kept`
/// pairs: all of them when there are fewer than twice [`BOOTSTRAP_PAIRS`]; otherwise
/// runs of [`BOOTSTRAP_RUN`] consecutive pairs spread evenly over the log, one run in
/// every `kept / BOOTSTRAP_PAIRS`, so that both the subset and the pairs left are
/// chains whose scans are prepared once.
fn bootstrap_subset(kept: usize) -> Vec<usize> {
    if kept < 2 * BOOTSTRAP_PAIRS {
        return (0..kept).collect();
    }
    let every = kept / BOOTSTRAP_PAIRS;
    (0..kept)
        .filter(|i| (i / BOOTSTRAP_RUN) % every == 0)
        .collect()
}

/// Ticks per revolution from the options or the log, checking the log has what
/// calibration needs.
fn ticks_per_revolution(log: &Log, opts: &Options) -> Result<f64, PipelineError> {
    match opts.ticks_per_revolution {
        Some(t) => {
            if !(t.is_finite() && t > 0.0) {
                return Err(PipelineError::InvalidSetting(format!(
                    "ticks per revolution must be a positive number, got {t}"
                )));
            }
            // The log's own check reports missing encoders or scans before ticks.
            if log.encoders.is_empty() || log.scans.len() < 2 {
                log.check_calibration_inputs()?;
            }
            Ok(t)
        }
        None => Ok(log.check_calibration_inputs()?),
    }
}

/// Wheel motions for every pair at a given clock offset.
fn wheel_motions(
    track: &EncoderTrack<'_>,
    pairs: &[ScanPair],
    limits: &SyncLimits,
    offset: f64,
) -> Vec<Result<WheelMotion, DiscardReason>> {
    pairs
        .iter()
        .map(|p| track.motion(p.t0 - offset, p.t1 - offset, limits))
        .collect()
}

/// First guesses of ŝ for each pair: identity, or predicted by odometry.
fn first_guesses(
    motions: &[(usize, WheelMotion)],
    params: Option<&Params>,
    use_profile: bool,
) -> Vec<Pose2> {
    match params {
        None => vec![Pose2::IDENTITY; motions.len()],
        Some(p) => {
            let predictor = Predictor::new(p, use_profile);
            motions
                .iter()
                .map(|(_, w)| {
                    let s = crate::samples::wheel_only_sample(w);
                    Pose2::from_array(predictor.predict(&s))
                })
                .collect()
        }
    }
}

/// The time each scan stands for: its reference time (the timestamp without a sweep).
pub(crate) fn reference_times(log: &Log) -> Vec<f64> {
    (0..log.scans.len())
        .map(|i| {
            log.scans
                .get(i)
                .map_or(log.scans.scans[i].t, |s| reference_time(&s))
        })
        .collect()
}

/// Synchronizes the encoder and scan streams and matches the pairs.
pub fn synchronize_and_match(
    log: &Log,
    opts: &Options,
    progress: &dyn Progress,
    timing: &mut Timing,
) -> Result<Synchronized, PipelineError> {
    let ticks = ticks_per_revolution(log, opts)?;
    health::plausibility::check(log, ticks)?;
    let t_sync = Instant::now();
    let scan_times = reference_times(log);
    let sweep = has_sweep(&log.scans);
    let stride = chosen_stride(opts.stride, &scan_times)?;
    let encoder_times: Vec<f64> = log.encoders.iter().map(|e| e.t).collect();
    let limits = opts
        .limits
        .unwrap_or_else(|| SyncLimits::from_streams(&encoder_times, &scan_times, stride));
    let track = EncoderTrack::new(&log.encoders, ticks);
    let pairs = scan_pairs(&scan_times, stride);
    let mut discarded = DiscardCounts::default();
    let mut kept: Vec<(usize, WheelMotion)> = Vec::with_capacity(pairs.len());
    for (k, m) in wheel_motions(&track, &pairs, &limits, opts.time_offset)
        .into_iter()
        .enumerate()
    {
        match m {
            Ok(w) => kept.push((k, w)),
            Err(reason) => discarded.add(reason),
        }
    }
    timing.sync += t_sync.elapsed().as_secs_f64();

    let t_match = Instant::now();
    let index_pairs: Vec<(usize, usize)> = kept
        .iter()
        .map(|(k, _)| (pairs[*k].first, pairs[*k].second))
        .collect();
    progress.start("matching", index_pairs.len());
    let mut matched: Vec<Option<Result<MatchStats, MatchFailure>>> = vec![None; kept.len()];
    let mut guess_params = opts.initial_params;
    let mut guess_sigma = None;
    let bootstrap = (opts.bootstrap_guesses || sweep) && kept.len() >= MIN_SAMPLES;
    // The log's typical range noise, estimated once for every match of its scans.
    let matcher = opts.icp_for(log);
    let log_noise = typical_scan_noise(&log.scans, &matcher);
    let log_icp = with_typical_noise(&matcher, log_noise.range_sigma_m);
    if guess_params.is_none() && bootstrap {
        // Match a subset without odometry (an evenly spread one of long logs, every
        // pair of short ones; each pair guessed by the motion the pair before it
        // measured, or the identity: crate::bootstrap_runs), solve roughly, and guess
        // the rest — and the subset's failures — by odometry with that estimate (with
        // a sweep: compensate with it too).
        let subset = bootstrap_subset(kept.len());
        let sub_pairs: Vec<BootstrapPair> = subset
            .iter()
            .map(|&i| BootstrapPair {
                kept: i,
                first: index_pairs[i].0,
                second: index_pairs[i].1,
                wheels: [kept[i].1.dphi_l, kept[i].1.dphi_r],
            })
            .collect();
        // A match that leaves a direction free keeps its guess there (the identity,
        // or the previous pair's motion): refused, so that it is matched again from
        // the odometry guess.
        let results: Vec<_> = match_runs(&log.scans, &sub_pairs, &log_icp, || progress.advance())
            .into_iter()
            .map(|r| match r {
                Ok(m) if !m.fixes_every_direction() => Err(MatchFailure::new(
                    Rejection::Conditioning,
                    "the scans do not constrain the displacement from a guess without odometry",
                )),
                other => other,
            })
            .collect();
        let samples: Vec<_> = subset
            .iter()
            .zip(&results)
            .filter_map(|(&i, r)| {
                let icp = r.as_ref().ok()?.clone();
                let s = PairSample {
                    pair: pairs[kept[i].0],
                    wheel: kept[i].1.clone(),
                    icp,
                };
                Some(s.to_solver(opts.use_profile, false))
            })
            .collect();
        // Only first guesses: never judged, so never refused (the verdicts, and
        // --accept-weak, are for the final solve; a refusal here would leave the
        // pairs without guesses or sweep compensation and change the final data).
        let rough = SolveOptions {
            refine: false,
            accept_weak: true,
            ..opts.solve_options()
        };
        let rough_fit = odocal_solver::calibrate(&samples, &rough)
            .ok()
            .filter(|c| c.params.r_l > 0.0 && c.params.r_r > 0.0 && c.params.b > 0.0);
        guess_sigma = rough_fit.as_ref().map(|c| c.sm_sigma);
        guess_params = rough_fit.map(|c| c.params);
        for (i, r) in subset.into_iter().zip(results) {
            // A failure is matched again from the odometry guess when there is one.
            if r.is_ok() || guess_params.is_none() {
                matched[i] = Some(r);
            }
        }
    }
    // With a sweep and an estimate to compensate it with, every pair is matched on the
    // compensated scans (the bootstrap's matches are replaced).
    let mut scans = Cow::Borrowed(&log.scans);
    let mut uncovered = vec![false; kept.len()];
    if let (true, Some(p)) = (sweep, guess_params.as_ref()) {
        let (store, covered) = compensated_pairs(
            &log.scans,
            &index_pairs,
            &track,
            &limits,
            p,
            opts.time_offset,
        );
        scans = Cow::Owned(store);
        for (i, ok) in covered.into_iter().enumerate() {
            uncovered[i] = !ok;
            matched[i] = (!ok).then(|| {
                Err(MatchFailure::new(
                    Rejection::Other,
                    "the encoders do not cover the sweep",
                ))
            });
        }
    }
    let (noise, icp) = match &scans {
        Cow::Borrowed(_) => (log_noise, log_icp),
        Cow::Owned(store) => {
            let noise = typical_scan_noise(store, &matcher);
            (noise, with_typical_noise(&matcher, noise.range_sigma_m))
        }
    };
    let rest: Vec<usize> = (0..kept.len()).filter(|&i| matched[i].is_none()).collect();
    let rest_motions: Vec<(usize, WheelMotion)> =
        rest.iter().map(|&i| (i, kept[i].1.clone())).collect();
    let guesses = first_guesses(&rest_motions, guess_params.as_ref(), opts.use_profile);
    let rest_pairs: Vec<(usize, usize)> = rest.iter().map(|&i| index_pairs[i]).collect();
    let mut results = match_pairs(&scans, &rest_pairs, &guesses, &icp, || progress.advance());
    let sweep_compensated = matches!(scans, Cow::Owned(_));
    // Pairs refused for what closer scans cure, matched through the scans between.
    let links = LinkSource {
        scans: &log.scans,
        scan_times: &scan_times,
        track: &track,
        limits: &limits,
        params: guess_params.as_ref(),
        residual_sigma: guess_sigma,
        use_profile: opts.use_profile,
        time_offset: opts.time_offset,
    };
    rescue(
        &links,
        &mut scans,
        sweep_compensated,
        &rest_pairs,
        &mut results,
        &icp,
    );
    for (i, r) in rest.into_iter().zip(results) {
        matched[i] = Some(r);
    }
    progress.finish();
    timing.r#match += t_match.elapsed().as_secs_f64();

    let mut samples = Vec::with_capacity(kept.len());
    let mut match_rejections = RejectionCounts::default();
    for (((k, wheel), m), uncovered) in kept.into_iter().zip(matched).zip(uncovered) {
        match m.unwrap_or_else(|| Err(MatchFailure::new(Rejection::Other, "not matched"))) {
            Ok(icp) => samples.push(PairSample {
                pair: pairs[k],
                wheel,
                icp,
            }),
            Err(_) if uncovered => discarded.add(DiscardReason::EncoderGap),
            Err(f) => {
                discarded.add(DiscardReason::MatchFailed);
                match_rejections.add(f.reason);
            }
        }
    }
    let match_self_check = crate::self_check::closure_check(&scans, &samples, &icp, noise);
    Ok(Synchronized {
        stride,
        limits,
        ticks_per_revolution: ticks,
        pairs: pairs.len(),
        samples,
        discarded,
        match_rejections,
        match_self_check,
        time_offset: opts.time_offset,
        sweep_compensated,
        read_time_sigma: None,
        unrepaired_timing: None,
        heading_not_from_wheels: None,
        unmodelled_slide: None,
        unsettled_placement: None,
        scan_returns: crate::matching::scan_returns(&log.scans),
        shared_error_factor: 1.0,
    })
}

/// The pairs refused in `results`, matched again: through the scans between their
/// two ([`crate::chained`]), then, those of sparse scans still refused, with their
/// neighbouring scans ([`crate::local_map`]).
fn rescue(
    links: &LinkSource<'_>,
    scans: &mut Cow<'_, ScanStore>,
    compensated: bool,
    pairs: &[(usize, usize)],
    results: &mut [Result<MatchStats, MatchFailure>],
    icp: &IcpParams,
) {
    rescue_refused(links, scans, compensated, pairs, results, icp);
    rescue_with_neighbours(links, scans, compensated, pairs, results, icp);
}

/// Matches the samples again with first guesses from `first`'s estimate, within the
/// window its residuals allow ([`crate::guess_window`]) — and, when the scans were
/// swept, after compensating the sweep with that estimate (samples whose sweeps the
/// encoders do not cover are discarded as encoder gaps).
fn second_pass(
    log: &Log,
    synced: &mut Synchronized,
    first: &Calibration,
    opts: &Options,
    progress: &dyn Progress,
) {
    let params = &first.params;
    let window = crate::guess_window::from_residuals(first.sm_sigma);
    let motions: Vec<(usize, WheelMotion)> = synced
        .samples
        .iter()
        .enumerate()
        .map(|(k, s)| (k, s.wheel.clone()))
        .collect();
    let guesses = first_guesses(&motions, Some(params), opts.use_profile);
    let index_pairs: Vec<(usize, usize)> = synced
        .samples
        .iter()
        .map(|s| (s.pair.first, s.pair.second))
        .collect();
    let track = EncoderTrack::new(&log.encoders, synced.ticks_per_revolution);
    let sweep = has_sweep(&log.scans);
    let (mut scans, covered) = if sweep {
        let (store, covered) = compensated_pairs(
            &log.scans,
            &index_pairs,
            &track,
            &synced.limits,
            params,
            synced.time_offset,
        );
        synced.sweep_compensated = true;
        (Cow::<ScanStore>::Owned(store), covered)
    } else {
        (Cow::Borrowed(&log.scans), vec![true; index_pairs.len()])
    };
    let matcher = opts.icp_for(log);
    // The guesses are odometry with an estimate solved from the log: a match far
    // beyond their error is one the solver would trim (crate::guess_window).
    let icp = IcpParams {
        guess_window: window,
        ..with_typical_noise(&matcher, typical_noise_sigma(&scans, &matcher))
    };
    progress.start("matching (second pass)", index_pairs.len());
    let mut matched: Vec<Result<MatchStats, MatchFailure>> =
        match_pairs(&scans, &index_pairs, &guesses, &icp, || progress.advance());
    let scan_times = reference_times(log);
    let links = LinkSource {
        scans: &log.scans,
        scan_times: &scan_times,
        track: &track,
        limits: &synced.limits,
        params: Some(params),
        residual_sigma: Some(first.sm_sigma),
        use_profile: opts.use_profile,
        time_offset: synced.time_offset,
    };
    rescue(&links, &mut scans, sweep, &index_pairs, &mut matched, &icp);
    progress.finish();
    let old = std::mem::take(&mut synced.samples);
    for ((s, m), covered) in old.into_iter().zip(matched).zip(covered) {
        match m {
            Ok(icp) if covered => synced.samples.push(PairSample { icp, ..s }),
            Ok(_) => synced.discarded.add(DiscardReason::EncoderGap),
            Err(f) => {
                synced.discarded.add(DiscardReason::MatchFailed);
                synced.match_rejections.add(f.reason);
            }
        }
    }
}

/// The second pass with the clouds placed by `first`, then, while the estimate (solved
/// with `lenient`) moves from the one that placed them, again with them placed halfway
/// ([`crate::placement_rounds`]); an estimate that does not settle leaves no verdict
/// "well determined" (`Synchronized::unsettled_placement`).
fn settle_placement(
    log: &Log,
    synced: &mut Synchronized,
    first: Calibration,
    opts: &Options,
    lenient: &Options,
    progress: &dyn Progress,
) {
    use crate::placement_rounds::{
        halfway, largest_move, unsettled, PLACEMENT_ROUNDS, SETTLED_SIGMAS,
    };
    let before = synced.clone();
    second_pass(log, synced, &first, opts, progress);
    let mut placed = first;
    let mut rounds = 0;
    while synced.samples.iter().any(|s| s.icp.neighbours > 0) {
        let Ok(next) = solve(synced, lenient) else {
            return;
        };
        let moved = largest_move(&placed.params, &next.params, &next.covariance);
        if moved <= SETTLED_SIGMAS {
            return;
        }
        if rounds == PLACEMENT_ROUNDS {
            synced.unsettled_placement = Some(unsettled(moved, rounds));
            return;
        }
        placed = Calibration {
            params: halfway(&placed.params, &next.params),
            ..next
        };
        *synced = before.clone();
        second_pass(log, synced, &placed, opts, progress);
        rounds += 1;
    }
}

/// Recomputes every sample's wheel motion at a new clock offset, discarding (and
/// counting) the pairs that no longer synchronize.
pub fn resynchronize(log: &Log, synced: &mut Synchronized, offset: f64) {
    let track = EncoderTrack::new(&log.encoders, synced.ticks_per_revolution);
    let old = std::mem::take(&mut synced.samples);
    for s in old {
        match track.motion(s.pair.t0 - offset, s.pair.t1 - offset, &synced.limits) {
            Ok(wheel) => synced.samples.push(PairSample { wheel, ..s }),
            Err(reason) => synced.discarded.add(reason),
        }
    }
    synced.time_offset = offset;
}

fn solve(synced: &Synchronized, opts: &Options) -> Result<Calibration, PipelineError> {
    solve_widened(synced, opts, None)
}

/// [`solve`], with the covariance widened by `shift · shiftᵀ` before the verdicts:
/// how far the parameters move when the clock offset they were solved at moves by
/// its σ ([`OffsetEstimate::parameter_shift`]).
fn solve_widened(
    synced: &Synchronized,
    opts: &Options,
    shift: Option<&[f64; 6]>,
) -> Result<Calibration, PipelineError> {
    // Samples that leave a direction free (a corridor's) add to the others but do
    // not count toward the minimum: alone they determine less than a sample each.
    let usable = synced
        .samples
        .iter()
        .filter(|s| s.icp.fixes_every_direction())
        .count();
    if usable < MIN_SAMPLES {
        return Err(synced.too_few_samples(usable));
    }
    let samples: Vec<_> = synced
        .samples
        .iter()
        .map(|s| odocal_solver::Sample {
            read_time_sigma: synced.read_time_sigma,
            ..s.to_solver(opts.use_profile, opts.use_icp_covariance)
        })
        .collect();
    let solve_options = crate::matcher_bias::with_matcher_bias(opts.solve_options(), synced);
    // Parameters the motion does not excite are refused below, as weak ones are:
    // with their cause, and the parameters to hold (the solver alone would only name
    // them). When the motion excites none, there is nothing to hold: the solver's
    // refusal.
    let mut calibration = odocal_solver::calibrate(
        &samples,
        &SolveOptions {
            accept_weak: true,
            ..solve_options
        },
    )?;
    let excites_none = calibration
        .observability
        .parameters
        .iter()
        .all(|p| p.verdict == Verdict::NotExcited);
    if excites_none && !solve_options.accept_weak {
        odocal_solver::calibrate(&samples, &solve_options)?;
    }
    crate::lateral_slip::check_and_apply(
        &mut calibration,
        &samples,
        &solve_options,
        opts.lateral_slip,
    );
    // The matcher's own error, when larger than the residuals' noise, scales σ.
    crate::match_quality::scale_by_self_check(&mut calibration, synced.match_self_check.as_ref());
    if let Some(shift) = shift {
        odocal_solver::widen_along(&mut calibration, shift);
    }
    refuse_poorly_determined(calibration, synced, &samples, &solve_options, opts)
}

/// How far the parameters move when the clock offset moves by its σ: half the
/// difference of the estimates solved (leniently: only the values count) with the
/// samples synchronized at `offset ± σ`. `None` without a σ or when either fails.
///
/// The offset is estimated from the same samples, to a σ of a few ms on real logs
/// (the MinesRover's exp1: 2.8 ms), and the estimate solved at it moves with it: the
/// parameters' covariance must include that, as it includes not knowing the slide.
fn offset_parameter_shift(
    log: &Log,
    synced: &Synchronized,
    estimate: &OffsetEstimate,
    lenient: &Options,
) -> Option<[f64; 6]> {
    let sigma = estimate.sigma.filter(|s| s.is_finite() && *s > 0.0)?;
    let at = |offset: f64| {
        let mut shifted = synced.clone();
        resynchronize(log, &mut shifted, offset);
        solve(&shifted, lenient).ok().map(|c| c.params.to_vector())
    };
    let (plus, minus) = rayon::join(
        || at(estimate.offset + sigma),
        || at(estimate.offset - sigma),
    );
    let (plus, minus) = (plus?, minus?);
    Some(std::array::from_fn(|i| 0.5 * (plus[i] - minus[i])))
}

/// The calibration, or the refusal naming the parameters it does not determine well,
/// with their causes and the parameters to hold (unless weak parameters are
/// accepted). With unrepaired timing in the data, or in odometry-only mode a heading
/// not from the wheels, no verdict is "well determined".
pub(crate) fn refuse_poorly_determined(
    mut calibration: Calibration,
    synced: &Synchronized,
    samples: &[odocal_solver::Sample],
    solve_options: &SolveOptions,
    opts: &Options,
) -> Result<Calibration, PipelineError> {
    let unjudgeable = synced.unjudgeable();
    let sentence = calibration.observability.sentence.clone();
    if let Some(cause) = &unjudgeable {
        // Unrepaired timing, a heading not from the wheels: the σ do not hold what
        // they do, so no verdict is "well determined"; the sentence names the cause
        // (the heading's in short: its finding has the evidence and the way out).
        for p in calibration.observability.parameters.iter_mut() {
            if p.verdict == Verdict::WellDetermined && !matches!(p.constraint, Constraint::Held(_))
            {
                p.verdict = Verdict::Weak;
            }
        }
        let short = [
            synced.unrepaired_timing.clone(),
            synced
                .heading_not_from_wheels
                .as_ref()
                .map(|_| health::gyro_heading::CAUSE.to_string()),
            synced.unmodelled_slide.clone(),
            synced.unsettled_placement.clone(),
        ]
        .into_iter()
        .flatten()
        .collect::<Vec<_>>()
        .join("; ");
        let short = if short.is_empty() {
            cause.clone()
        } else {
            short
        };
        calibration.observability.sentence = format!("{short}; {}", would_give(synced, &sentence));
    }
    let poor_matching = synced
        .match_self_check
        .as_ref()
        .and_then(|c| crate::match_quality::judge(c, &synced.samples, synced.stride));
    let mut demoted = Vec::new();
    if let Some(poor) = &poor_matching {
        // Matching errors comparable to the motion: the parameters determined from
        // that motion are not "well determined", whatever their σ.
        for &i in &poor.parameters {
            if let Some(p) = calibration.observability.parameters.get_mut(i) {
                if p.verdict == Verdict::WellDetermined
                    && !matches!(p.constraint, Constraint::Held(_))
                {
                    p.verdict = Verdict::Weak;
                    demoted.push(p.name.clone());
                }
            }
        }
        if !demoted.is_empty() {
            let obs = &mut calibration.observability;
            obs.sentence = if obs
                .sentence
                .starts_with("all six parameters are well determined")
            {
                format!("{} weak: {}", demoted.join(", "), poor.statement)
            } else {
                format!(
                    "{}; {} weak too: {}",
                    obs.sentence,
                    demoted.join(", "),
                    poor.statement
                )
            };
        }
    }
    let poor: Vec<String> = calibration
        .observability
        .parameters
        .iter()
        .filter(|p| p.verdict != Verdict::WellDetermined)
        .map(|p| p.name.clone())
        .collect();
    if !poor.is_empty() && !solve_options.accept_weak {
        // The cause is named once, among the causes; the sentence says what the
        // motion alone would give.
        let sentence = match &unjudgeable {
            Some(_) => would_give(synced, &sentence),
            None => calibration.observability.sentence.clone(),
        };
        return Err(PipelineError::NotDetermined {
            parameters: poor,
            sentence,
            diagnosis: Box::new(refusal::Diagnosis {
                // Poor matching is named by the sentence (with its way out).
                causes: match &unjudgeable {
                    Some(cause) => vec![cause.clone()],
                    None => refusal::causes(&calibration, synced),
                },
                // Holding parameters does not help against unrepaired timing or a
                // heading not from the wheels, nor against matching errors comparable
                // to the motion (when they made parameters weak).
                holds: match (&unjudgeable, demoted.is_empty()) {
                    (Some(_), _) | (None, false) => Vec::new(),
                    (None, true) => refusal::holds(
                        samples,
                        solve_options,
                        &calibration,
                        opts.initial_params.as_ref(),
                        opts.lateral_slip,
                        synced,
                    ),
                },
                caveat: None,
                faults: None,
                no_hold: unjudgeable.is_some() || !demoted.is_empty(),
                stride: synced.stride,
            }),
        });
    }
    Ok(calibration)
}

/// The motion's own verdict `sentence`, as what it would give without the fault that
/// makes it unjudgeable.
fn would_give(synced: &Synchronized, sentence: &str) -> String {
    let without = if synced.unrepaired_timing.is_some() {
        "with its own acquisition times"
    } else if synced.heading_not_from_wheels.is_some() {
        "with a heading from the wheels"
    } else {
        "without the slide"
    };
    format!("{without} the motion would give: {sentence}")
}

/// Runs the pipeline on a log already in memory. Scan matching runs on rayon's
/// current thread pool (wrap the call in `ThreadPool::install` to choose the count).
///
/// Order: the data-health stage (repairs, findings), synchronization and matching,
/// the checks on the samples (clock offset, slip), the clock-offset estimate when
/// asked, then the solve and its observability verdicts — so that the verdicts are
/// those of the data at the estimated offset. A refusal names the data faults found.
pub fn calibrate_log(
    log: &Log,
    opts: &Options,
    progress: &dyn Progress,
) -> Result<Outcome, PipelineError> {
    let mut timing = Timing::default();
    let (log, mut findings, read_time_sigma) = health::check_log_and_read_times(log, opts);
    let log: &Log = &log;
    // A range asked for is checked before the long stages, so a refusal is quick.
    if let Some(range) = opts.estimate_time_offset {
        crate::time_offset::checked_range(range, scan_span(log), true)?;
    }
    // The scans' jitter is judged beside the matching (a few ms on one thread that the
    // matching's threads absorb).
    let (synced, jitter) = rayon::join(
        || synchronize_and_match(log, opts, progress, &mut timing),
        || health::scan_jitter::estimate(&log.scans.scans, &log.encoders, opts.time_offset),
    );
    let mut synced = synced.map_err(|e| PipelineError::with_faults(e, &findings))?;
    synced.read_time_sigma = read_time_sigma;
    if let Some(j) = jitter.filter(|j| j.detected()) {
        findings.push(j.finding());
        synced.unrepaired_timing = Some(j.cause());
    }
    let found = health::clock_offset::found_offset(log, &synced, opts);
    let search_range = match (opts.estimate_time_offset, found) {
        (Some(range), _) => Some(range),
        (None, Some(q)) if opts.estimate_found_time_offset => Some(
            health::clock_offset::suggested_range(q.offset - synced.time_offset),
        ),
        _ => None,
    };
    // Said once the estimate has confirmed it (or at once when only reported).
    let mut found_finding = found.map(|q| {
        health::clock_offset::found_offset_finding(&q, synced.time_offset, search_range.is_some())
    });
    if search_range.is_none() {
        findings.extend(found_finding.take());
    }
    // A swept log is matched again after compensating with the refined estimate.
    let sweep = has_sweep(&log.scans);
    // For the solves that are never judged (before the clock offset is estimated, and
    // the one that only compensates the sweep again): the verdicts come after.
    let lenient = Options {
        accept_weak: true,
        ..opts.clone()
    };

    let mut offset = None;
    if let Some(range) = search_range {
        let range = crate::time_offset::checked_range(
            range,
            scan_span(log),
            opts.estimate_time_offset.is_some(),
        )?;
        // Estimate first, on an estimate not yet judged: the verdicts come after.
        let t = Instant::now();
        let base = solve(&synced, &lenient).map_err(|e| {
            // Not yet confirmed, but what the quick check found goes with a refusal.
            let all: Vec<_> = findings.iter().chain(&found_finding).cloned().collect();
            PipelineError::with_faults(e, &all)
        })?;
        timing.solve += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let start = opts.time_offset;
        let est = estimate_time_offset(log, &synced, opts, start, range, &base)?;
        // Estimated only because the quick check found an offset (`found` is `None`
        // when an estimate was asked for), and the estimate does not confirm it: the
        // clocks agree, calibrated at the offset in use.
        match found.filter(|_| health::clock_offset::estimate_agrees(&est, start)) {
            Some(q) => findings.push(health::clock_offset::unconfirmed_finding(&q, start, &est)),
            None => {
                findings.extend(found_finding.take());
                findings.extend(edge_warning(log, &synced, start, range, est.offset));
                resynchronize(log, &mut synced, est.offset);
                offset = Some(est);
            }
        }
        timing.time_offset += t.elapsed().as_secs_f64();
    }
    let t_solve = Instant::now();
    if opts.second_pass || sweep {
        // This estimate only gives the second pass its first guesses and, with a
        // sweep, compensates the sweep again at the offset now used: the verdicts are
        // those of the final solve.
        // Without the pairs matched with their neighbouring scans where enough are
        // left: those were placed by odometry with the first guesses' estimate, and
        // an estimate made with them would pull the second pass's placements toward
        // those guesses (crate::local_map).
        let own = synced
            .samples
            .iter()
            .any(|s| s.icp.neighbours > 0)
            .then(|| {
                let mut own = synced.clone();
                own.samples.retain(|s| s.icp.neighbours == 0);
                own
            });
        let first = match own.as_ref().map(|own| solve(own, &lenient)) {
            Some(Ok(first)) => first,
            _ => solve(&synced, &lenient).map_err(|e| PipelineError::with_faults(e, &findings))?,
        };
        timing.solve += t_solve.elapsed().as_secs_f64();
        let t = Instant::now();
        settle_placement(log, &mut synced, first, opts, &lenient, progress);
        timing.r#match += t.elapsed().as_secs_f64();
        if let (true, Some(est)) = (sweep, offset.as_ref()) {
            // The offset was estimated on scans compensated at the starting offset
            // (2.5 ms low on 80 ms-offset TurtleBot logs): estimated again, near it,
            // on the scans compensated at it.
            let t = Instant::now();
            let base =
                solve(&synced, &lenient).map_err(|e| PipelineError::with_faults(e, &findings))?;
            let again =
                estimate_time_offset(log, &synced, opts, est.offset, REESTIMATE_RANGE_S, &base)?;
            resynchronize(log, &mut synced, again.offset);
            offset = Some(again);
            timing.time_offset += t.elapsed().as_secs_f64();
        }
    }
    // Slip is judged on the final samples: at the offset finally used and, with a
    // sweep, on the scans compensated at it (before, the offset and the sweep left
    // rotation residuals that were called slip).
    findings.extend(health::slip::episodes(log, &synced));
    let heading = odometry_heading(&synced, opts);
    synced.heading_not_from_wheels = heading.as_ref().map(|fit| fit.cause());
    let t = Instant::now();
    // Not knowing the offset exactly goes into the σ (and the verdicts) of the
    // estimate solved at it.
    if let Some(est) = offset.as_mut() {
        est.parameter_shift = offset_parameter_shift(log, &synced, est, &lenient);
    }
    let shift = offset.as_ref().and_then(|est| est.parameter_shift);
    let samples: Vec<_> = synced
        .samples
        .iter()
        .map(|s| s.to_solver(opts.use_profile, opts.use_icp_covariance))
        .collect();
    // The halves' check needs only the samples: it runs beside the final solve.
    let (calibration, consistency) = rayon::join(
        || solve_widened(&synced, opts, shift.as_ref()),
        || {
            check_halves(
                &samples,
                &opts.solve_options(),
                synced.match_self_check.as_ref(),
                opts.lateral_slip,
            )
        },
    );
    let calibration = calibration.map_err(|e| PipelineError::with_faults(e, &findings))?;
    if let Some(check) = synced.match_self_check.as_mut() {
        check.sigma_factor = crate::match_quality::sigma_inflation(check, calibration.sm_sigma);
    }
    timing.solve += t.elapsed().as_secs_f64();
    // Named in the findings only when the numbers are shown (--accept-weak): a
    // refusal names it as its cause.
    findings.extend(heading.map(|fit| fit.finding()));
    findings.extend(crate::lateral_slip::finding(
        &calibration,
        opts.lateral_slip,
    ));

    Ok(Outcome {
        health: findings,
        synced,
        calibration,
        offset,
        timing,
        consistency,
        range_scale: opts.range_scale(log),
    })
}

/// In odometry-only mode, the fit of the odometry's rotation when it shows a heading
/// not from the wheels (see [`health::gyro_heading`]).
fn odometry_heading(
    synced: &Synchronized,
    opts: &Options,
) -> Option<health::gyro_heading::HeadingFit> {
    let nominal = opts
        .initial_params
        .as_ref()
        .filter(|_| opts.odometry_only)?;
    health::gyro_heading::fit_heading(&synced.samples, nominal)
        .filter(|fit| fit.heading_not_from_wheels())
}

/// Time from the first scan to the last (s).
fn scan_span(log: &Log) -> f64 {
    match (log.scans.scans.first(), log.scans.scans.last()) {
        (Some(a), Some(b)) => b.t - a.t,
        _ => 0.0,
    }
}

/// A warning when the estimated offset lies at the edge of the search range: the true
/// offset may lie beyond it.
fn edge_warning(
    log: &Log,
    synced: &Synchronized,
    start: f64,
    range: f64,
    estimate: f64,
) -> Option<Finding> {
    let step = crate::time_offset::grid_step(range);
    if (estimate - start).abs() < range - 1.5 * step {
        return None;
    }
    let quick = health::clock_offset::quick_estimate(
        log,
        synced,
        start,
        health::clock_offset::QUICK_RANGE_S.max(2.0 * range),
    );
    let wider = match quick {
        Some(q) if health::clock_offset::is_large(&q, start) => {
            health::clock_offset::suggested_range(q.offset - start).max(2.0 * range)
        }
        _ => 2.0 * range,
    };
    let hint = match quick {
        Some(q) => format!(
            "; the quick check puts it near {:+.2} s (correlation {:.3})",
            q.offset, q.correlation
        ),
        None => String::new(),
    };
    Some(Finding::warning(
        FindingKind::ClockOffset,
        format!(
            "the estimated clock offset {estimate:+.3} s lies at the edge of the search range \
             ({start:+.2} ± {range:.2} s): the true offset may lie beyond it{hint}; widen the \
             search with `--time-offset-range {wider}`"
        ),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_short_log_bootstraps_on_every_pair() {
        let n = 2 * BOOTSTRAP_PAIRS - 1;
        assert_eq!(bootstrap_subset(n), (0..n).collect::<Vec<_>>());
    }

    #[test]
    fn a_long_log_bootstraps_on_evenly_spread_runs_of_consecutive_pairs() {
        for n in [2 * BOOTSTRAP_PAIRS, 1499, 10_000] {
            let subset = bootstrap_subset(n);
            // About BOOTSTRAP_PAIRS of them (one in every n / BOOTSTRAP_PAIRS).
            assert!(
                subset.len() >= BOOTSTRAP_PAIRS - BOOTSTRAP_RUN
                    && subset.len() <= 2 * BOOTSTRAP_PAIRS,
                "{n} pairs: {}",
                subset.len()
            );
            // Runs of BOOTSTRAP_RUN consecutive pairs (the last one possibly cut by
            // the end), the same distance apart, from the first pair to the last
            // tenth of the log.
            let runs: Vec<&[usize]> = subset.chunk_by(|a, b| b == &(a + 1)).collect();
            for run in &runs[..runs.len() - 1] {
                assert_eq!(run.len(), BOOTSTRAP_RUN, "{n} pairs");
            }
            let gaps: Vec<usize> = runs.windows(2).map(|w| w[1][0] - w[0][0]).collect();
            assert!(gaps.iter().all(|&g| g == gaps[0]), "{n} pairs: {gaps:?}");
            assert_eq!(subset[0], 0);
            assert!(*subset.last().unwrap() >= n - n / 10, "{n} pairs");
        }
    }
}
