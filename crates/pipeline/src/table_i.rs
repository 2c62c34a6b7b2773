//! Regression against published calibration results ("Table I").
//!
//! A *published row* is one experiment's calibrated parameters as printed in a paper
//! or shipped with a package, with the number of samples behind it. The regression
//! simulates a robot whose true parameters are the row's, runs the whole pipeline on
//! the simulated log ([`reproduce_from_text`]), and compares the recovered parameters
//! with the row ([`Reproduction::checks`]): within `3σ` of the covariance the pipeline
//! reports, and — for runs with enough samples — within absolute bounds.
//! The simulation itself is the caller's (this crate does not depend on the simulator).
//!
//! Two sources of rows:
//! - a *table file* ([`read_table`]), e.g. `fixtures/table-i.json`: the ICRA 2008
//!   Table I (19 rows, with its Table II of UMBmark trials);
//! - the T-RO 2013 package's published results ([`read_tro_reference`]): for each
//!   configuration `NAME` in [`TRO_CONFIGURATIONS`], `NAME_results.json` (the
//!   parameters and their covariance) and `NAME.tuple` (whose count of tuples is the
//!   number of samples).
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
//! relative to eq. (2), which [`j_consistency`] reveals). `sigma` (optional) holds the
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

use crate::error::PipelineError;
use crate::estimate::Estimate;
use crate::progress::NoProgress;
use crate::run::{calibrate_log, Options};
use odocal_geom::{wrap_angle, FlatParams};
use odocal_log::{read_carmen_from, read_tuples, ReadOptions};
use odocal_solver::Params;
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The T-RO 2013 package's configurations: file stem and description.
pub const TRO_CONFIGURATIONS: [(&str, &str); 3] = [
    (
        "lstraight",
        "T-RO 2013 configuration A: laser about aligned with the robot",
    ),
    ("l90", "T-RO 2013 configuration B: laser turned about −90°"),
    (
        "lmov",
        "T-RO 2013 configuration C: laser displaced and turned",
    ),
];

/// Names of the quantities compared, in the order of [`Reproduction::checks`].
pub const QUANTITY_NAMES: [&str; 8] = ["r_L", "r_R", "b", "l_x", "l_y", "l_theta", "J21", "J22"];

/// The project's Table I file, `fixtures/table-i.json` in the workspace.
pub fn workspace_table_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/table-i.json")
}

/// The reference data: the directory named by the environment variable
/// `ODOCAL_REFERENCE_DIR` when set (e.g. for a git worktree elsewhere), else
/// `../shared/reference/` beside the workspace (never copied into the repository).
pub fn workspace_reference_dir() -> PathBuf {
    match std::env::var_os("ODOCAL_REFERENCE_DIR") {
        Some(dir) if !dir.is_empty() => PathBuf::from(dir),
        _ => Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/reference"),
    }
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
    fn invalid(&self) -> Option<String> {
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

#[derive(Deserialize)]
struct TroResults {
    axle: f64,
    l_diam: f64,
    r_diam: f64,
    l_x: f64,
    l_y: f64,
    l_theta: f64,
    covariance: [[f64; 6]; 6],
}

/// Reads the T-RO 2013 package's published results from `dir`: one row per
/// configuration of [`TRO_CONFIGURATIONS`], from `NAME_results.json` (`axle` = b,
/// `l_diam`/`r_diam` = 2·radius, ℓ, covariance) and `NAME.tuple` (samples).
pub fn read_tro_reference(dir: &Path) -> Result<Vec<PublishedRow>, TableError> {
    let mut out = Vec::with_capacity(TRO_CONFIGURATIONS.len());
    for (name, description) in TRO_CONFIGURATIONS {
        let path = dir.join(format!("{name}_results.json"));
        let text = std::fs::read_to_string(&path).map_err(|source| TableError::Io {
            path: path.clone(),
            source,
        })?;
        let r: TroResults = serde_json::from_str(&text).map_err(|e| TableError::Format {
            path: path.clone(),
            message: format!(
                "{e}; expected the package's results: axle, l_diam, r_diam, l_x, l_y, \
                 l_theta and a 6×6 covariance"
            ),
        })?;
        let tuples_path = dir.join(format!("{name}.tuple"));
        let samples = read_tuples(&tuples_path)
            .map_err(|e| TableError::Format {
                path: tuples_path.clone(),
                message: e.to_string(),
            })?
            .len() as u64;
        let sigma = std::array::from_fn(|i| r.covariance[i][i].max(0.0).sqrt());
        let row = PublishedRow {
            name: name.to_string(),
            source: format!("{description}; the package's published `{name}_results.json`"),
            samples,
            printed: FlatParams {
                r_l: r.l_diam / 2.0,
                r_r: r.r_diam / 2.0,
                b: r.axle,
                l_x: r.l_x,
                l_y: r.l_y,
                l_theta: r.l_theta,
            },
            j: None,
            covariance: Some(r.covariance),
            sigma: Some(sigma),
        };
        if let Some(message) = row.invalid() {
            return Err(TableError::Format { path, message });
        }
        out.push(row);
    }
    Ok(out)
}

/// Bounds of the comparison.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Tolerances {
    /// Every quantity within this many reported standard deviations.
    pub sigma_multiple: f64,
    /// The absolute bounds below apply to runs with at least this many samples.
    pub min_samples_for_bounds: usize,
    /// Relative bound for r_L, r_R, b, J21, J22.
    pub relative: f64,
    /// Bound for ℓx, ℓy (m).
    pub position: f64,
    /// Bound for ℓθ (rad).
    pub heading: f64,
}

impl Default for Tolerances {
    /// 3σ; from 1,000 samples on also 0.35 %, 1.5 mm and 0.2°.
    fn default() -> Self {
        Tolerances {
            sigma_multiple: 3.0,
            min_samples_for_bounds: 1000,
            relative: 0.0035,
            position: 1.5e-3,
            heading: 0.2f64.to_radians(),
        }
    }
}

/// One published row reproduced in simulation.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Reproduction {
    /// The published row.
    pub row: PublishedRow,
    /// The simulation's true parameters ([`PublishedRow::truth`]).
    pub truth: Params,
    /// The number of samples asked of the simulation.
    pub target_samples: usize,
    /// The pipeline's result on the simulated log.
    pub estimate: Estimate,
}

/// One quantity of a [`Reproduction`], compared.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct QuantityCheck {
    /// Name (one of [`QUANTITY_NAMES`]).
    pub name: &'static str,
    /// The published (true) value.
    pub published: f64,
    /// The published standard deviation, when known.
    pub published_sigma: Option<f64>,
    /// The recovered value.
    pub recovered: f64,
    /// The standard deviation the pipeline reported.
    pub sigma: f64,
    /// `recovered − published` (angles wrapped).
    pub error: f64,
    /// The absolute bound, when it applies.
    pub bound: Option<f64>,
    /// `|error| ≤ sigma_multiple·sigma`.
    pub within_sigma: bool,
    /// `|error| ≤ bound` (true when no bound applies).
    pub within_bound: bool,
}

impl QuantityCheck {
    /// The error in reported standard deviations.
    pub fn error_in_sigma(&self) -> f64 {
        self.error / self.sigma
    }

    /// Both rules hold.
    pub fn passed(&self) -> bool {
        self.within_sigma && self.within_bound
    }
}

/// Gradients of J21 = −r_L/b and J22 = r_R/b with respect to (r_L, r_R, b, ℓ).
fn j_gradients(p: &Params) -> [[f64; 6]; 2] {
    [
        [-1.0 / p.b, 0.0, p.r_l / (p.b * p.b), 0.0, 0.0, 0.0],
        [0.0, 1.0 / p.b, -p.r_r / (p.b * p.b), 0.0, 0.0, 0.0],
    ]
}

fn propagate(g: &[f64; 6], cov: &[[f64; 6]; 6]) -> f64 {
    let mut v = 0.0;
    for i in 0..6 {
        for k in 0..6 {
            v += g[i] * cov[i][k] * g[k];
        }
    }
    v.max(0.0).sqrt()
}

impl Reproduction {
    /// Whether the absolute bounds apply: the run asked for at least
    /// [`Tolerances::min_samples_for_bounds`] samples.
    pub fn bounds_apply(&self, tol: &Tolerances) -> bool {
        self.target_samples >= tol.min_samples_for_bounds
    }

    /// Compares every quantity of [`QUANTITY_NAMES`] with the row.
    pub fn checks(&self, tol: &Tolerances) -> Vec<QuantityCheck> {
        let truth = self.truth;
        let rep = &self.estimate;
        let recovered = Params::from_vector(rep.values());
        let mut published: Vec<f64> = truth.to_vector().to_vec();
        let tj = truth.j();
        published.extend([tj[1][0], tj[1][1]]);
        let mut values: Vec<f64> = rep.values().to_vec();
        values.extend([rep.j[1][0], rep.j[1][1]]);
        let mut errors: Vec<f64> = recovered.difference(&truth).to_vec();
        errors.extend([values[6] - published[6], values[7] - published[7]]);
        let g = j_gradients(&recovered);
        let mut sigmas: Vec<f64> = rep.sigma.to_vec();
        sigmas.extend([
            propagate(&g[0], &rep.covariance),
            propagate(&g[1], &rep.covariance),
        ]);
        let published_sigma: Vec<Option<f64>> = (0..8)
            .map(|i| match (i, &self.row.covariance, &self.row.sigma) {
                (0..=5, _, Some(s)) => Some(s[i]),
                (6 | 7, Some(c), _) => Some(propagate(&j_gradients(&truth)[i - 6], c)),
                _ => None,
            })
            .collect();
        let apply = self.bounds_apply(tol);
        (0..8)
            .map(|i| {
                let bound = apply.then(|| match i {
                    3 | 4 => tol.position,
                    5 => tol.heading,
                    _ => tol.relative * published[i].abs(),
                });
                let error = if i == 5 {
                    wrap_angle(errors[i])
                } else {
                    errors[i]
                };
                QuantityCheck {
                    name: QUANTITY_NAMES[i],
                    published: published[i],
                    published_sigma: published_sigma[i],
                    recovered: values[i],
                    sigma: sigmas[i],
                    error,
                    bound,
                    within_sigma: error.abs() <= tol.sigma_multiple * sigmas[i],
                    within_bound: bound.is_none_or(|b| error.abs() <= b),
                }
            })
            .collect()
    }

    /// One sentence per quantity outside its bounds (empty when the row passes).
    pub fn failures(&self, tol: &Tolerances) -> Vec<String> {
        let mut out = Vec::new();
        for c in self.checks(tol) {
            if !c.within_sigma {
                out.push(format!(
                    "{}: {}: error {:.3e} is {:.2}σ, beyond {}σ (σ = {:.3e})",
                    self.row.name,
                    c.name,
                    c.error,
                    c.error_in_sigma(),
                    tol.sigma_multiple,
                    c.sigma
                ));
            }
            if !c.within_bound {
                out.push(format!(
                    "{}: {}: error {:.3e} above the bound {:.3e}",
                    self.row.name,
                    c.name,
                    c.error,
                    c.bound.unwrap_or(f64::NAN)
                ));
            }
        }
        out
    }

    /// The largest `|error|/σ` over the quantities.
    pub fn worst_error_in_sigma(&self, tol: &Tolerances) -> f64 {
        self.checks(tol)
            .iter()
            .map(|c| c.error_in_sigma().abs())
            .fold(0.0, f64::max)
    }
}

/// The pipeline options of the reproduction: the defaults with the original
/// package's T-RO trimming rule, as the published results were computed.
pub fn reproduction_options() -> Options {
    let mut opts = Options::default();
    opts.solve.trim = odocal_solver::Trim::TRO;
    opts
}

/// Runs the whole pipeline (read → synchronize → match → solve) on the text of a
/// Carmen log simulated with `row`'s parameters ([`PublishedRow::truth`]) and
/// returns the comparison material. `target_samples` is the number of samples the
/// simulation was sized for. Scan matching runs on rayon's current thread pool.
pub fn reproduce_from_text(
    row: &PublishedRow,
    target_samples: usize,
    log_text: &[u8],
    opts: &Options,
) -> Result<Reproduction, PipelineError> {
    let name = format!("{}.log (simulated)", row.name);
    let t_read = Instant::now();
    let log = read_carmen_from(log_text, &name, &ReadOptions::default())?;
    let parse = t_read.elapsed().as_secs_f64();
    let mut outcome = calibrate_log(&log, opts, &NoProgress)?;
    outcome.timing.parse = parse;
    Ok(Reproduction {
        row: row.clone(),
        truth: row.truth(),
        target_samples,
        estimate: Estimate::of(&outcome),
    })
}

/// How the printed J columns of a row relate to its printed radii and b.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum JReading {
    /// J agrees with eq. (2) under the printed headings.
    AsPrinted,
    /// J agrees with eq. (2) only with the r_L and r_R headings exchanged.
    HeadingsSwapped,
    /// Both readings agree (the radii are too close to tell).
    Ambiguous,
    /// Neither reading agrees.
    Neither,
}

/// The internal-consistency check of one published row: J recomputed from
/// (b, radii) by eq. (2), `J = [[r_L/2, r_R/2], [−r_L/b, r_R/b]]`, against the
/// printed J columns.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct JConsistency {
    /// Row name.
    pub name: String,
    /// Printed J11, J12, J21, J22 (NaN where not printed).
    pub printed: [f64; 4],
    /// J from the printed headings: r_L = column "r_L".
    pub from_headings: [f64; 4],
    /// J with the radius headings exchanged: r_L = column "r_R".
    pub from_swapped: [f64; 4],
    /// Largest relative deviation of the printed J from `from_headings`.
    pub deviation_as_printed: f64,
    /// Largest relative deviation of the printed J from `from_swapped`.
    pub deviation_swapped: f64,
    /// Largest absolute deviation of the printed J from `from_headings`.
    pub abs_deviation_as_printed: f64,
    /// Largest absolute deviation of the printed J from `from_swapped`.
    pub abs_deviation_swapped: f64,
    /// The verdict at the tolerance asked.
    pub reading: JReading,
}

fn j_entries(r_l: f64, r_r: f64, b: f64) -> [f64; 4] {
    [r_l / 2.0, r_r / 2.0, -r_l / b, r_r / b]
}

fn max_relative_deviation(printed: &[f64; 4], model: &[f64; 4]) -> f64 {
    printed
        .iter()
        .zip(model)
        .filter(|(p, _)| p.is_finite())
        .map(|(p, m)| ((p - m) / m).abs())
        .fold(0.0, f64::max)
}

fn max_absolute_deviation(printed: &[f64; 4], model: &[f64; 4]) -> f64 {
    printed
        .iter()
        .zip(model)
        .filter(|(p, _)| p.is_finite())
        .map(|(p, m)| (p - m).abs())
        .fold(0.0, f64::max)
}

/// Checks a row's printed J columns against eq. (2) under the printed and the
/// swapped radius headings; `None` when the row has no J columns. `tolerance` is
/// the relative deviation accepted as printing precision (e.g. `1e-3` for four
/// significant digits).
pub fn j_consistency(row: &PublishedRow, tolerance: f64) -> Option<JConsistency> {
    let p = &row.printed;
    Some(check_j(
        &row.name,
        p.r_l,
        p.r_r,
        p.b,
        row.j.as_ref()?,
        tolerance,
    ))
}

/// [`j_consistency`] for a UMBmark trial; `None` when it has no J columns.
pub fn umbmark_j_consistency(trial: &UmbmarkTrial, tolerance: f64) -> Option<JConsistency> {
    let name = format!("UMBmark {}", trial.trial);
    Some(check_j(
        &name,
        trial.r_l,
        trial.r_r,
        trial.b,
        trial.j.as_ref()?,
        tolerance,
    ))
}

fn check_j(name: &str, r_l: f64, r_r: f64, b: f64, j: &PrintedJ, tolerance: f64) -> JConsistency {
    let printed = [
        j.j11.unwrap_or(f64::NAN),
        j.j12.unwrap_or(f64::NAN),
        j.j21,
        j.j22,
    ];
    let from_headings = j_entries(r_l, r_r, b);
    let from_swapped = j_entries(r_r, r_l, b);
    let d1 = max_relative_deviation(&printed, &from_headings);
    let d2 = max_relative_deviation(&printed, &from_swapped);
    let reading = match (d1 <= tolerance, d2 <= tolerance) {
        (true, true) => JReading::Ambiguous,
        (true, false) => JReading::AsPrinted,
        (false, true) => JReading::HeadingsSwapped,
        (false, false) => JReading::Neither,
    };
    JConsistency {
        name: name.to_string(),
        printed,
        from_headings,
        from_swapped,
        deviation_as_printed: d1,
        deviation_swapped: d2,
        abs_deviation_as_printed: max_absolute_deviation(&printed, &from_headings),
        abs_deviation_swapped: max_absolute_deviation(&printed, &from_swapped),
        reading,
    }
}

/// Value, σ and error of a quantity in display units: (scale, unit, decimals).
fn display_unit(name: &str) -> (f64, &'static str, usize) {
    match name {
        "l_theta" => (180.0 / std::f64::consts::PI, "°", 4),
        "J21" | "J22" => (1.0, "", 6),
        _ => (1e3, "mm", 4),
    }
}

fn quantity_label(name: &str) -> &'static str {
    match name {
        "r_L" => "r_L (mm)",
        "r_R" => "r_R (mm)",
        "b" => "b (mm)",
        "l_x" => "ℓx (mm)",
        "l_y" => "ℓy (mm)",
        "l_theta" => "ℓθ (°)",
        "J21" => "J21",
        _ => "J22",
    }
}

/// A Markdown table of one reproduction: per quantity the published value (and
/// published σ), the recovered value ± reported σ, the error (also relative for
/// lengths of the odometry and J), the error in σ, the bound and the verdict.
pub fn format_reproduction(rep: &Reproduction, tol: &Tolerances) -> String {
    let r = &rep.estimate;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "**{}** — {}; published with {} samples; simulated for {}, {} synchronized, {} used \
         after trimming (stride {}, ≈{:.2} s intervals); absolute bounds {}.\n",
        rep.row.name,
        rep.row.source,
        rep.row.samples,
        rep.target_samples,
        r.samples_synchronized,
        r.samples_used,
        r.stride,
        r.interval_s,
        if rep.bounds_apply(tol) {
            "apply"
        } else {
            "do not apply (fewer samples)"
        }
    );
    let _ = writeln!(
        s,
        "| quantity | published | published σ | recovered ± σ | error | error/σ | bound | ok |"
    );
    let _ = writeln!(s, "|---|---:|---:|---:|---:|---:|---:|:-:|");
    for c in rep.checks(tol) {
        let (k, _, d) = display_unit(c.name);
        let relative = match c.name {
            "l_x" | "l_y" | "l_theta" => String::new(),
            _ => format!(" ({:+.3} %)", 100.0 * c.error / c.published.abs()),
        };
        let _ = writeln!(
            s,
            "| {} | {:.d$} | {} | {:.d$} ± {:.d$} | {:+.d$}{} | {:+.2} | {} | {} |",
            quantity_label(c.name),
            c.published * k,
            c.published_sigma
                .map_or("—".to_string(), |v| format!("{:.d$}", v * k)),
            c.recovered * k,
            c.sigma * k,
            c.error * k,
            relative,
            c.error_in_sigma(),
            c.bound
                .map_or("—".to_string(), |b| format!("{:.d$}", b * k)),
            if c.passed() { "✓" } else { "✗" },
        );
    }
    s
}

/// A Markdown summary table: one line per reproduction.
pub fn format_summary(reps: &[Reproduction], tol: &Tolerances) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "| row | published samples | simulated | used | worst \\|error\\|/σ | absolute bounds | result |"
    );
    let _ = writeln!(s, "|---|---:|---:|---:|---:|:-:|:-:|");
    for rep in reps {
        let failures = rep.failures(tol);
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {:.2} | {} | {} |",
            rep.row.name,
            rep.row.samples,
            rep.target_samples,
            rep.estimate.samples_used,
            rep.worst_error_in_sigma(tol),
            if rep.bounds_apply(tol) {
                "checked"
            } else {
                "—"
            },
            if failures.is_empty() {
                "pass".to_string()
            } else {
                format!("fail ({} check(s))", failures.len())
            }
        );
    }
    s
}

/// A Markdown table of the J consistency checks.
pub fn format_j_consistency(checks: &[JConsistency], tolerance: f64) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "| row | printed J11, J12, J21, J22 | eq. (2), headings as printed | eq. (2), r_L ↔ r_R | largest \\|Δ\\| as printed (relative) | largest \\|Δ\\| swapped (relative) | reading (relative tolerance {:.1e}) |",
        tolerance
    );
    let _ = writeln!(s, "|---|---|---|---|---:|---:|---|");
    let fmt = |v: &[f64; 4]| {
        v.iter()
            .map(|x| {
                if x.is_finite() {
                    format!("{x:.5}")
                } else {
                    "—".into()
                }
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    for c in checks {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {:.1e} ({:.1e}) | {:.1e} ({:.1e}) | {:?} |",
            c.name,
            fmt(&c.printed),
            fmt(&c.from_headings),
            fmt(&c.from_swapped),
            c.abs_deviation_as_printed,
            c.deviation_as_printed,
            c.abs_deviation_swapped,
            c.deviation_swapped,
            c.reading
        );
    }
    s
}

/// The simulation seed of a row: `seed` mixed with a hash (FNV-1a) of the row's
/// name, so a row gets the same log whichever other rows run.
pub fn row_seed(seed: u64, name: &str) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in name.bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    h ^ seed
}

/// One line of the UMBmark comparison: a name and (b, r_L, r_R) in metres.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OdometryLine {
    /// What the numbers are (e.g. "UMBmark trial 1", "odocal on the k22-k29 preset").
    pub name: String,
    /// Wheel distance (m).
    pub b: f64,
    /// Left wheel radius (m).
    pub r_l: f64,
    /// Right wheel radius (m).
    pub r_r: f64,
}

/// A Markdown table of UMBmark trials beside other odometry calibrations: b, radii,
/// mean radius r̄, and the ratios UMBmark can observe (b/r̄, r_R/r_L) of every trial,
/// every line of `shown` and every line of `calibrations`; then each trial's
/// differences from every line of `calibrations`.
pub fn format_umbmark(
    trials: &[UmbmarkTrial],
    shown: &[OdometryLine],
    calibrations: &[OdometryLine],
) -> String {
    let mut s = String::new();
    let lines: Vec<OdometryLine> = trials
        .iter()
        .map(|t| OdometryLine {
            name: format!("UMBmark trial {}", t.trial),
            b: t.b,
            r_l: t.r_l,
            r_r: t.r_r,
        })
        .chain(shown.iter().cloned())
        .chain(calibrations.iter().cloned())
        .collect();
    let _ = writeln!(
        s,
        "| calibration | b (mm) | r_L (mm) | r_R (mm) | r̄ (mm) | b/r̄ | r_R/r_L | J21 | J22 |"
    );
    let _ = writeln!(s, "|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    for l in &lines {
        let mean = 0.5 * (l.r_l + l.r_r);
        let _ = writeln!(
            s,
            "| {} | {:.2} | {:.3} | {:.3} | {:.3} | {:.4} | {:.5} | {:.5} | {:.5} |",
            l.name,
            l.b * 1e3,
            l.r_l * 1e3,
            l.r_r * 1e3,
            mean * 1e3,
            l.b / mean,
            l.r_r / l.r_l,
            -l.r_l / l.b,
            l.r_r / l.b
        );
    }
    if calibrations.is_empty() || trials.is_empty() {
        return s;
    }
    let _ = writeln!(
        s,
        "\nDifferences, UMBmark trial minus calibration: b and r̄ in mm and in %, and the \
         ratios in %.\n"
    );
    let _ = writeln!(
        s,
        "| trial | against | Δb (mm) | Δb (%) | Δr̄ (mm) | Δr̄ (%) | Δ(b/r̄) (%) | Δ(r_R/r_L) (%) |"
    );
    let _ = writeln!(s, "|---|---|---:|---:|---:|---:|---:|---:|");
    for t in trials {
        let tm = 0.5 * (t.r_l + t.r_r);
        for c in calibrations {
            let cm = 0.5 * (c.r_l + c.r_r);
            let pct = |a: f64, b: f64| 100.0 * (a - b) / b;
            let _ = writeln!(
                s,
                "| {} | {} | {:+.2} | {:+.2} | {:+.3} | {:+.2} | {:+.2} | {:+.3} |",
                t.trial,
                c.name,
                (t.b - c.b) * 1e3,
                pct(t.b, c.b),
                (tm - cm) * 1e3,
                pct(tm, cm),
                pct(t.b / tm, c.b / cm),
                pct(t.r_r / t.r_l, c.r_r / c.r_l)
            );
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use odocal_geom::Pose2;

    // Made-up numbers throughout: these test the mechanisms, not a published table.
    const TABLE: &str = r#"{"citation": "made up", "rows": [
        {"name": "swapped", "samples": 1200,
         "si": {"r_l": 0.0212, "r_r": 0.0208, "b": 0.09, "l_x": 0.01, "l_y": -0.02, "l_theta": 0.3},
         "J11": 0.0104, "J12": 0.0106, "J21": -0.2311111, "J22": 0.2355556,
         "sigma": {"r_l": 4e-5, "r_r": 4e-5, "b": 2e-4, "l_x": 8e-5, "l_y": 1e-4, "l_theta": 1.5e-3}},
        {"name": "plain", "samples": 900,
         "si": {"r_l": 0.0208, "r_r": 0.0212, "b": 0.09, "l_x": 0.0, "l_y": 0.0, "l_theta": 0.0},
         "j21": -0.2311111, "j22": 0.2355556},
        {"name": "no-j", "samples": 10,
         "si": {"r_l": 0.0208, "r_r": 0.0212, "b": 0.09, "l_x": 0.0, "l_y": 0.0, "l_theta": 0.0}}
    ], "label": "Made-up table",
    "table_ii": {"note": "made up", "rows": [
        {"trial": "1", "b": 0.09, "r_l": 0.0212, "r_r": 0.0208, "E_b": 1.0,
         "j11": 0.0106, "j12": 0.0104, "j21": -0.2355556, "j22": 0.2311111},
        {"trial": "2", "b": 0.08, "r_l": 0.02, "r_r": 0.02}
    ]}}"#;

    fn table() -> Vec<PublishedRow> {
        parse_table(TABLE, Path::new("made-up.json")).unwrap()
    }

    #[test]
    fn table_rows_parse_and_j_is_authoritative_for_the_radii() {
        let rows = table();
        assert_eq!(rows.len(), 3);
        // r_L = −b·J21, r_R = b·J22, whatever the printed radius columns say.
        for row in &rows[..2] {
            let t = row.truth();
            assert!((t.r_l - 0.0208).abs() < 1e-8, "{}", t.r_l);
            assert!((t.r_r - 0.0212).abs() < 1e-8, "{}", t.r_r);
        }
        assert_eq!(rows[0].sigma.unwrap()[2], 2e-4);
        assert_eq!(rows[2].truth().r_l, 0.0208);
        assert_eq!(rows[1].scaled_samples(0.5), 450);
    }

    #[test]
    fn umbmark_trials_parse_and_compare() {
        let t = parse_table_document(TABLE, Path::new("made-up.json")).unwrap();
        assert_eq!(t.rows[0].source, "Made-up table");
        assert_eq!(t.umbmark_note.as_deref(), Some("made up"));
        assert_eq!(t.umbmark.len(), 2);
        assert_eq!(t.umbmark[0].e_b, Some(1.0));
        assert_eq!(t.umbmark[1].e_d, None);
        let c = umbmark_j_consistency(&t.umbmark[0], 1e-3).unwrap();
        assert_eq!(c.reading, JReading::AsPrinted);
        assert!(c.abs_deviation_as_printed < 1e-6, "{c:?}");
        assert!(umbmark_j_consistency(&t.umbmark[1], 1e-3).is_none());
        let cal = OdometryLine {
            name: "cal".into(),
            b: 0.08,
            r_l: 0.019,
            r_r: 0.021,
        };
        let md = format_umbmark(&t.umbmark, &[], &[cal]);
        // Trial 2 against the calibration: same b and mean radius, r_R/r_L 1 vs 21/19.
        assert!(
            md.contains("| 2 | cal | +0.00 | +0.00 | +0.000 | +0.00 | +0.00 | -9.524 |"),
            "{md}"
        );
        let e = parse_table_document(
            r#"{"rows": [], "table_ii": {"rows": [{"trial": "x", "b": -1, "r_l": 0.02, "r_r": 0.02}]}}"#,
            Path::new("t.json"),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("trial 'x'") && e.contains("positive"), "{e}");
    }

    #[test]
    fn row_seeds_depend_on_the_name_only() {
        assert_eq!(row_seed(1, "k07"), row_seed(1, "k07"));
        assert_ne!(row_seed(1, "k07"), row_seed(1, "k08"));
        assert_ne!(row_seed(1, "k07"), row_seed(2, "k07"));
    }

    #[test]
    fn consistency_check_tells_the_heading_swap() {
        let rows = table();
        let c = j_consistency(&rows[0], 1e-3).unwrap();
        assert_eq!(c.reading, JReading::HeadingsSwapped);
        assert!(c.deviation_swapped < 1e-6 && c.deviation_as_printed > 1e-2);
        let c = j_consistency(&rows[1], 1e-3).unwrap();
        assert_eq!(c.reading, JReading::AsPrinted);
        assert!(c.printed[0].is_nan());
        assert!(j_consistency(&rows[2], 1e-3).is_none());
        // Equal radii cannot tell the readings apart; wrong J fits neither.
        let mut equal = rows[1].clone();
        equal.printed.r_r = equal.printed.r_l;
        equal.j = Some(PrintedJ {
            j11: None,
            j12: None,
            j21: -0.0208 / 0.09,
            j22: 0.0208 / 0.09,
        });
        assert_eq!(
            j_consistency(&equal, 1e-3).unwrap().reading,
            JReading::Ambiguous
        );
        equal.j.as_mut().unwrap().j22 = 0.3;
        assert_eq!(
            j_consistency(&equal, 1e-3).unwrap().reading,
            JReading::Neither
        );
    }

    #[test]
    fn bad_tables_are_clear_errors() {
        let p = Path::new("t.json");
        let e = parse_table("{\"rows\": 3}", p).unwrap_err().to_string();
        assert!(
            e.contains("t.json") && e.contains("expected an array"),
            "{e}"
        );
        let row = |extra: &str| {
            format!(
                r#"[{{"name": "x", "samples": 5, "si": {{"r_l": 0.02, "r_r": 0.02, "b": 0.09,
                   "l_x": 0, "l_y": 0, "l_theta": 0}}{extra}}}]"#
            )
        };
        let e = parse_table(&row(r#", "j21": -0.2"#), p)
            .unwrap_err()
            .to_string();
        assert!(e.contains("both j21 and j22"), "{e}");
        let e = parse_table(&row(r#", "j21": 0.2, "j22": 0.2"#), p)
            .unwrap_err()
            .to_string();
        assert!(e.contains("row 'x'") && e.contains("positive"), "{e}");
        let twice = format!("[{0}, {0}]", &row("")[1..row("").len() - 1]);
        let e = parse_table(&twice, p).unwrap_err().to_string();
        assert!(e.contains("twice"), "{e}");
    }

    #[test]
    fn the_tro_reference_reads_the_published_numbers() {
        let dir = workspace_reference_dir();
        if !dir.join("lstraight_results.json").exists() {
            println!("skipped: no reference data at {}", dir.display());
            return;
        }
        let rows = read_tro_reference(&dir).unwrap();
        let names: Vec<&str> = rows.iter().map(|r| r.name.as_str()).collect();
        assert_eq!(names, ["lstraight", "l90", "lmov"]);
        // The published numbers quoted in docs/method.md and the reference README.
        let a = &rows[0];
        assert_eq!(a.samples, 4396);
        assert_eq!(rows[1].samples, 3295);
        assert_eq!(rows[2].samples, 4345);
        let t = a.truth();
        assert_eq!(t.b, 0.0890519);
        // `l_diam`, `r_diam` are diameters: 0.0417709 / 2, 0.0418957 / 2.
        assert!((t.r_l - 0.02088545).abs() < 1e-12 && (t.r_r - 0.02094785).abs() < 1e-12);
        assert_eq!(t.laser, Pose2::new(-0.00581279, 0.000185606, 0.00949588));
        assert!((a.sigma.unwrap()[2] - 4.38323e-08f64.sqrt()).abs() < 1e-12);
    }
}
