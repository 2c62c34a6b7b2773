//! Named configurations: the built-in presets, plus one preset per row of a Table I
//! file (`fixtures/table-i.json`) when that file exists.
//!
//! A Table I file is JSON: either an array of rows, or an object holding the array
//! under `rows` or `table_i`. Each row has `name` (string), `samples` (number of
//! calibration samples) and `si` = `{r_l, r_r, b, l_x, l_y, l_theta}` in metres and
//! radians, and optionally the printed J columns `j21`, `j22` (also `J21`, `J22`).
//! Other fields are ignored. A row becomes a preset named after the row
//! ([`table_row_config`]): the `khepera` preset with the row's parameters as the true
//! ones — the radii from `r_L = −b·J21`, `r_R = b·J22` when the row prints J (the
//! ICRA 2008 Table I prints its `r_L`, `r_R` headings swapped; J is authoritative) —
//! driven for `samples` × [`SECONDS_PER_SAMPLE`].

use crate::config::SimConfig;
use crate::error::SimError;
use crate::kinematics::RobotParams;
use crate::laser::LaserConfig;
use crate::planner::TrajectoryKind;
use crate::robot_classes;
use odocal_geom::{FlatParams, Pose2};
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// The built-in preset names (the last three with the realistic laser in cluttered
/// worlds: [`crate::REALISTIC_PRESETS`]).
pub const BUILTIN_PRESETS: [&str; 12] = [
    "khepera",
    "turtlebot",
    "pioneer",
    "khepera-displaced",
    "office",
    "corridor",
    "straight-only",
    "spin-only",
    "identical-turns",
    "mines-rover",
    "neato-lds",
    "turtlebot4-rplidar",
];

/// Seconds of driving per calibration sample: the calibration pipeline's default
/// interval between the two scans of a sample (`odocal_pipeline::sync::TARGET_INTERVAL_S`,
/// 4 scan periods at 10 Hz).
pub const SECONDS_PER_SAMPLE: f64 = 0.4;

/// One row of a Table I file (see the module documentation).
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct TableRow {
    /// The row's name (`k07`, `k06-k15`, …), used as the preset name.
    pub name: String,
    /// Number of samples of the experiment.
    pub samples: u64,
    /// The calibrated parameters in SI units, under the headings as printed.
    pub si: FlatParams,
    /// The printed J21 (`−r_L/b`), when the table has it.
    #[serde(default, alias = "J21")]
    pub j21: Option<f64>,
    /// The printed J22 (`r_R/b`), when the table has it.
    #[serde(default, alias = "J22")]
    pub j22: Option<f64>,
}

impl TableRow {
    /// The row's true parameters: `si`, except that with J columns the radii are
    /// `r_L = −b·J21`, `r_R = b·J22`.
    pub fn truth(&self) -> FlatParams {
        let mut p = self.si;
        if let (Some(j21), Some(j22)) = (self.j21, self.j22) {
            p.r_l = -p.b * j21;
            p.r_r = p.b * j22;
        }
        p
    }
}

/// The `khepera` preset named `name` with `truth` as the true parameters, driven
/// long enough for about `samples` calibration samples at [`SECONDS_PER_SAMPLE`]
/// (the configuration of a Table I row).
pub fn table_row_config(name: &str, truth: &RobotParams, samples: u64) -> SimConfig {
    let mut c = builtin("khepera").unwrap_or_default();
    c.preset = name.to_string();
    c.robot = *truth;
    if samples > 0 {
        // Half a sample more, so that the last interval is complete.
        c.duration = (samples as f64 + 0.5) * SECONDS_PER_SAMPLE;
    }
    c
}

/// The Carmen log text of a Table I row's simulation ([`table_row_config`] with
/// `seed`), as `odocal table-i` and its tests calibrate it.
pub fn simulate_table_row(
    name: &str,
    truth: &RobotParams,
    samples: u64,
    seed: u64,
) -> Result<Vec<u8>, SimError> {
    let mut config = table_row_config(name, truth, samples);
    config.seed = seed;
    let run = crate::simulation::simulate(&config)?;
    let mut text = Vec::new();
    run.write_log(&mut text, &[])?;
    Ok(text)
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
            if row.j21.is_some() != row.j22.is_some() {
                return Err(err(format!(
                    "row '{}': J columns need both j21 and j22",
                    row.name
                )));
            }
            let p = row.truth();
            let lengths_ok = [p.r_l, p.r_r, p.b]
                .iter()
                .all(|v| v.is_finite() && *v > 0.0 && *v < 10.0);
            if !lengths_ok || ![p.l_x, p.l_y, p.l_theta].iter().all(|v| v.is_finite()) {
                return Err(err(format!(
                    "row '{}': si must hold positive radii (also −b·J21 and b·J22) and wheel \
                     distance (m) and a finite laser pose",
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
            let truth = RobotParams::from(row.truth());
            return Ok(table_row_config(&row.name, &truth, row.samples));
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
        _ => return crate::realistic_presets::preset(name, c),
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
                 "si": {"r_l": 0.021, "r_r": 0.022, "b": 0.09, "l_x": 0.01, "l_y": -0.02, "l_theta": 0.3}},
                {"name": "row-j", "samples": 10,
                 "si": {"r_l": 0.022, "r_r": 0.021, "b": 0.09, "l_x": 0, "l_y": 0, "l_theta": 0},
                 "J21": -0.23, "J22": 0.24}
            ]}"#,
        )
        .unwrap();
        let reg = PresetRegistry::builtin().with_table_file(&path).unwrap();
        assert!(reg.names().contains(&"row-a".to_string()));
        let c = reg.get("row-a").unwrap();
        assert_eq!(c.robot.r_r, 0.022);
        assert_eq!(c.robot.laser, Pose2::new(0.01, -0.02, 0.3));
        assert_eq!(c.duration, 1200.5 * SECONDS_PER_SAMPLE);
        // Printed J columns are authoritative for the radii.
        let c = reg.get("row-j").unwrap();
        assert!((c.robot.r_l - 0.09 * 0.23).abs() < 1e-15, "{}", c.robot.r_l);
        assert!((c.robot.r_r - 0.09 * 0.24).abs() < 1e-15, "{}", c.robot.r_r);
        c.validate().unwrap();

        std::fs::write(
            &path,
            r#"[{"name": "bad", "samples": 1, "si": {"r_l": -1}}]"#,
        )
        .unwrap();
        let e = PresetRegistry::builtin()
            .with_table_file(&path)
            .unwrap_err();
        assert!(e.to_string().contains("table.json"), "{e}");
        std::fs::write(
            &path,
            r#"[{"name": "half-j", "samples": 1, "j21": -0.2,
                 "si": {"r_l": 0.02, "r_r": 0.02, "b": 0.09, "l_x": 0, "l_y": 0, "l_theta": 0}}]"#,
        )
        .unwrap();
        let e = PresetRegistry::builtin()
            .with_table_file(&path)
            .unwrap_err();
        assert!(e.to_string().contains("both j21 and j22"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn every_row_of_the_project_table_is_a_valid_preset() {
        let path = PresetRegistry::default_table_path();
        if !path.exists() {
            println!("skipped: no {}", path.display());
            return;
        }
        let reg = PresetRegistry::builtin().with_table_file(&path).unwrap();
        assert_eq!(reg.table_rows().len(), 19);
        for row in reg.table_rows() {
            let c = reg.get(&row.name).unwrap();
            c.validate().unwrap();
            assert!(row.j21.is_some() && row.j22.is_some(), "{}", row.name);
        }
        // ICRA 2008 Table I, k22-k29: b = 0.08682, J21 = −0.23012, J22 = 0.23029.
        let c = reg.get("k22-k29").unwrap();
        assert!((c.robot.r_l - 0.08682 * 0.23012).abs() < 1e-15);
        assert!((c.robot.r_r - 0.08682 * 0.23029).abs() < 1e-15);
        assert_eq!(c.robot.laser, Pose2::new(-0.00603, 0.00125, -0.00156));
        assert_eq!(c.duration, 10987.5 * SECONDS_PER_SAMPLE);
    }
}
