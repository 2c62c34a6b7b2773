//! Writing Carmen-style logs: one message per line, numbers printed so that reading
//! them back gives exactly the same `f64` / `f32` (Rust's `Display` for floats prints
//! the shortest decimal that round-trips).

use crate::model::{Log, OdomRecord, ScanGeometry, ScanKind};
use odocal_geom::Pose2;
use std::fmt::Display;
use std::io::{self, Write};

/// The pose fields of a `ROBOTLASER1` line (read and written, never trusted).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RobotLaserPoses {
    /// Laser pose in the world (as estimated by the logger).
    pub laser: Pose2,
    /// Robot pose in the world (as estimated by the logger).
    pub robot: Pose2,
    /// Translational velocity (m/s).
    pub tv: f64,
    /// Rotational velocity (rad/s).
    pub rv: f64,
    /// Forward safety distance (m).
    pub forward_safety_dist: f64,
    /// Side safety distance (m).
    pub side_safety_dist: f64,
    /// Turn axis (m).
    pub turn_axis: f64,
}

/// Writes a Carmen-style log message by message.
///
/// Every message line ends with `timestamp hostname logger_timestamp`; this writer
/// uses the acquisition timestamp for both times.
pub struct LogWriter<W: Write> {
    w: W,
    hostname: String,
    line: Vec<u8>,
}

impl<W: Write> LogWriter<W> {
    /// A writer on `w`, naming `hostname` on every line (whitespace in it is replaced by
    /// `_`, an empty name by `odocal`, so that it stays one token).
    pub fn new(w: W, hostname: &str) -> Self {
        let mut host: String = hostname
            .chars()
            .map(|c| if c.is_whitespace() { '_' } else { c })
            .collect();
        if host.is_empty() {
            host = "odocal".into();
        }
        LogWriter {
            w,
            hostname: host,
            line: Vec::with_capacity(8192),
        }
    }

    /// Writes a comment (`# text`); a multi-line text gives one comment line per line.
    pub fn comment(&mut self, text: &str) -> io::Result<()> {
        for part in text.split('\n') {
            let part = part.trim_end_matches('\r');
            if part.is_empty() {
                self.w.write_all(b"#\n")?;
            } else {
                writeln!(self.w, "# {part}")?;
            }
        }
        Ok(())
    }

    /// Writes `PARAM name value hostname 0`. `name` and `value` must be single tokens.
    pub fn param(&mut self, name: &str, value: impl Display) -> io::Result<()> {
        let value = value.to_string();
        if !is_token(name) || !is_token(&value) {
            return Err(invalid(format!(
                "PARAM name and value must be single non-empty tokens, got {name:?} {value:?}"
            )));
        }
        writeln!(self.w, "PARAM {name} {value} {} 0", self.hostname)
    }

    /// Writes `ENCODER left right timestamp hostname logger_timestamp`.
    pub fn encoder(&mut self, t: f64, left: i64, right: i64) -> io::Result<()> {
        self.line.clear();
        write!(self.line, "ENCODER {left} {right}")?;
        self.finish(t)
    }

    /// Writes a `RAWLASER1` line without remissions.
    pub fn rawlaser1(&mut self, t: f64, geometry: &ScanGeometry, ranges: &[f32]) -> io::Result<()> {
        self.rawlaser1_with_remissions(t, geometry, ranges, &[])
    }

    /// Writes a `RAWLASER1` line with remissions.
    pub fn rawlaser1_with_remissions(
        &mut self,
        t: f64,
        geometry: &ScanGeometry,
        ranges: &[f32],
        remissions: &[f32],
    ) -> io::Result<()> {
        self.line.clear();
        self.line.extend_from_slice(b"RAWLASER1");
        self.scan_fields(geometry, ranges, remissions)?;
        self.finish(t)
    }

    /// Writes a `ROBOTLASER1` line (no remissions) with the given poses.
    pub fn robotlaser1(
        &mut self,
        t: f64,
        geometry: &ScanGeometry,
        ranges: &[f32],
        poses: &RobotLaserPoses,
    ) -> io::Result<()> {
        self.robotlaser1_with_remissions(t, geometry, ranges, &[], poses)
    }

    /// Writes a `ROBOTLASER1` line with remissions and the given poses.
    pub fn robotlaser1_with_remissions(
        &mut self,
        t: f64,
        geometry: &ScanGeometry,
        ranges: &[f32],
        remissions: &[f32],
        poses: &RobotLaserPoses,
    ) -> io::Result<()> {
        self.line.clear();
        self.line.extend_from_slice(b"ROBOTLASER1");
        self.scan_fields(geometry, ranges, remissions)?;
        let p = poses;
        write!(
            self.line,
            " {} {} {} {} {} {} {} {} {} {} {}",
            p.laser.x,
            p.laser.y,
            p.laser.theta,
            p.robot.x,
            p.robot.y,
            p.robot.theta,
            p.tv,
            p.rv,
            p.forward_safety_dist,
            p.side_safety_dist,
            p.turn_axis
        )?;
        self.finish(t)
    }

    /// Writes a legacy `FLASER` line. Its geometry is not in the line: readers take it
    /// from the `laser_front_laser_fov` / `laser_front_laser_resolution` PARAMs
    /// (default: field of view π centred on the x axis).
    pub fn flaser(&mut self, t: f64, ranges: &[f32], laser: Pose2, odom: Pose2) -> io::Result<()> {
        self.line.clear();
        write!(self.line, "FLASER {}", ranges.len())?;
        for r in ranges {
            write!(self.line, " {r}")?;
        }
        write!(
            self.line,
            " {} {} {} {} {} {}",
            laser.x, laser.y, laser.theta, odom.x, odom.y, odom.theta
        )?;
        self.finish(t)
    }

    /// Writes an `ODOM x y theta tv rv accel …` line.
    pub fn odom(&mut self, rec: &OdomRecord) -> io::Result<()> {
        self.line.clear();
        write!(
            self.line,
            "ODOM {} {} {} {} {} {}",
            rec.pose.x, rec.pose.y, rec.pose.theta, rec.tv, rec.rv, rec.accel
        )?;
        self.finish(rec.t)
    }

    /// Writes `text` followed by a newline, verbatim (e.g. to inject a garbage line).
    pub fn raw_line(&mut self, text: &str) -> io::Result<()> {
        self.w.write_all(text.as_bytes())?;
        self.w.write_all(b"\n")
    }

    /// Flushes the underlying writer.
    pub fn flush(&mut self) -> io::Result<()> {
        self.w.flush()
    }

    /// The underlying writer (not flushed).
    pub fn into_inner(self) -> W {
        self.w
    }

    /// The fields shared by RAWLASER1 and ROBOTLASER1, from `laser_type` to the
    /// remissions.
    fn scan_fields(
        &mut self,
        g: &ScanGeometry,
        ranges: &[f32],
        remissions: &[f32],
    ) -> io::Result<()> {
        if ranges.len() != g.num_readings() {
            return Err(invalid(format!(
                "scan has {} readings but its geometry has {} rays",
                ranges.len(),
                g.num_readings()
            )));
        }
        if !g.is_evenly_spaced() {
            return Err(invalid(
                "a RAWLASER1/ROBOTLASER1 line can only describe evenly spaced rays".into(),
            ));
        }
        write!(
            self.line,
            " {} {} {} {} {} {} {} {}",
            g.laser_type,
            g.start_angle,
            g.fov,
            g.resolution,
            g.max_range,
            g.accuracy,
            g.remission_mode,
            ranges.len()
        )?;
        for r in ranges {
            write!(self.line, " {r}")?;
        }
        write!(self.line, " {}", remissions.len())?;
        for m in remissions {
            write!(self.line, " {m}")?;
        }
        Ok(())
    }

    /// Appends `timestamp hostname logger_timestamp` and writes the line.
    fn finish(&mut self, t: f64) -> io::Result<()> {
        if !t.is_finite() {
            return Err(invalid(format!("timestamp must be finite, got {t}")));
        }
        writeln!(self.line, " {t} {} {t}", self.hostname)?;
        self.w.write_all(&self.line)
    }
}

/// True when `s` is one non-empty token (no whitespace).
fn is_token(s: &str) -> bool {
    !s.is_empty() && !s.contains(char::is_whitespace)
}

fn invalid(msg: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, msg)
}

/// Writes a whole [`Log`]: its PARAMs, then encoder, scan and odometry records merged
/// by timestamp. Scans read from JSON logs are written as RAWLASER1 (they must have
/// evenly spaced rays); FLASER scans as FLASER (their geometry travels in the PARAMs).
/// ROBOTLASER1 poses are not kept by [`Log`], so they are written as zeros.
pub fn write_log<W: Write>(w: W, log: &Log) -> io::Result<()> {
    let mut out = LogWriter::new(w, "odocal");
    out.comment("CARMEN Logfile (odocal)")?;
    out.comment("message_name [message contents] timestamp hostname logger_timestamp")?;
    let p = &log.params;
    for (name, value) in &p.all {
        out.param(name, value)?;
    }
    let typed: [(&str, Option<f64>); 5] = [
        (
            "robot_wheel_ticks_per_revolution",
            p.ticks_per_revolution.as_ref().map(|(v, _)| *v),
        ),
        ("robot_encoder_modulus", p.encoder_modulus),
        ("laser_front_laser_fov", p.flaser_fov),
        ("laser_front_laser_resolution", p.flaser_resolution),
        (
            "laser_front_laser_time_increment",
            p.laser_time_increment.or_else(|| {
                let dt = log
                    .scans
                    .geometries
                    .first()
                    .map_or(0.0, |g| g.time_increment);
                (dt != 0.0).then_some(dt)
            }),
        ),
    ];
    for (name, value) in typed {
        if let (Some(v), false) = (value, p.all.contains_key(name)) {
            out.param(name, v)?;
        }
    }
    if !p.all.contains_key("laser_front_laser_min_range") && p.laser_min_range != 0.02 {
        out.param("laser_front_laser_min_range", p.laser_min_range)?;
    }

    let (mut ie, mut is, mut io_) = (0, 0, 0);
    loop {
        let te = log.encoders.get(ie).map(|e| e.t);
        let ts = log.scans.scans.get(is).map(|s| s.t);
        let to = log.odom.get(io_).map(|o| o.t);
        let next = [te, ts, to]
            .iter()
            .enumerate()
            .filter_map(|(k, t)| t.map(|t| (k, t)))
            .min_by(|a, b| a.1.total_cmp(&b.1));
        match next {
            None => break,
            Some((0, _)) => {
                let e = &log.encoders[ie];
                out.encoder(e.t, e.left, e.right)?;
                ie += 1;
            }
            Some((1, _)) => {
                if let Some(s) = log.scans.get(is) {
                    match s.kind {
                        ScanKind::RawLaser1 | ScanKind::Json | ScanKind::LaserScan => {
                            out.rawlaser1_with_remissions(s.t, s.geometry, s.ranges, s.remissions)?
                        }
                        ScanKind::RobotLaser1 => out.robotlaser1_with_remissions(
                            s.t,
                            s.geometry,
                            s.ranges,
                            s.remissions,
                            &RobotLaserPoses::default(),
                        )?,
                        ScanKind::FLaser => {
                            out.flaser(s.t, s.ranges, Pose2::default(), Pose2::default())?
                        }
                    }
                }
                is += 1;
            }
            Some(_) => {
                out.odom(&log.odom[io_])?;
                io_ += 1;
            }
        }
    }
    out.flush()
}
