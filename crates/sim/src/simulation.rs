//! Running a simulation: the robot drives, the encoders and the laser sample it, and
//! everything is kept in memory with its ground truth ([`SimRun`]).

use crate::config::SimConfig;
use crate::drive::{Drive, DriveState};
use crate::error::SimError;
use crate::faults::SlipEpisode;
use crate::kinematics::arc_motion;
use crate::planner::Planner;
use crate::world::World;
use odocal_geom::Pose2;
use odocal_log::{OdomRecord, ScanGeometry};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::VecDeque;

/// Independent random streams, so that enabling one feature (faults, noise) does not
/// change the others (the same seed gives the same trajectory with or without faults).
#[derive(Debug, Clone, Copy)]
#[repr(u64)]
pub(crate) enum Stream {
    Planner = 1,
    EncoderTiming = 2,
    LaserTiming = 3,
    LaserNoise = 4,
    Slip = 5,
    Drop = 6,
    Garbage = 7,
}

/// The random generator of one stream: ChaCha8 (portable: same seed, same numbers on
/// every platform and version of this crate).
pub(crate) fn rng_for(seed: u64, stream: Stream) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(stream as u64);
    rng
}

/// How often (µs) the planner updates the wheel-speed command.
const CONTROL_PERIOD_US: u64 = 10_000;

/// One encoder reading with the truth behind it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimEncoderRecord {
    /// Timestamp as logged (s, encoder clock).
    pub t: f64,
    /// Cumulative counts `[left, right]`, unwrapped (the log shows them modulo
    /// `encoder.modulus` when set).
    pub ticks: [i64; 2],
    /// True cumulative wheel rotations `[left, right]` (rad) when the counts were read
    /// (at `t`, except for records stored with the scans and read with jitter).
    pub wheel_angles: [f64; 2],
    /// True robot pose when the counts were read.
    pub robot: Pose2,
    /// Left out of the log by the drop fault.
    pub dropped: bool,
}

/// One laser scan with the truth behind it (for a swept scan: at ray 0, whose time
/// the timestamp is).
#[derive(Debug, Clone, PartialEq)]
pub struct SimScan {
    /// Timestamp as logged (s, laser clock = encoder clock + clock offset).
    pub t: f64,
    /// True acquisition time on the encoder clock (s).
    pub t_true: f64,
    /// True robot pose at acquisition.
    pub robot: Pose2,
    /// True sensor pose at acquisition: `robot ⊕ laser`.
    pub sensor: Pose2,
    /// True sensor pose when the last ray was taken (equal to `sensor` without sweep).
    pub sensor_at_last_ray: Pose2,
    /// True sensor pose at the middle of the sweep, the time the scan stands for once
    /// its sweep is compensated (`timestamp + (n − 1) · time_increment / 2`; equal to
    /// `sensor` without sweep): the truth a compensated match is compared with.
    pub sensor_at_reference: Pose2,
    /// True cumulative wheel rotations `[left, right]` (rad) at acquisition.
    pub wheel_angles: [f64; 2],
    /// The readings (m), 0 for failures.
    pub ranges: Vec<f32>,
    /// Left out of the log by the drop fault.
    pub dropped: bool,
}

/// The result of a simulation: every record with its truth, before writing.
#[derive(Debug, Clone)]
pub struct SimRun {
    /// The configuration that produced it.
    pub config: SimConfig,
    /// The world driven in.
    pub world: World,
    /// The robot's pose at time 0.
    pub start_pose: Pose2,
    /// Encoder readings, in time order (dropped ones included, flagged).
    pub encoders: Vec<SimEncoderRecord>,
    /// Scans, in time order (dropped ones included, flagged).
    pub scans: Vec<SimScan>,
    /// Firmware odometry (nominal parameters), one per encoder reading, same times.
    pub odom: Vec<OdomRecord>,
    /// Wheel-slip episodes that happened.
    pub slips: Vec<SlipEpisode>,
}

impl SimRun {
    /// The scans' geometry as written to the log.
    pub fn geometry(&self) -> ScanGeometry {
        self.config.laser.geometry()
    }

    /// The scans that are in the log (not dropped).
    pub fn logged_scans(&self) -> impl Iterator<Item = &SimScan> + '_ {
        self.scans.iter().filter(|s| !s.dropped)
    }

    /// The encoder readings that are in the log (not dropped).
    pub fn logged_encoders(&self) -> impl Iterator<Item = &SimEncoderRecord> + '_ {
        self.encoders.iter().filter(|e| !e.dropped)
    }
}

/// Runs the simulation described by `config` in its preset world.
pub fn simulate(config: &SimConfig) -> Result<SimRun, SimError> {
    let world = World::preset(&config.world)?;
    simulate_in(config, &world)
}

/// Runs the simulation described by `config` in `world` (`config.world` is ignored).
pub fn simulate_in(config: &SimConfig, world: &World) -> Result<SimRun, SimError> {
    config.validate()?;
    let c = config;
    let duration_us = (c.duration * 1e6).round() as u64;
    let start_us = (c.start_time * 1e6).round() as i64;
    let offset_us = (c.faults.clock_offset * 1e6).round() as i64;
    let substep_us = c.motors.substep_us as u64;

    let (mut planner, start_pose) = Planner::new(
        c.trajectory,
        c.motion,
        c.robot,
        world,
        world.home(),
        rng_for(c.seed, Stream::Planner),
    )?;
    let mut encoder_times = sample_times(
        c.encoder.rate_hz,
        c.encoder.jitter_s,
        0,
        duration_us,
        &mut rng_for(c.seed, Stream::EncoderTiming),
    );
    let mut laser_timing = rng_for(c.seed, Stream::LaserTiming);
    let scan_period = (1e6 / c.laser.rate_hz).round() as u64;
    let phase = laser_timing.random_range(0..scan_period.max(1));
    let scan_times = sample_times(
        c.laser.rate_hz,
        c.laser.jitter_s,
        phase,
        duration_us,
        &mut laser_timing,
    );
    // When each record's counts are read, and the timestamp it is written with.
    let mut encoder_stamps = encoder_times.clone();
    if c.encoder.with_scans {
        // Stamped with the scan's timestamp (laser clock), read when the encoder clock
        // shows it, give or take the encoder jitter (not in the stamp).
        let jitter = (c.encoder.jitter_s * 1e6).round() as i64;
        let mut rng = rng_for(c.seed, Stream::EncoderTiming);
        encoder_times.clear();
        encoder_stamps.clear();
        for &t in &scan_times {
            let j = if jitter > 0 {
                rng.random_range(-jitter..=jitter)
            } else {
                0
            };
            let stamp = t as i64 + offset_us;
            let read = stamp + j;
            let after_last = encoder_times.last().is_none_or(|&l| read > l as i64);
            if stamp >= 0 && read >= 0 && read as u64 <= duration_us && after_last {
                encoder_times.push(read as u64);
                encoder_stamps.push(stamp as u64);
            }
        }
    }
    let slips = c.faults.slip_episodes(
        c.duration,
        substep_us as f64 * 1e-6,
        &mut rng_for(c.seed, Stream::Slip),
    );
    let slip_us: Vec<(u64, u64, [f64; 2])> = slips
        .iter()
        .map(|e| {
            (
                (e.start * 1e6).round() as u64,
                (e.end * 1e6).round() as u64,
                e.factors,
            )
        })
        .collect();

    let mut noise = rng_for(c.seed, Stream::LaserNoise);
    let mut drops = rng_for(c.seed, Stream::Drop);
    let is_dropped = |rng: &mut ChaCha8Rng| {
        c.faults.drop_fraction > 0.0 && rng.random::<f64>() < c.faults.drop_fraction
    };

    let mut drive = Drive::new(c.robot, c.motors, start_pose);
    let control_every = (CONTROL_PERIOD_US / substep_us).max(1);
    let mut command = [0.0; 2];
    let mut encoders = Vec::with_capacity(encoder_times.len());
    let mut scans = Vec::with_capacity(scan_times.len());
    let (mut ei, mut si, mut slip_i) = (0, 0, 0);
    let mut sweeps: VecDeque<Sweep> = VecDeque::new();
    loop {
        let t0 = drive.step_start_us();
        if t0 > duration_us {
            break;
        }
        let t1 = t0 + substep_us;
        if drive.step_index() % control_every == 0 {
            let now = drive.current();
            command = planner.command(now.t, &now.pose, world);
        }
        while slip_i < slip_us.len() && slip_us[slip_i].1 <= t0 {
            slip_i += 1;
        }
        let slip = match slip_us.get(slip_i) {
            Some(&(s, e, f)) if s <= t0 && t0 < e => f,
            _ => [1.0; 2],
        };
        drive.set_command(command, slip);
        while ei < encoder_times.len() && encoder_times[ei] < t1 {
            let s = drive.state_at_us(encoder_times[ei]);
            encoders.push(SimEncoderRecord {
                t: timestamp(start_us + encoder_stamps[ei] as i64),
                ticks: c.encoder.ticks(s.wheel_angles),
                wheel_angles: s.wheel_angles,
                robot: s.pose,
                dropped: is_dropped(&mut drops),
            });
            ei += 1;
        }
        if c.laser.time_increment == 0.0 {
            while si < scan_times.len() && scan_times[si] < t1 {
                let s = drive.state_at_us(scan_times[si]);
                let sensor = s.pose.compose(&c.robot.laser);
                let ranges = match &c.laser.realism {
                    None => c.laser.scan(world, &sensor, &mut noise),
                    Some(r) => {
                        let elapsed = scan_times[si] as f64 * 1e-6;
                        c.laser
                            .realistic_scan(r, world, &[sensor], elapsed, &mut noise)
                    }
                };
                scans.push(SimScan {
                    t: timestamp(start_us + scan_times[si] as i64 + offset_us),
                    t_true: timestamp(start_us + scan_times[si] as i64),
                    robot: s.pose,
                    sensor,
                    sensor_at_last_ray: sensor,
                    sensor_at_reference: sensor,
                    wheel_angles: s.wheel_angles,
                    ranges,
                    dropped: is_dropped(&mut drops),
                });
                si += 1;
            }
        } else {
            while si < scan_times.len() && scan_times[si] < t1 {
                sweeps.push_back(Sweep::new(scan_times[si], is_dropped(&mut drops)));
                si += 1;
            }
            for sweep in sweeps.iter_mut() {
                sweep.fire_rays_before(t1, &drive, c);
            }
            while sweeps
                .front()
                .is_some_and(|s| s.sensor_poses.len() == c.laser.num_rays)
            {
                let Some(sweep) = sweeps.pop_front() else {
                    break;
                };
                let first = sweep.first.unwrap_or_else(|| drive.current());
                let ranges = match &c.laser.realism {
                    None => c.laser.swept_scan(world, &sweep.sensor_poses, &mut noise),
                    Some(r) => {
                        let elapsed = sweep.start_us as f64 * 1e-6;
                        c.laser
                            .realistic_scan(r, world, &sweep.sensor_poses, elapsed, &mut noise)
                    }
                };
                scans.push(SimScan {
                    t: timestamp(start_us + sweep.start_us as i64 + offset_us),
                    t_true: timestamp(start_us + sweep.start_us as i64),
                    robot: first.pose,
                    sensor: sweep.sensor_poses[0],
                    sensor_at_last_ray: sweep.sensor_poses[c.laser.num_rays - 1],
                    sensor_at_reference: sweep.reference.unwrap_or(sweep.sensor_poses[0]),
                    wheel_angles: first.wheel_angles,
                    ranges,
                    dropped: sweep.dropped,
                });
            }
        }
        drive.finish_step();
    }
    let odom = firmware_odometry(c, &encoders);
    Ok(SimRun {
        config: c.clone(),
        world: world.clone(),
        start_pose,
        encoders,
        scans,
        odom,
        slips,
    })
}

/// A scan being swept: the sensor's pose at each ray fired so far.
struct Sweep {
    /// Time of ray 0 (µs since the start).
    start_us: u64,
    /// The robot's state at ray 0.
    first: Option<DriveState>,
    /// Sensor pose (world) at each ray fired so far.
    sensor_poses: Vec<Pose2>,
    /// Sensor pose at the middle of the sweep, once reached.
    reference: Option<Pose2>,
    /// Left out of the log by the drop fault (drawn when the sweep starts, so that the
    /// drop pattern does not depend on the sweep).
    dropped: bool,
}

impl Sweep {
    fn new(start_us: u64, dropped: bool) -> Self {
        Sweep {
            start_us,
            first: None,
            sensor_poses: Vec::new(),
            reference: None,
            dropped,
        }
    }

    /// Fires the rays due before `end_us` (the end of the drive's current sub-step).
    fn fire_rays_before(&mut self, end_us: u64, drive: &Drive, c: &SimConfig) {
        let increment_us = c.laser.time_increment * 1e6;
        let middle = self.start_us as f64 + 0.5 * c.laser.sweep_duration() * 1e6;
        if self.reference.is_none() && middle < end_us as f64 {
            let t = middle.max(drive.step_start_us() as f64);
            self.reference = Some(drive.state_at_fractional_us(t).pose.compose(&c.robot.laser));
        }
        while self.sensor_poses.len() < c.laser.num_rays {
            let t = self.start_us as f64 + self.sensor_poses.len() as f64 * increment_us;
            if t >= end_us as f64 {
                break;
            }
            let s = drive.state_at_fractional_us(t);
            if self.first.is_none() {
                self.first = Some(s);
            }
            self.sensor_poses.push(s.pose.compose(&c.robot.laser));
        }
    }
}

/// Sample times (µs since the start) at `rate_hz` from `phase_us`, each moved by a
/// uniform jitter in ±`jitter_s`, strictly increasing, within `[0, end_us]`.
fn sample_times(
    rate_hz: f64,
    jitter_s: f64,
    phase_us: u64,
    end_us: u64,
    rng: &mut ChaCha8Rng,
) -> Vec<u64> {
    let period = (1e6 / rate_hz).round().max(1.0) as u64;
    let jitter = (jitter_s * 1e6).round() as i64;
    let mut out: Vec<u64> = Vec::with_capacity((end_us / period + 2) as usize);
    let mut k = 0u64;
    loop {
        let nominal = phase_us + k * period;
        if nominal > end_us {
            break;
        }
        let j = if jitter > 0 {
            rng.random_range(-jitter..=jitter)
        } else {
            0
        };
        let mut t = (nominal as i64 + j).max(0) as u64;
        if let Some(&last) = out.last() {
            t = t.max(last + 1);
        }
        if t <= end_us {
            out.push(t);
        }
        k += 1;
    }
    out
}

/// An absolute time given in µs as seconds: the `f64` nearest to the decimal with six
/// places, so that the log (which prints the shortest round-tripping decimal) shows
/// exactly the microsecond timestamp.
fn timestamp(us: i64) -> f64 {
    let sign = if us < 0 { "-" } else { "" };
    let a = us.unsigned_abs();
    format!("{sign}{}.{:06}", a / 1_000_000, a % 1_000_000)
        .parse()
        .unwrap_or(us as f64 * 1e-6)
}

/// Rounds to the micrometre / microradian, as a firmware printing 6 decimals would.
fn round6(x: f64) -> f64 {
    (x * 1e6).round() / 1e6
}

/// The ODOM records a firmware would log: the encoder increments integrated with the
/// nominal parameters (constant speed between readings), from the origin.
fn firmware_odometry(c: &SimConfig, encoders: &[SimEncoderRecord]) -> Vec<OdomRecord> {
    let mut pose = Pose2::IDENTITY;
    let mut out = Vec::with_capacity(encoders.len());
    let mut prev: Option<&SimEncoderRecord> = None;
    for e in encoders {
        let (mut tv, mut rv) = (0.0, 0.0);
        if let Some(p) = prev {
            let dt = e.t - p.t;
            let dl = c.encoder.ticks_to_radians(e.ticks[0] - p.ticks[0]);
            let dr = c.encoder.ticks_to_radians(e.ticks[1] - p.ticks[1]);
            if dt > 0.0 {
                let (v, w) = c.nominal.body_velocity([dl / dt, dr / dt]);
                pose = pose.compose(&arc_motion(v, w, dt));
                tv = v;
                rv = w;
            }
        }
        out.push(OdomRecord {
            t: e.t,
            pose: Pose2::new(round6(pose.x), round6(pose.y), round6(pose.theta)),
            tv: round6(tv),
            rv: round6(rv),
            accel: 0.0,
            line: 0,
        });
        prev = Some(e);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn timestamps_are_the_microsecond_decimals() {
        assert_eq!(
            timestamp(1_190_000_000_017_285).to_string(),
            "1190000000.017285"
        );
        assert_eq!(timestamp(-1_500_000).to_string(), "-1.5");
        assert_eq!(timestamp(7).to_string(), "0.000007");
    }

    #[test]
    fn sample_times_are_increasing_and_near_the_rate() {
        let mut rng = rng_for(5, Stream::EncoderTiming);
        let t = sample_times(50.0, 0.002, 0, 10_000_000, &mut rng);
        assert!((499..=501).contains(&t.len()), "{}", t.len());
        for w in t.windows(2) {
            assert!(w[1] > w[0] && w[1] - w[0] >= 16_000 && w[1] - w[0] <= 24_000);
        }
    }
}
