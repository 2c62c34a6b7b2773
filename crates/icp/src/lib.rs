//! Point-to-line ICP for 2-D range scans: ŝ, the displacement of the laser between
//! two scans, with its covariance.
//!
//! The pipeline, one small step per module:
//! 1. [`PreparedScan::new`] (module `preprocess`): ranges → points, validity, runs
//!    without range discontinuities, a fitted local line for every segment between
//!    consecutive points. Done once per scan, reused as reference or current scan.
//! 2. `correspondence`: each current point ↔ the segment between its two closest
//!    consecutive reference points (angular walk over the ordered rays, or kiddo).
//! 3. `trimming`: adaptive outlier threshold (robust σ, previous step, fraction).
//! 4. `solve_step`: the exact constrained minimiser of the point-to-line cost for
//!    the current correspondences (closed form + 1-D secular equation; no
//!    linearisation).
//! 5. `covariance`: Hessian-based covariance scaled by the residual variance, and
//!    the conditioning flag.
//! 6. [`Matcher`]: the loop, convergence, and the checks that turn a doubtful answer
//!    into an [`IcpError`].
//!
//! ```no_run
//! use odocal_icp::{IcpParams, Matcher, PreparedScan};
//! # fn demo(r0: &[f32], r1: &[f32], angles: &[f64]) -> Result<(), odocal_icp::IcpError> {
//! let params = IcpParams::default();
//! let reference = PreparedScan::new(r0, angles, 0.02, 4.0, &params)?;
//! let current = PreparedScan::new(r1, angles, 0.02, 4.0, &params)?;
//! let mut matcher = Matcher::new(params);
//! let result = matcher.match_scans(&reference, &current, odocal_geom::Pose2::IDENTITY)?;
//! println!("ŝ = {} after {} iterations", result.pose, result.iterations);
//! # Ok(()) }
//! ```

#![deny(missing_docs)]

mod correspondence;
mod covariance;
mod error;
mod matcher;
mod params;
mod preprocess;
mod solve_step;
mod trimming;

pub use error::IcpError;
pub use matcher::{IcpResult, Matcher};
pub use params::{IcpParams, NeighbourSearch};
pub use preprocess::PreparedScan;
