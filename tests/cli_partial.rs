//! `--fix`, `--prior` and `--accept-weak` end to end: held parameters keep their
//! values and have zero covariance rows, the JSON and the summary say which
//! parameters were held or given priors, bad arguments fail with one sentence, and
//! `--accept-weak` also works together with `--estimate-time-offset`.

mod common;

use common::{cleanup, odocal, simulated_log, stderr};

#[test]
fn fix_and_prior_on_calibrate() {
    let (path, truth) = simulated_log("cli-fix", "khepera", 60.0, 41, |_| {});
    let log = path.to_str().unwrap();
    let fix_b = format!("b={}", truth[2]);
    let prior = format!("l_theta={}+-0.001", truth[5]);
    let o = odocal(&[
        "calibrate",
        log,
        "--json",
        "--fix",
        &fix_b,
        "--prior",
        &prior,
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("JSON");
    assert_eq!(v["b"].as_f64().unwrap(), truth[2]);
    for j in 0..6 {
        assert_eq!(v["covariance"][2][j].as_f64().unwrap(), 0.0);
        assert_eq!(v["covariance"][j][2].as_f64().unwrap(), 0.0);
    }
    let c = &v["settings"]["constraints"];
    assert_eq!(c[2]["held"].as_f64().unwrap(), truth[2], "{c}");
    assert_eq!(c[5]["prior"]["sigma"].as_f64().unwrap(), 0.001, "{c}");
    assert_eq!(c[0], "free");
    let params = &v["observability"]["parameters"];
    assert_eq!(params[2]["constraint"]["held"].as_f64().unwrap(), truth[2]);
    // The posterior σ of ℓθ is below the prior's.
    assert!(v["sigma"][5].as_f64().unwrap() < 0.001);

    let o = odocal(&["calibrate", log, "--fix", &fix_b, "--prior", &prior]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("held (--fix)"), "{text}");
    assert!(text.contains("(prior "), "{text}");

    for bad in [
        vec!["--fix", "wheelbase=0.1"],
        vec!["--fix", "b"],
        vec!["--fix", "b=-1"],
        vec!["--prior", "l_x=0.01"],
        vec!["--fix", "b=0.09", "--prior", "b=0.09±0.001"],
    ] {
        let mut args = vec!["calibrate", log];
        args.extend(bad.iter());
        let o = odocal(&args);
        let err = stderr(&o);
        assert!(!o.status.success(), "{bad:?} accepted");
        assert!(err.starts_with("error: --"), "{bad:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
    cleanup(&path);
}

/// Short logs: some are refused as weakly determined; each of those gives numbers
/// with `--accept-weak`, also together with `--estimate-time-offset`.
#[test]
fn accept_weak_with_every_option() {
    let mut refused = 0;
    for (seed, duration) in [(4, 9.0), (6, 11.0), (2, 9.0), (3, 9.0)] {
        let (path, _) = simulated_log("cli-weak", "khepera", duration, seed, |_| {});
        let log = path.to_str().unwrap();
        let plain = odocal(&["calibrate", log]);
        let err = stderr(&plain);
        if !plain.status.success() && err.contains("do not determine") {
            refused += 1;
            assert!(err.contains("--fix NAME=VALUE"), "{err}");
            for extra in [
                vec![],
                vec!["--estimate-time-offset"],
                vec!["--estimate-time-offset", "--second-pass"],
                vec!["--identity-guess", "--trim", "icra"],
            ] {
                let mut args = vec!["calibrate", log, "--accept-weak"];
                args.extend(extra.iter());
                let o = odocal(&args);
                assert!(o.status.success(), "{args:?}: {}", stderr(&o));
            }
        }
        cleanup(&path);
    }
    assert!(
        refused > 0,
        "no short log was refused: the test checks nothing"
    );
}
