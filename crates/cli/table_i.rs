//! `odocal table-i`: reproduce published calibration results in simulation and
//! compare. For every published row (the ICRA 2008 Table I file when present, the
//! T-RO 2013 package's results when the reference data are beside the repository),
//! simulate a Khepera III (2764.8 ticks/rev) with a URG-04LX whose true parameters
//! are the row's, for about the row's number of samples; run the whole pipeline on
//! the log text; print published vs recovered; optionally write `docs/table-i.md`.

use anyhow::Context;
use odocal_pipeline::sync::TARGET_INTERVAL_S;
use odocal_pipeline::table_i::{
    format_j_consistency, format_reproduction, format_summary, j_consistency, read_table_file,
    read_tro_reference, reproduce_from_text, workspace_reference_dir, workspace_table_path,
    JConsistency, PublishedRow, Reproduction, Tolerances,
};
use odocal_pipeline::Options;
use odocal_sim::{simulate, PresetRegistry};
use odocal_solver::Params;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Ticks per wheel revolution of the Khepera III's encoders.
pub const KHEPERA_TICKS_PER_REV: f64 = 2764.8;

/// Relative tolerance of the J consistency check: printing precision of about four
/// significant digits.
pub const J_PRINT_TOLERANCE: f64 = 1e-3;

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
    /// default: `../shared/reference` beside the source tree.
    #[arg(long, value_name = "DIR")]
    pub reference: Option<PathBuf>,
    /// Base seed of the simulations (each row's seed also depends on its name).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Scan-matching threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
}

/// The simulation seed of a row: `seed` mixed with a hash of the row's name, so a
/// row gets the same log whichever other rows run.
pub fn row_seed(seed: u64, name: &str) -> u64 {
    // FNV-1a.
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in name.bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    h ^ seed
}

/// Simulates a Khepera III with a URG-04LX whose true parameters are `truth`, long
/// enough for about `samples` pipeline samples at the default stride, and returns
/// the log text.
pub fn simulate_log_text(truth: &Params, samples: usize, seed: u64) -> anyhow::Result<Vec<u8>> {
    let mut config = PresetRegistry::builtin().get("khepera")?;
    config.seed = seed;
    config.robot.r_l = truth.r_l;
    config.robot.r_r = truth.r_r;
    config.robot.b = truth.b;
    config.robot.laser = truth.laser;
    config.encoder.ticks_per_revolution = KHEPERA_TICKS_PER_REV;
    let rate = config.laser.rate_hz;
    let stride = (TARGET_INTERVAL_S * rate).round().max(1.0);
    config.duration = (samples as f64 + 0.5) * stride / rate;
    let run = simulate(&config)?;
    let mut text = Vec::new();
    run.write_log(&mut text, &[])?;
    Ok(text)
}

/// The published rows: the Table I file's, then the T-RO reference's. Missing
/// sources are skipped with a notice on stderr.
fn load_rows(args: &Args) -> anyhow::Result<(Vec<PublishedRow>, Vec<String>)> {
    let mut rows = Vec::new();
    let mut notes = Vec::new();
    let table = match &args.table {
        Some(p) => Some(p.clone()),
        None => [
            PathBuf::from("fixtures/table-i.json"),
            workspace_table_path(),
        ]
        .into_iter()
        .find(|p| p.exists()),
    };
    match table {
        Some(path) => rows.extend(read_table_file(&path)?),
        None => notes.push(
            "No ICRA 2008 Table I file (fixtures/table-i.json): the published table could not \
             be retrieved and awaits transcription, so only the T-RO 2013 rows are compared."
                .to_string(),
        ),
    }
    let reference = args
        .reference
        .clone()
        .unwrap_or_else(workspace_reference_dir);
    if reference.join("lstraight_results.json").exists() {
        let tro = read_tro_reference(&reference)?;
        for r in tro {
            if rows.iter().any(|o| o.name == r.name) {
                anyhow::bail!(
                    "row '{}' is both in the Table I file and in the T-RO reference",
                    r.name
                );
            }
            rows.push(r);
        }
    } else {
        notes.push(format!(
            "No T-RO 2013 reference data at {}: those rows are skipped.",
            reference.display()
        ));
    }
    for n in &notes {
        eprintln!("note: {n}");
    }
    if rows.is_empty() {
        anyhow::bail!("no published rows: give --table FILE or --reference DIR");
    }
    if !args.rows.is_empty() {
        let known: Vec<String> = rows.iter().map(|r| r.name.clone()).collect();
        for want in &args.rows {
            if !known.contains(want) {
                anyhow::bail!("no row named '{want}'; the rows are {}", known.join(", "));
            }
        }
        rows.retain(|r| args.rows.contains(&r.name));
    }
    Ok((rows, notes))
}

/// Wall time spent on one row (s).
struct RowTiming {
    simulate: f64,
    log_mb: f64,
}

/// Runs `odocal table-i`.
pub fn run(args: Args) -> anyhow::Result<()> {
    if !(args.samples_scale.is_finite() && args.samples_scale > 0.0) {
        anyhow::bail!(
            "--samples-scale must be a positive number, got {}",
            args.samples_scale
        );
    }
    let (rows, notes) = load_rows(&args)?;
    let pool = crate::input::thread_pool(args.threads)?;
    let tol = Tolerances::default();
    let opts = Options::default();
    let mut reproductions: Vec<Reproduction> = Vec::new();
    let mut timings = Vec::new();
    let started = Instant::now();
    for row in &rows {
        let target = row.scaled_samples(args.samples_scale);
        let seed = row_seed(args.seed, &row.name);
        let t = Instant::now();
        let text = simulate_log_text(&row.truth(), target, seed)
            .with_context(|| format!("simulating row '{}'", row.name))?;
        let timing = RowTiming {
            simulate: t.elapsed().as_secs_f64(),
            log_mb: text.len() as f64 / 1e6,
        };
        let rep = pool
            .install(|| reproduce_from_text(row, target, &text, &opts))
            .with_context(|| format!("calibrating the simulated log of row '{}'", row.name))?;
        println!("{}", format_reproduction(&rep, &tol));
        println!("{}\n", timing_line(&rep, &timing));
        reproductions.push(rep);
        timings.push(timing);
    }
    println!("{}", format_summary(&reproductions, &tol));
    let consistency: Vec<JConsistency> = rows
        .iter()
        .filter_map(|r| j_consistency(r, J_PRINT_TOLERANCE))
        .collect();
    if !consistency.is_empty() {
        println!("{}", format_j_consistency(&consistency, J_PRINT_TOLERANCE));
    }
    let total = started.elapsed().as_secs_f64();
    if let Some(path) = &args.write {
        let doc = document(
            &args,
            &notes,
            &reproductions,
            &timings,
            &consistency,
            &tol,
            total,
            pool.current_num_threads(),
        );
        std::fs::write(path, doc).with_context(|| format!("writing {}", path.display()))?;
        eprintln!("wrote {}", path.display());
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

fn timing_line(rep: &Reproduction, t: &RowTiming) -> String {
    let s = &rep.estimate.timing_s;
    format!(
        "time: simulate {:.2} s ({:.1} MB of log), read {:.2} s, sync {:.3} s, match {:.2} s, \
         solve {:.3} s",
        t.simulate, t.log_mb, s.parse, s.sync, s.r#match, s.solve
    )
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

/// The Markdown document `--write` produces.
#[allow(clippy::too_many_arguments)]
fn document(
    args: &Args,
    notes: &[String],
    reps: &[Reproduction],
    timings: &[RowTiming],
    consistency: &[JConsistency],
    tol: &Tolerances,
    total_s: f64,
    threads: usize,
) -> String {
    let mut d = String::new();
    let _ = writeln!(
        d,
        "# Published calibration results reproduced in simulation\n"
    );
    let _ = writeln!(
        d,
        "Generated by `{}` (this file is its output; do not edit by hand). Every row is a \
         published calibration: a Khepera III (encoders {} ticks/rev) with a Hokuyo URG-04LX \
         is simulated (`odocal-sim`, Khepera arena, mixed trajectory) with the row's \
         parameters as the truth, for about the row's number of samples at the default \
         stride, and the whole pipeline runs on the log text (read → synchronize → match → \
         solve, default options: encoder profile, T-RO trimming, ML refinement). The \
         recovered parameters are compared with the row.\n",
        command_line(args),
        KHEPERA_TICKS_PER_REV
    );
    let _ = writeln!(d, "## Sources\n");
    let _ = writeln!(
        d,
        "- **ICRA 2008 Table I** (rows k07 … k45): `fixtures/table-i.json` when present \
         (format: `crates/pipeline/src/table_i.rs`). The published table could not be \
         retrieved where this project was built, so it is not transcribed yet and its \
         numbers are not invented here. When it is, its `(b, J21, J22)` are authoritative \
         for the radii (`r_L = −b·J21`, `r_R = b·J22`; the printed `r_L`/`r_R` headings are \
         swapped, see `docs/method.md`)."
    );
    let _ = writeln!(
        d,
        "- **T-RO 2013 package**: the published results of the three real configurations \
         (A `lstraight`, B `l90`, C `lmov`), read at run time from `../shared/reference/` \
         (never copied into the repository); the number of samples is the count of tuples \
         in each configuration's `.tuple` file. \"Published σ\" is the square root of the \
         package's covariance on the real robot's data; \"± σ\" after the recovered value \
         is what odocal reports on the simulated log, whose scan-matching noise is the \
         simulator's, not the real laser's.\n"
    );
    for n in notes {
        let _ = writeln!(d, "Note: {n}\n");
    }
    let _ = writeln!(d, "## Rules\n");
    let _ = writeln!(
        d,
        "Every quantity (r_L, r_R, b, ℓx, ℓy, ℓθ and the derived J21 = −r_L/b, \
         J22 = r_R/b) within {}σ of the covariance odocal reports; for runs of at least \
         {} samples also r_L, r_R, b, J21, J22 within {:.2} %, ℓx, ℓy within {:.1} mm and \
         ℓθ within {:.1}°. The same checks run in `tests/table_i.rs` (quick: about 800 samples per \
         row, 3σ only; full size: the ignored test `full_size_rows_meet_every_bound`; the \
         ignored test `three_sigma_rule_holds_over_seeds` measures how often the 3σ rule \
         holds over 8 seeds, and the RMS of error/σ).\n",
        tol.sigma_multiple,
        tol.min_samples_for_bounds,
        tol.relative * 100.0,
        tol.position * 1e3,
        tol.heading.to_degrees()
    );
    let _ = writeln!(d, "## Summary\n");
    let _ = writeln!(d, "{}", format_summary(reps, tol));
    let _ = writeln!(d, "## Rows\n");
    for (rep, t) in reps.iter().zip(timings) {
        let _ = writeln!(d, "### {}\n", rep.row.name);
        let _ = writeln!(d, "{}", format_reproduction(rep, tol));
        let _ = writeln!(d, "{}\n", timing_line(rep, t));
    }
    let _ = writeln!(d, "## Internal consistency of the published table\n");
    let _ = writeln!(
        d,
        "J recomputed by eq. (2), `J = [[r_L/2, r_R/2], [−r_L/b, r_R/b]]`, from the printed \
         b and radii, once with the headings as printed and once with r_L and r_R exchanged, \
         against the printed J columns (`j_consistency` in `crates/pipeline/src/table_i.rs`; \
         test `published_j_columns_reveal_the_heading_swap`)."
    );
    if consistency.is_empty() {
        let _ = writeln!(
            d,
            "\n**Awaits the ICRA 2008 Table I**: none of the rows above prints J columns (the \
             T-RO package publishes radii and b only), so there is nothing to check yet. \
             `docs/method.md` states that in every row of the ICRA table the printed J \
             satisfies `J11 = r_R/2`, `J21 = −r_R/b`, `J22 = r_L/b`, i.e. the reading \
             `HeadingsSwapped`; the test asserts exactly that once the table is transcribed."
        );
    } else {
        let _ = writeln!(
            d,
            "\n{}",
            format_j_consistency(consistency, J_PRINT_TOLERANCE)
        );
    }
    let _ = writeln!(d, "\n## Machine\n");
    let _ = writeln!(
        d,
        "{} row(s) in {:.1} s wall with {} scan-matching thread(s) on {} ({} cores, \
         release build).",
        reps.len(),
        total_s,
        threads,
        cpu_model(),
        std::thread::available_parallelism().map_or(0, |n| n.get())
    );
    d
}

/// The CPU's model name from `/proc/cpuinfo`, or "unknown CPU".
fn cpu_model() -> String {
    std::fs::read_to_string(Path::new("/proc/cpuinfo"))
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into())
}
