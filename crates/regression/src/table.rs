//! Published rows and the table file they are read from.
//!
//! # Table file format
//!
//! JSON: an array of rows, or an object holding the array under `rows` (or
//! `table_i`) and optionally `citation` (the full reference), `label` (a short name
//! of the source, used in the rows' `source`) and `table_ii` (UMBmark trials, below);
//! other top-level fields (notes) are ignored. One row:
//!
//! ```json
//! { "name": "k07", "samples": 1500,
//!   "si": { "r_l": 0.0209, "r_r": 0.0210, "b": 0.089,
//!           "l_x": -0.006, "l_y": 0.0002, "l_theta": 0.01 },
//!   "j11": 0.0105, "j12": 0.0104, "j21": -0.236, "j22": 0.2348,
//!   "sigma": { "r_l": 4e-5, "r_r": 4e-5, "b": 2e-4,
//!              "l_x": 8e-5, "l_y": 1e-4, "l_theta": 1.5e-3 } }
//! ```
//!
//! (made-up numbers). `si` holds the numbers printed under each heading, in metres and
//! radians — the same layout the simulator's presets read (`odocal-sim`'s `TableRow`),
//! so one file serves both. `j11`, `j12`, `j21`, `j22` (also accepted as `J11` …)
//! are the printed J columns and are optional; when `j21` and `j22` are present they
//! are authoritative for the radii: `r_L = −b·J21`, `r_R = b·J22`
//! (`docs/method.md`: the ICRA 2008 Table I has its `r_L` and `r_R` headings swapped
//! relative to eq. (2), which [`j_consistency`](crate::j_consistency) reveals). `sigma` (optional) holds the
//! published standard deviations, same keys and units as `si`.
//!
//! `table_ii` is `{"note": "...", "rows": [...]}`, one row per UMBmark trial
//! ([`UmbmarkTrial`]):
//!
//! ```json
//! { "trial": "1", "b": 0.0897, "r_l": 0.021, "r_r": 0.021,
//!   "E_b": 0.9968, "E_d": 0.9996, "E_max": 8.2,
//!   "j11": 0.0105, "j12": 0.0105, "j21": -0.2341, "j22": 0.2340 }
//! ```
//!
//! (made-up numbers; `E_b`, `E_d`, `E_max` and the J columns optional).

use odocal_geom::FlatParams;
use odocal_solver::Params;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The project's Table I file, `fixtures/table-i.json` in the workspace.
pub fn workspace_table_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/table-i.json")
}

/// Why published rows could not be read.
#[derive(Debug, thiserror::Error)]
pub enum TableError {
    /// A file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// A file is not in the expected format.
    #[error("{path}: {message}")]
    Format {
        /// The file.
        path: PathBuf,
        /// What was wrong and what was expected.
        message: String,
    },
}

/// The printed J columns of a row (`J11`, `J12` may be missing).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PrintedJ {
    /// Column J11, if printed.
    pub j11: Option<f64>,
    /// Column J12, if printed.
    pub j12: Option<f64>,
    /// Column J21.
    pub j21: f64,
    /// Column J22.
    pub j22: f64,
}

/// One published experiment: parameters and the number of samples behind them.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PublishedRow {
    /// Row name (`k07`, `lstraight`, …).
    pub name: String,
    /// Where it was published (a sentence).
    pub source: String,
    /// Number of samples of the experiment.
    pub samples: u64,
    /// The parameters under their printed headings.
    pub printed: FlatParams,
    /// The printed J columns, when the table has them.
    pub j: Option<PrintedJ>,
    /// Published covariance (order r_L, r_R, b, ℓx, ℓy, ℓθ), when available.
    pub covariance: Option<[[f64; 6]; 6]>,
    /// Published standard deviations (same order), when available.
    pub sigma: Option<[f64; 6]>,
}

impl PublishedRow {
    /// The row's parameters as the truth of a simulation: the printed values, except
    /// that with J columns the radii are `r_L = −b·J21`, `r_R = b·J22`.
    pub fn truth(&self) -> Params {
        let p = &self.printed;
        let (r_l, r_r) = match &self.j {
            Some(j) => (-p.b * j.j21, p.b * j.j22),
            None => (p.r_l, p.r_r),
        };
        Params {
            r_l,
            r_r,
            b: p.b,
            laser: p.laser(),
        }
    }

    /// The row's number of samples scaled by `scale` (at least 1).
    pub fn scaled_samples(&self, scale: f64) -> usize {
        ((self.samples as f64 * scale).round() as usize).max(1)
    }

    /// What is wrong with the row, if anything.
    pub(crate) fn invalid(&self) -> Option<String> {
        if self.samples == 0 {
            return Some("samples must be a positive count".into());
        }
        let t = self.truth();
        let lengths = [t.r_l, t.r_r, t.b];
        if !lengths
            .iter()
            .all(|v| v.is_finite() && *v > 0.0 && *v < 10.0)
        {
            return Some(format!(
                "the radii and wheel distance must be positive lengths in metres, found \
                 r_L = {}, r_R = {}, b = {}{}",
                t.r_l,
                t.r_r,
                t.b,
                if self.j.is_some() {
                    " (radii from −b·J21 and b·J22)"
                } else {
                    ""
                }
            ));
        }
        if !self.printed.to_array().iter().all(|v| v.is_finite()) {
            return Some("every value of si must be a finite number".into());
        }
        if let Some(s) = &self.sigma {
            if !s.iter().all(|v| v.is_finite() && *v > 0.0) {
                return Some("every sigma must be a positive number".into());
            }
        }
        None
    }
}

#[derive(Deserialize)]
struct FileRow {
    name: String,
    samples: u64,
    si: FlatParams,
    #[serde(flatten)]
    j: FileJ,
    #[serde(default)]
    sigma: Option<FlatParams>,
}

/// Printed J columns of a file row (any may be missing).
#[derive(Deserialize, Default)]
struct FileJ {
    #[serde(default, alias = "J11")]
    j11: Option<f64>,
    #[serde(default, alias = "J12")]
    j12: Option<f64>,
    #[serde(default, alias = "J21")]
    j21: Option<f64>,
    #[serde(default, alias = "J22")]
    j22: Option<f64>,
}

impl FileJ {
    /// The J columns, `None` when none is printed; an error when J21 or J22 is
    /// missing but others are printed.
    fn printed(&self) -> Result<Option<PrintedJ>, String> {
        match (self.j21, self.j22) {
            (Some(j21), Some(j22)) => Ok(Some(PrintedJ {
                j11: self.j11,
                j12: self.j12,
                j21,
                j22,
            })),
            (None, None) if self.j11.is_none() && self.j12.is_none() => Ok(None),
            _ => Err("J columns need both j21 and j22".into()),
        }
    }
}

#[derive(Deserialize)]
struct FileTrial {
    trial: String,
    b: f64,
    r_l: f64,
    r_r: f64,
    #[serde(default, rename = "E_b")]
    e_b: Option<f64>,
    #[serde(default, rename = "E_d")]
    e_d: Option<f64>,
    #[serde(default, rename = "E_max")]
    e_max: Option<f64>,
    #[serde(flatten)]
    j: FileJ,
}

#[derive(Deserialize)]
struct FileTableII {
    #[serde(default)]
    note: Option<String>,
    rows: Vec<FileTrial>,
}

#[derive(Deserialize)]
#[serde(untagged)]
enum TableFile {
    Rows(Vec<FileRow>),
    Keyed {
        #[serde(alias = "table_i")]
        rows: Vec<FileRow>,
        #[serde(default)]
        citation: Option<String>,
        #[serde(default)]
        label: Option<String>,
        #[serde(default)]
        table_ii: Option<FileTableII>,
    },
}

/// One trial of a UMBmark calibration table (the ICRA 2008 Table II): the wheel
/// distance and radii it gives. UMBmark corrects only the ratios b/r̄ and r_R/r_L;
/// the mean radius stays at its nominal value.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct UmbmarkTrial {
    /// Trial name (`nominal`, `1`, …).
    pub trial: String,
    /// Wheel distance (m).
    pub b: f64,
    /// Column "r_L" (m).
    pub r_l: f64,
    /// Column "r_R" (m).
    pub r_r: f64,
    /// Printed E_b = b / b_nominal, when printed.
    pub e_b: Option<f64>,
    /// Printed E_d (ratio of the wheel diameters), when printed.
    pub e_d: Option<f64>,
    /// Printed E_max (largest UMBmark return error), when printed.
    pub e_max: Option<f64>,
    /// The printed J columns, when printed.
    pub j: Option<PrintedJ>,
}

/// A table file: its rows, UMBmark trials and citation.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PublishedTable {
    /// The full reference, when the file gives one.
    pub citation: Option<String>,
    /// The published rows.
    pub rows: Vec<PublishedRow>,
    /// The note of the UMBmark table, when the file has one.
    pub umbmark_note: Option<String>,
    /// The UMBmark trials (empty when the file has none).
    pub umbmark: Vec<UmbmarkTrial>,
}

/// Reads a table file's rows (format in the module documentation).
pub fn read_table_file(path: &Path) -> Result<Vec<PublishedRow>, TableError> {
    Ok(read_table(path)?.rows)
}

/// Reads a table file: rows, UMBmark trials, citation.
pub fn read_table(path: &Path) -> Result<PublishedTable, TableError> {
    let text = std::fs::read_to_string(path).map_err(|source| TableError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_table_document(&text, path)
}

/// Parses the text of a table file's rows; `path` names it in messages and in the
/// rows' source.
pub fn parse_table(text: &str, path: &Path) -> Result<Vec<PublishedRow>, TableError> {
    Ok(parse_table_document(text, path)?.rows)
}

/// Parses the text of a table file: rows, UMBmark trials, citation.
pub fn parse_table_document(text: &str, path: &Path) -> Result<PublishedTable, TableError> {
    let err = |message: String| TableError::Format {
        path: path.to_path_buf(),
        message,
    };
    let (rows, citation, label, table_ii) = match serde_json::from_str::<TableFile>(text) {
        Ok(TableFile::Rows(r)) => (r, None, None, None),
        Ok(TableFile::Keyed {
            rows,
            citation,
            label,
            table_ii,
        }) => (rows, citation, label, table_ii),
        Err(e) => {
            return Err(err(format!(
                "{e}; expected an array of rows (or {{\"rows\": [...]}}), each with name, \
                 samples, si {{r_l, r_r, b, l_x, l_y, l_theta}} and optionally j21, j22 \
                 (j11, j12) and sigma; optionally table_ii {{\"rows\": [...]}} of UMBmark \
                 trials, each with trial, b, r_l, r_r"
            )))
        }
    };
    let source = label.unwrap_or_else(|| {
        format!(
            "table file `{}`",
            path.file_name()
                .unwrap_or(path.as_os_str())
                .to_string_lossy()
        )
    });
    let mut out = Vec::with_capacity(rows.len());
    for r in rows {
        let j =
            r.j.printed()
                .map_err(|m| err(format!("row '{}': {m}", r.name)))?;
        let row = PublishedRow {
            source: source.clone(),
            samples: r.samples,
            printed: r.si,
            j,
            covariance: None,
            sigma: r.sigma.map(|s| s.to_array()),
            name: r.name,
        };
        if let Some(message) = row.invalid() {
            return Err(err(format!("row '{}': {message}", row.name)));
        }
        if out.iter().any(|o: &PublishedRow| o.name == row.name) {
            return Err(err(format!("row '{}' appears twice", row.name)));
        }
        out.push(row);
    }
    let (umbmark_note, trials) = match table_ii {
        Some(t) => (t.note, t.rows),
        None => (None, Vec::new()),
    };
    let mut umbmark = Vec::with_capacity(trials.len());
    for t in trials {
        let j =
            t.j.printed()
                .map_err(|m| err(format!("table_ii trial '{}': {m}", t.trial)))?;
        if ![t.b, t.r_l, t.r_r]
            .iter()
            .all(|v| v.is_finite() && *v > 0.0 && *v < 10.0)
        {
            return Err(err(format!(
                "table_ii trial '{}': b, r_l, r_r must be positive lengths in metres",
                t.trial
            )));
        }
        umbmark.push(UmbmarkTrial {
            trial: t.trial,
            b: t.b,
            r_l: t.r_l,
            r_r: t.r_r,
            e_b: t.e_b,
            e_d: t.e_d,
            e_max: t.e_max,
            j,
        });
    }
    Ok(PublishedTable {
        citation,
        rows: out,
        umbmark_note,
        umbmark,
    })
}
