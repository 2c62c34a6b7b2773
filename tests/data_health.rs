//! Every fault of issue 14's table, on a simulated log edited in the test: the
//! data-health stage names it (a finding with its kind and line), repairs what it can,
//! and the parameters come out within the bounds where the data allow — or the
//! refusal names the fault.

mod common;

use odocal_log::{read_carmen_from, Log, ReadOptions};
use odocal_pipeline::{calibrate_log, FindingKind, NoProgress, Options, Outcome, PipelineError};
use odocal_sim::{simulate, SimConfig};

/// r_L, r_R, b, ℓx, ℓy, ℓθ.
use common::Truth;

/// A simulated log as text lines, and its true parameters.
fn sim_lines(duration: f64, seed: u64, tweak: impl FnOnce(&mut SimConfig)) -> (Vec<String>, Truth) {
    let mut config = SimConfig::preset("khepera-displaced").expect("preset");
    config.duration = duration;
    config.seed = seed;
    tweak(&mut config);
    let run = simulate(&config).expect("simulation runs");
    let mut bytes = Vec::new();
    let summary = run.write_log(&mut bytes, &[]).expect("log written");
    let p = run.ground_truth(&summary).params;
    let text = String::from_utf8(bytes).expect("text");
    (text.lines().map(String::from).collect(), p.to_array())
}

fn read(lines: &[String]) -> Log {
    read_carmen_from(
        lines.join("\n").as_bytes(),
        "edited.log",
        &ReadOptions::default(),
    )
    .expect("the edited log reads")
}

fn run(log: &Log, opts: &Options) -> Result<Outcome, PipelineError> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .expect("pool")
        .install(|| calibrate_log(log, opts, &NoProgress))
}

/// The timestamp token (third from the end) of a message line.
fn timestamp(line: &str) -> f64 {
    let t: Vec<&str> = line.split(' ').collect();
    t[t.len() - 3].parse().expect("a timestamp")
}

/// The line with its timestamp (and logger timestamp) replaced.
fn with_timestamp(line: &str, t: f64) -> String {
    let mut tok: Vec<String> = line.split(' ').map(String::from).collect();
    let n = tok.len();
    tok[n - 3] = format!("{t:.6}");
    tok[n - 1] = format!("{t:.6}");
    tok.join(" ")
}

fn finding(o: &Outcome, kind: FindingKind) -> &odocal_pipeline::Finding {
    o.health
        .iter()
        .find(|f| f.kind == kind)
        .unwrap_or_else(|| panic!("no {kind:?} finding in {:#?}", o.health))
}

/// The bounds (0.35 % on r_L, r_R, b; 1.5 mm on ℓx, ℓy; 0.2° on ℓθ) scaled by
/// `loose`, and `k` σ.
fn assert_within(label: &str, o: &Outcome, truth: &Truth, loose: f64, k: f64) {
    let est = o.calibration.params.to_vector();
    let bounds = common::bounds(truth);
    for i in 0..6 {
        let err = est[i] - truth[i];
        let sigma = o.calibration.covariance[i][i].sqrt();
        println!("{label}: param {i} error {err:+.3e} ({:+.2}σ)", err / sigma);
        assert!(
            err.abs() <= loose * bounds[i],
            "{label}: param {i} error {err:.3e} above the bound"
        );
        assert!(
            err.abs() <= k * sigma,
            "{label}: param {i} error {:.2}σ",
            err / sigma
        );
    }
}

#[test]
fn a_clean_log_has_no_warnings() {
    let (lines, truth) = sim_lines(60.0, 41, |_| {});
    let o = run(&read(&lines), &Options::default()).expect("calibrates");
    let warnings: Vec<_> = o
        .health
        .iter()
        .filter(|f| f.severity == odocal_pipeline::Severity::Warning)
        .collect();
    assert!(warnings.is_empty(), "{warnings:#?}");
    assert_within("clean", &o, &truth, 1.0, 4.0);
}

#[test]
fn colliding_and_rounded_encoder_timestamps_are_merged() {
    let (mut lines, truth) = sim_lines(60.0, 42, |_| {});
    let first = lines.iter().position(|l| l.starts_with("ENCODER")).unwrap();
    // Two ENCODER records with the same timestamp …
    let k = lines
        .iter()
        .skip(first + 300)
        .position(|l| l.starts_with("ENCODER"))
        .unwrap()
        + first
        + 300;
    let next = lines
        .iter()
        .skip(k + 1)
        .position(|l| l.starts_with("ENCODER"))
        .unwrap()
        + k
        + 1;
    let t = timestamp(&lines[k]);
    lines[next] = with_timestamp(&lines[next], t);
    let o = run(&read(&lines), &Options::default()).expect("one collision calibrates");
    let f = finding(&o, FindingKind::TimestampCollision);
    assert_eq!((f.count, f.first_line), (1, Some(next as u64 + 1)));
    assert_within("one collision", &o, &truth, 1.0, 4.0);
    // … and every ENCODER timestamp rounded to 0.1 s.
    for l in lines.iter_mut().filter(|l| l.starts_with("ENCODER")) {
        *l = with_timestamp(l, (timestamp(l) * 10.0).round() / 10.0);
    }
    let o = run(&read(&lines), &Options::default()).expect("rounded timestamps calibrate");
    let f = finding(&o, FindingKind::TimestampCollision);
    assert!(f.count > 1000 && f.message.contains("0.100 s"), "{f:?}");
    // The encoder timing is blurred to 0.1 s: twice the bounds.
    assert_within("rounded", &o, &truth, 2.0, 4.0);
}

#[test]
fn wrapping_counters_without_the_param_are_unwrapped() {
    let (lines, truth) = sim_lines(60.0, 43, |c| c.encoder.modulus = Some(65536));
    let lines: Vec<String> = lines
        .into_iter()
        .filter(|l| !l.starts_with("PARAM robot_encoder_modulus"))
        .collect();
    let o = run(&read(&lines), &Options::default()).expect("calibrates");
    let f = finding(&o, FindingKind::EncoderWrap);
    assert!(
        f.count > 0 && f.message.contains("--encoder-modulus 65536"),
        "{f:?}"
    );
    assert_within("wraps", &o, &truth, 1.0, 4.0);
}

#[test]
fn a_laser_clock_jumping_back_keeps_the_longest_stretch() {
    let (mut lines, truth) = sim_lines(90.0, 44, |_| {});
    let scans: Vec<usize> = (0..lines.len())
        .filter(|&i| lines[i].starts_with("RAWLASER1"))
        .collect();
    let jump_at = scans[scans.len() * 2 / 3];
    for &i in scans.iter().filter(|&&i| i >= jump_at) {
        lines[i] = with_timestamp(&lines[i], timestamp(&lines[i]) - 10.0);
    }
    let o = run(&read(&lines), &Options::default()).expect("calibrates");
    let f = finding(&o, FindingKind::ClockJump);
    assert_eq!(f.first_line, Some(jump_at as u64 + 1));
    assert!(f.message.contains("back 10.0"), "{}", f.message);
    assert_within("clock jump", &o, &truth, 1.5, 4.0);
}

#[test]
fn a_frozen_scan_is_left_out() {
    let (mut lines, truth) = sim_lines(60.0, 45, |_| {});
    let scans: Vec<usize> = (0..lines.len())
        .filter(|&i| lines[i].starts_with("RAWLASER1"))
        .collect();
    // 5 s of one repeated scan (ranges and all; only the timestamps advance).
    let frozen = lines[scans[200]].clone();
    for &i in &scans[201..251] {
        lines[i] = with_timestamp(&frozen, timestamp(&lines[i]));
    }
    let o = run(&read(&lines), &Options::default()).expect("calibrates");
    let f = finding(&o, FindingKind::FrozenScan);
    assert_eq!((f.count, f.first_line), (50, Some(scans[201] as u64 + 1)));
    assert_within("frozen", &o, &truth, 1.0, 4.0);
}

#[test]
fn a_log_of_one_frozen_scan_is_refused_naming_it() {
    let (mut lines, _) = sim_lines(30.0, 46, |_| {});
    let scans: Vec<usize> = (0..lines.len())
        .filter(|&i| lines[i].starts_with("RAWLASER1"))
        .collect();
    let frozen = lines[scans[0]].clone();
    for &i in &scans[1..] {
        lines[i] = with_timestamp(&frozen, timestamp(&lines[i]));
    }
    let e = run(&read(&lines), &Options::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("frozen scan") && !e.contains("drive longer"),
        "{e}"
    );
}

#[test]
fn duplicated_scan_lines_are_dropped() {
    let (lines, _) = sim_lines(60.0, 47, |_| {});
    let clean = run(&read(&lines), &Options::default()).expect("calibrates");
    let doubled: Vec<String> = lines
        .iter()
        .flat_map(|l| {
            let n = if l.starts_with("RAWLASER1") { 2 } else { 1 };
            std::iter::repeat_n(l.clone(), n)
        })
        .collect();
    let o = run(&read(&doubled), &Options::default()).expect("calibrates");
    let f = finding(&o, FindingKind::Duplicate);
    assert_eq!(f.count as usize, read(&lines).scans.len());
    // The same samples, the same numbers and σ's as the clean log.
    assert_eq!(o.synced.samples.len(), clean.synced.samples.len());
    assert_eq!(o.calibration.params, clean.calibration.params);
    assert_eq!(o.calibration.covariance, clean.calibration.covariance);
}

#[test]
fn encoder_spikes_are_dropped() {
    let (mut lines, truth) = sim_lines(60.0, 48, |_| {});
    let enc: Vec<usize> = (0..lines.len())
        .filter(|&i| lines[i].starts_with("ENCODER"))
        .collect();
    let edit = |line: &str, left: &str| {
        let mut t: Vec<String> = line.split(' ').map(String::from).collect();
        t[1] = left.to_string();
        t.join(" ")
    };
    let l0: i64 = lines[enc[700]].split(' ').nth(1).unwrap().parse().unwrap();
    lines[enc[700]] = edit(&lines[enc[700]], &(l0 + 1_000_000_000_000).to_string());
    lines[enc[1500]] = edit(&lines[enc[1500]], &i64::MAX.to_string());
    let o = run(&read(&lines), &Options::default()).expect("calibrates");
    let f = finding(&o, FindingKind::EncoderSpike);
    assert_eq!((f.count, f.first_line), (2, Some(enc[700] as u64 + 1)));
    assert_within("spikes", &o, &truth, 1.0, 4.0);
}

#[test]
fn a_large_clock_offset_is_flagged_and_estimated_first() {
    let (lines, truth) = sim_lines(60.0, 49, |c| c.faults.clock_offset = 0.3);
    let log = read(&lines);
    // Given as known (`--time-offset`): the quick check names the offset and the flags.
    let known = Options {
        accept_weak: true,
        estimate_found_time_offset: false,
        ..Options::default()
    };
    let text = match run(&log, &known) {
        Ok(o) => finding(&o, FindingKind::ClockOffset).message.clone(),
        Err(e) => e.to_string(),
    };
    println!("{text}");
    assert!(
        text.contains("+0.30 s") && text.contains("--estimate-time-offset"),
        "{text}"
    );
    // Not given: the offset the quick check finds is estimated, and said so.
    let o = run(&log, &Options::default()).expect("calibrates");
    let text = &finding(&o, FindingKind::ClockOffset).message;
    assert!(
        text.contains("+0.30 s") && text.contains("was estimated"),
        "{text}"
    );
    let est = o.offset.as_ref().expect("estimated").offset;
    assert!((est - 0.3).abs() < 0.005, "estimated {est}");
    assert_within("0.3 s offset found", &o, &truth, 1.0, 4.0);
    // With it: estimated before observability is judged.
    let opts = Options {
        estimate_time_offset: Some(0.5),
        ..Options::default()
    };
    let o = run(&log, &opts).expect("calibrates");
    let est = o.offset.as_ref().unwrap().offset;
    assert!((est - 0.3).abs() < 0.005, "estimated {est}");
    assert!(
        o.health.iter().all(|f| f.kind != FindingKind::ClockOffset),
        "{:#?}",
        o.health
    );
    assert_within("0.3 s offset", &o, &truth, 1.0, 4.0);
}

#[test]
fn an_offset_beyond_the_search_range_is_an_edge_warning() {
    let (lines, _) = sim_lines(60.0, 50, |c| c.faults.clock_offset = 2.0);
    let opts = Options {
        estimate_time_offset: Some(0.5),
        accept_weak: true,
        ..Options::default()
    };
    let text = match run(&read(&lines), &opts) {
        Ok(o) => finding(&o, FindingKind::ClockOffset).message.clone(),
        Err(e) => e.to_string(),
    };
    assert!(
        text.contains("edge of the search range") && text.contains("--time-offset-range 3.1"),
        "{text}"
    );
}
