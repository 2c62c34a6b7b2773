//! Partial calibration: parameters held at known values, or given a Gaussian prior
//! (`NAME=VALUE`, `NAME=VALUE±SIGMA` on the command line).

use crate::normal_equations::NormalEquations;
use crate::params::{Params, PARAMETER_NAMES};
use odocal_geom::wrap_angle;
use serde::{Deserialize, Serialize};
use std::fmt;

/// What is known about one parameter before calibrating.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Constraint {
    /// Nothing: estimated from the data alone.
    #[default]
    Free,
    /// Held at this value (m or rad); not estimated, zero variance.
    Held(f64),
    /// A Gaussian prior `mean ± sigma` (m or rad) combined with the data.
    Prior {
        /// Prior mean.
        mean: f64,
        /// Prior standard deviation (positive).
        sigma: f64,
    },
}

/// One [`Constraint`] per parameter, in the order of [`PARAMETER_NAMES`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Constraints(pub [Constraint; 6]);

impl Constraints {
    /// Whether parameter `i` is held.
    pub fn is_held(&self, i: usize) -> bool {
        matches!(self.0[i], Constraint::Held(_))
    }

    /// The held value of parameter `i`, if any.
    pub fn held(&self, i: usize) -> Option<f64> {
        match self.0[i] {
            Constraint::Held(v) => Some(v),
            _ => None,
        }
    }

    /// Whether every parameter is free.
    pub fn is_empty(&self) -> bool {
        self.0.iter().all(|c| *c == Constraint::Free)
    }

    /// Whether any parameter has a prior.
    pub fn has_priors(&self) -> bool {
        self.0.iter().any(|c| matches!(c, Constraint::Prior { .. }))
    }

    /// The same constraints with every prior replaced by holding its mean (the
    /// closed form's fallback when the data alone do not determine a parameter).
    pub fn priors_held(&self) -> Constraints {
        Constraints(self.0.map(|c| match c {
            Constraint::Prior { mean, .. } => Constraint::Held(mean),
            other => other,
        }))
    }

    /// `params` with the held values put in.
    pub fn apply_held(&self, params: &Params) -> Params {
        let mut v = params.to_vector();
        for (i, x) in v.iter_mut().enumerate() {
            if let Some(h) = self.held(i) {
                *x = h;
            }
        }
        Params::from_vector(v)
    }

    /// Adds the priors to the normal equations at `params` (cost, `g`, `H`) and
    /// decouples the held parameters (zero gradient, unit diagonal, zero coupling),
    /// so that a Gauss–Newton step leaves them where they are.
    pub(crate) fn apply_to(&self, ne: &mut NormalEquations, params: &Params) {
        let v = params.to_vector();
        for i in 0..6 {
            match self.0[i] {
                Constraint::Free => {}
                Constraint::Held(_) => {
                    for j in 0..6 {
                        ne.h[i][j] = 0.0;
                        ne.h[j][i] = 0.0;
                    }
                    ne.h[i][i] = 1.0;
                    ne.g[i] = 0.0;
                }
                Constraint::Prior { mean, sigma } => {
                    let d = if i == 5 {
                        wrap_angle(v[i] - mean)
                    } else {
                        v[i] - mean
                    };
                    let w = 1.0 / (sigma * sigma);
                    ne.cost += w * d * d;
                    ne.g[i] += w * d;
                    ne.h[i][i] += w;
                }
            }
        }
    }

    /// Sets `constraint` on the parameter called `name` (one of
    /// [`PARAMETER_NAMES`], case-insensitive; `l_θ`-style spellings `ltheta`,
    /// `l_th` are not accepted). Errors when the name is unknown or the parameter
    /// already has a constraint.
    pub fn set(&mut self, name: &str, constraint: Constraint) -> Result<(), ConstraintError> {
        let i = parameter_index(name).ok_or_else(|| ConstraintError::UnknownName(name.into()))?;
        if self.0[i] != Constraint::Free {
            return Err(ConstraintError::Twice(PARAMETER_NAMES[i].into()));
        }
        self.0[i] = constraint;
        Ok(())
    }

    /// Names of the held parameters.
    pub fn held_names(&self) -> Vec<&'static str> {
        (0..6)
            .filter(|&i| self.is_held(i))
            .map(|i| PARAMETER_NAMES[i])
            .collect()
    }
}

/// A `--fix` or `--prior` argument that cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ConstraintError {
    /// The name is not one of the six parameters.
    #[error("unknown parameter '{0}': expected one of r_L, r_R, b, l_x, l_y, l_theta")]
    UnknownName(String),
    /// The same parameter was constrained twice.
    #[error("{0} is held or given a prior more than once")]
    Twice(String),
    /// The text is not `NAME=VALUE` (or `NAME=VALUE±SIGMA` for a prior).
    #[error("'{text}': expected {expected}")]
    Syntax {
        /// The argument as given.
        text: String,
        /// What was expected.
        expected: &'static str,
    },
    /// A value is not a finite number, a σ not positive, or a radius or the wheel
    /// distance not positive.
    #[error("'{text}': {reason}")]
    Value {
        /// The argument as given.
        text: String,
        /// What is wrong.
        reason: String,
    },
}

/// Index of a parameter by name (case-insensitive).
pub fn parameter_index(name: &str) -> Option<usize> {
    PARAMETER_NAMES
        .iter()
        .position(|n| n.eq_ignore_ascii_case(name.trim()))
}

fn number(field: &str, whole: &str) -> Result<f64, ConstraintError> {
    let v: f64 = field.trim().parse().map_err(|_| ConstraintError::Value {
        text: whole.into(),
        reason: format!("'{}' is not a number", field.trim()),
    })?;
    if !v.is_finite() {
        return Err(ConstraintError::Value {
            text: whole.into(),
            reason: format!("{v} is not a finite number"),
        });
    }
    Ok(v)
}

/// Radii and the wheel distance must be positive.
fn check_positive(i: usize, v: f64, whole: &str) -> Result<(), ConstraintError> {
    if i < 3 && v <= 0.0 {
        return Err(ConstraintError::Value {
            text: whole.into(),
            reason: format!("{} must be positive (m), got {v}", PARAMETER_NAMES[i]),
        });
    }
    Ok(())
}

/// Parses `NAME=VALUE` (SI units: m, rad) into a name and a held constraint.
pub fn parse_fix(text: &str) -> Result<(String, Constraint), ConstraintError> {
    const EXPECTED: &str = "NAME=VALUE with NAME one of r_L, r_R, b, l_x, l_y, l_theta (m, rad)";
    let (name, value) = text.split_once('=').ok_or(ConstraintError::Syntax {
        text: text.into(),
        expected: EXPECTED,
    })?;
    let i = parameter_index(name).ok_or_else(|| ConstraintError::UnknownName(name.into()))?;
    let v = number(value, text)?;
    check_positive(i, v, text)?;
    Ok((PARAMETER_NAMES[i].into(), Constraint::Held(v)))
}

/// Parses `NAME=VALUE±SIGMA` (or `NAME=VALUE+-SIGMA`; SI units) into a name and a
/// prior.
pub fn parse_prior(text: &str) -> Result<(String, Constraint), ConstraintError> {
    const EXPECTED: &str =
        "NAME=VALUE±SIGMA (or NAME=VALUE+-SIGMA) with NAME one of r_L, r_R, b, l_x, l_y, \
         l_theta (m, rad)";
    let syntax = || ConstraintError::Syntax {
        text: text.into(),
        expected: EXPECTED,
    };
    let (name, rest) = text.split_once('=').ok_or_else(syntax)?;
    let i = parameter_index(name).ok_or_else(|| ConstraintError::UnknownName(name.into()))?;
    let (mean, sigma) = rest
        .split_once('±')
        .or_else(|| rest.split_once("+-"))
        .ok_or_else(syntax)?;
    let mean = number(mean, text)?;
    let sigma = number(sigma, text)?;
    check_positive(i, mean, text)?;
    if sigma <= 0.0 {
        return Err(ConstraintError::Value {
            text: text.into(),
            reason: format!("the prior's σ must be positive, got {sigma}"),
        });
    }
    Ok((PARAMETER_NAMES[i].into(), Constraint::Prior { mean, sigma }))
}

impl fmt::Display for Constraint {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Constraint::Free => write!(f, "estimated"),
            Constraint::Held(v) => write!(f, "held at {v}"),
            Constraint::Prior { mean, sigma } => write!(f, "prior {mean} ± {sigma}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_fix_and_prior() {
        assert_eq!(
            parse_fix("b=0.089").unwrap(),
            ("b".to_string(), Constraint::Held(0.089))
        );
        assert_eq!(
            parse_fix("L_THETA=-0.5").unwrap(),
            ("l_theta".to_string(), Constraint::Held(-0.5))
        );
        let want = Constraint::Prior {
            mean: 0.01,
            sigma: 0.002,
        };
        assert_eq!(parse_prior("l_y=0.01±0.002").unwrap().1, want);
        assert_eq!(parse_prior("l_y=0.01+-0.002").unwrap().1, want);
        assert!(matches!(
            parse_fix("x=1"),
            Err(ConstraintError::UnknownName(_))
        ));
        assert!(matches!(
            parse_fix("b"),
            Err(ConstraintError::Syntax { .. })
        ));
        assert!(matches!(
            parse_fix("b=-0.1"),
            Err(ConstraintError::Value { .. })
        ));
        assert!(matches!(
            parse_fix("l_x=nan"),
            Err(ConstraintError::Value { .. })
        ));
        assert!(matches!(
            parse_prior("l_x=0.1"),
            Err(ConstraintError::Syntax { .. })
        ));
        assert!(matches!(
            parse_prior("l_x=0.1±0"),
            Err(ConstraintError::Value { .. })
        ));
        let mut c = Constraints::default();
        c.set("b", Constraint::Held(0.1)).unwrap();
        assert!(matches!(
            c.set("B", Constraint::Held(0.2)),
            Err(ConstraintError::Twice(_))
        ));
    }
}
