//! What `odocal info` reports about a log: counts per message kind, time span, scan
//! geometry, encoder rate, where ticks per revolution came from, unknown and skipped
//! lines.

use crate::model::{Log, ValueSource};
use serde::Serialize;
use std::collections::BTreeMap;
use std::fmt;

/// One distinct scan geometry and how many scans use it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GeometrySummary {
    /// Number of rays.
    pub rays: usize,
    /// Angle of the first ray (rad).
    pub start_angle: f64,
    /// Angle between consecutive rays (rad).
    pub resolution: f64,
    /// Field of view as logged (rad).
    pub fov: f64,
    /// Maximum range (m); `null` in JSON when unbounded.
    pub max_range: Option<f64>,
    /// Minimum range (m).
    pub min_range: f64,
    /// Laser type code (2 = Hokuyo URG).
    pub laser_type: i32,
    /// Scans with this geometry.
    pub scans: usize,
}

impl GeometrySummary {
    /// True when `other` describes the same rays (everything but the scan count).
    fn same_shape(&self, other: &GeometrySummary) -> bool {
        GeometrySummary {
            scans: other.scans,
            ..self.clone()
        } == *other
    }
}

impl GeometrySummary {
    /// The rays in words (count, angles, range), without the Carmen laser type: what
    /// a `sensor_msgs/LaserScan` says of them.
    pub fn rays_text(&self) -> String {
        format!(
            "{} rays from {:.6} rad every {:.8} rad (fov {:.6} rad), range ({}, {}) m",
            self.rays,
            self.start_angle,
            self.resolution,
            self.fov,
            sensor_value(self.min_range),
            self.max_range.map_or("∞".to_string(), sensor_value),
        )
    }
}

impl fmt::Display for GeometrySummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}, laser type {}: {} scans",
            self.rays_text(),
            self.laser_type,
            self.scans
        )
    }
}

/// A value as text with the precision it was recorded with: a value that is exactly a
/// 32-bit float (a ROS message's `float32` field) with the digits of an `f32`
/// (0.12, not 0.11999999731779099), any other with those of an `f64`.
pub fn sensor_value(x: f64) -> String {
    let narrow = x as f32;
    if f64::from(narrow) == x {
        narrow.to_string()
    } else {
        x.to_string()
    }
}

/// One skipped line (lenient mode).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SkippedLine {
    /// 1-based line number.
    pub line: u64,
    /// Why it was skipped.
    pub error: String,
}

/// A description of a log, printable as text or JSON.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LogSummary {
    /// The file it was read from.
    pub source: String,
    /// Lines read.
    pub lines: u64,
    /// Accepted lines per known message kind.
    pub messages: BTreeMap<String, u64>,
    /// Number of scans (all kinds).
    pub scans: usize,
    /// Number of encoder records.
    pub encoder_records: usize,
    /// Number of ODOM records.
    pub odom_records: usize,
    /// Comment lines.
    pub comments: u64,
    /// Blank lines.
    pub blank_lines: u64,
    /// Unknown message name → count (skipped, not errors).
    pub unknown: BTreeMap<String, u64>,
    /// Malformed lines skipped (lenient mode).
    pub skipped_lines: u64,
    /// The first few skipped lines.
    pub first_skipped: Vec<SkippedLine>,
    /// Earliest timestamp over all records (s).
    pub start_time: Option<f64>,
    /// Latest timestamp over all records (s).
    pub end_time: Option<f64>,
    /// `end_time − start_time` (s), 0 for an empty log.
    pub duration_s: f64,
    /// Rays per scan of the most used geometry (`null` without scans).
    pub rays_per_scan: Option<usize>,
    /// Every distinct geometry.
    pub geometries: Vec<GeometrySummary>,
    /// Scans per second over the laser stream's span.
    pub scan_rate_hz: Option<f64>,
    /// Encoder records per second over the encoder stream's span.
    pub encoder_rate_hz: Option<f64>,
    /// Odometry (`ODOM`) records per second over their span.
    pub odom_rate_hz: Option<f64>,
    /// Encoder ticks per wheel revolution, when known.
    pub ticks_per_revolution: Option<f64>,
    /// Where it came from.
    pub ticks_per_revolution_source: Option<ValueSource>,
    /// Encoder counter modulus, when counters wrap.
    pub encoder_modulus: Option<f64>,
    /// Wrap-arounds undone.
    pub encoder_wraps: u64,
    /// Invalid readings over all scans.
    pub invalid_readings: u64,
    /// Fraction of readings that are invalid.
    pub invalid_fraction: f64,
    /// Records out of order within their stream (stream → count).
    pub out_of_order: BTreeMap<String, u64>,
    /// Warnings from the reader.
    pub warnings: Vec<String>,
}

/// Records per second over a span, for `n` records from `t0` to `t1`.
fn rate(n: usize, t0: Option<f64>, t1: Option<f64>) -> Option<f64> {
    match (t0, t1) {
        (Some(a), Some(b)) if n >= 2 && b > a => Some((n - 1) as f64 / (b - a)),
        _ => None,
    }
}

impl LogSummary {
    /// Summarizes a log as read.
    pub fn of(log: &Log) -> LogSummary {
        let st = &log.stats;
        let scans = &log.scans;
        let enc_span = (
            log.encoders.first().map(|e| e.t),
            log.encoders.last().map(|e| e.t),
        );
        let scan_span = (
            scans.scans.first().map(|s| s.t),
            scans.scans.last().map(|s| s.t),
        );
        let odom_span = (log.odom.first().map(|o| o.t), log.odom.last().map(|o| o.t));
        let starts = [enc_span.0, scan_span.0, odom_span.0];
        let ends = [enc_span.1, scan_span.1, odom_span.1];
        let start_time = starts.iter().flatten().copied().reduce(f64::min);
        let end_time = ends.iter().flatten().copied().reduce(f64::max);
        let mut per_geometry = vec![0usize; scans.geometries.len()];
        for s in &scans.scans {
            per_geometry[s.geometry as usize] += 1;
        }
        let mut geometries: Vec<GeometrySummary> = Vec::new();
        let described = scans
            .geometries
            .iter()
            .zip(&per_geometry)
            .map(|(g, &n)| GeometrySummary {
                rays: g.num_readings(),
                start_angle: g.start_angle,
                resolution: g.resolution,
                fov: g.fov,
                max_range: Some(g.max_range).filter(|r| r.is_finite()),
                min_range: g.min_range,
                laser_type: g.laser_type,
                scans: n,
            });
        // Geometries that differ only in what the summary does not show (a laser that
        // writes its own sweep timing in every message) are one line, their scans summed.
        for g in described {
            match geometries.iter_mut().find(|s| s.same_shape(&g)) {
                Some(same) => same.scans += g.scans,
                None => geometries.push(g),
            }
        }
        let rays_per_scan = geometries
            .iter()
            .filter(|g| g.scans > 0)
            .max_by_key(|g| g.scans)
            .map(|g| g.rays);
        let total_readings = scans.iter().map(|s| s.ranges.len()).sum::<usize>();
        LogSummary {
            source: st.source.clone(),
            lines: st.lines,
            messages: st.messages.clone(),
            scans: scans.len(),
            encoder_records: log.encoders.len(),
            odom_records: log.odom.len(),
            comments: st.comments,
            blank_lines: st.blank,
            unknown: st.unknown.clone(),
            skipped_lines: st.skipped_lines,
            first_skipped: st
                .first_skipped
                .iter()
                .map(|(line, error)| SkippedLine {
                    line: *line,
                    error: error.clone(),
                })
                .collect(),
            start_time,
            end_time,
            duration_s: match (start_time, end_time) {
                (Some(a), Some(b)) => b - a,
                _ => 0.0,
            },
            rays_per_scan,
            geometries,
            scan_rate_hz: rate(scans.len(), scan_span.0, scan_span.1),
            encoder_rate_hz: rate(log.encoders.len(), enc_span.0, enc_span.1),
            odom_rate_hz: rate(log.odom.len(), odom_span.0, odom_span.1),
            ticks_per_revolution: log.params.ticks_per_revolution.as_ref().map(|p| p.0),
            ticks_per_revolution_source: log
                .params
                .ticks_per_revolution
                .as_ref()
                .map(|p| p.1.clone()),
            encoder_modulus: log.params.encoder_modulus,
            encoder_wraps: st.encoder_wraps,
            invalid_readings: st.invalid_readings,
            invalid_fraction: if total_readings > 0 {
                st.invalid_readings as f64 / total_readings as f64
            } else {
                0.0
            },
            out_of_order: st.out_of_order.clone(),
            warnings: st.warnings.clone(),
        }
    }
}

impl fmt::Display for ValueSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ValueSource::LogParam { line } => write!(f, "PARAM on line {line}"),
            ValueSource::CommandLine => write!(f, "command line"),
            ValueSource::Default => write!(f, "default"),
            ValueSource::Convention => write!(f, "wheel angles in radians, fixed scale"),
        }
    }
}

impl fmt::Display for LogSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "log:            {}", self.source)?;
        writeln!(f, "lines:          {}", self.lines)?;
        writeln!(f, "messages:")?;
        for (name, n) in &self.messages {
            writeln!(f, "  {name:<13} {n}")?;
        }
        writeln!(
            f,
            "records:        {} scans, {} encoder, {} odom",
            self.scans, self.encoder_records, self.odom_records
        )?;
        writeln!(
            f,
            "comments:       {} (+ {} blank lines)",
            self.comments, self.blank_lines
        )?;
        if self.unknown.is_empty() {
            writeln!(f, "unknown:        none")?;
        } else {
            let list: Vec<String> = self
                .unknown
                .iter()
                .map(|(k, v)| format!("{k} ×{v}"))
                .collect();
            writeln!(f, "unknown:        {} (skipped)", list.join(", "))?;
        }
        writeln!(f, "skipped lines:  {}", self.skipped_lines)?;
        for s in &self.first_skipped {
            writeln!(f, "  line {}: {}", s.line, s.error)?;
        }
        match (self.start_time, self.end_time) {
            (Some(a), Some(b)) => {
                writeln!(f, "time span:      {a} … {b} ({:.3} s)", self.duration_s)?
            }
            _ => writeln!(f, "time span:      no timestamped records")?,
        }
        for g in &self.geometries {
            writeln!(f, "scan geometry:  {g}")?;
        }
        let hz = |r: Option<f64>| r.map_or("n/a".to_string(), |r| format!("{r:.2} Hz"));
        writeln!(f, "scan rate:      {}", hz(self.scan_rate_hz))?;
        if self.encoder_records == 0 && self.odom_records > 0 {
            // Odometry-only data: no encoder counts, so no ticks per revolution.
            writeln!(f, "odometry rate:  {}", hz(self.odom_rate_hz))?;
            writeln!(
                f,
                "wheels:         odometry only (ODOM poses, no ENCODER records): calibrate \
                 recovers the wheel rotations with --nominal r_L,r_R,b"
            )?;
        } else {
            writeln!(f, "encoder rate:   {}", hz(self.encoder_rate_hz))?;
            match (
                &self.ticks_per_revolution,
                &self.ticks_per_revolution_source,
            ) {
                (Some(t), Some(src)) => writeln!(f, "ticks/rev:      {t} ({src})")?,
                _ => writeln!(
                    f,
                    "ticks/rev:      unknown (pass --ticks-per-rev X or add \
                     `PARAM robot_wheel_ticks_per_revolution X`)"
                )?,
            }
        }
        if let Some(m) = self.encoder_modulus {
            writeln!(f, "encoder wraps:  {} (modulus {m})", self.encoder_wraps)?;
        }
        writeln!(
            f,
            "invalid:        {} readings ({:.2}%)",
            self.invalid_readings,
            100.0 * self.invalid_fraction
        )?;
        for (stream, n) in &self.out_of_order {
            writeln!(f, "out of order:   {n} {stream} records (sorted)")?;
        }
        for w in &self.warnings {
            writeln!(f, "warning:        {w}")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{read_carmen_from, ReadOptions};

    #[test]
    fn odometry_only_data_speak_of_odometry_not_ticks() {
        // Before: "encoder rate: n/a" and "ticks/rev: unknown (pass --ticks-per-rev X …)",
        // advice that cannot help a log without encoder counts.
        let mut text = String::new();
        for i in 0..=50 {
            let t = 100.0 + i as f64 * 0.02;
            text.push_str(&format!(
                "ODOM {} 0 0 0.1 0 0 {t} h {t}\n",
                i as f64 * 0.002
            ));
        }
        let log =
            read_carmen_from(text.as_bytes(), "odom.log", &ReadOptions::default()).expect("reads");
        let s = LogSummary::of(&log);
        assert!((s.odom_rate_hz.unwrap() - 50.0).abs() < 1e-6, "{s:?}");
        let shown = s.to_string();
        assert!(shown.contains("odometry rate:  50.00 Hz"), "{shown}");
        assert!(shown.contains("--nominal r_L,r_R,b"), "{shown}");
        for word in ["ticks/rev", "encoder rate", "--ticks-per-rev"] {
            assert!(!shown.contains(word), "{word:?} in {shown}");
        }
    }

    #[test]
    fn summary_counts_rates_and_sources() {
        let mut text =
            String::from("PARAM robot_wheel_ticks_per_revolution 2764.8 h 0\nSYNC x\nSYNC y\n");
        for i in 0..=50 {
            text.push_str(&format!(
                "ENCODER {i} {i} {} h 0\n",
                100.0 + i as f64 * 0.02
            ));
        }
        for i in 0..=10 {
            text.push_str(&format!(
                "RAWLASER1 2 -0.5 1 0.5 4 0.01 0 3 1 0 2 0 {} h 0\n",
                100.05 + i as f64 * 0.1
            ));
        }
        text.push_str("ODOM 0 0 0 0 0 0 99.5 h 0\nENCODER bad\n");
        let log = read_carmen_from(text.as_bytes(), "s.log", &ReadOptions::lenient()).unwrap();
        let s = LogSummary::of(&log);
        assert_eq!((s.scans, s.encoder_records, s.odom_records), (11, 51, 1));
        assert_eq!(s.unknown["SYNC"], 2);
        assert_eq!(s.skipped_lines, 1);
        assert_eq!(s.first_skipped[0].line, 67);
        assert_eq!(s.start_time, Some(99.5));
        assert_eq!(s.end_time, Some(100.05 + 10.0 * 0.1));
        assert!((s.duration_s - 1.55).abs() < 1e-9);
        assert!((s.encoder_rate_hz.unwrap() - 50.0).abs() < 1e-6);
        assert!((s.scan_rate_hz.unwrap() - 10.0).abs() < 1e-6);
        assert_eq!(s.rays_per_scan, Some(3));
        assert_eq!(s.ticks_per_revolution, Some(2764.8));
        assert_eq!(
            s.ticks_per_revolution_source,
            Some(ValueSource::LogParam { line: 1 })
        );
        assert_eq!(s.invalid_readings, 11);
        let json = serde_json::to_value(&s).unwrap();
        for key in [
            "scans",
            "encoder_records",
            "odom_records",
            "unknown",
            "skipped_lines",
            "duration_s",
            "rays_per_scan",
            "ticks_per_revolution",
        ] {
            assert!(json.get(key).is_some(), "missing {key}");
        }
        assert_eq!(json["unknown"]["SYNC"], 2);
        assert_eq!(json["ticks_per_revolution_source"]["log_param"]["line"], 1);
        let text = s.to_string();
        assert!(
            text.contains("ticks/rev:      2764.8 (PARAM on line 1)"),
            "{text}"
        );
        assert!(text.contains("encoder rate:   50.00 Hz"), "{text}");
    }
}
