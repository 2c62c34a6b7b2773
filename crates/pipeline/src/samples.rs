//! A synchronized, matched scan pair — the unit the solver works on — and its
//! conversions to the solver's sample and to a tuple record.

use crate::matching::MatchStats;
use crate::sync::{ScanPair, WheelMotion};
use odocal_log::{write_tuple, TupleRecord};
use odocal_solver::{ProfileSegment, Sample};
use rayon::prelude::*;
use std::io::{self, Write};
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
            free_direction: self.icp.free_direction,
            matcher_cov: Some(self.icp.covariance),
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
    /// `icp_mean_residual`, `scan0`, `scan1`; `icp_links` when ŝ was composed of several
    /// matches, `icp_neighbours` when the pair's scans were densified by their
    /// neighbours).
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
        rec.free_direction = self.icp.free_direction;
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
        if self.icp.links > 1 {
            // Matched through the scans between the pair's two (crate::chained).
            extra.insert("icp_links".into(), self.icp.links.into());
        }
        if self.icp.neighbours > 0 {
            // Matched with the pair's scans densified by their neighbours
            // (crate::local_map).
            extra.insert("icp_neighbours".into(), self.icp.neighbours.into());
        }
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
        free_direction: None,
        matcher_cov: None,
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

/// Samples whose tuples are rendered together before they are written (bounded
/// memory: about 2 kB of text each).
const TUPLES_PER_BLOCK: usize = 4096;
/// Samples rendered by one thread at a time within a block.
const TUPLES_PER_PART: usize = 128;

/// Writes the samples as tuples, one JSON object per line. The text is rendered on
/// the current rayon pool's threads, a block at a time, and written in order.
pub fn write_tuples(path: &Path, samples: &[PairSample]) -> io::Result<()> {
    crate::atomic_file::write_atomically(path, |w| {
        for block in samples.chunks(TUPLES_PER_BLOCK) {
            let parts: Vec<io::Result<Vec<u8>>> = block
                .par_chunks(TUPLES_PER_PART)
                .map(|part| {
                    let mut text = Vec::with_capacity(2048 * part.len());
                    for s in part {
                        write_tuple(&mut text, &s.to_tuple())?;
                    }
                    Ok(text)
                })
                .collect();
            for text in parts {
                w.write_all(&text?)?;
            }
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sync::ProfilePiece;
    use odocal_geom::Pose2;

    fn sample(k: usize) -> PairSample {
        let x = k as f64;
        PairSample {
            pair: ScanPair {
                first: 4 * k,
                second: 4 * k + 4,
                t0: 0.4 * x,
                t1: 0.4 * x + 0.4,
            },
            wheel: WheelMotion {
                t0: 0.4 * x,
                dt: 0.4,
                dphi_l: 0.1 + 1e-3 * x,
                dphi_r: 0.1 - 1e-3 * x / 3.0,
                profile: vec![ProfilePiece {
                    dt: 0.4,
                    dphi_l: 0.1 + 1e-3 * x,
                    dphi_r: 0.1 - 1e-3 * x / 3.0,
                }],
            },
            icp: MatchStats {
                pose: Pose2 {
                    x: 0.02 + x / 7e4,
                    y: -x / 9e5,
                    theta: (x / 1e3).sin(),
                },
                covariance: [
                    [1e-7 * (1.0 + x), 0.0, 0.0],
                    [0.0, 1e-7, 0.0],
                    [0.0, 0.0, 1e-8],
                ],
                iterations: k as u32 % 17,
                correspondences: 600 + k % 50,
                mean_residual: 1e-3 / (1.0 + x),
                links: 1,
                neighbours: 0,
                free_direction: None,
            },
        }
    }

    #[test]
    fn tuples_rendered_on_several_threads_are_the_sequential_text() {
        // Several blocks, parts and a remainder.
        let samples: Vec<PairSample> = (0..TUPLES_PER_BLOCK + 3 * TUPLES_PER_PART + 5)
            .map(sample)
            .collect();
        let mut expected = Vec::new();
        for s in &samples {
            write_tuple(&mut expected, &s.to_tuple()).unwrap();
        }
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("samples.tuple");
        for threads in [1, 3] {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| write_tuples(&path, &samples))
                .unwrap();
            assert!(
                std::fs::read(&path).unwrap() == expected,
                "{threads} threads"
            );
        }
    }
}
