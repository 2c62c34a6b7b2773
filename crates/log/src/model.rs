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
    /// Ray angles (rad), one per reading.
    pub angles: Arc<[f64]>,
}

impl ScanGeometry {
    /// A geometry with its angle table computed from `start_angle` and `resolution`.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        laser_type: i32,
        start_angle: f64,
        fov: f64,
        resolution: f64,
        max_range: f64,
        min_range: f64,
        accuracy: f64,
        remission_mode: i32,
        num_readings: usize,
    ) -> Self {
        let angles: Arc<[f64]> = (0..num_readings)
            .map(|i| start_angle + i as f64 * resolution)
            .collect();
        ScanGeometry {
            laser_type,
            start_angle,
            resolution,
            fov,
            max_range,
            min_range,
            accuracy,
            remission_mode,
            angles,
        }
    }

    /// The Hokuyo URG-04LX as logged by the reference robot: 681 rays, 2π/1024 rad
    /// apart, starting at −340·2π/1024, maximum range 4 m.
    pub fn urg_04lx() -> Self {
        let res = std::f64::consts::TAU / 1024.0;
        ScanGeometry::new(2, -340.0 * res, 680.0 * res, res, 4.0, 0.02, 0.01, 0, 681)
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
            ranges: &self.ranges[m.offset..m.offset + n],
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
        debug_assert_eq!(ranges.len(), geometry.num_readings());
        let gi = match self.geometries.iter().position(|g| g == geometry) {
            Some(i) => i,
            None => {
                self.geometries.push(geometry.clone());
                self.geometries.len() - 1
            }
        };
        let offset = self.ranges.len();
        self.ranges.extend_from_slice(ranges);
        self.scans.push(ScanMeta {
            t,
            geometry: gi as u32,
            offset,
            kind,
            line,
        });
    }
}

/// What the reader saw besides the data: counts, skipped lines, warnings.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ReadStats {
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
