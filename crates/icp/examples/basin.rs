//! Basin of convergence of the matcher (see `tests/common/basin.rs`): simulated
//! URG-04LX pairs 0.4 s apart in the office and the Khepera arena, first guesses off
//! the truth by up to 0.25 m and ±45°; per cell of the grid, how many matches reached
//! the truth, were refused with a reason, or were accepted wrong.
//!
//! `cargo run --release -p odocal-icp --example basin [seconds] [every]`
//! (defaults: 60 s of driving per world, every 8th pair).

#[path = "../tests/common/basin.rs"]
mod basin;

use basin::{Tally, ROTATIONS_DEG, TRANSLATIONS};
use odocal_icp::IcpParams;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let seconds: f64 = args.next().map(|a| a.parse()).transpose()?.unwrap_or(60.0);
    let every: usize = args.next().map(|a| a.parse()).transpose()?.unwrap_or(8);
    let params = IcpParams::default();
    for (world, preset) in [("office", "office"), ("arena", "khepera")] {
        let run = basin::simulate_preset(preset, seconds, 1);
        let scans = basin::prepare(&run, &params);
        let pairs = basin::pairs(&run, 4, every.max(1));
        let start = Instant::now();
        let cells = basin::basin(&scans, &pairs, &params);
        let elapsed = start.elapsed().as_secs_f64();
        let mut total = Tally::default();
        println!("{world}: {} pairs 0.4 s apart, seed 1", pairs.len());
        println!("  converged % (false accepts) per |Δxy| (rows) and Δθ (columns, °)");
        print!("  {:>8}", "|Δxy| m");
        for r in ROTATIONS_DEG {
            print!("{r:>10}");
        }
        println!();
        for t in TRANSLATIONS {
            print!("  {t:>8.2}");
            for r in ROTATIONS_DEG {
                let (_, tally) = cells
                    .iter()
                    .find(|(k, _)| *k == (t, r))
                    .ok_or("missing cell")?;
                total.merge(tally);
                let pct = 100.0 * tally.converged as f64 / tally.total().max(1) as f64;
                print!("{:>10}", format!("{pct:.0} ({})", tally.false_accepts));
            }
            println!();
        }
        let n = total.total();
        println!(
            "  total {n} matches: converged {} ({:.1} %), refused {} (error) + {} (ill-conditioned), \
             false accepts {}; {:.0} µs per match",
            total.converged,
            100.0 * total.converged as f64 / n.max(1) as f64,
            total.refused,
            total.ill_conditioned,
            total.false_accepts,
            elapsed / n.max(1) as f64 * 1e6
        );
    }
    Ok(())
}
