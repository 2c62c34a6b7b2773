//! Planar geometry shared by every odocal crate.
//!
//! [`Pose2`] is a rigid motion of the plane (an element of SE(2)): a translation
//! `(x, y)` in metres and a rotation `theta` in radians. It is used both for poses
//! (where a frame is) and for displacements (how a frame moved), exactly as in the
//! calibration papers, where ⊕ is [`Pose2::compose`] and ⊖ is [`Pose2::inverse`].
//!
//! Angles are kept wrapped to (−π, π] by [`wrap_angle`].

#![deny(missing_docs)]

mod angle;
mod pose;

pub use angle::{one_minus_cos_over_x, sin_over_x, wrap_angle};
pub use pose::Pose2;
