//! The laser's range-scale uncertainty of a run: stated by the user
//! (`--laser-range-scale`), taken from the data sheet of a recognised range finder
//! ([`crate::range_finder`]), or unknown (the distances then assume the laser's
//! range scale exact, and the summary says so and how to state it).

use crate::range_finder::{recognise, LaserSignature};
use serde::Serialize;

/// Where a run's range-scale σ came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RangeScaleSource {
    /// Stated on the command line (`--laser-range-scale`) or by the caller.
    Stated,
    /// The data sheet of the range finder recognised in the input.
    DataSheet,
    /// Neither: the laser was not recognised and nothing was stated (σ 0).
    Unknown,
}

/// The laser's range-scale uncertainty that a run's distances carry.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RangeScale {
    /// One σ of the laser's range scale, relative (0.01: 1 %); 0 means the distances
    /// assume the range scale exact.
    pub sigma: f64,
    /// Where `sigma` came from.
    pub source: RangeScaleSource,
    /// The range finder recognised in the input, when any (also when `sigma` was
    /// stated).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sensor: Option<String>,
    /// What in the input identified it (rays, spacing, coverage, range limits, …).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub recognised_from: Option<String>,
    /// What its data sheet says about range accuracy, and where.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub data_sheet: Option<String>,
}

/// The command-line option that states the scale.
pub const RANGE_SCALE_OPTION: &str = "--laser-range-scale";

impl RangeScale {
    /// No scale term and no sensor: what a run without scans to look at gets.
    pub fn unknown() -> RangeScale {
        RangeScale {
            sigma: 0.0,
            source: RangeScaleSource::Unknown,
            sensor: None,
            recognised_from: None,
            data_sheet: None,
        }
    }

    /// The scale of a run: `stated` (relative σ) when given, else the data sheet's of
    /// the range finder `signature` identifies, else unknown (σ 0).
    pub fn resolve(stated: Option<f64>, signature: Option<&LaserSignature>) -> RangeScale {
        let recognised = signature.and_then(recognise);
        let mut scale = match &recognised {
            Some(r) => RangeScale {
                sigma: r.finder.scale_sigma,
                source: RangeScaleSource::DataSheet,
                sensor: Some(r.finder.name.to_string()),
                recognised_from: Some(r.why.clone()),
                data_sheet: Some(r.finder.data_sheet.to_string()),
            },
            None => RangeScale::unknown(),
        };
        if let Some(s) = stated {
            scale.sigma = s;
            scale.source = RangeScaleSource::Stated;
        }
        scale
    }

    /// True when the distances carry a scale term.
    pub fn applies(&self) -> bool {
        self.sigma > 0.0
    }

    /// The scale in words for the parameter lines: "laser range scale 1 %".
    pub fn label(&self) -> String {
        format!("laser range scale {} %", percent(self.sigma))
    }

    /// What the run's distances rest on, in one sentence: the sensor recognised and
    /// why, the σ used and where it came from, what does not depend on it; or, with no
    /// scale term, that the distances assume an exact range scale and how to state one.
    pub fn sentence(&self) -> String {
        let sensor = match (&self.sensor, &self.recognised_from) {
            (Some(name), Some(why)) => format!("laser recognised as a {name} ({why})"),
            _ => "laser not recognised".to_string(),
        };
        let turning = "how the robot turns per wheel rotation (J21, J22) and l_theta do not \
                       depend on it (while no parameter is held: a held one does not move \
                       with it, and the others take the share the data give them)";
        match self.source {
            RangeScaleSource::Stated if self.applies() => format!(
                "{sensor}; range scale ±{} % as stated ({RANGE_SCALE_OPTION}): r_L, r_R, b, \
                 l_x, l_y scale with it, their σ include it; {turning}",
                percent(self.sigma)
            ),
            RangeScaleSource::DataSheet if self.applies() => format!(
                "{sensor}; range scale ±{} % from its data sheet ({}): r_L, r_R, b, l_x, l_y \
                 scale with it, their σ include it ({RANGE_SCALE_OPTION} PCT to state your \
                 unit's); {turning}",
                percent(self.sigma),
                self.data_sheet.as_deref().unwrap_or("")
            ),
            RangeScaleSource::DataSheet => format!(
                "{sensor}; its data sheet gives no range-proportional error ({}): distances \
                 assume an exact laser range scale ({RANGE_SCALE_OPTION} PCT to state one)",
                self.data_sheet.as_deref().unwrap_or("")
            ),
            RangeScaleSource::Stated => format!(
                "{sensor}; range scale stated exact ({RANGE_SCALE_OPTION} 0): the distances \
                 carry no scale term"
            ),
            RangeScaleSource::Unknown => format!(
                "{sensor}; distances (r_L, r_R, b, l_x, l_y) assume an exact laser range scale: \
                 a laser reading 1 % long makes them 1 % large, and the data cannot tell; \
                 state the data sheet's range accuracy with {RANGE_SCALE_OPTION} PCT (e.g. \
                 {RANGE_SCALE_OPTION} 1); {turning}"
            ),
        }
    }
}

/// `sigma` (relative) in per cent, without trailing zeros: 0.01 → "1", 0.005 → "0.5".
fn percent(sigma: f64) -> String {
    let s = format!("{:.3}", 100.0 * sigma);
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

#[cfg(test)]
mod tests {
    use super::*;
    use odocal_log::ScanGeometry;

    #[test]
    fn resolved_from_the_sheet_or_the_statement() {
        let urg = LaserSignature::of_geometry(&ScanGeometry::urg_04lx(), None);
        let sheet = RangeScale::resolve(None, Some(&urg));
        assert_eq!(sheet.sigma, 0.01);
        assert_eq!(sheet.source, RangeScaleSource::DataSheet);
        assert!(sheet.sentence().contains("Hokuyo URG-04LX"));
        assert!(sheet.sentence().contains("±1 % from its data sheet"));
        let stated = RangeScale::resolve(Some(0.002), Some(&urg));
        assert_eq!(stated.sigma, 0.002);
        assert_eq!(stated.source, RangeScaleSource::Stated);
        assert_eq!(stated.label(), "laser range scale 0.2 %");
        let exact = RangeScale::resolve(Some(0.0), Some(&urg));
        assert!(
            exact.sentence().contains("stated exact"),
            "{}",
            exact.sentence()
        );
        let none = RangeScale::resolve(None, None);
        assert!(!none.applies());
        assert!(none
            .sentence()
            .contains("assume an exact laser range scale"));
        assert!(none.sentence().contains("--laser-range-scale"));
    }
}
