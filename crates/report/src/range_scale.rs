//! The laser's range scale in the report: `results.json`'s `range_scale` (the scale
//! term and the combined σ and covariance, beside `sigma` and `covariance`, which stay
//! the data's alone) and the summary's words for it.

use odocal_pipeline::{Estimate, RangeScale};
use serde::Serialize;

/// `results.json`'s `range_scale`: where the scale σ came from (stated, the data
/// sheet of the range finder recognised, or unknown), what it adds, and data and
/// scale together.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RangeScaleReport {
    /// The scale, where it came from, the sensor recognised and why.
    #[serde(flatten)]
    pub scale: RangeScale,
    /// What the run's distances rest on, in one sentence (as the summary prints it).
    pub statement: String,
    /// Standard deviations the scale adds, order r_L, r_R, b, ℓx, ℓy, ℓθ (0 for a
    /// held parameter, and for ℓθ unless some parameters are held or have priors).
    pub sigma_from_scale: [f64; 6],
    /// Standard deviations of data and scale together (`sigma` is the data's alone).
    pub sigma_total: [f64; 6],
    /// Covariance of data and scale together (`covariance` is the data's alone).
    pub covariance_total: [[f64; 6]; 6],
}

impl RangeScaleReport {
    /// The report's range-scale part for `scale` and the estimate `e`.
    pub fn new(scale: &RangeScale, e: &Estimate) -> RangeScaleReport {
        RangeScaleReport {
            scale: scale.clone(),
            statement: scale.sentence(),
            sigma_from_scale: e.sigma_range_scale,
            sigma_total: e.sigma_total,
            covariance_total: e.covariance_total,
        }
    }

    /// The σ part of parameter `i`'s summary line: `± 0.2000 mm` with no scale term,
    /// `± 0.2000 mm (data) ± 0.7460 mm (laser range scale 1 %) = ± 0.7723 mm` with one
    /// (ℓθ has one only when some parameters are held or have priors). `unit` is the
    /// factor to the shown unit.
    pub fn sigma_words(&self, i: usize, data_sigma: f64, unit: f64, name: &str) -> String {
        if !self.scale.applies() || (i == 5 && self.sigma_from_scale[5] == 0.0) {
            return format!("± {:.4} {name}", data_sigma * unit);
        }
        format!(
            "± {:.4} {name} (data) ± {:.4} {name} ({}) = ± {:.4} {name}",
            data_sigma * unit,
            self.sigma_from_scale[i] * unit,
            self.scale.label(),
            self.sigma_total[i] * unit
        )
    }
}
