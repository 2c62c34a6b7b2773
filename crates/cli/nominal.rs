//! `--nominal`: the parameters the robot's own odometry uses. `calibrate` and `match`
//! take them for first guesses of scan matching from odometry, and need them for
//! odometry-only inputs (odometry poses, no wheel encoders), whose wheel rotations are
//! recovered from the poses with them.

use odocal_log::{encoders_from_odometry, NominalWheels, ValueSource, WHEEL_TICKS_PER_REVOLUTION};
use odocal_solver::Params;
use std::path::Path;

/// Parameters from `--nominal`: three values (r_L, r_R, b; laser at the origin) or six.
pub fn nominal_params(v: &[f64]) -> anyhow::Result<Params> {
    let full = match v.len() {
        3 => [v[0], v[1], v[2], 0.0, 0.0, 0.0],
        6 => [v[0], v[1], v[2], v[3], v[4], v[5]],
        n => anyhow::bail!(
            "--nominal takes 3 values (r_L,r_R,b) or 6 (r_L,r_R,b,l_x,l_y,l_theta), got {n}"
        ),
    };
    if !(full.iter().all(|x| x.is_finite()) && full[..3].iter().all(|x| *x > 0.0)) {
        anyhow::bail!("--nominal needs positive radii and wheel distance and finite values");
    }
    check_plausible(&full)?;
    Ok(Params::from_vector(full))
}

/// Largest plausible wheel radius (m): a value above it is taken for a unit slip.
pub const MAX_RADIUS_M: f64 = 2.0;
/// Largest plausible wheel distance and laser offset (m).
pub const MAX_LENGTH_M: f64 = 20.0;
/// Largest plausible |ℓθ| (rad): beyond 2π it is degrees, not radians.
pub const MAX_ANGLE_RAD: f64 = 2.0 * std::f64::consts::PI;

/// Refuses nominal values no robot has, naming the unit they must be in: radii in
/// millimetres (`--nominal 35,35,230`) would otherwise give radii of metres and a laser
/// metres away, all "well determined".
fn check_plausible(full: &[f64; 6]) -> anyhow::Result<()> {
    let names = ["r_L", "r_R", "b", "l_x", "l_y", "l_theta"];
    let limits = [
        MAX_RADIUS_M,
        MAX_RADIUS_M,
        MAX_LENGTH_M,
        MAX_LENGTH_M,
        MAX_LENGTH_M,
        MAX_ANGLE_RAD,
    ];
    let bad: Vec<String> = (0..6)
        .filter(|&i| full[i].abs() > limits[i])
        .map(|i| format!("{} = {} (at most {})", names[i], full[i], limits[i]))
        .collect();
    if bad.is_empty() {
        return Ok(());
    }
    if full[..5].iter().zip(&limits).all(|(x, l)| x.abs() <= *l) {
        anyhow::bail!(
            "--nominal: implausible {}: ℓθ must be in radians ({} degrees would be {:.6} rad)",
            bad.join(", "),
            full[5],
            full[5].to_radians()
        );
    }
    // The lengths read as millimetres, ℓθ kept (three values when ℓ was not given).
    let mut metres: Vec<String> = full[..5]
        .iter()
        .map(|x| format!("{}", x / 1000.0))
        .collect();
    metres.push(format!("{}", full[5]));
    let given = if full[3..].iter().all(|x| *x == 0.0) {
        3
    } else {
        6
    };
    let metres = metres[..given].join(",");
    anyhow::bail!(
        "--nominal: implausible {}: the values must be in metres (and ℓθ in radians); if \
         they were millimetres, give --nominal {metres}",
        bad.join(", ")
    )
}

/// Odometry-only mode: a log (or bag) with odometry poses but no wheel encoders. The
/// poses were integrated with nominal parameters; each interval's wheel rotations are
/// recovered from the pose increments with them (`--nominal`, required here) and become
/// the log's encoder records. Returns the nominal wheels when the mode applies.
pub fn odometry_only_mode(
    file: &Path,
    log: &mut odocal_log::Log,
    nominal: Option<&Params>,
) -> anyhow::Result<Option<NominalWheels>> {
    if !log.encoders.is_empty() || log.odom.is_empty() {
        return Ok(None);
    }
    let Some(p) = nominal else {
        anyhow::bail!(
            "{}: odometry-only mode (odometry poses, no wheel encoders): the wheel rotations \
             are recovered from the poses with the parameters the robot integrated them \
             with; give them with --nominal r_L,r_R,b (metres)",
            file.display()
        );
    };
    let wheels = NominalWheels {
        r_l: p.r_l,
        r_r: p.r_r,
        b: p.b,
    };
    let Some(encoders) = encoders_from_odometry(&log.odom, wheels) else {
        anyhow::bail!("{}: an odometry pose is not finite", file.display());
    };
    log.encoders = encoders;
    log.params.ticks_per_revolution = Some((WHEEL_TICKS_PER_REVOLUTION, ValueSource::Convention));
    Ok(Some(wheels))
}

/// What odometry-only mode did, in words.
pub fn describe(n: &NominalWheels) -> String {
    format!(
        "odometry-only mode: wheel rotations recovered from the odometry poses with the \
         nominal r_L = {} m, r_R = {} m, b = {} m; {ODOMETRY_ONLY_CAVEAT}",
        n.r_l, n.r_r, n.b
    )
}

/// What odometry-only results mean: the correction factors are measured, the absolute
/// values inherit the error of `--nominal` (a wrong nominal radius moves both radii).
pub const ODOMETRY_ONLY_CAVEAT: &str = "the result is the correction factors of the \
    nominal values; the absolute radii and wheel distance are only as good as --nominal \
    (a wrong nominal radius moves both radii by its factor, and the σ do not include it)";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn millimetres_are_refused_with_the_values_in_metres() {
        let err = nominal_params(&[35.0, 35.0, 230.0])
            .unwrap_err()
            .to_string();
        assert!(err.contains("r_L = 35"), "{err}");
        assert!(err.contains("metres"), "{err}");
        assert!(err.contains("--nominal 0.035,0.035,0.23"), "{err}");
        let err = nominal_params(&[35.0, 35.0, 230.0, 100.0, 0.0, 0.1])
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("--nominal 0.035,0.035,0.23,0.1,0,0.1"),
            "{err}"
        );
    }

    #[test]
    fn degrees_for_the_laser_heading_are_refused() {
        let err = nominal_params(&[0.035, 0.035, 0.23, 0.1, 0.0, 90.0])
            .unwrap_err()
            .to_string();
        assert!(err.contains("l_theta = 90"), "{err}");
        assert!(err.contains("1.570796 rad"), "{err}");
    }

    #[test]
    fn plausible_values_in_metres_are_taken() {
        let p = nominal_params(&[0.035, 0.035, 0.23]).unwrap();
        assert_eq!((p.r_l, p.r_r, p.b), (0.035, 0.035, 0.23));
        assert!(nominal_params(&[0.2, 0.2, 0.6, 0.3, -0.1, 3.1]).is_ok());
    }
}
