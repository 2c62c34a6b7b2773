//! Helpers shared by the end-to-end tests: simulated logs in a temporary directory.

#![allow(dead_code)]

pub mod accuracy;

use odocal_sim::{simulate, simulate_in, SimConfig, World};
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

/// The six true parameters, in the order r_L, r_R, b, ℓx, ℓy, ℓθ.
pub type Truth = [f64; 6];

/// The accuracy bounds of the issues for each parameter of `truth`: 0.35 % on r_L, r_R
/// and b, 1.5 mm on ℓx and ℓy, 0.2° on ℓθ.
pub fn bounds(truth: &[f64]) -> [f64; 6] {
    [
        0.0035 * truth[0],
        0.0035 * truth[1],
        0.0035 * truth[2],
        1.5e-3,
        1.5e-3,
        0.2f64.to_radians(),
    ]
}

/// A fresh directory under the system's temporary directory.
pub fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("odocal-e2e-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("create a temporary directory");
    dir
}

/// Simulates `preset` (after `tweak`) and writes `DIR/NAME.log`; returns the path and
/// the true parameters.
pub fn simulated_log(
    name: &str,
    preset: &str,
    duration: f64,
    seed: u64,
    tweak: impl FnOnce(&mut SimConfig),
) -> (PathBuf, Truth) {
    let mut config = SimConfig::preset(preset).expect("preset exists");
    config.duration = duration;
    config.seed = seed;
    tweak(&mut config);
    let run = simulate(&config).expect("simulation runs");
    let dir = temp_dir(name);
    let path = dir.join(format!("{name}.log"));
    let file = File::create(&path).expect("create the log");
    let summary = run
        .write_log(BufWriter::new(file), &[])
        .expect("write the log");
    let p = run.ground_truth(&summary).params;
    (path, p.to_array())
}

/// A 120 s log of `preset` with `seed`, in memory.
pub fn simulated_120s(preset: &str, seed: u64) -> odocal_log::Log {
    let mut config = SimConfig::preset(preset).expect("preset exists");
    config.seed = seed;
    config.duration = 120.0;
    let world = World::preset(&config.world).expect("the preset's world exists");
    simulate_in(&config, &world)
        .expect("simulation runs")
        .to_log()
}

/// A scan's geometry and readings with its rays listed the other way: the angles and
/// readings reversed, the angular step negated (the sweep's timing left as it is).
pub fn rays_listed_backwards(
    g: &odocal_log::ScanGeometry,
    ranges: &[f32],
) -> (odocal_log::ScanGeometry, Vec<f32>) {
    let angles: Vec<f64> = g.angles.iter().rev().copied().collect();
    let geometry = odocal_log::ScanGeometry {
        start_angle: angles[0],
        resolution: -g.resolution,
        angles: angles.into(),
        ..g.clone()
    };
    (geometry, ranges.iter().rev().copied().collect())
}

/// Removes a test's directory (best effort).
pub fn cleanup(path: &Path) {
    if let Some(dir) = path.parent() {
        let _ = std::fs::remove_dir_all(dir);
    }
}

/// Runs the `odocal` binary with `args`.
pub fn odocal(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_odocal"))
        .args(args)
        .output()
        .expect("the binary runs")
}

/// A run's standard error as text.
pub fn stderr(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// `odocal calibrate ARGS --json`, parsed; panics with stderr when it fails.
pub fn calibrate_json(args: &[&str]) -> serde_json::Value {
    let mut all = vec!["calibrate"];
    all.extend_from_slice(args);
    all.push("--json");
    let o = odocal(&all);
    assert!(o.status.success(), "{}", stderr(&o));
    serde_json::from_slice(&o.stdout).expect("one JSON object")
}

/// The real MinesRover log `name` (`exp1.log`, `exp2.log`) from `../shared/real/mines`
/// beside the repository; `None`, with a notice on standard output, when it is absent.
pub fn mines_log(name: &str) -> Option<PathBuf> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/real/mines")
        .join(name);
    if path.exists() {
        Some(path)
    } else {
        println!("skipped: {} is absent", path.display());
        None
    }
}
