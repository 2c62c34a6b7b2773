//! The fields the solver's repeated passes read, packed contiguously: about 100 bytes
//! per sample instead of a whole [`Sample`] (covariance, profile vector), rebuilt after
//! each trimming round so that every pass streams through memory in order.

use crate::kinematics::Pieces;
use crate::sample::{ProfileSegment, Sample};

/// One sample as the passes see it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Packed<'a> {
    /// Left wheel rotation over the interval (rad).
    pub dphi_l: f64,
    /// Right wheel rotation over the interval (rad).
    pub dphi_r: f64,
    /// `ŝ` as `[x, y, θ]`.
    pub sm: [f64; 3],
    /// Index of the sample in the caller's slice.
    pub index: usize,
    /// The wheel-speed profile, when present and used.
    pub profile: Option<&'a [ProfileSegment]>,
    /// Timestamps of the two scans, when known.
    pub scan_times: Option<[f64; 2]>,
    /// Standard deviation of the read-time error of the encoder readings (s).
    pub read_time_sigma: Option<f64>,
    /// The direction ŝ leaves free ([`Sample::free_direction`]), when there is one.
    pub free_direction: Option<[f64; 3]>,
}

impl<'a> Packed<'a> {
    /// Packs sample `index`; its profile is kept only when `use_profile`.
    pub(crate) fn new(sample: &'a Sample, index: usize, use_profile: bool) -> Self {
        Packed {
            dphi_l: sample.dphi_l,
            dphi_r: sample.dphi_r,
            sm: sample.sm.to_array(),
            index,
            scan_times: sample.scan_times,
            read_time_sigma: sample.read_time_sigma,
            free_direction: sample.free_direction,
            profile: if use_profile {
                sample.profile.as_deref()
            } else {
                None
            },
        }
    }

    /// Packs every sample.
    pub(crate) fn all(samples: &'a [Sample], use_profile: bool) -> Vec<Self> {
        samples
            .iter()
            .enumerate()
            .map(|(k, s)| Packed::new(s, k, use_profile))
            .collect()
    }

    /// The constant-speed pieces of the interval.
    #[inline]
    pub(crate) fn pieces(&self) -> Pieces<'a> {
        match self.profile {
            Some(p) => Pieces::Many(p.iter()),
            None => Pieces::One(Some((self.dphi_l, self.dphi_r))),
        }
    }
}
