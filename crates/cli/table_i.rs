//! `odocal table-i`: reproduce published calibration results in simulation and
//! compare. For every published row (the ICRA 2008 Table I file when present, the
//! T-RO 2013 package's results when the reference data are beside the repository),
//! simulate a Khepera III (2764.8 ticks/rev) with a URG-04LX whose true parameters
//! are the row's, for about the row's number of samples; run the whole pipeline on
//! the log text; print published vs recovered; optionally write `docs/table-i.md`.
//! The work is the `odocal-regression` crate's.

use crate::terminal::{errln, outln};
use anyhow::Context;
use odocal_regression::{
    document, format_j_consistency, format_reproduction, format_summary, j_consistency, join_parts,
    kept_findings, load_sources, reproduce_from_text, reproduce_join_from_texts,
    reproduction_options, row_seed, simulate_log_text, timing_line, umbmark_section,
    workspace_reference_dir, DocumentInputs, JConsistency, Reproduction, RowTiming, Sources,
    Tolerances, J_PRINT_TOLERANCE,
};
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

/// Arguments.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Only these rows (comma-separated names, e.g. `lstraight,l90`).
    #[arg(long, value_delimiter = ',')]
    pub rows: Vec<String>,
    /// Simulate `F` times each row's number of samples (e.g. 0.2 for a quick run).
    #[arg(long, value_name = "F", default_value_t = 1.0)]
    pub samples_scale: f64,
    /// Write the comparison as Markdown to this file (e.g. docs/table-i.md).
    #[arg(long, value_name = "FILE")]
    pub write: Option<PathBuf>,
    /// Table I file (default: fixtures/table-i.json in the current directory or the
    /// source tree, when it exists).
    #[arg(long, value_name = "FILE")]
    pub table: Option<PathBuf>,
    /// Directory of the T-RO 2013 reference data (`*_results.json`, `*.tuple`);
    /// default: `$ODOCAL_REFERENCE_DIR`, else `../shared/reference` beside the source tree.
    #[arg(long, value_name = "DIR")]
    pub reference: Option<PathBuf>,
    /// Base seed of the simulations (each row's seed also depends on its name).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Scan-matching threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
}

/// Runs `odocal table-i`.
pub fn run(args: Args) -> anyhow::Result<()> {
    if !(args.samples_scale.is_finite() && args.samples_scale > 0.0) {
        anyhow::bail!(
            "--samples-scale must be a positive number, got {}",
            args.samples_scale
        );
    }
    let reference = args
        .reference
        .clone()
        .unwrap_or_else(workspace_reference_dir);
    let mut sources = load_sources(args.table.as_deref(), &reference)?;
    for n in &sources.notes {
        errln!("note: {n}");
    }
    let all_rows = sources.rows.clone();
    sources.select(&args.rows)?;
    let Sources { rows, table, notes } = sources;
    let pool = crate::input::thread_pool(args.threads)?;
    let tol = Tolerances::default();
    let opts = reproduction_options();
    let mut reproductions: Vec<Reproduction> = Vec::new();
    let mut timings = Vec::new();
    let started = Instant::now();
    for row in &rows {
        let target = row.scaled_samples(args.samples_scale);
        let seed = row_seed(args.seed, &row.name);
        let t = Instant::now();
        let parts = join_parts(row, &all_rows, target);
        let (rep, timing) = if parts.is_empty() {
            let text = simulate_log_text(&row.name, &row.truth(), target, seed)
                .with_context(|| format!("simulating row '{}'", row.name))?;
            let timing = RowTiming {
                simulate: t.elapsed().as_secs_f64(),
                log_mb: text.len() as f64 / 1e6,
            };
            let rep = pool
                .install(|| reproduce_from_text(row, target, &text, &opts))
                .with_context(|| format!("calibrating the simulated log of row '{}'", row.name))?;
            (rep, timing)
        } else {
            // A true join: one simulated log per component row, calibrated jointly.
            let mut texts = Vec::with_capacity(parts.len());
            for (part, n) in &parts {
                let name = format!("{}.log (simulated, part of {})", part.name, row.name);
                let text =
                    simulate_log_text(&part.name, &row.truth(), *n, row_seed(seed, &part.name))
                        .with_context(|| {
                            format!("simulating part '{}' of row '{}'", part.name, row.name)
                        })?;
                texts.push((name, *n, text));
            }
            let timing = RowTiming {
                simulate: t.elapsed().as_secs_f64(),
                log_mb: texts.iter().map(|(_, _, t)| t.len()).sum::<usize>() as f64 / 1e6,
            };
            let rep = pool
                .install(|| reproduce_join_from_texts(row, &texts, &opts))
                .with_context(|| format!("calibrating the simulated logs of row '{}'", row.name))?;
            let list: Vec<String> = parts
                .iter()
                .map(|(p, n)| format!("{} {n}", p.name))
                .collect();
            outln!(
                "{}: a true join of {} simulated logs (samples asked: {})",
                row.name,
                parts.len(),
                list.join(", ")
            )?;
            (rep, timing)
        };
        outln!("{}", format_reproduction(&rep, &tol))?;
        outln!("{}\n", timing_line(&rep, &timing))?;
        reproductions.push(rep);
        timings.push(timing);
    }
    outln!("{}", format_summary(&reproductions, &tol))?;
    let consistency: Vec<JConsistency> = rows
        .iter()
        .filter_map(|r| j_consistency(r, J_PRINT_TOLERANCE))
        .collect();
    if !consistency.is_empty() {
        outln!("{}", format_j_consistency(&consistency, J_PRINT_TOLERANCE))?;
    }
    let umbmark = table.as_ref().map(|t| umbmark_section(t, &reproductions));
    if let Some(u) = &umbmark {
        outln!("{u}")?;
    }
    let total = started.elapsed().as_secs_f64();
    if let Some(path) = &args.write {
        let findings = std::fs::read_to_string(path)
            .ok()
            .and_then(|old| kept_findings(&old));
        let doc = document(
            &DocumentInputs {
                command: &command_line(&args),
                notes: &notes,
                table: table.as_ref(),
                umbmark: umbmark.as_deref(),
                findings: findings.as_deref(),
            },
            &reproductions,
            &timings,
            &consistency,
            &tol,
            total,
            pool.current_num_threads(),
        );
        std::fs::write(path, doc).with_context(|| format!("writing {}", path.display()))?;
        errln!("wrote {}", path.display());
    }
    let failures: Vec<String> = reproductions
        .iter()
        .flat_map(|r| r.failures(&tol))
        .collect();
    if !failures.is_empty() {
        anyhow::bail!(
            "{} check(s) outside the bounds: {}",
            failures.len(),
            failures.join("; ")
        );
    }
    Ok(())
}

/// The command line that reproduces a run with these arguments.
fn command_line(args: &Args) -> String {
    let mut c = String::from("cargo run --release -- table-i");
    if !args.rows.is_empty() {
        let _ = write!(c, " --rows {}", args.rows.join(","));
    }
    if args.samples_scale != 1.0 {
        let _ = write!(c, " --samples-scale {}", args.samples_scale);
    }
    if args.seed != 1 {
        let _ = write!(c, " --seed {}", args.seed);
    }
    if let Some(w) = &args.write {
        let _ = write!(c, " --write {}", w.display());
    }
    c
}
