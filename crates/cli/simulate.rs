//! `odocal simulate`: write a simulated log (`PREFIX.log`) and its ground truth
//! (`PREFIX.truth.json`) from a preset, with every parameter overridable.

use crate::terminal::{outln, write_json_stdout};
use anyhow::Context;
use odocal_geom::Pose2;
use odocal_sim::{simulate, PresetRegistry, SimConfig, TrajectoryKind};
use std::io::BufWriter;
use std::path::{Path, PathBuf};

/// Arguments of `odocal simulate`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Preset to start from: khepera, turtlebot, pioneer, khepera-displaced, office,
    /// corridor, straight-only, spin-only, identical-turns, the realistic mines-rover,
    /// neato-lds and turtlebot4-rplidar (sparse, cluttered scans of real sensors; see
    /// docs/realistic-presets.md), or a row of the Table I file.
    #[arg(long, default_value = "khepera")]
    preset: String,
    /// Seed of every random choice (same seed and options → same bytes).
    #[arg(long)]
    seed: Option<u64>,
    /// Length of the run (s); default: the preset's.
    #[arg(long)]
    duration: Option<f64>,
    /// Output prefix: writes PREFIX.log and PREFIX.truth.json.
    #[arg(long, required_unless_present = "list_presets")]
    out: Option<PathBuf>,
    /// Table I file whose rows become presets (default: fixtures/table-i.json when it
    /// exists, in the current directory or the source tree).
    #[arg(long)]
    table: Option<PathBuf>,
    /// List the preset names and exit.
    #[arg(long)]
    list_presets: bool,
    /// Print the effective configuration (JSON) to stdout before simulating.
    #[arg(long)]
    print_config: bool,

    /// True left wheel radius (m).
    #[arg(long, allow_hyphen_values = true)]
    r_l: Option<f64>,
    /// True right wheel radius (m).
    #[arg(long, allow_hyphen_values = true)]
    r_r: Option<f64>,
    /// True wheel distance (m).
    #[arg(long, allow_hyphen_values = true)]
    b: Option<f64>,
    /// True laser x in the robot frame (m).
    #[arg(long, allow_hyphen_values = true)]
    laser_x: Option<f64>,
    /// True laser y in the robot frame (m).
    #[arg(long, allow_hyphen_values = true)]
    laser_y: Option<f64>,
    /// True laser heading in the robot frame (rad).
    #[arg(long, allow_hyphen_values = true)]
    laser_theta: Option<f64>,
    /// Encoder ticks per wheel revolution.
    #[arg(long)]
    ticks_per_rev: Option<f64>,
    /// Encoder counters wrap modulo this (e.g. 65536); written as a PARAM.
    #[arg(long)]
    modulus: Option<u64>,
    /// Encoder counts at the start, left and right (e.g. 65000,12).
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    initial_ticks: Option<Vec<i64>>,
    /// Encoder records per second.
    #[arg(long)]
    encoder_rate: Option<f64>,
    /// Encoder timing jitter (± s, uniform).
    #[arg(long)]
    encoder_jitter: Option<f64>,
    /// One encoder record per scan, with the scan's timestamp (a log that stores the
    /// counts with each scan), instead of --encoder-rate.
    #[arg(long)]
    encoder_with_scans: bool,
    /// Scans per second.
    #[arg(long)]
    scan_rate: Option<f64>,
    /// Scan timing jitter (± s, uniform).
    #[arg(long)]
    scan_jitter: Option<f64>,
    /// Laser model: urg-04lx, lds (360°, 5 Hz), sick (180°, clockwise), or the
    /// realistic urg-04lx-realistic, neato-lds and rplidar; each sweeps its rays (see
    /// --no-sweep). Default: the preset's.
    #[arg(long)]
    laser: Option<String>,
    /// Every ray of a scan at the scan's timestamp (no sweep, no
    /// laser_front_laser_time_increment PARAM).
    #[arg(long)]
    no_sweep: bool,
    /// World: khepera-arena, office, corridor, hall, or the realistic office-cluttered
    /// and hall-cluttered (glass, dark furniture, clutter, people).
    #[arg(long)]
    world: Option<String>,
    /// Trajectory: mixed, straight-only, spin-only, identical-turns or no-spins (a joystick
    /// drive: straights and arcs, no spins in place).
    #[arg(long)]
    trajectory: Option<String>,
    /// Range noise standard deviation per reading (m).
    #[arg(long)]
    range_noise: Option<f64>,
    /// Number of neighbouring rays the range noise is correlated over.
    #[arg(long)]
    noise_correlation: Option<usize>,
    /// Range quantization step (m); 0 = none.
    #[arg(long)]
    quantization: Option<f64>,
    /// Probability of a random reading failure (reported as 0).
    #[arg(long)]
    dropout: Option<f64>,
    /// Exact scans: no range noise, no quantization, no random failures.
    #[arg(long)]
    noise_free: bool,
    /// Laser clock minus encoder clock (s).
    #[arg(long, allow_hyphen_values = true)]
    clock_offset: Option<f64>,
    /// Wheel-slip episodes per minute.
    #[arg(long)]
    slip: Option<f64>,
    /// Fraction of ENCODER/RAWLASER1 messages dropped.
    #[arg(long)]
    drop: Option<f64>,
    /// Probability per message of a malformed line after it.
    #[arg(long)]
    garbage: Option<f64>,
    /// Motor lag time constant (s).
    #[arg(long)]
    motor_tau: Option<f64>,
    /// Sideways slide in turns (s), a skid-steer robot's: v_y = −K·v·ω (0.05 gives a
    /// 3° slip angle at 1 rad/s).
    #[arg(long, value_name = "K")]
    lateral_slip: Option<f64>,
    /// Largest forward speed (m/s).
    #[arg(long)]
    max_speed: Option<f64>,
    /// Largest turn rate (rad/s).
    #[arg(long)]
    max_turn_rate: Option<f64>,
    /// Smallest distance to walls kept by the planner (m).
    #[arg(long)]
    clearance: Option<f64>,
    /// Radius of the identical-turns circle, smallest turning radius of no-spins (m).
    #[arg(long)]
    turn_radius: Option<f64>,
    /// Encoder-clock time of the start (s).
    #[arg(long)]
    start_time: Option<f64>,
    /// Host name on every line.
    #[arg(long)]
    hostname: Option<String>,
    /// Do not write ODOM messages.
    #[arg(long)]
    no_odom: bool,
}

/// Runs `odocal simulate`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let registry = registry(args.table.as_deref())?;
    if args.list_presets {
        for name in registry.names() {
            outln!("{name}")?;
        }
        return Ok(());
    }
    let mut config = registry.get(&args.preset)?;
    apply_overrides(&mut config, &args)?;
    config.validate()?;
    if args.print_config {
        write_json_stdout(&serde_json::to_string_pretty(&config)?)?;
    }
    let Some(prefix) = args.out.as_deref() else {
        anyhow::bail!("--out PREFIX is required");
    };
    let log_path = with_suffix(prefix, ".log");
    let truth_path = with_suffix(prefix, ".truth.json");

    let started = std::time::Instant::now();
    let sim = simulate(&config)?;
    let header = vec![format!("generated by: {}", command_line())];
    let log_file = std::fs::File::create(&log_path)
        .with_context(|| format!("cannot create {}", log_path.display()))?;
    let summary = sim
        .write_log(BufWriter::new(log_file), &header)
        .with_context(|| format!("writing {}", log_path.display()))?;
    let truth_file = std::fs::File::create(&truth_path)
        .with_context(|| format!("cannot create {}", truth_path.display()))?;
    sim.write_truth(&summary, BufWriter::new(truth_file))
        .with_context(|| format!("writing {}", truth_path.display()))?;
    let bytes = std::fs::metadata(&log_path).map(|m| m.len()).unwrap_or(0);
    outln!(
        "{}: {} scans, {} encoder records, {} odom records, {} garbage lines, {:.2} MB, {:.1} s simulated in {:.2} s",
        log_path.display(),
        summary.scans,
        summary.encoder_records,
        summary.odom_records,
        summary.garbage_lines.len(),
        bytes as f64 / 1e6,
        config.duration,
        started.elapsed().as_secs_f64()
    )?;
    outln!("{}: ground truth", truth_path.display())?;
    Ok(())
}

/// The preset registry: built-in presets plus the rows of a Table I file.
fn registry(table: Option<&Path>) -> anyhow::Result<PresetRegistry> {
    if let Some(path) = table {
        return Ok(PresetRegistry::builtin().with_table_file(path)?);
    }
    let local = Path::new("fixtures/table-i.json");
    if local.exists() {
        return Ok(PresetRegistry::builtin().with_table_file(local)?);
    }
    Ok(PresetRegistry::standard())
}

fn apply_overrides(c: &mut SimConfig, a: &Args) -> anyhow::Result<()> {
    fn set<T: Copy>(target: &mut T, value: Option<T>) {
        if let Some(v) = value {
            *target = v;
        }
    }
    set(&mut c.seed, a.seed);
    set(&mut c.duration, a.duration);
    // The model first: the laser settings below refine it.
    if let Some(name) = &a.laser {
        c.laser = odocal_sim::LaserConfig::model(name)?;
    }
    if a.no_sweep {
        c.laser.time_increment = 0.0;
    }
    set(&mut c.robot.r_l, a.r_l);
    set(&mut c.robot.r_r, a.r_r);
    set(&mut c.robot.b, a.b);
    let l = c.robot.laser;
    c.robot.laser = Pose2::new(
        a.laser_x.unwrap_or(l.x),
        a.laser_y.unwrap_or(l.y),
        a.laser_theta.unwrap_or(l.theta),
    );
    set(&mut c.encoder.ticks_per_revolution, a.ticks_per_rev);
    if a.modulus.is_some() {
        c.encoder.modulus = a.modulus;
    }
    if let Some(t) = &a.initial_ticks {
        let [l, r] = t[..] else {
            anyhow::bail!("--initial-ticks takes two counts, LEFT,RIGHT (got {t:?})");
        };
        c.encoder.initial_ticks = [l, r];
    }
    set(&mut c.encoder.rate_hz, a.encoder_rate);
    set(&mut c.encoder.jitter_s, a.encoder_jitter);
    c.encoder.with_scans |= a.encoder_with_scans;
    set(&mut c.laser.rate_hz, a.scan_rate);
    set(&mut c.laser.jitter_s, a.scan_jitter);
    if let Some(w) = &a.world {
        odocal_sim::World::preset(w)?;
        c.world = w.clone();
    }
    if let Some(t) = &a.trajectory {
        c.trajectory = TrajectoryKind::from_name(t)?;
    }
    if a.noise_free {
        c.laser.range_sigma = 0.0;
        c.laser.quantization = 0.0;
        c.laser.dropout_probability = 0.0;
    }
    set(&mut c.laser.range_sigma, a.range_noise);
    set(&mut c.laser.correlation_rays, a.noise_correlation);
    set(&mut c.laser.quantization, a.quantization);
    set(&mut c.laser.dropout_probability, a.dropout);
    set(&mut c.faults.clock_offset, a.clock_offset);
    set(&mut c.faults.slip_per_minute, a.slip);
    set(&mut c.faults.drop_fraction, a.drop);
    set(&mut c.faults.garbage_fraction, a.garbage);
    set(&mut c.motors.time_constant, a.motor_tau);
    set(&mut c.motors.lateral_slip, a.lateral_slip);
    set(&mut c.motion.max_speed, a.max_speed);
    set(&mut c.motion.max_turn_rate, a.max_turn_rate);
    set(&mut c.motion.clearance, a.clearance);
    set(&mut c.motion.turn_radius, a.turn_radius);
    set(&mut c.start_time, a.start_time);
    if let Some(h) = &a.hostname {
        c.hostname = h.clone();
    }
    if a.no_odom {
        c.write_odom = false;
    }
    Ok(())
}

/// `PREFIX` + `suffix` (appended, not replacing an extension: `run.v2` → `run.v2.log`).
fn with_suffix(prefix: &Path, suffix: &str) -> PathBuf {
    let mut s = prefix.as_os_str().to_os_string();
    s.push(suffix);
    PathBuf::from(s)
}

/// The command as invoked, with the program named `odocal`, for the log's header.
fn command_line() -> String {
    let mut parts = vec!["odocal".to_string()];
    parts.extend(std::env::args().skip(1).map(|a| {
        if a.is_empty() || a.contains(char::is_whitespace) {
            format!("'{a}'")
        } else {
            a
        }
    }));
    parts.join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Wrapper {
        #[command(flatten)]
        args: Args,
    }

    fn parse(cmd: &str) -> Args {
        Wrapper::try_parse_from(std::iter::once("simulate").chain(cmd.split_whitespace()))
            .unwrap()
            .args
    }

    #[test]
    fn overrides_reach_the_configuration() {
        let a = parse(
            "--preset khepera --seed 9 --duration 12 --out x --r-l 0.03 --r-r 0.031 --b 0.2 \
             --laser-x -0.1 --laser-y 0.05 --laser-theta -1.5 --ticks-per-rev 4096 \
             --modulus 65536 --initial-ticks 65000,-5 --encoder-rate 100 --scan-rate 5 \
             --world office --trajectory spin-only --range-noise 0.01 --clock-offset -0.02 \
             --slip 3 --drop 0.1 --garbage 0.01 --no-odom",
        );
        let mut c = PresetRegistry::builtin().get(&a.preset).unwrap();
        apply_overrides(&mut c, &a).unwrap();
        c.validate().unwrap();
        assert_eq!((c.seed, c.duration), (9, 12.0));
        assert_eq!((c.robot.r_l, c.robot.r_r, c.robot.b), (0.03, 0.031, 0.2));
        assert_eq!(c.robot.laser, Pose2::new(-0.1, 0.05, -1.5));
        assert_eq!(c.encoder.ticks_per_revolution, 4096.0);
        assert_eq!(c.encoder.modulus, Some(65536));
        assert_eq!(c.encoder.initial_ticks, [65000, -5]);
        assert_eq!((c.encoder.rate_hz, c.laser.rate_hz), (100.0, 5.0));
        assert_eq!(c.world, "office");
        assert_eq!(c.trajectory, TrajectoryKind::SpinOnly);
        assert_eq!(c.laser.range_sigma, 0.01);
        assert_eq!(c.faults.clock_offset, -0.02);
        assert_eq!(
            (
                c.faults.slip_per_minute,
                c.faults.drop_fraction,
                c.faults.garbage_fraction
            ),
            (3.0, 0.1, 0.01)
        );
        assert!(!c.write_odom);
    }

    #[test]
    fn bad_names_and_values_are_errors() {
        let mut c = SimConfig::default();
        assert!(apply_overrides(&mut c, &parse("--out x --world moon")).is_err());
        let mut c = SimConfig::default();
        assert!(apply_overrides(&mut c, &parse("--out x --trajectory loops")).is_err());
        let mut c = SimConfig::default();
        assert!(apply_overrides(&mut c, &parse("--out x --initial-ticks 5")).is_err());
        let mut c = SimConfig::default();
        assert!(apply_overrides(&mut c, &parse("--out x --laser velodyne")).is_err());
        let mut c = SimConfig::default();
        apply_overrides(&mut c, &parse("--out x --b -1")).unwrap();
        assert!(c.validate().is_err());
        assert!(PresetRegistry::builtin().get("k99").is_err());
    }

    #[test]
    fn laser_models_and_sweep() {
        let mut c = PresetRegistry::builtin().get("khepera").unwrap();
        assert_eq!(c.laser.time_increment, 0.0);
        apply_overrides(&mut c, &parse("--out x --laser lds --scan-rate 4")).unwrap();
        assert_eq!((c.laser.num_rays, c.laser.rate_hz), (360, 4.0));
        assert!(c.laser.time_increment > 0.0);
        let mut c = PresetRegistry::builtin().get("pioneer").unwrap();
        assert!(c.laser.time_increment > 0.0);
        apply_overrides(&mut c, &parse("--out x --no-sweep")).unwrap();
        assert_eq!(c.laser.time_increment, 0.0);
    }

    #[test]
    fn noise_free_clears_every_error_source() {
        let mut c = SimConfig::default();
        apply_overrides(&mut c, &parse("--out x --noise-free")).unwrap();
        assert_eq!(c.laser.range_sigma, 0.0);
        assert_eq!(c.laser.quantization, 0.0);
        assert_eq!(c.laser.dropout_probability, 0.0);
        assert_eq!(
            with_suffix(Path::new("a/run.v2"), ".log"),
            Path::new("a/run.v2.log")
        );
    }
}
