//! Named configurations: the built-in presets, plus one preset per row of a Table I
//! file (`fixtures/table-i.json`) when that file exists.
//!
//! A Table I file is JSON: either an array of rows, or an object holding the array
//! under `rows` or `table_i`. Each row has `name` (string), `samples` (number of
//! samples, i.e. scan intervals) and `si` = `{r_l, r_r, b, l_x, l_y, l_theta}` in
//! metres and radians. Other fields are ignored. A row becomes a preset named after
//! the row: the `khepera` preset with the row's parameters as the true ones, and a
//! duration of `samples` scan periods.

use crate::config::SimConfig;
use crate::error::SimError;
use crate::laser::LaserConfig;
use crate::planner::TrajectoryKind;
use crate::robot_classes;
use crate::truth::TruthParams;
use odocal_geom::Pose2;
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// The built-in preset names.
pub const BUILTIN_PRESETS: [&str; 9] = [
    "khepera",
    "turtlebot",
    "pioneer",
    "khepera-displaced",
    "office",
    "corridor",
    "straight-only",
    "spin-only",
    "identical-turns",
];

/// One row of a Table I file (see the module documentation).
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct TableRow {
    /// The row's name (`k07`, `k06-k15`, …), used as the preset name.
    pub name: String,
    /// Number of samples of the experiment.
    pub samples: u64,
    /// The calibrated parameters in SI units.
    pub si: TruthParams,
}

/// The presets available to [`SimConfig::preset`] and the command line.
#[derive(Debug, Clone, Default)]
pub struct PresetRegistry {
    rows: Vec<TableRow>,
    table: Option<PathBuf>,
    /// Why the project's Table I file could not be used, when it exists but is bad.
    table_error: Option<String>,
}

#[derive(Deserialize)]
#[serde(untagged)]
enum TableFile {
    Rows(Vec<TableRow>),
    Keyed {
        #[serde(alias = "table_i")]
        rows: Vec<TableRow>,
    },
}

impl PresetRegistry {
    /// Only the built-in presets.
    pub fn builtin() -> Self {
        PresetRegistry::default()
    }

    /// The project's Table I file, `fixtures/table-i.json` at the workspace root.
    pub fn default_table_path() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/table-i.json")
    }

    /// The built-in presets plus the rows of the project's Table I file, if it exists.
    ///
    /// A Table I file that cannot be used does not take the built-in presets down:
    /// its error is reported when an unknown preset name is asked for.
    pub fn standard() -> Self {
        let path = Self::default_table_path();
        if !path.exists() {
            return Self::builtin();
        }
        match Self::builtin().with_table_file(&path) {
            Ok(r) => r,
            Err(e) => PresetRegistry {
                table_error: Some(e.to_string()),
                ..Self::builtin()
            },
        }
    }

    /// Adds one preset per row of the Table I file at `path`.
    pub fn with_table_file(mut self, path: &Path) -> Result<Self, SimError> {
        let err = |message: String| SimError::TableFile {
            path: path.to_path_buf(),
            message,
        };
        let text = std::fs::read_to_string(path).map_err(|e| err(e.to_string()))?;
        let rows = match serde_json::from_str::<TableFile>(&text) {
            Ok(TableFile::Rows(r)) | Ok(TableFile::Keyed { rows: r }) => r,
            Err(e) => {
                return Err(err(format!(
                    "{e}; expected an array of rows (or {{\"rows\": [...]}}), each with \
                     name, samples and si {{r_l, r_r, b, l_x, l_y, l_theta}}"
                )))
            }
        };
        for row in &rows {
            let p = row.si;
            let lengths_ok = [p.r_l, p.r_r, p.b]
                .iter()
                .all(|v| v.is_finite() && *v > 0.0 && *v < 10.0);
            if !lengths_ok || ![p.l_x, p.l_y, p.l_theta].iter().all(|v| v.is_finite()) {
                return Err(err(format!(
                    "row '{}': si must hold positive radii and wheel distance (m) and a finite laser pose",
                    row.name
                )));
            }
            if BUILTIN_PRESETS.contains(&row.name.as_str()) {
                return Err(err(format!(
                    "row '{}' has the name of a built-in preset",
                    row.name
                )));
            }
        }
        self.rows.extend(rows);
        self.table = Some(path.to_path_buf());
        Ok(self)
    }

    /// Every preset name: the built-in ones, then the table rows.
    pub fn names(&self) -> Vec<String> {
        BUILTIN_PRESETS
            .iter()
            .map(|s| s.to_string())
            .chain(self.rows.iter().map(|r| r.name.clone()))
            .collect()
    }

    /// The Table I rows loaded.
    pub fn table_rows(&self) -> &[TableRow] {
        &self.rows
    }

    /// The configuration of the preset `name`.
    pub fn get(&self, name: &str) -> Result<SimConfig, SimError> {
        if let Some(c) = builtin(name) {
            return Ok(c);
        }
        if let Some(row) = self.rows.iter().find(|r| r.name == name) {
            let mut c = builtin("khepera").unwrap_or_default();
            c.preset = row.name.clone();
            let p = row.si;
            c.robot.r_l = p.r_l;
            c.robot.r_r = p.r_r;
            c.robot.b = p.b;
            c.robot.laser = Pose2::new(p.l_x, p.l_y, p.l_theta);
            if row.samples > 0 {
                c.duration = row.samples as f64 / c.laser.rate_hz;
            }
            return Ok(c);
        }
        let mut known = self.names().join(", ");
        if let Some(e) = &self.table_error {
            known.push_str(&format!("; Table I rows unavailable: {e}"));
        } else if self.table.is_none() {
            known.push_str(&format!(
                "; Table I rows become presets when {} exists",
                Self::default_table_path().display()
            ));
        }
        Err(SimError::UnknownName {
            what: "preset",
            name: name.to_string(),
            known,
        })
    }
}

impl SimConfig {
    /// The preset `name` from [`PresetRegistry::standard`] (built-in presets and, when
    /// `fixtures/table-i.json` exists, its rows).
    pub fn preset(name: &str) -> Result<SimConfig, SimError> {
        PresetRegistry::standard().get(name)
    }
}

/// The built-in presets (see [`BUILTIN_PRESETS`]).
fn builtin(name: &str) -> Option<SimConfig> {
    let base = SimConfig::default();
    let mut c = SimConfig {
        preset: name.to_string(),
        ..base
    };
    match name {
        "khepera" => {}
        "khepera-displaced" => {
            // A laser mounted off-centre and rotated, like the ICRA 2008 k40–k45 runs.
            c.robot.laser = Pose2::new(0.024, 0.041, 0.36);
        }
        "office" => {
            c.world = "office".into();
            c.duration = 300.0;
        }
        "corridor" => {
            c.world = "corridor".into();
            c.duration = 300.0;
        }
        "straight-only" => c.trajectory = TrajectoryKind::StraightOnly,
        "spin-only" => c.trajectory = TrajectoryKind::SpinOnly,
        "identical-turns" => c.trajectory = TrajectoryKind::IdenticalTurns,
        "turtlebot" => return Some(robot_classes::turtlebot(c)),
        "pioneer" => return Some(robot_classes::pioneer(c)),
        _ => return None,
    }
    // The Khepera presets keep the instantaneous URG-04LX of the logs they reproduce.
    debug_assert_eq!(c.laser, LaserConfig::default());
    Some(c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_builtin_preset_is_valid() {
        let reg = PresetRegistry::builtin();
        for name in BUILTIN_PRESETS {
            let c = reg.get(name).unwrap();
            assert_eq!(c.preset, name);
            c.validate().unwrap();
        }
        assert!(matches!(reg.get("k99"), Err(SimError::UnknownName { .. })));
    }

    #[test]
    fn table_rows_become_presets() {
        let dir = std::env::temp_dir().join(format!("odocal-sim-table-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("table.json");
        // Made-up numbers: this tests the mechanism, not the published table.
        std::fs::write(
            &path,
            r#"{"citation": "test", "rows": [
                {"name": "row-a", "samples": 1200, "extra": 1,
                 "si": {"r_l": 0.021, "r_r": 0.022, "b": 0.09, "l_x": 0.01, "l_y": -0.02, "l_theta": 0.3}}
            ]}"#,
        )
        .unwrap();
        let reg = PresetRegistry::builtin().with_table_file(&path).unwrap();
        assert!(reg.names().contains(&"row-a".to_string()));
        let c = reg.get("row-a").unwrap();
        assert_eq!(c.robot.r_r, 0.022);
        assert_eq!(c.robot.laser, Pose2::new(0.01, -0.02, 0.3));
        assert_eq!(c.duration, 120.0);

        std::fs::write(
            &path,
            r#"[{"name": "bad", "samples": 1, "si": {"r_l": -1}}]"#,
        )
        .unwrap();
        let e = PresetRegistry::builtin()
            .with_table_file(&path)
            .unwrap_err();
        assert!(e.to_string().contains("table.json"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
