//! The six calibration parameters as six plain numbers, the way JSON files carry them.

use crate::Pose2;
use serde::{Deserialize, Serialize};

/// Wheel radii, wheel distance and the laser pose as six plain numbers in metres and
/// radians: the fields `r_l`, `r_r`, `b`, `l_x`, `l_y`, `l_theta` of the files that
/// hold parameters (a calibration's `results.json`, a simulation's truth, a Table I
/// row). Use it with `#[serde(flatten)]` where the six fields sit among others.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FlatParams {
    /// Left wheel radius (m).
    pub r_l: f64,
    /// Right wheel radius (m).
    pub r_r: f64,
    /// Wheel distance (m).
    pub b: f64,
    /// Laser x in the robot frame (m).
    pub l_x: f64,
    /// Laser y in the robot frame (m).
    pub l_y: f64,
    /// Laser heading in the robot frame (rad).
    pub l_theta: f64,
}

impl FlatParams {
    /// From `[r_L, r_R, b, ℓx, ℓy, ℓθ]`, as given.
    pub fn from_array(v: [f64; 6]) -> Self {
        FlatParams {
            r_l: v[0],
            r_r: v[1],
            b: v[2],
            l_x: v[3],
            l_y: v[4],
            l_theta: v[5],
        }
    }

    /// From the radii, the wheel distance and the laser pose.
    pub fn new(r_l: f64, r_r: f64, b: f64, laser: &Pose2) -> Self {
        FlatParams::from_array([r_l, r_r, b, laser.x, laser.y, laser.theta])
    }

    /// The values in the order r_L, r_R, b, ℓx, ℓy, ℓθ.
    pub fn to_array(&self) -> [f64; 6] {
        [self.r_l, self.r_r, self.b, self.l_x, self.l_y, self.l_theta]
    }

    /// The laser pose ℓ (ℓθ wrapped to (−π, π]).
    pub fn laser(&self) -> Pose2 {
        Pose2::new(self.l_x, self.l_y, self.l_theta)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_and_writes_the_six_fields_by_name() {
        let text = r#"{"r_l":0.03,"r_r":0.031,"b":0.2,"l_x":0.1,"l_y":-0.02,"l_theta":0.5}"#;
        let p: FlatParams = serde_json::from_str(text).unwrap();
        assert_eq!(p.to_array(), [0.03, 0.031, 0.2, 0.1, -0.02, 0.5]);
        assert_eq!(serde_json::to_string(&p).unwrap(), text);
        assert_eq!(FlatParams::new(p.r_l, p.r_r, p.b, &p.laser()), p);
    }
}
