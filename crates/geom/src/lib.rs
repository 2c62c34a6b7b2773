//! Planar geometry shared by every odocal crate.
//!
//! [`Pose2`] is a rigid motion of the plane (an element of SE(2)): a translation
//! `(x, y)` in metres and a rotation `theta` in radians. It is used both for poses
//! (where a frame is) and for displacements (how a frame moved), exactly as in the
//! calibration papers, where ⊕ is [`Pose2::compose`] and ⊖ is [`Pose2::inverse`].
//!
//! Angles are kept wrapped to (−π, π] by [`wrap_angle`].
//!
//! [`FlatParams`] is the robot's geometry that odocal calibrates (wheel radii, wheel
//! distance, laser pose) as the six plain numbers files carry.

#![deny(missing_docs)]

mod angle;
mod flat_params;
mod pose;

pub use angle::{one_minus_cos_over_x, sin_over_x, wrap_angle};
pub use flat_params::FlatParams;
pub use pose::Pose2;
