//! Tuple files: the samples the solver works on, one per scan interval.
//!
//! A tuple file is a stream of JSON objects (several may share a line), each
//! `{ "T": s, "phi_l": rad/s, "phi_r": rad/s, "sm": [x, y, theta], … }`. Optional
//! fields `t0`, `t1`, `sm_cov`, `free_direction`, `profile` are ours; any other field (e.g. ICP
//! statistics) is preserved in [`TupleRecord::extra`].

use crate::error::LogError;
use crate::json_stream::for_each_object;
use serde::{Deserialize, Serialize};
use std::fs::File;
use std::io::{self, BufReader, Read, Write};
use std::path::Path;

/// One sample: the wheel speeds over a scan interval and the sensor displacement
/// estimated by scan matching over the same interval.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TupleRecord {
    /// Length of the interval (s). JSON field `T`.
    #[serde(rename = "T")]
    pub t: f64,
    /// Average left wheel speed over the interval (rad/s).
    pub phi_l: f64,
    /// Average right wheel speed over the interval (rad/s).
    pub phi_r: f64,
    /// Sensor displacement from scan matching (m, m, rad).
    pub sm: [f64; 3],
    /// Start of the interval (s), when known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub t0: Option<f64>,
    /// End of the interval (s), when known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub t1: Option<f64>,
    /// Covariance of `sm`, when known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sm_cov: Option<[[f64; 3]; 3]>,
    /// The motion `(x, y, θ)` along which `sm` says nothing (a match along a
    /// corridor keeps its first guess there), when there is one: the solver gives
    /// the residual's component along it no weight.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub free_direction: Option<[f64; 3]>,
    /// Pieces inside the interval: (duration s, left wheel rotation rad, right wheel
    /// rotation rad), when the wheel speeds were not constant.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub profile: Option<Vec<[f64; 3]>>,
    /// Every other field, preserved as read.
    #[serde(flatten)]
    pub extra: serde_json::Map<String, serde_json::Value>,
}

impl TupleRecord {
    /// A record with only the four required fields.
    pub fn new(t: f64, phi_l: f64, phi_r: f64, sm: [f64; 3]) -> Self {
        TupleRecord {
            t,
            phi_l,
            phi_r,
            sm,
            t0: None,
            t1: None,
            sm_cov: None,
            free_direction: None,
            profile: None,
            extra: serde_json::Map::new(),
        }
    }

    /// The first non-finite or out-of-range field, as a description.
    fn invalid_field(&self) -> Option<String> {
        if !(self.t.is_finite() && self.t > 0.0) {
            return Some(format!(
                "\"T\" to be a positive number of seconds, found {}",
                self.t
            ));
        }
        let finite = [self.phi_l, self.phi_r, self.sm[0], self.sm[1], self.sm[2]];
        if finite.iter().any(|v| !v.is_finite()) {
            return Some("\"phi_l\", \"phi_r\" and \"sm\" to be finite numbers".into());
        }
        None
    }
}

/// Reads a whole tuple file.
pub fn read_tuples(path: &Path) -> Result<Vec<TupleRecord>, LogError> {
    let name = path.display().to_string();
    let file = File::open(path).map_err(|e| LogError::io(&name, e))?;
    read_tuples_from(BufReader::new(file), &name)
}

/// Reads tuples from any reader; `name` is used in error messages.
pub fn read_tuples_from<R: Read>(reader: R, name: &str) -> Result<Vec<TupleRecord>, LogError> {
    let mut out = Vec::new();
    for_each_object(
        reader,
        name,
        "tuple",
        "a tuple object {\"T\": s, \"phi_l\": rad/s, \"phi_r\": rad/s, \"sm\": [x, y, theta]}",
        |rec: TupleRecord, line| {
            if let Some(what) = rec.invalid_field() {
                return Err(LogError::parse(
                    name,
                    line,
                    "tuple",
                    format!("expected {what}"),
                ));
            }
            out.push(rec);
            Ok(())
        },
    )?;
    Ok(out)
}

/// Writes one tuple as a JSON object on its own line. Numbers are printed so that
/// reading them back gives the same `f64`.
pub fn write_tuple<W: Write>(w: &mut W, rec: &TupleRecord) -> io::Result<()> {
    serde_json::to_writer(&mut *w, rec).map_err(io::Error::other)?;
    w.write_all(b"\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn objects_sharing_a_line_are_all_read() {
        let text = "{\"T\": 1.0, \"phi_l\": 0.5, \"phi_r\": -0.5, \"sm\": [0.1, 0.2, 0.3]}\n\
                    {\"T\": 2.0, \"phi_l\": 1, \"phi_r\": 2, \"sm\": [1, 2, 3]} {\"T\": 3.0, \"phi_l\": 0, \"phi_r\": 0, \"sm\": [0, 0, 0]}\n\
                    {\"T\": 4.0, \"phi_l\": 0, \"phi_r\": 0, \"sm\": [0, 0, 0]}{\"T\": 5.0, \"phi_l\": 0, \"phi_r\": 0, \"sm\": [0, 0, 0]}";
        let recs = read_tuples_from(text.as_bytes(), "inline").unwrap();
        let ts: Vec<f64> = recs.iter().map(|r| r.t).collect();
        assert_eq!(ts, vec![1.0, 2.0, 3.0, 4.0, 5.0]);
        assert_eq!(recs[1].sm, [1.0, 2.0, 3.0]);
        assert_eq!(recs[0].phi_r, -0.5);
    }

    #[test]
    fn extra_fields_and_optional_fields_survive_a_round_trip() {
        let mut rec = TupleRecord::new(0.1, 1.5, -2.25, [1e-3, -2e-4, 0.1 + 0.2]);
        rec.t0 = Some(1190000000.017285);
        rec.t1 = Some(1190000000.117285);
        rec.sm_cov = Some([[1e-6, 0.0, 0.0], [0.0, 2e-6, 1e-9], [0.0, 1e-9, 3e-7]]);
        rec.profile = Some(vec![[0.05, 0.01, 0.02], [0.05, 0.011, 0.019]]);
        rec.extra
            .insert("icp_iterations".into(), serde_json::json!(12));
        rec.extra
            .insert("icp_valid".into(), serde_json::json!([1, 2, 3]));
        let mut buf = Vec::new();
        write_tuple(&mut buf, &rec).unwrap();
        write_tuple(&mut buf, &TupleRecord::new(1.0, 0.0, 0.0, [0.0; 3])).unwrap();
        assert_eq!(buf.iter().filter(|&&b| b == b'\n').count(), 2);
        let back = read_tuples_from(&buf[..], "buf").unwrap();
        assert_eq!(back.len(), 2);
        assert_eq!(back[0], rec);
        let text = String::from_utf8(buf).unwrap();
        assert!(text.starts_with("{\"T\":0.1,"), "{text}");
        assert!(!text.lines().nth(1).unwrap().contains("t0"));
    }

    #[test]
    fn syntax_error_names_file_and_line() {
        let text = "{\"T\": 1.0, \"phi_l\": 0.5, \"phi_r\": -0.5, \"sm\": [0.1, 0.2, 0.3]}\n\
                    {\"T\": 1.0, \"phi_l\": 0.5, \"phi_r\": -0.5, \"sm\": [0.1, 0.2, 0.3]}\n\
                    {\"T\": 1.0, \"phi_l\": 0.5 \"phi_r\": -0.5, \"sm\": [0.1, 0.2, 0.3]}\n";
        let e = read_tuples_from(text.as_bytes(), "bad.tuple").unwrap_err();
        assert_eq!(e.line(), Some(3));
        let msg = e.to_string();
        assert!(
            msg.starts_with("bad.tuple:3: tuple: expected a tuple object"),
            "{msg}"
        );
    }

    #[test]
    fn missing_field_names_file_and_line() {
        let text = "{\"T\": 1.0, \"phi_l\": 0.5, \"phi_r\": -0.5, \"sm\": [0.1, 0.2, 0.3]}\n\n\
                    {\"T\": 1.0, \"phi_l\": 0.5,\n \"phi_r\": -0.5}\n";
        let e = read_tuples_from(text.as_bytes(), "m.tuple").unwrap_err();
        assert_eq!(e.line(), Some(4), "{e}");
        assert!(e.to_string().contains("missing field `sm`"), "{e}");
    }

    #[test]
    fn non_positive_interval_is_rejected_with_its_line() {
        let text = "{\"T\": 1.0, \"phi_l\": 0.5, \"phi_r\": -0.5, \"sm\": [0.1, 0.2, 0.3]} \
                    {\"T\": 2.0, \"phi_l\": 0.5, \"phi_r\": -0.5, \"sm\": [0.1, 0.2, 0.3]}\n\
                    {\"T\": 0.0, \"phi_l\": 0.5, \"phi_r\": -0.5, \"sm\": [0.1, 0.2, 0.3]}\n";
        let e = read_tuples_from(text.as_bytes(), "z.tuple").unwrap_err();
        assert_eq!(e.line(), Some(2), "{e}");
        assert!(e.to_string().contains("positive"), "{e}");
    }

    #[test]
    fn empty_input_gives_no_tuples() {
        assert!(read_tuples_from(&b"  \n\n"[..], "e").unwrap().is_empty());
    }

    #[test]
    fn reference_tuple_files_have_the_published_counts() {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/reference");
        let dir = Path::new(dir);
        if !dir.is_dir() {
            println!("skipped: reference folder {} is absent", dir.display());
            return;
        }
        for (file, count) in [
            ("lstraight.tuple", 4396),
            ("l90.tuple", 3295),
            ("lmov.tuple", 4345),
        ] {
            let recs = read_tuples(&dir.join(file)).unwrap();
            assert_eq!(recs.len(), count, "{file}");
            assert!(recs.iter().all(|r| r.t > 0.0 && r.extra.is_empty()));
        }
    }
}
