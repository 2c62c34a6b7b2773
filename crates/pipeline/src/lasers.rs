//! Several lasers in a joint calibration: which laser each log's samples come from
//! (a log's own laser: `--own-laser`, or a bag's second `--scan-topic`), the joint
//! solve with the wheels shared and one ℓ per laser, and each laser's view of it.

use odocal_geom::Pose2;
use odocal_solver::{
    calibrate, calibrate_lasers_constrained, laser_constraints, Calibration, Constraint,
    Constraints, LasersCalibration, Params, SolveError, SolveOptions,
};

/// The lasers of a joint calibration: which laser each log's samples come from and,
/// for the lasers after the first, their first guesses and their held parameters or
/// priors (the first laser's are the options' own, as with one laser).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LaserSetup {
    /// Per log, its laser: logs with equal numbers share a laser, numbered from 0 (the
    /// first log's) in order of first appearance ([`laser_indices`]).
    pub of_log: Vec<usize>,
    /// Per laser after the first (`nominal[0]` is laser 2's): its nominal pose (a
    /// bag's `/tf_static` or URDF for its scan topic's frame), the first guess of
    /// scan matching together with the wheels of `Options::initial_params`; `None`
    /// (or no nominal wheels): that laser's logs bootstrap their guesses.
    pub nominal: Vec<Option<Pose2>>,
    /// Per laser after the first (`constraints[0]` is laser 2's): its (ℓx, ℓy, ℓθ)
    /// held or given priors; lasers beyond the vector are free.
    pub constraints: Vec<[Constraint; 3]>,
}

impl LaserSetup {
    /// Every log on the first laser.
    pub fn one_laser(logs: usize) -> LaserSetup {
        LaserSetup {
            of_log: vec![0; logs],
            ..LaserSetup::default()
        }
    }

    /// Scan matching's first guesses for the logs of laser `k`: `initial` (the
    /// nominal parameters) for the first laser; for another, the nominal wheels with
    /// that laser's nominal pose, or `None` when either is unknown.
    pub fn initial_params(&self, k: usize, initial: Option<Params>) -> Option<Params> {
        if k == 0 {
            return initial;
        }
        let laser = (*self.nominal.get(k - 1)?)?;
        initial.map(|p| Params { laser, ..p })
    }

    /// The held parameters and priors laser `k` sees: the wheels' and (for the first
    /// laser) ℓ's of `shared`, its own ℓ's for another.
    pub fn constraints_of(&self, k: usize, shared: &Constraints) -> Constraints {
        laser_constraints(shared, &self.constraints, k)
    }
}

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
    more: &[[Constraint; 3]],
) -> Result<Solved, SolveError> {
    if laser_of.iter().all(|&k| k == 0) {
        return Ok(Solved {
            first: calibrate(samples, options)?,
            lasers: None,
        });
    }
    let joint = calibrate_lasers_constrained(samples, laser_of, options, more)?;
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

/// The options a log of a laser whose constraints are `constraints` is compared with
/// the joint estimate under: with several lasers, a log that is the only one of its
/// laser brought all of that laser's information on ℓ, so only the shared wheels are
/// compared (ℓ counts as held at `view`'s).
pub(crate) fn comparison_options(
    options: &SolveOptions,
    constraints: Constraints,
    view: &Calibration,
    alone_on_its_laser: bool,
) -> SolveOptions {
    let mut o = SolveOptions {
        constraints,
        ..*options
    };
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
    fn another_lasers_first_guess_needs_the_nominal_wheels_and_its_pose() {
        let wheels = Params::from_vector([0.033, 0.033, 0.16, 0.1, 0.0, 0.0]);
        let rear = Pose2::new(-0.12, 0.015, 3.1);
        let setup = LaserSetup {
            of_log: vec![0, 1, 2],
            nominal: vec![Some(rear), None],
            constraints: Vec::new(),
        };
        // The first laser: the options' own guess, whatever the bag says.
        assert_eq!(setup.initial_params(0, Some(wheels)), Some(wheels));
        // Laser 2: the nominal wheels with its own pose; none without the wheels.
        let guess = setup.initial_params(1, Some(wheels)).unwrap();
        assert_eq!((guess.b, guess.laser), (0.16, rear));
        assert_eq!(setup.initial_params(1, None), None);
        // Laser 3 has no pose of its own (and laser 4 no entry): bootstrap.
        assert_eq!(setup.initial_params(2, Some(wheels)), None);
        assert_eq!(setup.initial_params(3, Some(wheels)), None);
    }

    #[test]
    fn lasers_numbered_by_first_appearance() {
        assert_eq!(
            laser_indices(&["a", "a", "b", "a", "c", "b"]),
            [0, 0, 1, 0, 2, 1]
        );
        assert_eq!(laser_indices::<&str>(&[]), Vec::<usize>::new());
    }
}
