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
    Ok(Params::from_vector(full))
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
         nominal r_L = {} m, r_R = {} m, b = {} m",
        n.r_l, n.r_r, n.b
    )
}
