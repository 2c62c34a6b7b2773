//! The in-memory form of a log: what the reader produces and the writer consumes.

use std::collections::BTreeMap;
use std::sync::Arc;

/// Where a configuration value came from.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ValueSource {
    /// A `PARAM` line of the log, with its 1-based line number.
    LogParam {
        /// 1-based line number of the (last) PARAM line that set it.
        line: u64,
    },
    /// The command line (or the caller of the library).
    CommandLine,
    /// The format's default.
    Default,
    /// Fixed by the reader's convention: wheel angles read in radians (ROS joint states,
    /// odometry) are counted in [`crate::WHEEL_TICKS_PER_REVOLUTION`] ticks per turn.
    Convention,
}

/// Configuration gathered from `PARAM` lines (later lines override earlier ones).
#[derive(Debug, Clone, PartialEq)]
pub struct Params {
    /// Encoder ticks per wheel revolution, and where it came from.
    pub ticks_per_revolution: Option<(f64, ValueSource)>,
    /// Counters wrap modulo this value; `None` means no wrapping.
    pub encoder_modulus: Option<f64>,
    /// Readings at or below this range (m) are invalid.
    pub laser_min_range: f64,
    /// Field of view (rad) for `FLASER` scans, when given by a PARAM.
    pub flaser_fov: Option<f64>,
    /// Angular resolution (rad) for `FLASER` scans, when given by a PARAM.
    pub flaser_resolution: Option<f64>,
    /// Seconds between two consecutive rays of a scan (`laser_front_laser_time_increment`
    /// or the command line); `None`: every ray at the scan's timestamp.
    pub laser_time_increment: Option<f64>,
    /// Every PARAM seen, name → last value token.
    pub all: BTreeMap<String, String>,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            ticks_per_revolution: None,
            encoder_modulus: None,
            laser_min_range: 0.02,
            flaser_fov: None,
            flaser_resolution: None,
            laser_time_increment: None,
            all: BTreeMap::new(),
        }
    }
}

/// One `ENCODER` record: cumulative wheel ticks at a time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EncoderRecord {
    /// Acquisition timestamp (s), on the encoder clock.
    pub t: f64,
    /// Cumulative left ticks, unwrapped (see `robot_encoder_modulus`).
    pub left: i64,
    /// Cumulative right ticks, unwrapped.
    pub right: i64,
    /// 1-based line number in the source (0 when not from a file).
    pub line: u64,
}

/// One `ODOM` record: the firmware's own integrated pose (never a measurement).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OdomRecord {
    /// Acquisition timestamp (s).
    pub t: f64,
    /// Integrated pose (m, m, rad).
    pub pose: odocal_geom::Pose2,
    /// Translational velocity (m/s).
    pub tv: f64,
    /// Rotational velocity (rad/s).
    pub rv: f64,
    /// Acceleration field as logged.
    pub accel: f64,
    /// 1-based line number in the source.
    pub line: u64,
}

/// The message kind a scan was read from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
pub enum ScanKind {
    /// `RAWLASER1`.
    RawLaser1,
    /// `ROBOTLASER1`.
    RobotLaser1,
    /// `FLASER` (geometry from PARAMs).
    FLaser,
    /// The original package's JSON log.
    Json,
    /// A `sensor_msgs/LaserScan` message of a ROS bag.
    LaserScan,
}

/// The geometry shared by scans from one sensor configuration.
///
/// Ray `i` points at `start_angle + i · resolution` (rad, sensor frame, CCW). The angle
/// table is computed once per distinct geometry and shared by all its scans.
#[derive(Debug, Clone, PartialEq)]
pub struct ScanGeometry {
    /// Laser type code as logged (2 = Hokuyo URG); 0 when unknown.
    pub laser_type: i32,
    /// Angle of ray 0 (rad).
    pub start_angle: f64,
    /// Angle between consecutive rays (rad).
    pub resolution: f64,
    /// Field of view as logged (rad).
    pub fov: f64,
    /// Maximum range (m): readings at or above it are invalid.
    pub max_range: f64,
    /// Minimum range (m): readings at or below it are invalid.
    pub min_range: f64,
    /// Accuracy field as logged (m).
    pub accuracy: f64,
    /// Remission mode as logged.
    pub remission_mode: i32,
    /// Seconds between two consecutive rays (the sweep; ROS `time_increment`, Carmen
    /// `laser_front_laser_time_increment`). Ray `i` was taken at the scan's timestamp
    /// plus `i · time_increment`; 0 means every ray at the timestamp. Negative values
    /// (a driver that stamps the last ray) are kept as logged.
    pub time_increment: f64,
    /// Seconds between two scans as the driver reports it (ROS `scan_time`); 0 when
    /// unknown.
    pub scan_time: f64,
    /// Ray angles (rad), one per reading.
    pub angles: Arc<[f64]>,
}

/// The fields a laser line logs about its geometry (RAWLASER1 / ROBOTLASER1 order;
/// `min_range` comes from a PARAM or the reader's options): what a [`ScanGeometry`] is
/// built from, before its angle table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LaserFields {
    /// Laser type code (2 = Hokuyo URG); 0 when unknown.
    pub laser_type: i32,
    /// Angle of ray 0 (rad).
    pub start_angle: f64,
    /// Field of view (rad).
    pub fov: f64,
    /// Angle between consecutive rays (rad).
    pub resolution: f64,
    /// Maximum range (m).
    pub max_range: f64,
    /// Minimum range (m).
    pub min_range: f64,
    /// Accuracy field (m).
    pub accuracy: f64,
    /// Remission mode.
    pub remission_mode: i32,
}

/// True when `a` and `b` are the same number, NaN included (geometries compare by bits
/// so that a NaN field cannot make a geometry unequal to itself).
fn same_f64(a: f64, b: f64) -> bool {
    a.to_bits() == b.to_bits()
}

impl ScanGeometry {
    /// A geometry with `num_readings` rays, its angle table computed from the fields
    /// `start_angle` and `resolution`.
    pub fn new(fields: LaserFields, num_readings: usize) -> Self {
        let angles: Arc<[f64]> = (0..num_readings)
            .map(|i| fields.start_angle + i as f64 * fields.resolution)
            .collect();
        ScanGeometry {
            laser_type: fields.laser_type,
            start_angle: fields.start_angle,
            resolution: fields.resolution,
            fov: fields.fov,
            max_range: fields.max_range,
            min_range: fields.min_range,
            accuracy: fields.accuracy,
            remission_mode: fields.remission_mode,
            time_increment: 0.0,
            scan_time: 0.0,
            angles,
        }
    }

    /// The same geometry with the sweep timing set: `time_increment` seconds between
    /// consecutive rays and `scan_time` seconds between scans (0 when unknown).
    pub fn with_timing(mut self, time_increment: f64, scan_time: f64) -> Self {
        self.time_increment = time_increment;
        self.scan_time = scan_time;
        self
    }

    /// Time (s) from the scan's timestamp to ray `i`: `i · time_increment`.
    pub fn ray_time_offset(&self, i: usize) -> f64 {
        i as f64 * self.time_increment
    }

    /// Duration (s) of one sweep, first ray to last: `(n − 1) · time_increment`.
    pub fn sweep_duration(&self) -> f64 {
        self.num_readings().saturating_sub(1) as f64 * self.time_increment
    }

    /// The Hokuyo URG-04LX as logged by the reference robot: 681 rays, 2π/1024 rad
    /// apart, starting at −340·2π/1024, maximum range 4 m.
    pub fn urg_04lx() -> Self {
        let res = std::f64::consts::TAU / 1024.0;
        let fields = LaserFields {
            laser_type: 2,
            start_angle: -340.0 * res,
            fov: 680.0 * res,
            resolution: res,
            max_range: 4.0,
            min_range: 0.02,
            accuracy: 0.01,
            remission_mode: 0,
        };
        ScanGeometry::new(fields, 681)
    }

    /// A geometry with an explicit angle table (rays need not be evenly spaced, as in
    /// the original package's JSON logs). `start_angle`, `resolution` and `fov` are
    /// derived from the first and last angles.
    pub fn from_angles(angles: Vec<f64>, max_range: f64, min_range: f64) -> Self {
        let n = angles.len();
        let start_angle = angles.first().copied().unwrap_or(0.0);
        let fov = if n > 1 {
            angles[n - 1] - start_angle
        } else {
            0.0
        };
        let resolution = if n > 1 { fov / (n - 1) as f64 } else { 0.0 };
        ScanGeometry {
            laser_type: 0,
            start_angle,
            resolution,
            fov,
            max_range,
            min_range,
            accuracy: 0.0,
            remission_mode: 0,
            time_increment: 0.0,
            scan_time: 0.0,
            angles: angles.into(),
        }
    }

    /// True when the angle table is `start_angle + i · resolution` for every ray, so that
    /// a RAWLASER1 line can describe it exactly.
    pub fn is_evenly_spaced(&self) -> bool {
        self.angles
            .iter()
            .enumerate()
            .all(|(i, &a)| same_f64(a, self.start_angle + i as f64 * self.resolution))
    }

    /// True when the logged fields equal `fields` and there are `num_readings` rays (the
    /// angle table is then equal too, being computed from them). Used by the reader to
    /// reuse a geometry without building a new angle table.
    pub fn has_fields(&self, fields: &LaserFields, num_readings: usize) -> bool {
        self.laser_type == fields.laser_type
            && same_f64(self.start_angle, fields.start_angle)
            && same_f64(self.fov, fields.fov)
            && same_f64(self.resolution, fields.resolution)
            && same_f64(self.max_range, fields.max_range)
            && same_f64(self.min_range, fields.min_range)
            && same_f64(self.accuracy, fields.accuracy)
            && self.remission_mode == fields.remission_mode
            && self.num_readings() == num_readings
            && self.time_increment == 0.0
            && self.scan_time == 0.0
    }

    /// Number of readings per scan.
    pub fn num_readings(&self) -> usize {
        self.angles.len()
    }

    /// True when a reading is a valid range: finite, above `min_range` (and not 0),
    /// below `max_range`.
    pub fn is_valid(&self, r: f32) -> bool {
        let r = r as f64;
        r.is_finite() && r > self.min_range && r < self.max_range && r != 0.0
    }

    /// True when two geometries describe the same rays (same angle table and limits).
    pub fn same_rays(&self, other: &ScanGeometry) -> bool {
        self.num_readings() == other.num_readings()
            && self.start_angle == other.start_angle
            && self.resolution == other.resolution
            && self.max_range == other.max_range
            && self.min_range == other.min_range
            && self.time_increment == other.time_increment
    }
}

/// Metadata of one stored scan; its ranges live in [`ScanStore::ranges`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScanMeta {
    /// Acquisition timestamp (s), on the laser clock.
    pub t: f64,
    /// Index into [`ScanStore::geometries`].
    pub geometry: u32,
    /// Offset of the first reading in [`ScanStore::ranges`].
    pub offset: usize,
    /// Message kind it came from.
    pub kind: ScanKind,
    /// 1-based line number in the source (0 when not from a file).
    pub line: u64,
    /// Offset of the first remission in [`ScanStore::remissions`].
    pub remission_offset: usize,
    /// Number of remissions logged with this scan (usually 0).
    pub num_remissions: u32,
}

/// All scans of a log: ranges packed as `f32`, one geometry per distinct sensor setup.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ScanStore {
    /// Distinct geometries.
    pub geometries: Vec<ScanGeometry>,
    /// Per-scan metadata, in file order.
    pub scans: Vec<ScanMeta>,
    /// Every reading of every scan, back to back (m).
    pub ranges: Vec<f32>,
    /// Remissions, when logged (back to back; empty otherwise). Kept, not used.
    pub remissions: Vec<f32>,
}

/// A borrowed view of one scan.
#[derive(Debug, Clone, Copy)]
pub struct ScanRef<'a> {
    /// Acquisition timestamp (s).
    pub t: f64,
    /// Its geometry (angle table, limits).
    pub geometry: &'a ScanGeometry,
    /// Its readings (m), one per angle.
    pub ranges: &'a [f32],
    /// Remission values logged with the scan (usually empty).
    pub remissions: &'a [f32],
    /// Message kind it came from.
    pub kind: ScanKind,
    /// 1-based source line.
    pub line: u64,
}

impl ScanStore {
    /// Number of scans.
    pub fn len(&self) -> usize {
        self.scans.len()
    }

    /// True when there are no scans.
    pub fn is_empty(&self) -> bool {
        self.scans.is_empty()
    }

    /// The `i`-th scan, or `None` past the end.
    pub fn get(&self, i: usize) -> Option<ScanRef<'_>> {
        let m = self.scans.get(i)?;
        let g = &self.geometries[m.geometry as usize];
        let n = g.num_readings();
        Some(ScanRef {
            t: m.t,
            geometry: g,
            ranges: self.ranges.get(m.offset..m.offset + n)?,
            remissions: self
                .remissions
                .get(m.remission_offset..m.remission_offset + m.num_remissions as usize)?,
            kind: m.kind,
            line: m.line,
        })
    }

    /// Iterates over the scans in stored order.
    pub fn iter(&self) -> impl Iterator<Item = ScanRef<'_>> + '_ {
        (0..self.len()).filter_map(move |i| self.get(i))
    }

    /// Appends a scan, reusing an equal geometry when one is stored already.
    ///
    /// `ranges.len()` must equal `geometry.num_readings()`.
    pub fn push(
        &mut self,
        t: f64,
        geometry: &ScanGeometry,
        ranges: &[f32],
        kind: ScanKind,
        line: u64,
    ) {
        self.push_with_remissions(t, geometry, ranges, &[], kind, line);
    }

    /// Appends a scan with its remissions, reusing an equal geometry when one is stored.
    ///
    /// `ranges.len()` must equal `geometry.num_readings()`.
    pub fn push_with_remissions(
        &mut self,
        t: f64,
        geometry: &ScanGeometry,
        ranges: &[f32],
        remissions: &[f32],
        kind: ScanKind,
        line: u64,
    ) {
        debug_assert_eq!(ranges.len(), geometry.num_readings());
        let gi = self.geometry_index(geometry);
        self.ranges.extend_from_slice(ranges);
        self.remissions.extend_from_slice(remissions);
        self.push_meta(t, gi, ranges.len(), remissions.len(), kind, line);
    }

    /// The index of `geometry` in [`ScanStore::geometries`], adding it when new.
    pub fn geometry_index(&mut self, geometry: &ScanGeometry) -> u32 {
        match self.geometries.iter().position(|g| g == geometry) {
            Some(i) => i as u32,
            None => {
                self.geometries.push(geometry.clone());
                (self.geometries.len() - 1) as u32
            }
        }
    }

    /// Records a scan whose `num_ranges` readings and `num_remissions` remissions were
    /// just appended to [`ScanStore::ranges`] and [`ScanStore::remissions`] by the
    /// caller (the reader parses straight into them).
    pub(crate) fn push_meta(
        &mut self,
        t: f64,
        geometry: u32,
        num_ranges: usize,
        num_remissions: usize,
        kind: ScanKind,
        line: u64,
    ) {
        self.scans.push(ScanMeta {
            t,
            geometry,
            offset: self.ranges.len() - num_ranges,
            kind,
            line,
            remission_offset: self.remissions.len() - num_remissions,
            num_remissions: num_remissions as u32,
        });
    }

    /// Readings that are not valid ranges (out of range, 0, non-finite), over all scans.
    pub fn count_invalid_readings(&self) -> u64 {
        use rayon::prelude::*;
        // On the current rayon pool's threads (an integer sum: the same on any number).
        (0..self.len())
            .into_par_iter()
            .filter_map(|i| self.get(i))
            .map(|s| {
                s.ranges
                    .iter()
                    .filter(|&&r| !s.geometry.is_valid(r))
                    .count() as u64
            })
            .sum()
    }

    /// Sorts the scans by timestamp (stable: equal timestamps keep file order). The
    /// ranges stay where they are; only the metadata moves.
    pub fn sort_by_time(&mut self) {
        self.scans.sort_by(|a, b| a.t.total_cmp(&b.t));
    }
}

/// What the reader saw besides the data: counts, skipped lines, warnings.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ReadStats {
    /// The file (or stream name) the log was read from.
    pub source: String,
    /// What kind of source it was (text log or bag): how messages point into it.
    pub origin: crate::Origin,
    /// Total lines read.
    pub lines: u64,
    /// Comment lines (`#`).
    pub comments: u64,
    /// Blank lines.
    pub blank: u64,
    /// Unknown message name → count.
    pub unknown: BTreeMap<String, u64>,
    /// Known messages per name (PARAM, ENCODER, …) → count of lines accepted.
    pub messages: BTreeMap<String, u64>,
    /// Malformed lines skipped in lenient mode.
    pub skipped_lines: u64,
    /// The first few skipped lines: (1-based line, error text).
    pub first_skipped: Vec<(u64, String)>,
    /// Readings found invalid (out of range, 0, non-finite), over all scans.
    pub invalid_readings: u64,
    /// Encoder wrap-arounds undone.
    pub encoder_wraps: u64,
    /// Records out of timestamp order within their own stream (encoder, laser, odom).
    pub out_of_order: BTreeMap<String, u64>,
    /// Warnings worth showing once (e.g. FOV disagreeing with the resolution).
    pub warnings: Vec<String>,
}

/// A whole log in memory.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Log {
    /// Configuration from PARAM lines.
    pub params: Params,
    /// Encoder records, sorted by timestamp.
    pub encoders: Vec<EncoderRecord>,
    /// Firmware odometry records, sorted by timestamp.
    pub odom: Vec<OdomRecord>,
    /// Scans, sorted by timestamp.
    pub scans: ScanStore,
    /// What the reader counted.
    pub stats: ReadStats,
}

impl Log {
    /// Checks that the log holds what calibration needs: at least one ENCODER record,
    /// at least two scans, and ticks per revolution (from a PARAM or the caller).
    /// Returns the ticks per revolution.
    pub fn check_calibration_inputs(&self) -> Result<f64, crate::LogError> {
        let missing = |what| crate::LogError::MissingData {
            file: self.stats.source.clone(),
            what,
        };
        if self.encoders.is_empty() {
            return Err(missing(crate::MissingData::NoEncoderRecords));
        }
        if self.scans.len() < 2 {
            return Err(missing(crate::MissingData::TooFewScans {
                found: self.scans.len(),
            }));
        }
        match &self.params.ticks_per_revolution {
            Some((ticks, _)) => Ok(*ticks),
            None => Err(missing(crate::MissingData::NoTicksPerRevolution)),
        }
    }
}
