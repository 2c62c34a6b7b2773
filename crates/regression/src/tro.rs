//! The T-RO 2013 package's published results as published rows.

use crate::table::{PublishedRow, TableError};
use odocal_geom::FlatParams;
use odocal_log::read_tuples;
use serde::Deserialize;
use std::path::{Path, PathBuf};

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

/// The reference data: the directory named by the environment variable
/// `ODOCAL_REFERENCE_DIR` when set (e.g. for a git worktree elsewhere), else
/// `../shared/reference/` beside the workspace (never copied into the repository).
pub fn workspace_reference_dir() -> PathBuf {
    match std::env::var_os("ODOCAL_REFERENCE_DIR") {
        Some(dir) if !dir.is_empty() => PathBuf::from(dir),
        _ => Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/reference"),
    }
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
