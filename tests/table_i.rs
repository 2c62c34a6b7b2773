//! Published calibration results reproduced in simulation (issues 6, 11).
//!
//! Rows come from `fixtures/table-i.json` (the ICRA 2008 Table I, 19 rows) and from
//! the T-RO 2013 package's published results in `../shared/reference/` (skipped with
//! a notice when absent). For each row a Khepera III (2764.8 ticks/rev) with a
//! URG-04LX is simulated with the row's parameters as the truth, the whole pipeline
//! runs on the log text, and the recovered parameters are compared:
//!
//! - default run: every row at up to [`QUICK_SAMPLES`] samples, every quantity within
//!   [`FAMILY_SIGMAS`] of the reported covariance (fixed seeds): 3σ per quantity would
//!   be a family of 176 checks that honest σ fail together about 40 % of the time;
//!   the 3σ rule itself is measured over many seeds by the ignored test;
//! - ignored (CI: `cargo test --release -p odocal --test table_i -- --include-ignored`):
//!   every row at its published number of samples with the absolute bounds too (and
//!   the same family-wise σ bound), and the 3σ rule measured over many seeds.

use odocal_pipeline::sync::TARGET_INTERVAL_S;
use odocal_regression::{
    format_j_consistency, format_reproduction, format_summary, j_consistency, read_table,
    read_table_file, read_tro_reference, reproduce_from_text, reproduction_options, row_seed,
    simulate_log_text, umbmark_j_consistency, workspace_reference_dir, workspace_table_path,
    JReading, PublishedRow, Reproduction, Tolerances,
};
use odocal_sim::SECONDS_PER_SAMPLE;
use std::process::Command;

/// Largest number of samples per row in the default (quick) run.
const QUICK_SAMPLES: usize = 600;

/// Base seed of the fixed-seed runs.
const SEED: u64 = 1;

/// Per-quantity bound of the quick run, in reported σ. The quick run checks 22 rows ×
/// 8 quantities at once; with Gaussian errors and honest σ, P(|z| > 4) per check is
/// 6.3e-5, so the whole family passes with probability ≈ 99 % (Bonferroni). At 3σ it
/// would pass with probability 0.9973^176 ≈ 62 % only: with the shared-scan σ model the
/// seed-1 run has lmov ℓx at 3.48σ, while over 8 other seeds lmov's worst is 2.17σ and
/// all 1,056 estimates give RMS error/σ 0.96 with 0.5 % beyond 3σ (the second version
/// of that model, long-run unshared noise: 1.07, 0.7 %; seed 1's worst full-size
/// quantity k28 ℓθ at 3.36σ).
const FAMILY_SIGMAS: f64 = 4.0;

/// The published rows available here: the Table I file's and the T-RO reference's.
fn published_rows() -> Vec<PublishedRow> {
    let mut rows = Vec::new();
    let table = workspace_table_path();
    if table.exists() {
        rows.extend(read_table_file(&table).expect("the Table I file reads"));
    } else {
        println!(
            "notice: no {} (the ICRA 2008 Table I awaits transcription); its rows are skipped",
            table.display()
        );
    }
    let reference = workspace_reference_dir();
    if reference.join("lstraight_results.json").exists() {
        rows.extend(read_tro_reference(&reference).expect("the T-RO reference reads"));
    } else {
        println!(
            "notice: no T-RO 2013 reference data at {}; those rows are skipped",
            reference.display()
        );
    }
    rows
}

/// Simulates `row` for `samples` samples and runs the pipeline on 2 threads.
fn reproduce(row: &PublishedRow, samples: usize, seed: u64) -> Reproduction {
    let text = simulate_log_text(&row.name, &row.truth(), samples, row_seed(seed, &row.name))
        .expect("the simulation runs");
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .expect("a thread pool");
    pool.install(|| reproduce_from_text(row, samples, &text, &reproduction_options()))
        .unwrap_or_else(|e| panic!("row {}: the pipeline fails: {e}", row.name))
}

/// Runs every row, prints the side-by-side tables, asserts the rules, and returns
/// the reproductions.
fn check_rows(samples_of: impl Fn(&PublishedRow) -> usize, tol: &Tolerances) -> Vec<Reproduction> {
    let rows = published_rows();
    if rows.is_empty() {
        println!("notice: no published rows available; nothing to reproduce");
        return Vec::new();
    }
    let mut reps = Vec::new();
    let mut failures = Vec::new();
    for row in &rows {
        let rep = reproduce(row, samples_of(row), SEED);
        println!("{}", format_reproduction(&rep, tol));
        failures.extend(rep.failures(tol));
        reps.push(rep);
    }
    println!("{}", format_summary(&reps, tol));
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    reps
}

#[test]
fn quick_rows_are_within_the_family_wise_sigma_bound() {
    // σ only: the absolute bounds are for runs of 1,000 samples or more.
    let tol = Tolerances {
        min_samples_for_bounds: usize::MAX,
        sigma_multiple: FAMILY_SIGMAS,
        ..Tolerances::default()
    };
    check_rows(|row| (row.samples as usize).min(QUICK_SAMPLES), &tol);
}

#[test]
fn simulated_samples_match_the_pipeline_stride() {
    // The simulator sizes a row's run at SECONDS_PER_SAMPLE per sample; the pipeline
    // pairs scans TARGET_INTERVAL_S apart. They must be the same interval.
    assert_eq!(SECONDS_PER_SAMPLE, TARGET_INTERVAL_S);
}

#[test]
#[ignore = "full-size rows (75,626 samples) take 1-3 minutes; CI runs them with --include-ignored"]
fn full_size_rows_meet_every_bound() {
    // The absolute bounds, and σ with the same family-wise multiple as the quick run
    // (176 quantities at once); docs/table-i.md gives each row's 3σ verdict.
    let tol = Tolerances {
        sigma_multiple: FAMILY_SIGMAS,
        ..Tolerances::default()
    };
    let reps = check_rows(|row| row.samples as usize, &tol);
    // Issue 20's target for the table itself: at most one row beyond its per-quantity
    // 3σ rule (seed 1). Before the matcher-bias term five rows were (six checks: the
    // matcher's rotation bias, common to every sample, as large as σ at full size);
    // with it one, k28 ℓθ at 3.36σ. With honest σ, two or more rows of 22 fail by
    // chance with probability ≈ 8 %: a change that trips this alone deserves a look
    // over seeds (`three_sigma_rule_holds_over_seeds`), not a new seed.
    let three_sigma = Tolerances::default();
    let beyond: Vec<String> = reps
        .iter()
        .filter(|r| !r.failures(&three_sigma).is_empty())
        .map(|r| r.failures(&three_sigma).join("; "))
        .collect();
    assert!(
        beyond.len() <= 1,
        "{} rows beyond 3σ: {}",
        beyond.len(),
        beyond.join("\n")
    );
}

#[test]
#[ignore = "measures the 3σ rule over 8 seeds (100,000 samples, 1-3 minutes); CI runs it with --include-ignored"]
fn three_sigma_rule_holds_over_seeds() {
    const SEEDS: u64 = 8;
    let rows = published_rows();
    if rows.is_empty() {
        println!("notice: no published rows available; nothing to measure");
        return;
    }
    let tol = Tolerances {
        min_samples_for_bounds: usize::MAX,
        ..Tolerances::default()
    };
    let (mut checks, mut beyond2, mut beyond3) = (0usize, 0usize, 0usize);
    let mut sum_sq = 0.0;
    for seed in 100..100 + SEEDS {
        for row in &rows {
            let rep = reproduce(row, (row.samples as usize).min(QUICK_SAMPLES), seed);
            // The six parameters (J21, J22 are functions of them).
            for c in rep.checks(&tol).iter().take(6) {
                let z = c.error_in_sigma();
                checks += 1;
                sum_sq += z * z;
                beyond2 += usize::from(z.abs() > 2.0);
                beyond3 += usize::from(z.abs() > 3.0);
            }
            println!(
                "seed {seed} {}: worst |error|/σ {:.2}",
                row.name,
                rep.worst_error_in_sigma(&tol)
            );
        }
    }
    let rms = (sum_sq / checks as f64).sqrt();
    println!(
        "{checks} parameter estimates: {beyond2} beyond 2σ ({:.1} %), {beyond3} beyond 3σ \
         ({:.1} %), RMS error/σ {rms:.2} (a Gaussian: 4.6 %, 0.27 %, 1.00)",
        100.0 * beyond2 as f64 / checks as f64,
        100.0 * beyond3 as f64 / checks as f64
    );
    // Issue 13's band for honest σ (measured 1.07 with the shared-scan σ model, 1.04
    // with the matcher-bias term of issue 20 (5.1 % beyond 2σ, 0.5 % beyond 3σ); 0.54
    // with the independent-samples model before them).
    assert!(
        rms < 1.3,
        "errors are {rms:.2}σ RMS: the covariance is too small"
    );
    assert!(
        rms > 0.7,
        "errors are only {rms:.2}σ RMS: the covariance is too pessimistic"
    );
    assert!(
        (beyond3 as f64) <= 0.02 * checks as f64,
        "{beyond3} of {checks} estimates beyond 3σ"
    );
}

#[test]
fn published_j_columns_reveal_the_heading_swap() {
    let rows = published_rows();
    let checks: Vec<_> = rows.iter().filter_map(|r| j_consistency(r, 1e-3)).collect();
    if checks.is_empty() {
        println!("notice: no published row has J columns (no Table I file); nothing to check");
        return;
    }
    println!("{}", format_j_consistency(&checks, 1e-3));
    assert_eq!(checks.len(), 19, "every ICRA 2008 Table I row prints J");
    // docs/method.md: in every row of the ICRA 2008 Table I the printed J satisfies
    // eq. (2) with r_L and r_R exchanged — J11 = r_R/2, J21 = −r_R/b, J22 = r_L/b — to
    // printing precision (five decimals: about 1e-4).
    for c in &checks {
        assert!(
            c.abs_deviation_swapped <= 1e-4 && c.deviation_swapped <= 1e-3,
            "row {}: printed J deviates {:.2e} ({:.2e} relative) from eq. (2) with the \
             headings exchanged",
            c.name,
            c.abs_deviation_swapped,
            c.deviation_swapped
        );
        // Rows whose two radii are equal to printing precision fit both readings.
        assert!(
            matches!(c.reading, JReading::HeadingsSwapped | JReading::Ambiguous),
            "row {}: reading {:?}",
            c.name,
            c.reading
        );
    }
    let swapped = checks
        .iter()
        .filter(|c| c.reading == JReading::HeadingsSwapped)
        .count();
    assert!(swapped >= 15, "only {swapped} rows tell the swap");
}

#[test]
fn fixture_is_the_reference_transcription() {
    let reference = workspace_reference_dir().join("icra2008-tables.json");
    let Ok(text) = std::fs::read_to_string(&reference) else {
        println!("notice: no {}; nothing to compare", reference.display());
        return;
    };
    let ours = read_table(&workspace_table_path()).expect("the Table I file reads");
    let theirs = odocal_regression::parse_table_document(&text, &reference)
        .expect("the transcription reads");
    assert_eq!(ours.citation, theirs.citation);
    assert_eq!(ours.umbmark, theirs.umbmark);
    assert_eq!(ours.rows.len(), theirs.rows.len());
    for (a, b) in ours.rows.iter().zip(&theirs.rows) {
        assert_eq!(
            (&a.name, a.samples, a.printed, a.j),
            (&b.name, b.samples, b.printed, b.j)
        );
    }
    // Table II (UMBmark): its J columns agree with the headings as printed.
    assert_eq!(ours.umbmark.len(), 5);
    for t in &ours.umbmark {
        let c = umbmark_j_consistency(t, 1e-3).expect("Table II prints J");
        assert!(
            c.abs_deviation_as_printed <= 1e-4,
            "trial {}: {:.2e}",
            t.trial,
            c.abs_deviation_as_printed
        );
    }
}

#[test]
fn command_writes_the_comparison_from_a_table_file() {
    let dir = std::env::temp_dir().join(format!("odocal-table-i-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a temporary directory");
    let table = dir.join("table.json");
    // A made-up row (not a published one) with J columns printed under swapped
    // headings, as the ICRA table does: tests the command, not the paper.
    std::fs::write(
        &table,
        r#"{"rows": [{"name": "made-up", "samples": 2000,
            "si": {"r_l": 0.02095, "r_r": 0.02088, "b": 0.089,
                   "l_x": 0.024, "l_y": 0.041, "l_theta": 0.36},
            "j11": 0.01044, "j12": 0.010475, "j21": -0.2346067, "j22": 0.2353933}]}"#,
    )
    .expect("write the table");
    let doc = dir.join("table-i.md");
    let out = Command::new(env!("CARGO_BIN_EXE_odocal"))
        .args([
            "table-i",
            "--samples-scale",
            "0.2",
            "--threads",
            "2",
            "--table",
        ])
        .arg(&table)
        .arg("--reference")
        .arg(dir.join("no-reference-here"))
        .arg("--write")
        .arg(&doc)
        .output()
        .expect("run odocal");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stdout}\n{stderr}");
    assert!(stderr.contains("No T-RO 2013 reference data"), "{stderr}");
    let text = std::fs::read_to_string(&doc).expect("the document is written");
    assert!(text.contains("### made-up"), "{text}");
    assert!(text.contains("| r_L (mm) | 20.8800 |"), "{text}");
    assert!(text.contains("HeadingsSwapped"), "{text}");
    assert!(text.contains("simulated for 400"), "{text}");
    // An unknown row is a clear error.
    let out = Command::new(env!("CARGO_BIN_EXE_odocal"))
        .args(["table-i", "--rows", "k99", "--table"])
        .arg(&table)
        .output()
        .expect("run odocal");
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("no row named 'k99'"), "{stderr}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn every_row_is_a_simulate_preset() {
    let table = workspace_table_path();
    if !table.exists() {
        println!("notice: no {}; nothing to check", table.display());
        return;
    }
    let rows = read_table_file(&table).expect("the Table I file reads");
    let out = Command::new(env!("CARGO_BIN_EXE_odocal"))
        .args(["simulate", "--list-presets"])
        .output()
        .expect("run odocal");
    let listed = String::from_utf8_lossy(&out.stdout);
    for row in &rows {
        assert!(
            listed.lines().any(|l| l == row.name),
            "preset {} missing from\n{listed}",
            row.name
        );
    }
    // What a reader of the table tries first.
    let dir = std::env::temp_dir().join(format!("odocal-preset-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a temporary directory");
    let prefix = dir.join("k22-k29");
    let out = Command::new(env!("CARGO_BIN_EXE_odocal"))
        .args([
            "simulate",
            "--preset",
            "k22-k29",
            "--seed",
            "3",
            "--duration",
            "20",
            "--out",
        ])
        .arg(&prefix)
        .output()
        .expect("run odocal");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let truth: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.join("k22-k29.truth.json")).expect("the truth file"),
    )
    .expect("JSON");
    // ICRA 2008 Table I, k22-k29: b = 0.08682, J21 = −0.23012, J22 = 0.23029.
    let p = &truth["params"];
    assert!((p["r_l"].as_f64().unwrap_or(0.0) - 0.08682 * 0.23012).abs() < 1e-12);
    assert!((p["r_r"].as_f64().unwrap_or(0.0) - 0.08682 * 0.23029).abs() < 1e-12);
    assert_eq!(p["l_x"].as_f64(), Some(-0.00603));
    let row = rows
        .iter()
        .find(|r| r.name == "k22-k29")
        .expect("row k22-k29");
    assert!((row.truth().r_l - 0.08682 * 0.23012).abs() < 1e-12);
    let _ = std::fs::remove_dir_all(&dir);
}
