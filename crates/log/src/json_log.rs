//! The original calibration package's raw JSON logs: a stream of objects, each with a
//! scan (`timestamp` `[sec, usec]`, `readings`, `theta`) and the encoder counts
//! (`left`, `right`, `leftTimestamp`, `rightTimestamp`).

use crate::builder::{LogBuilder, Stream};
use crate::error::LogError;
use crate::json_stream::for_each_object;
use crate::model::{Log, ScanGeometry, ScanKind};
use crate::options::ReadOptions;
use serde::Deserialize;
use std::io::Read;

/// One object of the stream. Every field is optional so that objects carrying only
/// encoders (or only a scan) are accepted; unknown fields are ignored.
#[derive(Debug, Deserialize)]
struct JsonRecord {
    timestamp: Option<[f64; 2]>,
    readings: Option<Vec<Option<f64>>>,
    theta: Option<Vec<Option<f64>>>,
    valid: Option<Vec<serde_json::Value>>,
    left: Option<f64>,
    right: Option<f64>,
    #[serde(rename = "leftTimestamp")]
    left_timestamp: Option<[f64; 2]>,
    #[serde(rename = "rightTimestamp")]
    right_timestamp: Option<[f64; 2]>,
}

/// `[sec, usec]` → seconds.
fn seconds(t: [f64; 2]) -> f64 {
    t[0] + t[1] * 1e-6
}

/// Name under which objects with neither a scan nor encoders are counted.
const OTHER: &str = "JSON object without scan or encoders";

/// Reads the original package's JSON log from `reader`; `name` is used in messages.
///
/// JSON syntax errors stop the reader in both modes (the stream cannot be resumed);
/// objects with inconsistent content (e.g. `readings` and `theta` of different
/// lengths) are errors in strict mode and skipped in lenient mode.
pub fn read_json_log_from<R: Read>(
    reader: R,
    name: &str,
    opts: &ReadOptions,
) -> Result<Log, LogError> {
    if let Some((option, expected)) = opts.invalid() {
        return Err(LogError::InvalidOption { option, expected });
    }
    let mut b = LogBuilder::new(name, opts);
    let mut objects = 0u64;
    let mut scans = 0u64;
    let mut encoders = 0u64;
    let mut last_geometry: Option<u32> = None;
    for_each_object(
        reader,
        name,
        "JSON",
        "a JSON log object",
        |rec: JsonRecord, line| {
            objects += 1;
            b.log.stats.lines = line;
            match add_record(&mut b, rec, line, &mut last_geometry) {
                Ok((s, e)) => {
                    scans += s as u64;
                    encoders += e as u64;
                    Ok(())
                }
                Err(expected) => b.reject(LogError::parse(name, line, "JSON", expected)),
            }
        },
    )?;
    let stats = &mut b.log.stats;
    stats.messages.insert("JSON objects".into(), objects);
    if scans > 0 {
        stats.messages.insert("JSON scans".into(), scans);
    }
    if encoders > 0 {
        stats.messages.insert("JSON encoders".into(), encoders);
    }
    Ok(b.finish())
}

/// Adds the scan and/or encoder record of one object; says which were present.
fn add_record(
    b: &mut LogBuilder<'_>,
    rec: JsonRecord,
    line: u64,
    last_geometry: &mut Option<u32>,
) -> Result<(bool, bool), String> {
    let has_scan = rec.readings.is_some();
    let has_encoders = rec.left.is_some() || rec.right.is_some();
    if !has_scan && !has_encoders {
        *b.log.stats.unknown.entry(OTHER.into()).or_insert(0) += 1;
        return Ok((false, false));
    }
    // Validate everything before adding anything.
    let scan = match rec.readings {
        Some(readings) => {
            let t = rec
                .timestamp
                .map(seconds)
                .filter(|t| t.is_finite())
                .ok_or("expected \"timestamp\": [sec, usec] with the scan")?;
            let theta = rec
                .theta
                .ok_or("expected \"theta\" (ray angles) with \"readings\"")?;
            if theta.len() != readings.len() {
                return Err(format!(
                    "expected as many \"theta\" as \"readings\", found {} and {}",
                    theta.len(),
                    readings.len()
                ));
            }
            let angles: Option<Vec<f64>> = theta
                .into_iter()
                .map(|a| a.filter(|a| a.is_finite()))
                .collect();
            let angles = angles.ok_or("expected finite numbers in \"theta\"")?;
            let mut ranges: Vec<f32> = readings
                .iter()
                .map(|r| r.map_or(f32::NAN, |r| r as f32))
                .collect();
            if let Some(valid) = rec.valid {
                if valid.len() != ranges.len() {
                    return Err(format!(
                        "expected as many \"valid\" flags as \"readings\", found {} and {}",
                        valid.len(),
                        ranges.len()
                    ));
                }
                for (r, v) in ranges.iter_mut().zip(valid) {
                    let ok = v.as_bool().unwrap_or(false) || v.as_f64().is_some_and(|v| v != 0.0);
                    if !ok {
                        *r = f32::NAN;
                    }
                }
            }
            Some((t, angles, ranges))
        }
        None => None,
    };
    let encoder = if has_encoders {
        let (Some(l), Some(r)) = (rec.left, rec.right) else {
            return Err("expected both \"left\" and \"right\" encoder counts".into());
        };
        if !(l.fract() == 0.0 && r.fract() == 0.0 && l.abs() < 9.0e15 && r.abs() < 9.0e15) {
            return Err(format!(
                "expected integer encoder counts, found {l} and {r}"
            ));
        }
        let t = match (rec.left_timestamp, rec.right_timestamp) {
            (Some(a), Some(b)) => 0.5 * (seconds(a) + seconds(b)),
            (Some(a), None) | (None, Some(a)) => seconds(a),
            (None, None) => rec
                .timestamp
                .map(seconds)
                .ok_or("expected \"leftTimestamp\"/\"rightTimestamp\" or \"timestamp\"")?,
        };
        if !t.is_finite() {
            return Err("expected finite encoder timestamps".into());
        }
        Some((t, l as i64, r as i64))
    } else {
        None
    };
    if let Some((t, l, r)) = encoder {
        b.add_encoder(t, l, r, line)?;
    }
    if let Some((t, angles, ranges)) = scan {
        let min_range = b.opts.min_range.unwrap_or(b.log.params.laser_min_range);
        let store = &mut b.log.scans;
        let reuse = last_geometry.filter(|&i| *store.geometries[i as usize].angles == angles[..]);
        let gi = match reuse {
            Some(i) => i,
            None => {
                let g = ScanGeometry::from_angles(angles, f64::INFINITY, min_range);
                let i = store.geometry_index(&g);
                *last_geometry = Some(i);
                i
            }
        };
        let n = ranges.len();
        store.ranges.extend_from_slice(&ranges);
        store.push_meta(t, gi, n, 0, ScanKind::Json, line);
        b.check_order(Stream::Scan, t, line);
    }
    Ok((has_scan, has_encoders))
}
