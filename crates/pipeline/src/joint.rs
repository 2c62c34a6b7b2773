//! One robot, several logs, one calibration. Each log goes through the per-log
//! stages on its own ([`calibrate_log`]: its time base, health findings, clock
//! offset, sweep timing and scan pairs, and its own estimate, never refused); the
//! joint stages then solve once over every log's samples (the parameters shared)
//! and compare each log's own estimate with the joint one
//! ([`crate::log_agreement`]). Data flow one way: logs → per-log outcomes → joint
//! estimate.

use crate::consistency::Consistency;
use crate::error::PipelineError;
use crate::finding::{Finding, FindingKind};
use crate::lasers::{comparison_options, solve, LaserSetup, Solved};
use crate::log_agreement::{check_log, check_phase, information_shares};
use crate::options::{Options, MIN_SAMPLES};
use crate::phase_correlation::PhaseCorrelation;
use crate::progress::Progress;
use crate::rejection::RejectionCounts;
use crate::run::{calibrate_log, refuse_poorly_determined, Outcome, Timing};
use crate::self_check::MatchSelfCheck;
use crate::sync::DiscardCounts;
use crate::synchronized::Synchronized;
use odocal_log::Log;
use odocal_solver::{Calibration, LasersCalibration, Params, Sample, SolveOptions};
use serde::Serialize;
use std::time::Instant;

/// Gap (s) put between the time bases of consecutive logs in the joint solve, so
/// that no scan of one log is taken for a scan of another (samples that share a
/// scan are recognised by its timestamp).
const LOG_TIME_GAP_S: f64 = 1000.0;

/// What one log brought to the joint estimate.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Contribution {
    /// Samples the log handed to the joint solve.
    pub samples: usize,
    /// Of them, the samples the joint estimate used (after trimming).
    pub samples_used: usize,
    /// Per parameter (r_L, r_R, b, ℓx, ℓy, ℓθ): the log's share of the information
    /// (1/σ² of its own estimate over the sum of the logs').
    pub information_share: [f64; 6],
    /// The log's own estimate against the joint one.
    pub agreement: Consistency,
}

/// The result of [`calibrate_logs`].
#[derive(Debug, Clone)]
pub struct JointOutcome {
    /// Per log, in the order given: its own stages and estimate (solved with weak
    /// parameters accepted: never judged, only compared).
    pub logs: Vec<Outcome>,
    /// The joint result: every log's findings (each prefixed with its log), samples
    /// and discards together, the joint calibration and the summed timing. Its
    /// `consistency` says that the logs are compared one by one instead of halves.
    pub joint: Outcome,
    /// Per log, in the same order: what it contributed and whether it agrees.
    pub contributions: Vec<Contribution>,
    /// Per log, in the same order: its laser (0: the first log's).
    pub laser_of_log: Vec<usize>,
    /// With more than one laser: the joint estimate with every laser's ℓ (the
    /// `joint` outcome's calibration is the first laser's view of it).
    pub lasers: Option<LasersCalibration>,
    /// With the phases of several logs ([`calibrate_log_phases`]): per log given, its
    /// phases' estimate together against the joint one; empty otherwise.
    pub phase_groups: Vec<PhaseGroupCheck>,
    /// Per log given in phases: how much its phases share their errors (the joint σ
    /// are scaled by the largest factor).
    pub phase_correlations: Vec<(String, PhaseCorrelation)>,
    /// The logs are the phases of one log ([`calibrate_log_phases`] with one log
    /// given): each is compared as a phase ([`crate::log_agreement::check_phase`]).
    pub phases_of_one_log: bool,
}

/// The phases of one log given (`--all-pairs`, [`crate::phases`]): the logs of a
/// joint calibration that are that log paired from different scans.
#[derive(Debug, Clone, PartialEq)]
pub struct LogPhases {
    /// The log's name as given (its path).
    pub name: String,
    /// Its phases: positions in the joint calibration's logs.
    pub logs: Vec<usize>,
}

/// One log given, its phases solved together, against the joint estimate of every
/// log's phases.
#[derive(Debug, Clone)]
pub struct PhaseGroupCheck {
    /// The log's name as given.
    pub name: String,
    /// Its phases: positions in the joint calibration's logs.
    pub logs: Vec<usize>,
    /// The estimate of its phases together (weak parameters accepted: never judged,
    /// only compared).
    pub calibration: Calibration,
    /// Its estimate against the joint one ([`check_log`]).
    pub agreement: Consistency,
}

/// Why [`calibrate_logs`] failed.
#[derive(Debug, thiserror::Error)]
pub enum JointError {
    /// One log failed its own stages.
    #[error("{name}: {source}")]
    Log {
        /// Index of the log in the order given.
        index: usize,
        /// The log's name as given.
        name: String,
        /// What failed.
        source: PipelineError,
    },
    /// The joint solve failed or was refused.
    #[error("the joint calibration of the logs: {0}")]
    Joint(PipelineError),
    /// The joint estimate was refused, and logs disagree with it: they do not
    /// describe one robot with one mounting.
    #[error(
        "the logs do not describe one robot: {sentences}; calibrate them separately, or \
         without the log(s) named (the joint estimate was refused: {refusal})"
    )]
    Disagree {
        /// Each disagreeing log's sentence, joined, and (when it applies) the command
        /// that gives the logs whose laser was mounted elsewhere their own ℓ.
        sentences: String,
        /// The joint refusal.
        refusal: PipelineError,
    },
}

/// Calibrates one robot from several logs: `logs` pairs each log with the name the
/// messages give it (its path). Scan matching runs on rayon's current thread pool,
/// one log after another (each log's pairs in parallel). One laser: every log's.
pub fn calibrate_logs(
    logs: &[(&str, &Log)],
    opts: &Options,
    progress: &dyn Progress,
) -> Result<JointOutcome, JointError> {
    calibrate_logs_with_lasers(logs, &LaserSetup::one_laser(logs.len()), opts, progress)
}

/// [`calibrate_logs`] with each log's laser (`lasers.of_log`: logs with equal numbers
/// share a laser, renumbered from 0, the first log's, in order of appearance;
/// [`crate::laser_indices`] numbers them from keys). The wheels are shared; each
/// laser gets its own ℓ. `opts.initial_params` and `opts.solve.constraints` are the
/// wheels' and the first laser's; the other lasers' first guesses and held
/// parameters or priors are `lasers`' (without a first guess, a laser's logs
/// bootstrap their guesses).
pub fn calibrate_logs_with_lasers(
    logs: &[(&str, &Log)],
    lasers: &LaserSetup,
    opts: &Options,
    progress: &dyn Progress,
) -> Result<JointOutcome, JointError> {
    calibrate_joint(logs, lasers, &[], opts, progress)
}

/// [`calibrate_logs`] for the phases of one or several logs of one laser
/// (`--all-pairs`): `logs` are every log's phases ([`crate::phases`]), `groups` says
/// which are the phases of which log. Besides each phase, each log given (its phases
/// solved together) is compared with the joint estimate when there are several: a
/// phase alone rarely determines every parameter, and the logs' disagreement is what
/// the comparison is for.
pub fn calibrate_log_phases(
    logs: &[(&str, &Log)],
    groups: &[LogPhases],
    opts: &Options,
    progress: &dyn Progress,
) -> Result<JointOutcome, JointError> {
    calibrate_joint(
        logs,
        &LaserSetup::one_laser(logs.len()),
        groups,
        opts,
        progress,
    )
}

/// The joint calibration: [`calibrate_logs_with_lasers`], with each of `groups` (the
/// phases of one log; empty: none) compared with the joint estimate as one log when
/// there are several groups. Logs in phases are one laser's (`calibrate_log_phases`).
fn calibrate_joint(
    logs: &[(&str, &Log)],
    lasers: &LaserSetup,
    groups: &[LogPhases],
    opts: &Options,
    progress: &dyn Progress,
) -> Result<JointOutcome, JointError> {
    // Numbered densely from the first log's laser, whatever numbers were given.
    let laser_of_log = crate::lasers::laser_indices(&lasers.of_log);
    // The log's laser's first guess and constraints; its own estimate is never
    // refused (only compared).
    let own_options = |index: usize, initial_params: Option<Params>| {
        let k = laser_of_log.get(index).copied().unwrap_or(0);
        let mut own = Options {
            accept_weak: true,
            initial_params: lasers.initial_params(k, initial_params),
            ..opts.clone()
        };
        own.solve.constraints = lasers.constraints_of(k, &opts.solve.constraints);
        own
    };
    let failed = |index: usize, source: PipelineError| JointError::Log {
        index,
        name: logs[index].0.to_string(),
        source,
    };
    // A phase with too few samples from its own first guesses (its pairs matched
    // without odometry gave no estimate, or a poor one, to guess and place the others by)
    // waits for another phase of its log; any other failure stops the run at once.
    let mut results: Vec<Result<Outcome, PipelineError>> = Vec::with_capacity(logs.len());
    for (index, (_, log)) in logs.iter().enumerate() {
        let result = calibrate_log(log, &own_options(index, opts.initial_params), progress);
        match result {
            Err(e @ PipelineError::TooFewSamples { .. })
                if opts.initial_params.is_none() && in_phases(groups, index) =>
            {
                results.push(Err(e))
            }
            Err(e) => return Err(failed(index, e)),
            Ok(outcome) => results.push(Ok(outcome)),
        }
    }
    // Such a phase is matched again from the estimate of another phase of its log
    // (first guesses only, as a nominal would be).
    let mut guessed = Vec::new();
    for index in 0..logs.len() {
        if results[index].is_ok() {
            continue;
        }
        let Some((sibling, estimate)) = sibling_estimate(groups, &results, index) else {
            continue;
        };
        let retried = calibrate_log(logs[index].1, &own_options(index, Some(estimate)), progress);
        if retried.is_ok() {
            guessed.push((index, sibling));
            results[index] = retried;
        }
    }
    let mut outcomes = Vec::with_capacity(logs.len());
    for (index, result) in results.into_iter().enumerate() {
        outcomes.push(result.map_err(|source| failed(index, source))?);
    }
    let t = Instant::now();
    let mut health: Vec<Finding> = logs
        .iter()
        .zip(&outcomes)
        .flat_map(|((name, _), o)| {
            o.health.iter().cloned().map(move |mut f| {
                f.message = format!("{name}: {}", f.message);
                f
            })
        })
        .collect();
    health.extend(guessed.iter().map(|&(index, sibling)| {
        Finding::note(
            FindingKind::PhaseGuesses,
            format!(
                "{}: too few of its pairs matched from its own first guesses (those matched \
                 without odometry gave no estimate, or a poor one, to guess and place the \
                 others by); matched again from first guesses by the estimate of {} (first guesses \
                 only: its samples are its own)",
                logs[index].0, logs[sibling].0
            ),
        )
    }));
    let all: Vec<&Outcome> = outcomes.iter().collect();
    let Together {
        samples,
        mut synced,
        solve_options,
        mut solved,
    } = solve_together(&all, &laser_of_log, lasers, opts).map_err(|e| {
        // Too few samples together: each log's own findings were already given.
        JointError::Joint(match e {
            e @ PipelineError::TooFewSamples { .. } => e,
            e => e.with_faults(&health),
        })
    })?;
    if solved.lasers.is_none() {
        health.extend(
            crate::lateral_slip::finding(&solved.first, opts.lateral_slip).map(|mut f| {
                f.message = format!("the logs together: {}", f.message);
                f
            }),
        );
    } else if let Some(sliding) = sliding_logs(logs, &outcomes) {
        // Several lasers: the joint model has no slide term (docs/skid-steer.md), and
        // a slide left out biases every parameter it moves: no verdict is "well
        // determined" then, and no held parameter cures it.
        synced.unmodelled_slide = Some(format!(
            "{sliding} slides sideways in turns (its own estimate includes the slide), but \
             the joint model of several lasers has no slide term: calibrate each laser's \
             logs on their own (`odocal calibrate LOG --lateral-slip`), or give \
             `--no-lateral-slip` if the robot does not slide"
        ));
    }
    // Several logs given in phases: each log given is compared whole. One log given
    // in phases (every log its phase, in order): the joint estimate is its own.
    let logs_given_in_phases = groups.len() > 1;
    let one_log_in_phases = matches!(groups, [one] if one.logs.iter().copied().eq(0..logs.len()));
    // Several logs given in phases: each solved on its own, its phases' shared
    // errors measured on its own estimate's residuals.
    let group_estimates: Vec<(Calibration, Option<PhaseCorrelation>)> = if logs_given_in_phases {
        groups
            .iter()
            .map(|g| group_estimate(g, &outcomes, opts))
            .collect::<Result<_, _>>()?
    } else {
        Vec::new()
    };
    // One log's phases share their errors where they overlap in time: the joint σ
    // scaled by the largest log's factor before anything is compared with them.
    let phase_correlations: Vec<(String, PhaseCorrelation)> = match groups {
        [one] if one_log_in_phases => {
            let residuals = slide_residuals(&solved.first, &samples, opts);
            crate::phase_correlation::measure(&all, &residuals, &solved.first.used)
                .map(|c| vec![(one.name.clone(), c)])
                .unwrap_or_default()
        }
        _ => groups
            .iter()
            .zip(&group_estimates)
            .filter_map(|(g, (_, c))| c.map(|c| (g.name.clone(), c)))
            .collect(),
    };
    // The phases of one log are compared by the joint covariance before the widening
    // for their shared errors ([`crate::log_agreement::check_phase`]), and their
    // spread judged by it.
    let joint_of_phases = one_log_in_phases.then(|| solved.first.clone());
    let phases_alike: Vec<Calibration> = joint_of_phases
        .iter()
        .flat_map(|joint| {
            outcomes
                .iter()
                .map(|o| crate::log_agreement::as_exchangeable_phase(&o.calibration, joint))
        })
        .collect();
    let shared_factor = phase_correlations
        .iter()
        .map(|(_, c)| c.sigma_factor)
        .fold(1.0, f64::max);
    odocal_solver::inflate_sigma(&mut solved.first, shared_factor);
    synced.shared_error_factor = shared_factor;
    if let Some(finding) = crate::phase_correlation::finding(&phase_correlations) {
        health.push(finding);
    }
    let agreements: Vec<Consistency> = logs
        .iter()
        .zip(&outcomes)
        .zip(&laser_of_log)
        .enumerate()
        .map(|(index, (((name, _), o), &k))| {
            // With several logs given in phases, each log given is compared (its
            // phases together), not each phase: a phase against the estimate of
            // other logs mixes its own matching noise with the logs' difference.
            if let Some(g) = groups
                .iter()
                .find(|g| g.logs.contains(&index))
                .filter(|_| logs_given_in_phases)
            {
                return Consistency::NotAvailable {
                    reason: format!(
                        "{name} is a phase of {}: compared with the joint estimate together \
                         with that log's other phases",
                        g.name
                    ),
                };
            }
            let view = solved.view(k);
            let alone =
                solved.lasers.is_some() && laser_of_log.iter().filter(|&&j| j == k).count() == 1;
            let constraints = lasers.constraints_of(k, &solve_options.constraints);
            let compared = comparison_options(&solve_options, constraints, &view, alone);
            // One laser: the other logs' own estimates are the comparison's other side.
            let others = if solved.lasers.is_none() {
                all_but(
                    index,
                    logs.iter().map(|(n, _)| *n),
                    outcomes.iter().map(|o| &o.calibration),
                )
            } else {
                Vec::new()
            };
            match (&joint_of_phases, phases_alike.get(index)) {
                (Some(joint), Some(alike)) => check_phase(alike, joint, &compared, name),
                _ => check_log(&o.calibration, &others, &view, &compared, name, alone),
            }
        })
        .collect();
    // Each log given in phases, its phases sharing their errors as they do in the
    // joint solve, against the other logs so given.
    let group_calibrations: Vec<Calibration> = group_estimates
        .into_iter()
        .map(|(mut calibration, shared)| {
            odocal_solver::inflate_sigma(&mut calibration, shared.map_or(1.0, |c| c.sigma_factor));
            calibration
        })
        .collect();
    let group_names: Vec<String> = groups
        .iter()
        .map(|g| format!("{} (its {} phases together)", g.name, g.logs.len()))
        .collect();
    // (None for one log given in phases: its phases are compared one by one.)
    let group_agreements: Vec<Consistency> = (0..group_calibrations.len())
        .map(|index| {
            check_log(
                &group_calibrations[index],
                &all_but(
                    index,
                    group_names.iter().map(String::as_str),
                    &group_calibrations,
                ),
                &solved.first,
                &solve_options,
                &group_names[index],
                false,
            )
        })
        .collect();
    let phase_groups: Vec<PhaseGroupCheck> = groups
        .iter()
        .zip(group_calibrations)
        .zip(group_agreements)
        .map(|((g, calibration), agreement)| PhaseGroupCheck {
            name: g.name.clone(),
            logs: g.logs.clone(),
            calibration,
            agreement,
        })
        .collect();
    let Solved {
        first: mut calibration,
        mut lasers,
    } = solved;
    let factor = crate::match_quality::scale_by_self_check(
        &mut calibration,
        synced.match_self_check.as_ref(),
    );
    if let Some(l) = lasers
        .as_mut()
        .filter(|_| factor.is_finite() && factor > 1.0)
    {
        l.covariance
            .iter_mut()
            .flatten()
            .for_each(|v| *v *= factor * factor);
    }
    // Each log's clock-offset uncertainty, in its own σ, carried into the joint σ
    // (crate::joint_offsets): with several lasers into the whole joint covariance, every
    // laser's row and the first laser's view alike; the logs' offsets were estimated
    // apart.
    let offsets: Vec<crate::joint_offsets::LogOffset> = outcomes
        .iter()
        .zip(&laser_of_log)
        .filter_map(|(o, &laser)| {
            Some(crate::joint_offsets::LogOffset {
                laser,
                covariance: &o.calibration.covariance,
                shift: o.offset.as_ref()?.parameter_shift?,
            })
        })
        .collect();
    crate::joint_offsets::widen_by_offsets(&mut calibration, lasers.as_mut(), &offsets);
    if lasers.is_none() {
        // Logs that disagree widen the joint σ to their spread: the logs given when
        // they are phases, else each log.
        let what = if phases_alike.is_empty() {
            "logs"
        } else {
            "phases"
        };
        let compared: Vec<(&Calibration, &Consistency)> = if !phases_alike.is_empty() {
            phases_alike.iter().zip(&agreements).collect()
        } else if phase_groups.is_empty() {
            outcomes
                .iter()
                .map(|o| &o.calibration)
                .zip(&agreements)
                .collect()
        } else {
            phase_groups
                .iter()
                .map(|g| (&g.calibration, &g.agreement))
                .collect()
        };
        if let Some(sentence) =
            crate::log_agreement::widen_to_spread(&mut calibration, &compared, what)
        {
            health.push(Finding::warning(FindingKind::LogAgreement, sentence));
        }
    }
    let calibration =
        match refuse_poorly_determined(calibration, &synced, &samples, &solve_options, opts) {
            Ok(c) => c,
            Err(refusal) => {
                // Logs of different robots (or mountings) make one model fit none of them:
                // the residuals grow and the joint verdicts weaken. Name the logs that
                // disagree rather than ask for more driving.
                let mut disagreeing: Vec<(usize, String)> = agreements
                    .iter()
                    .enumerate()
                    .filter_map(|(i, a)| match a {
                        Consistency::Checked(h) if !h.agree => Some((i, h.sentence.clone())),
                        _ => None,
                    })
                    .collect();
                // A log given whose phases together disagree: named by its first phase.
                disagreeing.extend(phase_groups.iter().filter_map(|g| match &g.agreement {
                    Consistency::Checked(h) if !h.agree => {
                        Some((g.logs.first().copied().unwrap_or(0), h.sentence.clone()))
                    }
                    _ => None,
                }));
                return Err(if disagreeing.is_empty() {
                    JointError::Joint(refusal.with_faults(&health))
                } else {
                    let names: Vec<&str> = logs.iter().map(|(n, _)| *n).collect();
                    let which: Vec<usize> = disagreeing.iter().map(|(i, _)| *i).collect();
                    // Two logs (or two logs given in phases) are one comparison, each
                    // against the other: said once.
                    let given = if groups.is_empty() {
                        logs.len()
                    } else {
                        groups.len()
                    };
                    if given == 2 {
                        disagreeing.truncate(1);
                    }
                    let mut sentences: Vec<String> =
                        disagreeing.into_iter().map(|(_, s)| s).collect();
                    // Phases are not logs to give a laser of their own (`--own-laser`
                    // counts the logs given).
                    if groups.is_empty() {
                        sentences.extend(own_laser_hint(&names, &which, &laser_of_log));
                    }
                    JointError::Disagree {
                        sentences: sentences.join("; "),
                        refusal,
                    }
                });
            }
        };
    let own: Vec<_> = outcomes.iter().map(|o| &o.calibration).collect();
    let shares = information_shares(&own);
    let mut first = 0;
    let contributions = logs
        .iter()
        .zip(&outcomes)
        .zip(shares)
        .zip(agreements)
        .map(|(((_, o), information_share), agreement)| {
            let n = o.synced.samples.len();
            let used = calibration.used[first..first + n]
                .iter()
                .filter(|u| **u)
                .count();
            first += n;
            Contribution {
                samples: n,
                samples_used: used,
                information_share,
                agreement,
            }
        })
        .collect();
    let consistency = Consistency::NotAvailable {
        // Measured (stop 44): the halves of one log in phases, at every pair's σ,
        // differ on 13 of 30 simulated TurtleBot 4 logs, by the range bias that drifts
        // with time, which the σ with the range scale already cover.
        reason: if one_log_in_phases {
            "one log in phases: each phase's own estimate is compared with the joint one \
             instead"
                .into()
        } else {
            "several logs: each log's own estimate is compared with the joint one instead".into()
        },
    };
    let mut timing = outcomes.iter().fold(Timing::default(), |a, o| Timing {
        parse: a.parse + o.timing.parse,
        sync: a.sync + o.timing.sync,
        r#match: a.r#match + o.timing.r#match,
        time_offset: a.time_offset + o.timing.time_offset,
        solve: a.solve + o.timing.solve,
    });
    timing.solve += t.elapsed().as_secs_f64();
    // One laser's range scale for the six parameters: the first log's (several
    // lasers' own scales are not composed; docs/several-lasers.md).
    let range_scale = outcomes
        .first()
        .map_or_else(crate::RangeScale::unknown, |o| o.range_scale.clone());
    let joint = Outcome {
        range_scale,
        health,
        synced,
        calibration,
        offset: None,
        timing,
        consistency,
    };
    Ok(JointOutcome {
        logs: outcomes,
        joint,
        contributions,
        laser_of_log,
        lasers,
        phase_groups,
        phase_correlations,
        phases_of_one_log: one_log_in_phases,
    })
}

/// The samples of several logs' outcomes solved together.
struct Together {
    /// Every log's solver samples, in log order.
    samples: Vec<Sample>,
    /// The logs' samples and discards together ([`merged`]).
    synced: Synchronized,
    /// The options the solve ran with (the matcher's bias included).
    solve_options: SolveOptions,
    /// The estimate (with one laser, the sideways slide weighed in).
    solved: Solved,
}

/// Solves `outcomes`' samples together: `laser_of_log` is each outcome's laser (dense
/// from 0), `lasers` their first guesses and constraints. Refused with fewer than
/// [`MIN_SAMPLES`] usable samples.
fn solve_together(
    outcomes: &[&Outcome],
    laser_of_log: &[usize],
    lasers: &LaserSetup,
    opts: &Options,
) -> Result<Together, PipelineError> {
    let samples = joint_samples(outcomes, opts);
    let synced = merged(outcomes);
    // As for one log: matches along a corridor do not count toward the minimum.
    let usable = samples
        .iter()
        .filter(|s| s.free_direction.is_none())
        .count();
    if usable < MIN_SAMPLES {
        return Err(synced.too_few_samples(usable));
    }
    let solve_options = crate::matcher_bias::with_matcher_bias(opts.solve_options(), &synced);
    let laser_of: Vec<usize> = outcomes
        .iter()
        .zip(laser_of_log)
        .flat_map(|(o, &k)| std::iter::repeat_n(k, o.synced.samples.len()))
        .collect();
    let mut solved = solve(&samples, &laser_of, &solve_options, &lasers.constraints)?;
    if solved.lasers.is_none() {
        // One robot, one slide: the logs' samples together determine `k` better than
        // any one log, and a slide left out of the joint model biases ℓx there as it
        // does in one log (the MinesRover's logs: ℓx 121 ± 8 mm without it, against
        // 141 ± 17 mm from the first log alone with it).
        crate::lateral_slip::check_and_apply(
            &mut solved.first,
            &samples,
            &solve_options,
            opts.lateral_slip,
        );
    }
    Ok(Together {
        samples,
        synced,
        solve_options,
        solved,
    })
}

/// The log `group` given, its phases (`outcomes` at `group.logs`) solved together as
/// a log is alone (the slide weighed in, σ scaled by the matcher's own error, the
/// verdicts judged with weak parameters accepted), with how much its phases share
/// their errors, measured on its own residuals (not yet applied to its σ).
fn group_estimate(
    group: &LogPhases,
    outcomes: &[Outcome],
    opts: &Options,
) -> Result<(Calibration, Option<PhaseCorrelation>), JointError> {
    let members: Vec<&Outcome> = group.logs.iter().filter_map(|&i| outcomes.get(i)).collect();
    let own = Options {
        accept_weak: true,
        ..opts.clone()
    };
    let failed = |source: PipelineError| JointError::Log {
        index: group.logs.first().copied().unwrap_or(0),
        name: format!("{} (its phases together)", group.name),
        source,
    };
    let zeros = vec![0; members.len()];
    let t = solve_together(
        &members,
        &zeros,
        &LaserSetup::one_laser(members.len()),
        &own,
    )
    .map_err(failed)?;
    let mut calibration = t.solved.first;
    let residuals = slide_residuals(&calibration, &t.samples, opts);
    let shared = crate::phase_correlation::measure(&members, &residuals, &calibration.used);
    crate::match_quality::scale_by_self_check(&mut calibration, t.synced.match_self_check.as_ref());
    let calibration =
        refuse_poorly_determined(calibration, &t.synced, &t.samples, &t.solve_options, &own)
            .map_err(failed)?;
    Ok((calibration, shared))
}

/// Every log's name and estimate (`names`, `calibrations`, in the same order) but
/// the one at `index`: the other side of its comparison.
fn all_but<'a>(
    index: usize,
    names: impl Iterator<Item = &'a str>,
    calibrations: impl IntoIterator<Item = &'a Calibration>,
) -> Vec<(&'a str, &'a Calibration)> {
    names
        .zip(calibrations)
        .enumerate()
        .filter(|&(j, _)| j != index)
        .map(|(_, pair)| pair)
        .collect()
}

/// The residuals of `samples` at `calibration`'s estimate, its sideways slide as
/// weighed in.
fn slide_residuals(calibration: &Calibration, samples: &[Sample], opts: &Options) -> Vec<[f64; 3]> {
    let k = calibration
        .lateral_slip
        .as_ref()
        .map_or(0.0, |s| s.weight * s.k);
    odocal_solver::residuals_with_slide(&calibration.params, k, samples, opts.use_profile)
}

/// The command that gives the disagreeing logs (`which`, positions in `names`) their
/// own laser: every disagreeing log but the first log (whose laser is the reference),
/// or the first when it alone disagrees; `None` when the logs already have lasers of
/// their own (several lasers: the disagreement is not the mounting).
fn own_laser_hint(names: &[&str], which: &[usize], laser_of_log: &[usize]) -> Option<String> {
    if laser_of_log.iter().any(|&k| k > 0) {
        return None;
    }
    let mut own: Vec<usize> = which.iter().copied().filter(|&i| i > 0).collect();
    if own.is_empty() {
        own.push(0);
    }
    let flags: String = own
        .iter()
        .map(|i| format!(" --own-laser {}", i + 1))
        .collect();
    Some(format!(
        "if the laser was mounted elsewhere for some of them, give each its own ℓ with the \
         wheels shared (`odocal calibrate {}{flags}`, with the other options you gave)",
        names.join(" ")
    ))
}

/// The names of the logs whose own estimate includes the slide, joined; `None` when
/// none does.
fn sliding_logs(logs: &[(&str, &Log)], outcomes: &[Outcome]) -> Option<String> {
    let names: Vec<&str> = logs
        .iter()
        .zip(outcomes)
        .filter(|(_, o)| {
            o.calibration
                .lateral_slip
                .as_ref()
                .is_some_and(crate::lateral_slip::more_likely_than_not)
        })
        .map(|((n, _), _)| *n)
        .collect();
    (!names.is_empty()).then(|| names.join(", "))
}

/// Every log's solver samples, in log order, each log with its own read-time noise,
/// and the logs' scan times moved apart so that no two logs share a scan.
fn joint_samples(outcomes: &[&Outcome], opts: &Options) -> Vec<Sample> {
    let mut samples = Vec::new();
    let mut next_start = 0.0;
    for o in outcomes {
        let s = &o.synced;
        let (lo, hi) = s
            .samples
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p.pair.t0), hi.max(p.pair.t1))
            });
        let shift = if lo.is_finite() { next_start - lo } else { 0.0 };
        samples.extend(s.samples.iter().map(|p| {
            let sample = p.to_solver(opts.use_profile, opts.use_icp_covariance);
            Sample {
                read_time_sigma: s.read_time_sigma,
                scan_times: sample.scan_times.map(|[a, b]| [a + shift, b + shift]),
                ..sample
            }
        }));
        if hi.is_finite() {
            next_start = hi + shift + LOG_TIME_GAP_S;
        }
    }
    samples
}

/// The logs' samples and discards together (stride, limits, ticks and clock offset
/// of the first log: each log's own are in its outcome).
fn merged(outcomes: &[&Outcome]) -> Synchronized {
    let mut discarded = DiscardCounts::default();
    for o in outcomes {
        for (k, n) in &o.synced.discarded.0 {
            *discarded.0.entry(k).or_insert(0) += n;
        }
    }
    let mut match_rejections = RejectionCounts::default();
    for o in outcomes {
        for (k, n) in &o.synced.match_rejections.0 {
            *match_rejections.0.entry(k).or_insert(0) += n;
        }
    }
    let first = &outcomes[0].synced;
    Synchronized {
        match_rejections,
        match_self_check: pooled_self_check(outcomes),
        stride: first.stride,
        limits: first.limits,
        ticks_per_revolution: first.ticks_per_revolution,
        pairs: outcomes.iter().map(|o| o.synced.pairs).sum(),
        samples: outcomes
            .iter()
            .flat_map(|o| o.synced.samples.iter().cloned())
            .collect(),
        discarded,
        time_offset: first.time_offset,
        sweep_compensated: outcomes.iter().any(|o| o.synced.sweep_compensated),
        read_time_sigma: None,
        // One log's unrepaired timing weakens the joint verdicts too.
        unrepaired_timing: joined_causes(outcomes, |s| &s.unrepaired_timing),
        heading_not_from_wheels: joined_causes(outcomes, |s| &s.heading_not_from_wheels),
        // Set by the joint solve when its model cannot hold a log's slide.
        unmodelled_slide: None,
        // One log's unsettled placement weakens the joint verdicts too.
        unsettled_placement: joined_causes(outcomes, |s| &s.unsettled_placement),
        scan_returns: first.scan_returns,
        // Set by the joint solve when the logs are one log's phases.
        shared_error_factor: 1.0,
    }
}

/// The log of `groups` of which the log at `index` is one of several phases.
fn phases_of(groups: &[LogPhases], index: usize) -> Option<&LogPhases> {
    groups
        .iter()
        .find(|g| g.logs.len() > 1 && g.logs.contains(&index))
}

/// Whether the log at `index` is one of several phases of a log of `groups`.
fn in_phases(groups: &[LogPhases], index: usize) -> bool {
    phases_of(groups, index).is_some()
}

/// For the log at `index`, a phase of a log of `groups`: another phase of that log
/// that calibrated (`results`), and its estimate; `None` when `index` is no phase or
/// no other phase of its log calibrated.
fn sibling_estimate(
    groups: &[LogPhases],
    results: &[Result<Outcome, PipelineError>],
    index: usize,
) -> Option<(usize, Params)> {
    phases_of(groups, index)?
        .logs
        .iter()
        .find_map(|&other| match results.get(other)? {
            Ok(outcome) if other != index => Some((other, outcome.calibration.params)),
            _ => None,
        })
}

/// The causes `cause` gives of the logs' verdicts not being judged, joined; `None`
/// when no log has one.
fn joined_causes(
    outcomes: &[&Outcome],
    cause: impl Fn(&Synchronized) -> &Option<String>,
) -> Option<String> {
    let causes: Vec<&str> = outcomes
        .iter()
        .filter_map(|o| cause(&o.synced).as_deref())
        .collect();
    (!causes.is_empty()).then(|| causes.join("; "))
}

/// The logs' scan-matching self-checks pooled: RMS errors weighted by the triples
/// that closed in each log (`None` when no log had enough).
fn pooled_self_check(outcomes: &[&Outcome]) -> Option<MatchSelfCheck> {
    let checks: Vec<&MatchSelfCheck> = outcomes
        .iter()
        .filter_map(|o| o.synced.match_self_check.as_ref())
        .collect();
    let triples: usize = checks.iter().map(|c| c.triples).sum();
    if triples == 0 {
        return None;
    }
    let mean_square = |f: fn(&MatchSelfCheck) -> f64| {
        (checks
            .iter()
            .map(|c| c.triples as f64 * f(c).powi(2))
            .sum::<f64>()
            / triples as f64)
            .sqrt()
    };
    let mut noise: Vec<f64> = checks.iter().map(|c| c.range_noise_m).collect();
    noise.sort_by(f64::total_cmp);
    let mut spacing: Vec<f64> = checks.iter().map(|c| c.ray_spacing_rad).collect();
    spacing.sort_by(f64::total_cmp);
    let mut tilt: Vec<f64> = checks.iter().filter_map(|c| c.tilt_sigma_rad).collect();
    tilt.sort_by(f64::total_cmp);
    Some(MatchSelfCheck {
        triples,
        tried: checks.iter().map(|c| c.tried).sum(),
        left_out: checks.iter().map(|c| c.left_out).sum(),
        xy_m: mean_square(|c| c.xy_m),
        theta_rad: mean_square(|c| c.theta_rad),
        range_noise_m: noise[noise.len() / 2],
        ray_spacing_rad: spacing[spacing.len() / 2],
        tilt_sigma_rad: tilt.get(tilt.len() / 2).copied(),
        sigma_factor: 1.0,
    })
}
