//! A synchronized, matched scan pair — the unit the solver works on — and its
//! conversions to the solver's sample and to a tuple record.

use crate::matching::MatchStats;
use crate::sync::{ScanPair, WheelMotion};
use odocal_log::{write_tuple, TupleRecord};
use odocal_solver::{ProfileSegment, Sample};
use std::io;
use std::path::Path;

/// One scan pair that survived synchronization and matching.
#[derive(Debug, Clone, PartialEq)]
pub struct PairSample {
    /// The two scans (laser-clock timestamps).
    pub pair: ScanPair,
    /// What the encoders say over the interval (encoder clock).
    pub wheel: WheelMotion,
    /// What the scan matcher says.
    pub icp: MatchStats,
}

impl PairSample {
    /// The solver's sample. `use_profile` attaches the encoder profile (for the
    /// non-constant-speed formulas); `use_icp_covariance` attaches ŝ's covariance
    /// (so the solver weights by it).
    pub fn to_solver(&self, use_profile: bool, use_icp_covariance: bool) -> Sample {
        Sample {
            t: self.wheel.dt,
            dphi_l: self.wheel.dphi_l,
            dphi_r: self.wheel.dphi_r,
            sm: self.icp.pose,
            sm_cov: use_icp_covariance.then_some(self.icp.covariance),
            scan_times: Some([self.pair.t0, self.pair.t1]),
            read_time_sigma: None,
            profile: use_profile.then(|| {
                self.wheel
                    .profile
                    .iter()
                    .map(|p| ProfileSegment {
                        duration: p.dt,
                        dphi_l: p.dphi_l,
                        dphi_r: p.dphi_r,
                    })
                    .collect()
            }),
        }
    }

    /// The tuple record: the original package's `T`, `phi_l`, `phi_r`, `sm`, plus the
    /// scan timestamps `t0`, `t1` (laser clock), ŝ's covariance, the encoder profile and
    /// the ICP statistics (`icp_iterations`, `icp_correspondences`,
    /// `icp_mean_residual`, `scan0`, `scan1`).
    pub fn to_tuple(&self) -> TupleRecord {
        let w = &self.wheel;
        let mut rec = TupleRecord::new(
            w.dt,
            w.dphi_l / w.dt,
            w.dphi_r / w.dt,
            self.icp.pose.to_array(),
        );
        rec.t0 = Some(self.pair.t0);
        rec.t1 = Some(self.pair.t1);
        rec.sm_cov = Some(self.icp.covariance);
        rec.profile = Some(
            w.profile
                .iter()
                .map(|p| [p.dt, p.dphi_l, p.dphi_r])
                .collect(),
        );
        let extra = &mut rec.extra;
        extra.insert("scan0".into(), self.pair.first.into());
        extra.insert("scan1".into(), self.pair.second.into());
        extra.insert("icp_iterations".into(), self.icp.iterations.into());
        extra.insert(
            "icp_correspondences".into(),
            self.icp.correspondences.into(),
        );
        extra.insert("icp_mean_residual".into(), self.icp.mean_residual.into());
        rec
    }
}

/// A solver sample carrying only the wheel motion (ŝ = identity): enough to
/// predict ŝ by odometry.
pub fn wheel_only_sample(w: &WheelMotion) -> Sample {
    Sample {
        t: w.dt,
        dphi_l: w.dphi_l,
        dphi_r: w.dphi_r,
        sm: odocal_geom::Pose2::IDENTITY,
        sm_cov: None,
        scan_times: None,
        read_time_sigma: None,
        profile: Some(
            w.profile
                .iter()
                .map(|p| ProfileSegment {
                    duration: p.dt,
                    dphi_l: p.dphi_l,
                    dphi_r: p.dphi_r,
                })
                .collect(),
        ),
    }
}

/// Writes the samples as tuples, one JSON object per line.
pub fn write_tuples(path: &Path, samples: &[PairSample]) -> io::Result<()> {
    crate::atomic_file::write_atomically(path, |w| {
        for s in samples {
            write_tuple(&mut *w, &s.to_tuple())?;
        }
        Ok(())
    })
}
