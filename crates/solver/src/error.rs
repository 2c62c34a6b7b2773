//! The one error type of the solver: what is wrong with the samples, and which
//! sample or parameter it concerns.

use serde::Serialize;

/// Why the solver refused to return numbers.
#[derive(Debug, Clone, PartialEq, thiserror::Error, Serialize)]
pub enum SolveError {
    /// Not enough samples for the estimate (before or after outlier trimming).
    #[error("too few samples: {got} usable, at least {needed} needed ({stage})")]
    TooFewSamples {
        /// How many samples were usable.
        got: usize,
        /// The minimum the solver needs.
        needed: usize,
        /// Where the shortage occurred (e.g. "input", "after trimming round 2").
        stage: String,
    },
    /// A field of a sample is NaN or infinite.
    #[error("sample {index} (counting from 0): {field} is not finite ({value})")]
    NonFinite {
        /// Index of the sample in the input slice, from 0.
        index: usize,
        /// The offending field (e.g. `sm.theta`, `dphi_l`, `sm_cov[1][1]`).
        field: String,
        /// The value found.
        value: f64,
    },
    /// A sample is finite but unusable (non-positive interval, covariance not
    /// positive definite, profile inconsistent with the totals, …).
    #[error("sample {index} (counting from 0): {reason}")]
    InvalidSample {
        /// Index of the sample in the input slice, from 0.
        index: usize,
        /// What is wrong and what was expected.
        reason: String,
    },
    /// The data do not excite some parameters: the motion needed to observe them is
    /// missing, so no numbers are returned for any of them.
    #[error("the data do not determine {}: {sentence}", parameters.join(", "))]
    NotExcited {
        /// Names of the parameters that are not excited (`r_L`, `r_R`, `b`, `l_x`,
        /// `l_y`, `l_theta`).
        parameters: Vec<String>,
        /// What motion is missing, in words.
        sentence: String,
    },
    /// A numerical step failed in a way the checks above did not foresee.
    #[error("numerical failure: {0}")]
    Numerical(String),
}
