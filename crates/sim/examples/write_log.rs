//! Writes a preset's log and ground truth with the library alone (the `odocal
//! simulate` command does the same with every option):
//!
//! `cargo run --release -p odocal-sim --example write_log -- PRESET SEED DURATION PREFIX`

use odocal_sim::{simulate, SimConfig};
use std::io::BufWriter;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() != 4 {
        return Err("usage: write_log PRESET SEED DURATION PREFIX".into());
    }
    let mut config = SimConfig::preset(&args[0])?;
    config.seed = args[1].parse()?;
    config.duration = args[2].parse()?;
    let started = std::time::Instant::now();
    let run = simulate(&config)?;
    let log = BufWriter::new(std::fs::File::create(format!("{}.log", args[3]))?);
    let summary = run.write_log(log, &[format!("example write_log {}", args.join(" "))])?;
    let truth = BufWriter::new(std::fs::File::create(format!("{}.truth.json", args[3]))?);
    run.write_truth(&summary, truth)?;
    println!(
        "{} scans, {} encoder records in {:.2} s",
        summary.scans,
        summary.encoder_records,
        started.elapsed().as_secs_f64()
    );
    Ok(())
}
