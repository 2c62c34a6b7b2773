//! The streaming reader for Carmen-style text logs (see `docs/log-format.md`).
//!
//! One reused line buffer; tokens are byte slices of it; numbers are parsed in place;
//! readings go straight into the log's packed `f32` store. Nothing else is kept of the
//! text.

use crate::builder::{LogBuilder, Stream};
use crate::error::LogError;
use crate::line_batch::LineBatch;
use crate::line_reader::{Line, MAX_LINE_BYTES};
use crate::model::{LaserFields, Log, OdomRecord, ScanGeometry, ScanKind, ValueSource};
use crate::options::{is_valid_modulus, ReadOptions};
use crate::printable::printable;
use crate::range_prescan::{prescan, Prescan, Ready};
use crate::tokens::{FieldError, Fields, Tokens};
use odocal_geom::Pose2;
use std::io::BufRead;

/// The messages this reader understands.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Message {
    Param,
    Encoder,
    RawLaser1,
    RobotLaser1,
    FLaser,
    Odom,
}

const MESSAGES: [(Message, &str); 6] = [
    (Message::Param, "PARAM"),
    (Message::Encoder, "ENCODER"),
    (Message::RawLaser1, "RAWLASER1"),
    (Message::RobotLaser1, "ROBOTLASER1"),
    (Message::FLaser, "FLASER"),
    (Message::Odom, "ODOM"),
];

impl Message {
    fn from_name(name: &[u8]) -> Option<Message> {
        MESSAGES
            .iter()
            .find(|(_, n)| n.as_bytes() == name)
            .map(|(m, _)| *m)
    }

    fn name(self) -> &'static str {
        MESSAGES[self as usize].1
    }

    /// The fields after the name, for messages with a fixed number of them.
    fn fixed_fields(self) -> Option<&'static str> {
        match self {
            Message::Encoder => Some("left_ticks right_ticks timestamp hostname logger_timestamp"),
            Message::Odom => Some("x y theta tv rv accel timestamp hostname logger_timestamp"),
            _ => None,
        }
    }
}

/// Distinct unknown message names kept; further ones are counted under
/// [`OTHER_UNKNOWN`].
const MAX_UNKNOWN_NAMES: usize = 100;
/// The name under which unknown messages beyond [`MAX_UNKNOWN_NAMES`] are counted.
const OTHER_UNKNOWN: &str = "(other names)";

/// Parser state across lines.
struct CarmenReader<'o> {
    b: LogBuilder<'o>,
    name: String,
    counts: [u64; 6],
    /// Index of the geometry used by the previous scan (most scans share it).
    last_geometry: Option<u32>,
    /// Maximum range of FLASER scans (PARAM `laser_front_laser_max_range`).
    flaser_max_range: f64,
    /// A RAWLASER1/ROBOTLASER1 field of view disagreed with its resolution already.
    warned_fov: bool,
    /// The FLASER field of view PARAM disagreed with the resolution PARAM already.
    warned_flaser_fov: bool,
}

/// Reads a Carmen-style log from `reader`; `name` is used in messages.
pub fn read_carmen_from<R: BufRead>(
    mut reader: R,
    name: &str,
    opts: &ReadOptions,
) -> Result<Log, LogError> {
    if let Some((option, expected)) = opts.invalid() {
        return Err(LogError::InvalidOption { option, expected });
    }
    let mut r = CarmenReader {
        b: LogBuilder::new(name, opts),
        name: name.to_string(),
        counts: [0; 6],
        last_geometry: None,
        flaser_max_range: f64::INFINITY,
        warned_fov: false,
        warned_flaser_fov: false,
    };
    // While the lines of one batch are handled in order, the next batch's readings
    // are parsed ahead on the pool's other threads.
    let mut batch = LineBatch::new();
    batch.fill(&mut reader);
    let mut ahead = prescan(&batch);
    let mut next = LineBatch::new();
    let mut line_no: u64 = 0;
    loop {
        let more = !batch.last;
        if more {
            next.fill(&mut reader);
        }
        let (handled, next_ahead) = rayon::join(
            || r.batch(&batch, &ahead, &mut line_no),
            || {
                if more {
                    prescan(&next)
                } else {
                    Prescan::default()
                }
            },
        );
        handled?;
        if let Some(e) = batch.error.take() {
            return Err(LogError::io(name, e));
        }
        if !more {
            break;
        }
        std::mem::swap(&mut batch, &mut next);
        ahead = next_ahead;
    }
    r.b.log.stats.lines = line_no;
    for (k, (_, msg)) in MESSAGES.iter().enumerate() {
        if r.counts[k] > 0 {
            r.b.log.stats.messages.insert(msg.to_string(), r.counts[k]);
        }
    }
    Ok(r.b.finish())
}

impl CarmenReader<'_> {
    /// Handles the lines of `batch` in order, numbering them on from `line_no`;
    /// `ahead`: their readings parsed ahead.
    fn batch(
        &mut self,
        batch: &LineBatch,
        ahead: &Prescan,
        line_no: &mut u64,
    ) -> Result<(), LogError> {
        for (k, (_, read)) in batch.lines.iter().enumerate() {
            *line_no += 1;
            let text = batch.line(k);
            match *read {
                Line::Nul(column) => {
                    return Err(LogError::NotText {
                        file: self.name.clone(),
                        line: *line_no,
                        detail: format!(
                            "a NUL byte at column {} (binary data; expected Carmen-style \
                             text or a JSON log)",
                            column + 1
                        ),
                    })
                }
                Line::TooLong => {
                    let head = printable(&text[..text.len().min(40)], 20);
                    let err = LogError::parse(
                        &self.name,
                        *line_no,
                        "line",
                        format!(
                            "expected a line of at most {MAX_LINE_BYTES} bytes, found a \
                             longer one starting `{head}`"
                        ),
                    );
                    self.b.reject(err)?;
                }
                _ => self.line(text, *line_no, ahead.get(k))?,
            }
        }
        Ok(())
    }

    /// Handles one line (with its `\n`, if any); `ready`: its readings, parsed ahead.
    fn line(&mut self, text: &[u8], line: u64, ready: Option<Ready<'_>>) -> Result<(), LogError> {
        let mut tokens = Tokens::new(text);
        let Some(first) = tokens.next() else {
            self.b.log.stats.blank += 1;
            return Ok(());
        };
        if first[0] == b'#' {
            self.b.log.stats.comments += 1;
            return Ok(());
        }
        let Some(msg) = Message::from_name(first) else {
            let unknown = &mut self.b.log.stats.unknown;
            let mut name = printable(first, 40);
            if !unknown.contains_key(&name) && unknown.len() >= MAX_UNKNOWN_NAMES {
                name = OTHER_UNKNOWN.to_string();
            }
            *unknown.entry(name).or_insert(0) += 1;
            return Ok(());
        };
        let mut f = Fields { tokens };
        let result = match msg {
            Message::Param => self.param(&mut f, line),
            Message::Encoder => self.encoder(&mut f, line),
            Message::RawLaser1 | Message::RobotLaser1 => self.laser(&mut f, msg, line, ready),
            Message::FLaser => self.flaser(&mut f, line, ready),
            Message::Odom => self.odom(&mut f, line),
        };
        match result {
            Ok(()) => {
                self.counts[msg as usize] += 1;
                Ok(())
            }
            Err(e) => {
                let expected = match msg.fixed_fields() {
                    Some(fields) => {
                        let want = fields.split(' ').count();
                        let found = Tokens::new(text).count() - 1;
                        if found == want {
                            e.describe()
                        } else {
                            format!(
                                "expected {want} fields ({fields}), found {found}: {}",
                                e.describe()
                            )
                        }
                    }
                    None => e.describe(),
                };
                let err = LogError::parse(&self.name, line, msg.name(), expected);
                self.b.reject(err)
            }
        }
    }

    /// `timestamp hostname logger_timestamp` and the end of the line.
    fn trailer(f: &mut Fields<'_>) -> Result<f64, FieldError> {
        let t = f.finite_f64("timestamp")?;
        f.token("hostname")?;
        f.f64("logger_timestamp")?;
        f.end("logger_timestamp")?;
        Ok(t)
    }

    fn param(&mut self, f: &mut Fields<'_>, line: u64) -> Result<(), FieldError> {
        let name = f.token("parameter name")?;
        let value_token = f.token("parameter value")?;
        let value = || crate::number::parse_f64(value_token);
        let bad = |what: &str| FieldError::new(what, Some(value_token));
        let params = &mut self.b.log.params;
        match name {
            b"robot_wheel_ticks_per_revolution" => {
                let v = value()
                    .filter(|v| v.is_finite() && *v > 0.0)
                    .ok_or_else(|| bad("ticks per revolution (a positive number)"))?;
                params.ticks_per_revolution = Some((v, ValueSource::LogParam { line }));
            }
            b"robot_encoder_modulus" => {
                let v = value()
                    .filter(|v| is_valid_modulus(*v))
                    .ok_or_else(|| bad("encoder modulus (an integer between 2 and 2^62)"))?;
                params.encoder_modulus = Some(v);
            }
            b"laser_front_laser_min_range" => {
                let v = value()
                    .filter(|v| v.is_finite() && *v >= 0.0)
                    .ok_or_else(|| bad("minimum range (a finite number ≥ 0, m)"))?;
                params.laser_min_range = v;
            }
            b"laser_front_laser_fov" => {
                let v = value()
                    .filter(|v| v.is_finite() && *v > 0.0)
                    .ok_or_else(|| bad("field of view (a positive number, rad)"))?;
                params.flaser_fov = Some(v);
            }
            b"laser_front_laser_resolution" => {
                let v = value()
                    .filter(|v| v.is_finite() && *v > 0.0)
                    .ok_or_else(|| bad("angular resolution (a positive number, rad)"))?;
                params.flaser_resolution = Some(v);
            }
            b"laser_front_laser_time_increment" => {
                let v = value()
                    .filter(|v| v.is_finite() && v.abs() < 1.0)
                    .ok_or_else(|| {
                        bad("time between rays (a finite number of seconds, |x| < 1)")
                    })?;
                params.laser_time_increment = Some(v);
            }
            b"laser_front_laser_max_range" => {
                let v = value()
                    .filter(|v| *v > 0.0)
                    .ok_or_else(|| bad("maximum range (a positive number, m)"))?;
                self.flaser_max_range = v;
            }
            _ => {}
        }
        let params = &mut self.b.log.params;
        let name = printable(name, 80);
        let value = printable(value_token, 80);
        params.all.insert(name, value);
        Ok(())
    }

    fn encoder(&mut self, f: &mut Fields<'_>, line: u64) -> Result<(), FieldError> {
        let left = f.i64("left_ticks")?;
        let right = f.i64("right_ticks")?;
        let t = Self::trailer(f)?;
        self.b
            .add_encoder(t, left, right, line)
            .map_err(|e| FieldError::new(e, None))
    }

    fn odom(&mut self, f: &mut Fields<'_>, line: u64) -> Result<(), FieldError> {
        let x = f.f64("x")?;
        let y = f.f64("y")?;
        let theta = f.f64("theta")?;
        let tv = f.f64("tv")?;
        let rv = f.f64("rv")?;
        let accel = f.f64("accel")?;
        let t = Self::trailer(f)?;
        self.b.add_odom(OdomRecord {
            t,
            pose: Pose2 { x, y, theta },
            tv,
            rv,
            accel,
            line,
        });
        Ok(())
    }

    /// RAWLASER1 and ROBOTLASER1.
    fn laser(
        &mut self,
        f: &mut Fields<'_>,
        msg: Message,
        line: u64,
        ready: Option<Ready<'_>>,
    ) -> Result<(), FieldError> {
        let h = LaserFields {
            laser_type: f.i32("laser_type")?,
            start_angle: f.finite_f64("start_angle")?,
            fov: f.finite_f64("field_of_view")?,
            resolution: f.finite_f64("angular_resolution")?,
            max_range: f.f64("maximum_range").and_then(|v| {
                if v.is_nan() {
                    Err(FieldError::new("maximum_range (a number)", Some(b"nan")))
                } else {
                    Ok(v)
                }
            })?,
            min_range: self.min_range(),
            accuracy: f.f64("accuracy")?,
            remission_mode: f.i32("remission_mode")?,
        };
        let n = f.count("num_readings")?;
        let store = &mut self.b.log.scans;
        let (r0, m0) = (store.ranges.len(), store.remissions.len());
        let body = Self::laser_body(f, msg, n, ready, &mut store.ranges, &mut store.remissions);
        let t = match body {
            Ok(t) => t,
            Err(e) => {
                store.ranges.truncate(r0);
                store.remissions.truncate(m0);
                return Err(e);
            }
        };
        let k = store.remissions.len() - m0;
        let n_f = n.saturating_sub(1) as f64;
        if !self.warned_fov && (h.fov - n_f * h.resolution).abs() > 1e-6 + 1e-4 * h.fov.abs() {
            self.warned_fov = true;
            self.b.warn(format!(
                "{}: line {line}: {} field_of_view {} disagrees with (num_readings − 1) · \
                 angular_resolution = {}; the resolution is used (warned once)",
                self.name,
                msg.name(),
                h.fov,
                n_f * h.resolution
            ));
        }
        let kind = if msg == Message::RawLaser1 {
            ScanKind::RawLaser1
        } else {
            ScanKind::RobotLaser1
        };
        let g = self.geometry_for(&h, n);
        self.b.check_order(Stream::Scan, t, line);
        self.b.log.scans.push_meta(t, g, n, k, kind, line);
        Ok(())
    }

    /// Readings, remissions, (ROBOTLASER1 poses,) trailer. Returns the timestamp.
    fn laser_body(
        f: &mut Fields<'_>,
        msg: Message,
        n: usize,
        ready: Option<Ready<'_>>,
        ranges: &mut Vec<f32>,
        remissions: &mut Vec<f32>,
    ) -> Result<f64, FieldError> {
        let explain = |e: FieldError, f: &Fields<'_>, k: Option<usize>| FieldError {
            expected: format!(
                "{} (num_readings = {n}{}; {} token(s) left on the line)",
                e.expected,
                k.map_or(String::new(), |k| format!(", num_remissions = {k}")),
                f.tokens.count_remaining()
            ),
            found: e.found,
        };
        Self::readings(f, n, ready, ranges).map_err(|e| explain(e, f, None))?;
        let k = f.count("num_remissions").map_err(|e| explain(e, f, None))?;
        for _ in 0..k {
            remissions.push(f.f32("remission").map_err(|e| explain(e, f, Some(k)))?);
        }
        if msg == Message::RobotLaser1 {
            for what in [
                "laser_pose_x",
                "laser_pose_y",
                "laser_pose_theta",
                "robot_pose_x",
                "robot_pose_y",
                "robot_pose_theta",
                "laser_tv",
                "laser_rv",
                "forward_safety_dist",
                "side_safety_dist",
                "turn_axis",
            ] {
                f.f64(what).map_err(|e| explain(e, f, Some(k)))?;
            }
        }
        Self::trailer(f).map_err(|e| explain(e, f, Some(k)))
    }

    /// The `n` range readings that come next on the line, appended to `ranges`: the
    /// ones parsed ahead when they start where the line's tokens are now (then they
    /// are the same tokens, parsed by the same function), else parsed here.
    fn readings(
        f: &mut Fields<'_>,
        n: usize,
        ready: Option<Ready<'_>>,
        ranges: &mut Vec<f32>,
    ) -> Result<(), FieldError> {
        if let Some(r) = ready.filter(|r| r.start == f.tokens.position() && r.values.len() == n) {
            ranges.extend_from_slice(r.values);
            f.tokens.resume_at(r.end);
            return Ok(());
        }
        for _ in 0..n {
            ranges.push(f.f32("range reading")?);
        }
        Ok(())
    }

    /// Minimum range of the scans read now: the reader's option, else the log's PARAM.
    fn min_range(&self) -> f64 {
        self.b
            .opts
            .min_range
            .unwrap_or(self.b.log.params.laser_min_range)
    }

    /// The index of the geometry described by `h` with `n` rays, reusing a stored one.
    fn geometry_for(&mut self, h: &LaserFields, n: usize) -> u32 {
        let fits = |g: &ScanGeometry| g.has_fields(h, n);
        let store = &mut self.b.log.scans;
        if let Some(i) = self.last_geometry {
            if fits(&store.geometries[i as usize]) {
                return i;
            }
        }
        let i = match store.geometries.iter().position(fits) {
            Some(i) => i as u32,
            None => {
                store.geometries.push(ScanGeometry::new(*h, n));
                (store.geometries.len() - 1) as u32
            }
        };
        self.last_geometry = Some(i);
        i
    }

    fn flaser(
        &mut self,
        f: &mut Fields<'_>,
        line: u64,
        ready: Option<Ready<'_>>,
    ) -> Result<(), FieldError> {
        let n = f.count("num_readings")?;
        let store = &mut self.b.log.scans;
        let r0 = store.ranges.len();
        let body = (|| {
            Self::readings(f, n, ready, &mut store.ranges)?;
            for what in ["x", "y", "theta", "odom_x", "odom_y", "odom_theta"] {
                f.f64(what)?;
            }
            Self::trailer(f)
        })();
        let t = match body {
            Ok(t) => t,
            Err(e) => {
                store.ranges.truncate(r0);
                return Err(FieldError {
                    expected: format!(
                        "{} (num_readings = {n}; {} token(s) left on the line)",
                        e.expected,
                        f.tokens.count_remaining()
                    ),
                    found: e.found,
                });
            }
        };
        let params = &self.b.log.params;
        let fov = params.flaser_fov.unwrap_or(std::f64::consts::PI);
        let n_f = n.saturating_sub(1) as f64;
        let resolution = match params.flaser_resolution {
            Some(res) => {
                if !self.warned_flaser_fov
                    && params.flaser_fov.is_some()
                    && (fov - n_f * res).abs() > 1e-6 + 1e-4 * fov
                {
                    self.warned_flaser_fov = true;
                    self.b.warn(format!(
                        "{}: line {line}: FLASER field of view {fov} (PARAM) disagrees with \
                         (num_readings − 1) · resolution = {}; the resolution is used \
                         (warned once)",
                        self.name,
                        n_f * res
                    ));
                }
                res
            }
            None if n > 1 => fov / n_f,
            None => 0.0,
        };
        let h = LaserFields {
            laser_type: 0,
            start_angle: -0.5 * n_f * resolution,
            fov: n_f * resolution,
            resolution,
            max_range: self.flaser_max_range,
            min_range: self.min_range(),
            accuracy: 0.0,
            remission_mode: 0,
        };
        let g = self.geometry_for(&h, n);
        self.b.check_order(Stream::Scan, t, line);
        self.b
            .log
            .scans
            .push_meta(t, g, n, 0, ScanKind::FLaser, line);
        Ok(())
    }
}
