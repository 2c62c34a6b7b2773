//! The report page, parsed with an HTML5 parser: every section and figure is there,
//! nothing needs a script or the network, and every number on the page agrees with
//! results.json (the page says where each comes from: `data-json`, `data-scale`,
//! `data-digits` / `data-sig`). Runs the pipeline on the bundled demo log.

use odocal_log::{read_log, ReadOptions};
use odocal_pipeline::{calibrate_log, NoProgress, Options, Outcome};
use odocal_report::figures::figures;
use odocal_report::html::{page, page_with_results};
use odocal_report::{build_report, Finding, FindingKind, Provenance, Report};
use scraper::{Html, Selector};
use serde_json::{json, Value};
use std::path::PathBuf;

fn demo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/demo.log")
}

/// The demo log calibrated with nominal values and the clock offset estimated.
fn calibrated() -> (Options, Outcome, Report) {
    let path = demo();
    let log = read_log(&path, &ReadOptions::default()).expect("the demo log reads");
    let opts = Options {
        initial_params: Some(odocal_solver::Params::from_vector([
            0.021, 0.021, 0.09, 0.0, 0.0, 0.0,
        ])),
        estimate_time_offset: Some(0.5),
        ..Options::default()
    };
    let outcome = calibrate_log(&log, &opts, &NoProgress).expect("the demo log calibrates");
    let report = build_report(&path, &log, &opts, &outcome);
    (opts, outcome, report)
}

fn sel(s: &str) -> Selector {
    Selector::parse(s).expect("a valid selector")
}

/// The sections every page has.
const SECTIONS: [&str; 8] = [
    "parameters",
    "ros",
    "j-matrix",
    "health",
    "consistency",
    "figures",
    "data",
    "run",
];

fn assert_sections(doc: &Html) {
    for id in SECTIONS {
        assert!(
            doc.select(&sel(&format!("section#{id}"))).next().is_some(),
            "section {id}"
        );
    }
}

/// Checks every number carrying `data-json` against `results`; returns the pointers.
fn numbers_agree(doc: &Html, results: &Value) -> Vec<String> {
    let mut pointers = Vec::new();
    for el in doc.select(&sel("[data-json]")) {
        let a = el.value();
        let pointer = a.attr("data-json").unwrap().to_string();
        let text: String = el.text().collect();
        let expected = results
            .pointer(&pointer)
            .and_then(Value::as_f64)
            .unwrap_or_else(|| panic!("{pointer} is not a number in results.json"));
        let shown: f64 = text
            .trim()
            .parse()
            .unwrap_or_else(|_| panic!("{pointer}: '{text}' is not a number"));
        if let Some(digits) = a.attr("data-digits") {
            let scale: f64 = a.attr("data-scale").unwrap().parse().unwrap();
            let digits: i32 = digits.parse().unwrap();
            let tol = 0.5 * 10f64.powi(-digits) * (1.0 + 1e-9) + 1e-12 * (expected * scale).abs();
            assert!(
                (shown - expected * scale).abs() <= tol,
                "{pointer}: page shows {text}, results.json has {expected} (×{scale})"
            );
        } else {
            let sig: i32 = a
                .attr("data-sig")
                .expect("data-digits or data-sig")
                .parse()
                .unwrap();
            let scale: f64 = a.attr("data-scale").map_or(1.0, |s| s.parse().unwrap());
            let expected = expected * scale;
            let tol = 0.5 * 10f64.powi(1 - sig) * expected.abs() * (1.0 + 1e-9);
            assert!(
                (shown - expected).abs() <= tol,
                "{pointer}: page shows {text}, results.json has {expected} (×{scale})"
            );
        }
        pointers.push(pointer);
    }
    pointers
}

#[test]
fn page_has_every_section_and_figure_and_agrees_with_results_json() {
    let (opts, outcome, mut report) = calibrated();
    let t0 = outcome.synced.samples[0].pair.t0;
    report.health.push(
        Finding::warning(
            FindingKind::Slip,
            "rotation of scan matching and odometry disagree for 2.5 s",
        )
        .at(1234, t0 + 10.0),
    );
    report.checks.push(
        Finding::note(FindingKind::TwoHalves, "the two halves agree within 2σ")
            .count(6)
            .spans(vec![[t0 + 10.0, t0 + 12.5]]),
    );
    report.provenance = Some(Provenance {
        command_line: "odocal calibrate fixtures/demo.log --report r.html".into(),
        version: "0.1.0".into(),
        input_sha256: "ab".repeat(32),
        input_bytes: 42,
        wall_time_s: 0.25,
    });
    // Fields of later features: held and prior parameters, an unknown result.
    let mut results = serde_json::to_value(&report).unwrap();
    results["settings"]["constraints"] = json!(["free", "free", {"held": 0.089}, "free", {"prior": {"mean": 0.0, "sigma": 0.002}}, "free"]);
    results["later_feature"] = json!({"max_difference_sigma": 1.25, "halves": 2});

    let figs = figures(&opts, &outcome, &report).expect("the figures draw");
    let html = page_with_results(&report, &results, &figs);
    let doc = Html::parse_document(&html);

    assert_sections(&doc);
    assert!(
        doc.select(&sel("section#further")).next().is_some(),
        "section further"
    );
    for name in [
        "trajectory",
        "residuals_time",
        "residual_histograms",
        "motion_coverage",
        "time_offset",
        "icp_quality",
    ] {
        let fig = doc
            .select(&sel(&format!("figure#fig-{name}")))
            .next()
            .unwrap_or_else(|| panic!("figure {name}"));
        assert!(
            fig.select(&sel("svg")).next().is_some(),
            "{name} has an inline SVG"
        );
        assert!(
            fig.select(&sel("figcaption")).next().is_some(),
            "{name} has a caption"
        );
    }
    // Self-contained: no script, nothing loaded from elsewhere.
    assert!(doc
        .select(&sel("script, link, img, iframe"))
        .next()
        .is_none());
    assert!(
        !html.contains("http://")
            || html.matches("http://").count()
                == html.matches("xmlns=\"http://www.w3.org/2000/svg\"").count()
    );
    assert!(!html.contains("https://"));

    let pointers = numbers_agree(&doc, &results);
    for p in [
        "/r_l",
        "/r_r",
        "/b",
        "/l_x",
        "/l_y",
        "/l_theta",
        "/sigma/0",
        "/sigma/5",
        "/j/1/1",
        "/nominal/2",
        "/correction_factors/0",
        "/settings/constraints/2/held",
        "/settings/constraints/4/prior/sigma",
        "/later_feature/max_difference_sigma",
        "/health/0/count",
        "/checks/0/count",
        "/provenance/wall_time_s",
        "/samples_used",
        "/time_offset_s",
        "/covariance/5/5",
    ] {
        assert!(pointers.iter().any(|q| q == p), "{p} is not on the page");
    }
    let text: String = doc.root_element().text().collect();
    assert!(text.contains("held at") && text.contains("prior") && text.contains("held (--fix)"));
    assert!(text.contains("rotation of scan matching and odometry disagree"));
    assert!(text.contains(&"ab".repeat(32)));
    // A finding's span is shaded in the residuals over time, and named in the legend.
    assert!(text.contains("flagged span (slip)"));
}

#[test]
fn page_without_optional_results_still_has_every_section() {
    let path = demo();
    let log = read_log(&path, &ReadOptions::default()).unwrap();
    let opts = Options::default();
    let outcome = calibrate_log(&log, &opts, &NoProgress).unwrap();
    let report = build_report(&path, &log, &opts, &outcome);
    let html = odocal_report::html_report(&opts, &outcome, &report).unwrap();
    let doc = Html::parse_document(&html);
    assert_sections(&doc);
    assert!(
        doc.select(&sel("section#further")).next().is_none(),
        "nothing unknown to show"
    );
    assert!(
        doc.select(&sel("figure#fig-time_offset")).next().is_none(),
        "no offset estimated"
    );
    let text: String = doc.root_element().text().collect();
    // Every run compares the two halves of its log: that check is always listed.
    assert!(text.contains("No data-health findings") && text.contains("two halves of the log"));
    numbers_agree(&doc, &serde_json::to_value(&report).unwrap());
}

#[test]
fn page_shows_the_results_in_ros_terms_ready_to_paste() {
    let (opts, outcome, report) = calibrated();
    let figs = figures(&opts, &outcome, &report).expect("the figures draw");
    let doc = Html::parse_document(&page(&report, &figs));
    let blocks: Vec<String> = doc
        .select(&sel("section#ros pre"))
        .map(|e| e.text().collect())
        .collect();
    let yaml = odocal_report::diff_drive_controller_yaml(&report.params).unwrap();
    let urdf = odocal_report::laser_joint_urdf(&report.params).unwrap();
    assert_eq!(blocks, vec![yaml, urdf]);
}

#[test]
fn parameters_table_has_the_clock_offset_and_the_page_says_odometry_only_and_the_tf_pose() {
    let (opts, outcome, mut report) = calibrated();
    report.time_offset_s = None;
    let figs = figures(&opts, &outcome, &report).expect("the figures draw");
    let plain = Html::parse_document(&page(&report, &figs));
    for id in ["clock-offset", "odometry-only", "nominal-laser"] {
        assert!(
            plain.select(&sel(&format!("#{id}"))).next().is_none(),
            "{id}"
        );
    }
    report.time_offset_s = Some(0.1234);
    report.odometry_only = true;
    report.nominal_laser = Some(odocal_report::NominalLaserPose {
        source: "/tf_static".into(),
        base_frame: "base_link".into(),
        laser_frame: "base_scan".into(),
        l_x: 0.01,
        l_y: 0.0,
        l_theta: 0.0,
    });
    let results = serde_json::to_value(&report).unwrap();
    let doc = Html::parse_document(&page_with_results(&report, &results, &figs));
    let row: String = doc
        .select(&sel("table.params tr#clock-offset"))
        .next()
        .expect("a clock-offset row")
        .text()
        .collect();
    assert!(
        row.contains("123.40") && row.contains("ms") && row.contains("—"),
        "{row}"
    );
    let odo: String = doc
        .select(&sel("#odometry-only"))
        .next()
        .unwrap()
        .text()
        .collect();
    assert!(odo.contains("--nominal"), "{odo}");
    let tf: String = doc
        .select(&sel("#nominal-laser"))
        .next()
        .unwrap()
        .text()
        .collect();
    assert!(tf.contains("base_scan") && tf.contains("10.0 mm"), "{tf}");
    assert!(numbers_agree(&doc, &results).contains(&"/time_offset_s".to_string()));
}

#[test]
fn coverage_advice_does_not_contradict_the_two_halves_note() {
    let (opts, outcome, mut report) = calibrated();
    assert!(
        report.observability.motion.missing().is_empty(),
        "the demo log was expected to have every kind of motion"
    );
    report.consistency = odocal_pipeline::consistency::Consistency::NotAvailable {
        reason: "the second half has no straight runs".into(),
    };
    let figs = figures(&opts, &outcome, &report).expect("the figures draw");
    let doc = Html::parse_document(&page(&report, &figs));
    let advice: String = doc
        .select(&sel("p.advice"))
        .next()
        .unwrap()
        .text()
        .collect();
    assert!(
        !advice.contains("every parameter has the motion it needs"),
        "{advice}"
    );
    assert!(advice.contains("halves"), "{advice}");
}

#[test]
fn data_and_solution_is_labelled_with_meanings_and_the_summary_units() {
    // Before: a key-value dump ("a condition", "chi2 limit", "wheel signs —", the
    // covariance in m² and rad² with no meaning given).
    let (opts, outcome, mut report) = calibrated();
    let figs = figures(&opts, &outcome, &report).expect("the figures draw");
    let results = serde_json::to_value(&report).unwrap();
    let doc = Html::parse_document(&page_with_results(&report, &results, &figs));
    let data = doc
        .select(&sel("section#data"))
        .next()
        .expect("the section");
    let text: String = data.text().collect();
    for label in [
        "Covariance of the estimate",
        "Closed-form solution",
        "Scan-matching noise σ",
        "Observability",
        "condition number, step 1 (r_L, r_R, b)",
        "wheel directions",
        "The two halves of the log",
        "Clock offset (laser − encoders)",
        "mm²",
        "3σ (99.73 %) level",
    ] {
        assert!(text.contains(label), "{label:?} missing: {text}");
    }
    for raw in [
        "a condition",
        "chi2 limit",
        "wheel signs",
        "step1",
        "sm sigma",
        "(rad)",
    ] {
        assert!(!text.contains(raw), "{raw:?} in: {text}");
    }
    // Every row says what it means.
    let rows: Vec<_> = data
        .select(&sel("table.data > tbody > tr, table.data > tr"))
        .collect();
    assert!(rows.len() >= 15, "{} rows", rows.len());
    for row in rows {
        let meaning = row.select(&sel("p.meaning")).next();
        assert!(meaning.is_some(), "{}", row.html());
    }
    let headings: Vec<String> = data
        .select(&sel("table.matrix th"))
        .map(|e| e.text().collect())
        .collect();
    assert!(headings.iter().any(|h| h == "ℓθ (°)"), "{headings:?}");
    assert!(
        headings.iter().filter(|h| h.as_str() == "ℓθ").count() >= 2,
        "{headings:?}"
    );
    numbers_agree(&doc, &results);
    // A two-halves check that could not run says so in a sentence.
    report.consistency = odocal_pipeline::consistency::Consistency::NotAvailable {
        reason: "the second half has no straight runs".into(),
    };
    let doc = Html::parse_document(&page(&report, &figs));
    let text: String = doc
        .select(&sel("section#data"))
        .next()
        .unwrap()
        .text()
        .collect();
    assert!(
        text.contains("Not compared: the second half has no straight runs."),
        "{text}"
    );
}
