//! Simultaneous calibration of a differential-drive robot's odometry (wheel radii
//! `r_L`, `r_R`, wheel distance `b`) and of its sensor's pose `ℓ = (ℓx, ℓy, ℓθ)`
//! from samples: wheel rotations over an interval and the sensor displacement `ŝ`
//! that scan matching estimated over the same interval.
//!
//! The method is Censi, Marchionni, Oriolo (ICRA 2008) and Censi, Franchi,
//! Marchionni, Oriolo (T-RO 2013), following `docs/method.md` (the papers' math with
//! the misprints corrected):
//!
//! 1. [`step1`]: `J21`, `J22` by linear least squares on the heading changes;
//! 2. [`step2`]: `b` and `ℓ` from `ℓ ⊕ ŝ = o ⊕ ℓ` via the Schur complement of the
//!    constrained quadratic problem (integrating the kinematics over wheel-speed
//!    profiles when samples carry them);
//! 3. [`trimming`]: outlier removal, ICRA or T-RO rule, re-solving each round;
//! 4. [`refine`]: maximum-likelihood refinement (Levenberg–Marquardt on `ŝ_pred − ŝ`);
//! 5. covariance (inverse Fisher information with analytic Jacobians) and an
//!    [`Observability`] report; degenerate data give [`SolveError::NotExcited`];
//!    the laser's range scale, which the data cannot tell, is added to it by
//!    [`with_range_scale`].
//! 6. optionally, for skid-steer robots, a seventh parameter: the sideways slide in
//!    turns `v_y = −k·v·ω` ([`fit_lateral_slip`], [`LateralSlip`]).
//!
//! Entry point: [`calibrate`]; for a robot with several lasers (wheels shared, one ℓ
//! per laser), [`calibrate_lasers`].
//!
//! ```
//! use odocal_geom::Pose2;
//! use odocal_solver::{calibrate, Params, Predictor, Sample, SolveOptions};
//!
//! // A robot and a drive with straight runs, spins and arcs; ŝ predicted exactly.
//! let truth = Params { r_l: 0.03, r_r: 0.031, b: 0.3, laser: Pose2::new(0.1, 0.02, 1.0) };
//! let predictor = Predictor::new(&truth, true);
//! let samples: Vec<Sample> = (0..60)
//!     .map(|k| {
//!         let (l, r) = [(5.0, 5.0), (-4.0, 4.0), (2.0, 6.0)][k % 3];
//!         let s = Sample::from_rotations(0.5, l * (1.0 + 0.01 * k as f64), r, Pose2::IDENTITY);
//!         Sample { sm: Pose2::from_array(predictor.predict(&s)), ..s }
//!     })
//!     .collect();
//! let cal = calibrate(&samples, &SolveOptions::default()).unwrap();
//! assert!((cal.params.b - 0.3).abs() < 1e-9);
//! assert!((cal.params.laser.theta - 1.0).abs() < 1e-9);
//! println!("{}", cal.observability.sentence);
//! ```

#![deny(missing_docs)]
// Dense 2×2 … 6×6 numerics read best with explicit indices.
#![allow(clippy::needless_range_loop)]

mod calibrate;
mod constraints;
mod covariance;
mod damping;
mod error;
mod inflate;
mod kinematics;
mod lasers;
mod lateral_slip;
mod linalg;
mod matcher_bias;
mod noise;
mod noise_shape;
mod normal_equations;
mod observability;
mod one_sample;
mod packed;
mod params;
mod partial;
mod range_scale;
pub mod refine;
mod sample;
mod shared_scans;
mod slide_kinematics;
pub mod step1;
pub mod step2;
pub mod trimming;

pub use calibrate::{
    calibrate, closed_form, Calibration, ClosedForm, NoiseSource, SigmaEstimate, SolveOptions,
    MIN_SAMPLES, STEP1_SINGULAR_CONDITION,
};
pub use constraints::{
    parameter_index, parse_fix, parse_prior, Constraint, ConstraintError, Constraints,
};
pub use covariance::INFORMATION_SINGULAR_RATIO;
pub use error::SolveError;
pub use inflate::{inflate_sigma, inflate_sigma_per_parameter, widen_along, widen_lasers_along};
pub use kinematics::{odometry, predict, predict_with_jacobian, residual, residuals, Predictor};
pub use lasers::{
    calibrate_lasers, calibrate_lasers_constrained, laser_constraints, LasersCalibration,
};
pub use lateral_slip::{fit_lateral_slip, LateralSlip, SlideFit, PLAUSIBLE_SLIDE_PER_SPEED};
pub use noise::{residual_sigmas, SIGMA_FLOOR};
pub use noise_shape::{NoiseShaping, MIN_SHAPED_SAMPLES};
pub use observability::{
    MotionContent, Observability, ParameterReport, Verdict, MOTION_CLASS_RATIO,
    PARTIAL_CALIBRATION_HINT,
};
pub use one_sample::{describe as describe_one_sample, OneSampleSupport, ONE_SAMPLE_SIGMA_RATIO};
pub use params::{Params, PARAMETER_NAMES};
pub use range_scale::{
    range_scale_covariance, range_scale_direction, scale_covariance_along, with_range_scale,
    with_scale_along,
};
pub use refine::Refinement;
pub use sample::{ProfileSegment, Sample};
pub use shared_scans::{SharedScanNoise, MIN_SHARED_SCANS};
pub use slide_kinematics::residuals_with_slide;
pub use trimming::{Trim, CHI2_3DOF_9999};
