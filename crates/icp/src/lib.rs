//! Point-to-line ICP for 2-D range scans: ŝ, the displacement of the laser between
//! two scans, with its covariance.
//!
//! The pipeline, one small step per module:
//! 1. [`PreparedScan::new`] (module `preprocess`): the valid readings → points, runs
//!    without range discontinuities (across up to
//!    [`IcpParams::bridged_missing_rays`] readings without a return), and for every
//!    segment between consecutive points a *local line* (total least squares over
//!    the best-fitting window of `line_fit_window` run points containing it); the
//!    scan's range noise from those windows, or from lines through metric
//!    neighbourhoods when it has too few. Before that, in scans of rays at most 0.6°
//!    apart, mixed pixels are left out as readings without a return (module
//!    `mixed_pixels`: the last reading of a run at a depth edge that lies off the
//!    run's continuation, towards the surface across the edge, by more than
//!    [`IcpParams::mixed_pixel_sigmas`] times the log's typical range noise, or the
//!    scan's own, found by a first preparation). Done once per scan, reused as
//!    reference or current scan.
//! 2. `correspondence`: each current point ↔ the segment between its two closest
//!    consecutive reference points (closest point by CSM's angular walk over the
//!    ordered rays — the default — or a kiddo k-d tree; no segment across a range
//!    discontinuity, none beyond the end of a run, except up to three segment lengths
//!    past a run that ends at readings without a return), measured against that segment's
//!    local line, weighted by the inverse variance range noise gives the distance at
//!    the two incidence angles.
//! 3. `trimming`: adaptive outlier threshold (robust σ from the median, the size of
//!    the previous step while far from convergence, optional fraction, never
//!    increasing).
//! 4. `solve_step`: the **exact** constrained minimiser of the weighted point-to-line
//!    cost for the current correspondences, Censi's closed form (ICRA 2008): the cost
//!    is quadratic in `(x, y, cos θ, sin θ)` under `cos²θ + sin²θ = 1`; after
//!    eliminating the translation, the Lagrange multiplier is the root of a 1-D
//!    secular equation (his quartic), solved to machine precision. No linearisation.
//!    The expected contribution of the local lines' tilt noise is removed from the
//!    normal equations first (errors-in-variables correction; without it the rotation
//!    is attenuated by ≈ 1e-4·θ on URG-04LX data), its scale estimated per scan.
//! 5. `covariance`: Hessian-based covariance `σ̂² I⁻¹` scaled by the residual
//!    variance and by the residual autocorrelation along the scan (not Censi's 2007
//!    closed form); the condition number and weakest direction.
//! 6. [`Matcher`]: the loop. Convergence when a step is below the epsilons (and the
//!    threshold would drop no more matches), when the contraction of the last two
//!    steps predicts a next step below the epsilons and negligible against the
//!    residual noise (never on noise-free scans), or when the same correspondences
//!    come back (a cycle). Along a direction the scans do not constrain (condition number above
//!    `max_condition_number`, e.g. a corridor) steps are not taken: the result keeps
//!    the first guess there and is flagged `ill_conditioned`. A result too far from
//!    the first guess, NaN, or too few matches is an [`IcpError`].
//! 7. `consistency`: a result whose residual spread is far above the range noise the
//!    two scans show themselves, or that uses too few of the current scan's points,
//!    is a wrong local minimum and is refused.
//! 8. `basin_check`: a result that is not comfortably well conditioned is matched
//!    again from a step away along its least constrained direction; when the
//!    iterations do not come back (the cost is flat there whatever its curvature with
//!    the correspondences fixed says), it is flagged `ill_conditioned` and its
//!    covariance widened.
//! 9. `cost_envelope`: a result that is not comfortably well conditioned has its
//!    cost evaluated ±10σ along its covariance's largest axis with the
//!    correspondences found again; where that cost rises less than the covariance
//!    predicts (a washboard: noisy short lines, each shift finds new ones), the
//!    variance along the axis is widened by the ratio.
//! 10. `small_objects`: a result that takes much of its information from small
//!     objects standing in front of the walls (a person's legs, a chair), and whose
//!     walls alone are not comfortably well conditioned, is matched again without
//!     them; when the two disagree (a person walking drags the iterations where the
//!     walls leave a direction weak), its covariance is widened by their difference.
//! 11. `rotation_search`: when the attempt from the first guess fails or is refused,
//!     the matcher starts again from the rotations where the two scans' histograms
//!     of line directions agree best (translation-independent); two distinct
//!     consistent results are refused as ambiguous.
//! 12. `sparse_fallback`: a pair where a scan's rays are coarse (≥ 0.7° apart) and
//!     its returns few (fewer than [`IcpParams::sparse_below_returns`] per full turn:
//!     a 1° LDS with most readings missing) is matched instead by a correlative grid
//!     search over `(x, y, θ)` (`correlative`, on the `nearest_grid` lookup table)
//!     followed by the exact point-to-line step against lines fitted over each
//!     reference point's nearest neighbours (`neighbourhood_lines`), whichever rays
//!     they come from. Distinct results that explain the scans about equally well
//!     are refused as ambiguous; a result uncertain along a wall is kept with its
//!     covariance; one ill-conditioned along a single direction (a corridor) keeps
//!     the first guess there and leaves that direction free (`free_direction`,
//!     [`IcpResult::free_direction`]).
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

mod basin_check;
mod consistency;
mod correlative;
mod correspondence;
mod cost_envelope;
mod covariance;
mod error;
mod free_direction;
mod matcher;
mod mixed_pixels;
mod nearest_grid;
mod neighbourhood_lines;
mod params;
mod preprocess;
mod range_noise;
mod ray_directions;
mod rotation_search;
mod small_objects;
mod solve_step;
mod sparse_fallback;
mod trimming;

pub use error::IcpError;
pub use free_direction::FREE_VARIANCE;
pub use matcher::{IcpResult, Matcher};
pub use params::{GuessWindow, IcpParams, NeighbourSearch};
pub use preprocess::PreparedScan;
pub use ray_directions::RayDirections;
pub use sparse_fallback::coarse_rays;
