//! Several lasers in a joint calibration: which laser each log's samples come from
//! (a log's own laser: `--own-laser`, or a bag's second `--scan-topic`), the joint
//! solve with the wheels shared and one ℓ per laser, and each laser's view of it.

use odocal_solver::{
    calibrate, calibrate_lasers, Calibration, Constraint, LasersCalibration, SolveError,
    SolveOptions,
};

/// The joint estimate: the first laser's view (what every single-laser stage reads)
/// and, with more than one laser, the whole joint estimate.
pub(crate) struct Solved {
    /// The first laser's view (with one laser: the single-laser solve itself).
    pub first: Calibration,
    /// With more than one laser: every laser's ℓ and the joint covariance.
    pub lasers: Option<LasersCalibration>,
}

/// Solves `samples`, `laser_of[i]` the laser of sample `i`: one laser is the
/// single-laser solve ([`calibrate`], numbers unchanged); more share the wheels.
pub(crate) fn solve(
    samples: &[odocal_solver::Sample],
    laser_of: &[usize],
    options: &SolveOptions,
) -> Result<Solved, SolveError> {
    if laser_of.iter().all(|&k| k == 0) {
        return Ok(Solved {
            first: calibrate(samples, options)?,
            lasers: None,
        });
    }
    let joint = calibrate_lasers(samples, laser_of, options)?;
    Ok(Solved {
        first: joint.first.clone(),
        lasers: Some(joint),
    })
}

impl Solved {
    /// What a log of laser `k` is compared with: that laser's view.
    pub(crate) fn view(&self, k: usize) -> Calibration {
        match &self.lasers {
            Some(l) if k > 0 => l.view(k),
            _ => self.first.clone(),
        }
    }
}

/// The options a log is compared with the joint estimate under: with several lasers,
/// a log that is the only one of its laser brought all of that laser's information
/// on ℓ, so only the shared wheels are compared (ℓ counts as held at `view`'s).
pub(crate) fn comparison_options(
    options: &SolveOptions,
    view: &Calibration,
    alone_on_its_laser: bool,
) -> SolveOptions {
    let mut o = *options;
    if alone_on_its_laser {
        let v = view.params.to_vector();
        for (c, &value) in o.constraints.0.iter_mut().zip(&v).skip(3) {
            *c = Constraint::Held(value);
        }
    }
    o
}

/// Laser indices (0 = the first log's laser) from each log's laser key: logs with
/// equal keys share a laser; lasers are numbered in the order of first appearance.
pub fn laser_indices<K: PartialEq>(keys: &[K]) -> Vec<usize> {
    let mut seen: Vec<&K> = Vec::new();
    keys.iter()
        .map(|k| match seen.iter().position(|s| *s == k) {
            Some(i) => i,
            None => {
                seen.push(k);
                seen.len() - 1
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lasers_numbered_by_first_appearance() {
        assert_eq!(
            laser_indices(&["a", "a", "b", "a", "c", "b"]),
            [0, 0, 1, 0, 2, 1]
        );
        assert_eq!(laser_indices::<&str>(&[]), Vec::<usize>::new());
    }
}
