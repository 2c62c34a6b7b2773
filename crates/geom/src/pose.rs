//! The [`Pose2`] type: an element of SE(2).

use crate::angle::wrap_angle;
use serde::{Deserialize, Serialize};

/// A rigid motion of the plane: translation `(x, y)` (m) then rotation `theta` (rad).
///
/// As a pose it is the frame's origin and heading in a parent frame; as a
/// displacement it is the second frame expressed in the first. `a.compose(&b)` is the
/// papers' `a ⊕ b`: first `a`, then `b` expressed in `a`'s frame.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Pose2 {
    /// Translation along the parent's x axis (m).
    pub x: f64,
    /// Translation along the parent's y axis (m).
    pub y: f64,
    /// Rotation (rad), wrapped to (−π, π] by the operations of this type.
    pub theta: f64,
}

impl Pose2 {
    /// The identity motion.
    pub const IDENTITY: Pose2 = Pose2 {
        x: 0.0,
        y: 0.0,
        theta: 0.0,
    };

    /// A pose from its components; the angle is wrapped to (−π, π].
    pub fn new(x: f64, y: f64, theta: f64) -> Self {
        Pose2 {
            x,
            y,
            theta: wrap_angle(theta),
        }
    }

    /// A pose from `[x, y, theta]`.
    pub fn from_array(a: [f64; 3]) -> Self {
        Pose2::new(a[0], a[1], a[2])
    }

    /// The components as `[x, y, theta]`.
    pub fn to_array(&self) -> [f64; 3] {
        [self.x, self.y, self.theta]
    }

    /// `self ⊕ other`: the motion `other`, expressed in `self`'s frame, appended to `self`.
    pub fn compose(&self, other: &Pose2) -> Pose2 {
        let (s, c) = self.theta.sin_cos();
        Pose2::new(
            self.x + c * other.x - s * other.y,
            self.y + s * other.x + c * other.y,
            self.theta + other.theta,
        )
    }

    /// The Jacobians of `self ⊕ other` with respect to `self` and to `other`
    /// (rows and columns `x, y, theta`), for first-order covariance propagation:
    /// `Σ = J_a Σ_a J_aᵀ + J_b Σ_b J_bᵀ` for independent `self` and `other`.
    pub fn compose_jacobians(&self, other: &Pose2) -> ([[f64; 3]; 3], [[f64; 3]; 3]) {
        let (s, c) = self.theta.sin_cos();
        let j_self = [
            [1.0, 0.0, -s * other.x - c * other.y],
            [0.0, 1.0, c * other.x - s * other.y],
            [0.0, 0.0, 1.0],
        ];
        let j_other = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]];
        (j_self, j_other)
    }

    /// `⊖self`: the inverse motion, so that `self.compose(&self.inverse())` is the identity.
    pub fn inverse(&self) -> Pose2 {
        let (s, c) = self.theta.sin_cos();
        Pose2::new(
            -c * self.x - s * self.y,
            s * self.x - c * self.y,
            -self.theta,
        )
    }

    /// `⊖self ⊕ other`: where `other` is, seen from `self`.
    pub fn between(&self, other: &Pose2) -> Pose2 {
        self.inverse().compose(other)
    }

    /// Maps a point given in this frame into the parent frame.
    pub fn transform_point(&self, p: [f64; 2]) -> [f64; 2] {
        let (s, c) = self.theta.sin_cos();
        [self.x + c * p[0] - s * p[1], self.y + s * p[0] + c * p[1]]
    }

    /// Length of the translation part (m).
    pub fn translation_norm(&self) -> f64 {
        self.x.hypot(self.y)
    }

    /// True when every component is finite.
    pub fn is_finite(&self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.theta.is_finite()
    }
}

impl std::fmt::Display for Pose2 {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "({:.6} m, {:.6} m, {:.6} rad)",
            self.x, self.y, self.theta
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: &Pose2, b: &Pose2) -> bool {
        (a.x - b.x).abs() < 1e-12
            && (a.y - b.y).abs() < 1e-12
            && wrap_angle(a.theta - b.theta).abs() < 1e-12
    }

    #[test]
    fn inverse_undoes_compose() {
        let a = Pose2::new(0.3, -1.2, 2.9);
        let b = Pose2::new(-0.7, 0.4, -3.0);
        assert!(close(&a.compose(&a.inverse()), &Pose2::IDENTITY));
        assert!(close(&a.inverse().compose(&a), &Pose2::IDENTITY));
        assert!(close(&a.compose(&b).compose(&b.inverse()), &a));
        assert!(close(&a.between(&a.compose(&b)), &b));
    }

    #[test]
    fn compose_jacobians_match_finite_differences() {
        let a = Pose2::new(0.3, -0.2, 0.7);
        let b = Pose2::new(-0.15, 0.4, -1.1);
        let (ja, jb) = a.compose_jacobians(&b);
        let h = 1e-7;
        for k in 0..3 {
            let mut da = a.to_array();
            da[k] += h;
            let mut db = b.to_array();
            db[k] += h;
            let fa = Pose2::from_array(da).compose(&b).to_array();
            let fb = a.compose(&Pose2::from_array(db)).to_array();
            let f0 = a.compose(&b).to_array();
            for r in 0..3 {
                assert!(
                    ((fa[r] - f0[r]) / h - ja[r][k]).abs() < 1e-6,
                    "J_a[{r}][{k}]"
                );
                assert!(
                    ((fb[r] - f0[r]) / h - jb[r][k]).abs() < 1e-6,
                    "J_b[{r}][{k}]"
                );
            }
        }
    }

    #[test]
    fn compose_is_associative() {
        let a = Pose2::new(1.0, 2.0, 0.5);
        let b = Pose2::new(-0.3, 0.1, 3.0);
        let c = Pose2::new(0.2, -0.9, -2.5);
        assert!(close(
            &a.compose(&b).compose(&c),
            &a.compose(&b.compose(&c))
        ));
    }

    #[test]
    fn transform_point_matches_compose() {
        let a = Pose2::new(1.0, 2.0, 0.5);
        let p = a.transform_point([0.3, -0.4]);
        let q = a.compose(&Pose2::new(0.3, -0.4, 0.0));
        assert!((p[0] - q.x).abs() < 1e-15 && (p[1] - q.y).abs() < 1e-15);
    }
}
