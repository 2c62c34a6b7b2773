//! The six calibration parameters.

use odocal_geom::{wrap_angle, FlatParams, Pose2};
use serde::{Deserialize, Serialize};

/// Names of the six parameters, in the order used by every vector and covariance of
/// this crate: `r_L`, `r_R`, `b`, `l_x`, `l_y`, `l_theta`.
pub const PARAMETER_NAMES: [&str; 6] = ["r_L", "r_R", "b", "l_x", "l_y", "l_theta"];

/// Wheel radii, wheel distance and the sensor's pose on the robot.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Params {
    /// Left wheel radius (m).
    pub r_l: f64,
    /// Right wheel radius (m).
    pub r_r: f64,
    /// Distance between the wheels (m).
    pub b: f64,
    /// Sensor pose ℓ = (ℓx, ℓy, ℓθ) in the robot frame (m, m, rad).
    pub laser: Pose2,
}

impl Params {
    /// The parameters as a vector in the order of [`PARAMETER_NAMES`].
    pub fn to_vector(&self) -> [f64; 6] {
        [
            self.r_l,
            self.r_r,
            self.b,
            self.laser.x,
            self.laser.y,
            self.laser.theta,
        ]
    }

    /// Parameters from a vector in the order of [`PARAMETER_NAMES`]; ℓθ is wrapped.
    pub fn from_vector(v: [f64; 6]) -> Self {
        Params {
            r_l: v[0],
            r_r: v[1],
            b: v[2],
            laser: Pose2::new(v[3], v[4], v[5]),
        }
    }

    /// The differential-drive matrix `J` with `[v, ω]ᵀ = J [ω_L, ω_R]ᵀ`:
    /// `[[r_L/2, r_R/2], [−r_L/b, r_R/b]]`.
    pub fn j(&self) -> [[f64; 2]; 2] {
        [
            [self.r_l / 2.0, self.r_r / 2.0],
            [-self.r_l / self.b, self.r_r / self.b],
        ]
    }

    /// Component-wise difference `self − other` (ℓθ wrapped), in the order of
    /// [`PARAMETER_NAMES`].
    pub fn difference(&self, other: &Params) -> [f64; 6] {
        let a = self.to_vector();
        let b = other.to_vector();
        [
            a[0] - b[0],
            a[1] - b[1],
            a[2] - b[2],
            a[3] - b[3],
            a[4] - b[4],
            wrap_angle(a[5] - b[5]),
        ]
    }
}

impl From<Params> for FlatParams {
    fn from(p: Params) -> Self {
        FlatParams::new(p.r_l, p.r_r, p.b, &p.laser)
    }
}

impl From<FlatParams> for Params {
    /// ℓθ is wrapped.
    fn from(p: FlatParams) -> Self {
        Params::from_vector(p.to_array())
    }
}
