//! A refusal names its true cause with the evidence, and the way out: a log without
//! spins in place is refused because the trajectory lacks them (not because of data
//! faults found on the side), with the parameters to hold and the exact command, and
//! that command gives numbers with the held parameters stated.

mod common;

use common::{cleanup, odocal, simulated_log, stderr};
use odocal_sim::TrajectoryKind;

/// The command the refusal prints after "run…:", as arguments.
fn printed_command(err: &str) -> Vec<String> {
    let line = err
        .lines()
        .skip_while(|l| !l.starts_with("to calibrate the other parameters, run"))
        .nth(1)
        .unwrap_or_else(|| panic!("no command in: {err}"));
    let words: Vec<String> = line.split_whitespace().map(str::to_string).collect();
    assert_eq!(words[0], "odocal", "{line}");
    words[1..].to_vec()
}

#[test]
fn no_spins_refusal_names_the_trajectory_and_the_command_to_run() {
    // A forward-only drive (straights and arcs) with noisy ranges: ℓx and ℓy weak.
    let (path, truth) = simulated_log("refusal-no-spins", "khepera", 30.0, 3, |c| {
        c.trajectory = TrajectoryKind::NoSpins;
        c.laser.range_sigma = 0.02;
    });
    let log = path.to_str().unwrap();
    let o = odocal(&["calibrate", log]);
    let err = stderr(&o);
    assert!(!o.status.success(), "{err}");
    assert!(
        err.contains("because the trajectory has no spins in place"),
        "{err}"
    );
    assert!(!err.contains("as a result"), "{err}");
    let mut args = printed_command(&err);
    assert!(args.iter().any(|a| a == "l_y=0"), "{args:?}");
    // ℓx must be measured: the test measures it exactly (the truth).
    for a in args.iter_mut() {
        if a.ends_with("=MEASURED") {
            let name = a.trim_end_matches("=MEASURED");
            let i = ["r_L", "r_R", "b", "l_x", "l_y", "l_theta"]
                .iter()
                .position(|n| *n == name)
                .unwrap();
            *a = format!("{name}={}", truth[i]);
        }
    }
    args.push("--json".into());
    let argv: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = odocal(&argv);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("JSON");
    let params = &v["observability"]["parameters"];
    let mut held = 0;
    for (i, t) in truth.iter().enumerate() {
        let p = &params[i];
        if p["constraint"]["held"].is_number() {
            held += 1;
            continue;
        }
        assert_eq!(p["verdict"], "well_determined", "{p}");
        let (value, sigma) = (p["value"].as_f64().unwrap(), p["sigma"].as_f64().unwrap());
        assert!((value - t).abs() < 4.0 * sigma, "{p}: truth {t}");
    }
    assert!((1..=2).contains(&held), "{params}");
    cleanup(&path);
}

#[test]
fn real_forward_only_log_is_refused_for_its_trajectory_not_its_faults() {
    let log = concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/real/mines/exp2.log");
    if !std::path::Path::new(log).exists() {
        eprintln!("skipped: {log} is absent");
        return;
    }
    // The nominal laser pose (tinySLAM): 145 mm ahead, on the centre line.
    let o = odocal(&["calibrate", log, "--nominal", "0.077,0.077,0.33,0.145,0,0"]);
    let err = stderr(&o);
    if o.status.success() {
        // Since the matcher keeps more of this log's pairs (issue 20), its arcs
        // determine every parameter: then nothing may be refused nor held.
        let out = String::from_utf8_lossy(&o.stdout);
        let verdicts = out.lines().filter(|l| l.ends_with("  well determined"));
        assert_eq!(verdicts.count(), 6, "{out}");
        assert!(!out.contains("held (--fix)"), "{out}");
        return;
    }
    assert!(!err.contains("the log has data faults"), "{err}");
    assert!(
        err.contains("because the trajectory has no spins in place")
            && err.contains("also found in the log (not the cause)"),
        "{err}"
    );
    let args = printed_command(&err);
    assert!(args.iter().any(|a| a == "l_x=0.145"), "{args:?}");
    let argv: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = odocal(&argv);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("held (--fix)"), "{out}");
}
