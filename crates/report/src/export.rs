//! The results in ROS terms, ready to paste: a ros2_control `diff_drive_controller`
//! parameter file and the laser joint's URDF `<origin>`. Both come from the same six
//! numbers as `results.json` (printed with every digit, so that they agree exactly).
//!
//! The controller takes one `wheel_radius` and per-wheel multipliers, its effective
//! radii being `wheel_radius · left_wheel_radius_multiplier` and `wheel_radius ·
//! right_wheel_radius_multiplier`, its effective separation `wheel_separation ·
//! wheel_separation_multiplier`. The file written gives `wheel_radius` = the mean of
//! r_L and r_R, the multipliers r_L and r_R over that mean, `wheel_separation` = b and
//! `wheel_separation_multiplier` = 1.
//!
//! The laser pose ℓ is relative to the wheel-axle midpoint (x forward, y left, θ
//! counter-clockwise; docs/frames.md): it is the joint origin of the laser when its
//! parent link sits at the axle midpoint. Height, roll and pitch are not calibrated
//! (the method is planar); the origin written has z = 0 and says so.

use odocal_geom::FlatParams;
use odocal_pipeline::write_bytes_atomically;
use std::io;
use std::path::Path;

/// The file name of the `diff_drive_controller` parameters written by `--out DIR`.
pub const DIFF_DRIVE_FILE: &str = "diff_drive_controller.yaml";
/// The file name of the laser joint's URDF origin written by `--out DIR`.
pub const URDF_FILE: &str = "laser_joint.urdf.xml";

/// Why parameters cannot be exported.
#[derive(Debug, Clone, PartialEq)]
pub struct ExportError {
    /// The parameter.
    pub name: &'static str,
    /// Its value.
    pub value: f64,
}

impl std::fmt::Display for ExportError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "cannot export {} = {}: the wheel radii and distance must be positive and every \
             value finite",
            self.name, self.value
        )
    }
}

impl std::error::Error for ExportError {}

/// The parameters, checked: finite, with positive radii and wheel distance.
fn checked(p: &FlatParams) -> Result<&FlatParams, ExportError> {
    let all = [
        ("r_l", p.r_l, true),
        ("r_r", p.r_r, true),
        ("b", p.b, true),
        ("l_x", p.l_x, false),
        ("l_y", p.l_y, false),
        ("l_theta", p.l_theta, false),
    ];
    match all
        .iter()
        .find(|(_, v, positive)| !v.is_finite() || (*positive && *v <= 0.0))
    {
        Some(&(name, value, _)) => Err(ExportError { name, value }),
        None => Ok(p),
    }
}

/// The ros2_control `diff_drive_controller` parameters (YAML) of `p`.
pub fn diff_drive_controller_yaml(p: &FlatParams) -> Result<String, ExportError> {
    let p = checked(p)?;
    let radius = 0.5 * (p.r_l + p.r_r);
    Ok(format!(
        "# odocal calibration in ros2_control diff_drive_controller terms: effective left\n\
         # radius = wheel_radius * left_wheel_radius_multiplier = r_L = {r_l} m, right = {r_r} m,\n\
         # separation = wheel_separation * wheel_separation_multiplier = b = {b} m.\n\
         # Rename the top-level key to your controller's name.\n\
         diff_drive_controller:\n  ros__parameters:\n\
         \x20   wheel_separation: {b:?}\n\
         \x20   wheel_radius: {radius:?}\n\
         \x20   wheel_separation_multiplier: 1.0\n\
         \x20   left_wheel_radius_multiplier: {left:?}\n\
         \x20   right_wheel_radius_multiplier: {right:?}\n",
        r_l = p.r_l,
        r_r = p.r_r,
        b = p.b,
        left = p.r_l / radius,
        right = p.r_r / radius,
    ))
}

/// The URDF `<origin>` of the laser joint (child: the scan's frame; parent: the link
/// at the wheel-axle midpoint), with a comment on what is not calibrated.
pub fn laser_joint_urdf(p: &FlatParams) -> Result<String, ExportError> {
    let p = checked(p)?;
    Ok(format!(
        "<!-- odocal: the laser's pose relative to the wheel-axle midpoint (x forward, y left,\n\
         \x20    yaw counter-clockwise). Paste into the laser's fixed joint when its parent link\n\
         \x20    is at the axle midpoint (else compose with the parent's offset, docs/frames.md).\n\
         \x20    z, roll and pitch are not calibrated (planar method): keep your own values. -->\n\
         <origin xyz=\"{:?} {:?} 0\" rpy=\"0 0 {:?}\"/>\n",
        p.l_x, p.l_y, p.l_theta
    ))
}

/// One laser of several in results.json's `lasers` (the fields export needs).
#[derive(Debug, Clone, PartialEq, serde::Deserialize)]
pub struct LaserPose {
    /// The bag's scan topic, when known.
    #[serde(default)]
    pub topic: Option<String>,
    /// ℓx (m).
    pub l_x: f64,
    /// ℓy (m).
    pub l_y: f64,
    /// ℓθ (rad).
    pub l_theta: f64,
}

/// The URDF `<origin>` of every laser's joint: [`laser_joint_urdf`] with `p`'s pose
/// when `lasers` has fewer than two; else one origin per laser, each under a comment
/// naming it (its topic, and its position among the lasers).
pub fn laser_joints_urdf(p: &FlatParams, lasers: &[LaserPose]) -> Result<String, ExportError> {
    if lasers.len() < 2 {
        return laser_joint_urdf(p);
    }
    let mut out = String::new();
    for (k, l) in lasers.iter().enumerate() {
        let one = FlatParams {
            l_x: l.l_x,
            l_y: l.l_y,
            l_theta: l.l_theta,
            ..*p
        };
        let origin = laser_joint_urdf(&one)?;
        let name = l.topic.as_deref().unwrap_or("(no topic)");
        // The topic is written inside an XML comment: no "--" may appear there.
        out.push_str(&format!(
            "<!-- laser {} of {}: {} -->\n{origin}",
            k + 1,
            lasers.len(),
            name.replace("--", "- -")
        ));
    }
    Ok(out)
}

/// Writes [`DIFF_DRIVE_FILE`] and [`URDF_FILE`] of `p` into `dir`, each atomically.
pub fn write_ros_files(dir: &Path, p: &FlatParams) -> io::Result<()> {
    let yaml = diff_drive_controller_yaml(p).map_err(io::Error::other)?;
    let urdf = laser_joint_urdf(p).map_err(io::Error::other)?;
    write_bytes_atomically(&dir.join(DIFF_DRIVE_FILE), yaml.as_bytes())?;
    write_bytes_atomically(&dir.join(URDF_FILE), urdf.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params() -> FlatParams {
        FlatParams {
            r_l: 0.02088,
            r_r: 0.02095,
            b: 0.089,
            l_x: -0.0058,
            l_y: 0.0002,
            l_theta: 0.0095,
        }
    }

    fn value(text: &str, key: &str) -> f64 {
        let line = text
            .lines()
            .find(|l| l.trim_start().starts_with(&format!("{key}:")))
            .unwrap_or_else(|| panic!("no {key} in {text}"));
        line.split(':').nth(1).unwrap().trim().parse().unwrap()
    }

    #[test]
    fn the_controller_file_gives_back_the_radii_and_distance() {
        let p = params();
        let yaml = diff_drive_controller_yaml(&p).unwrap();
        let radius = value(&yaml, "wheel_radius");
        let left = radius * value(&yaml, "left_wheel_radius_multiplier");
        let right = radius * value(&yaml, "right_wheel_radius_multiplier");
        let b = value(&yaml, "wheel_separation") * value(&yaml, "wheel_separation_multiplier");
        assert!((left - p.r_l).abs() <= 1e-15, "{left} vs {}", p.r_l);
        assert!((right - p.r_r).abs() <= 1e-15, "{right} vs {}", p.r_r);
        assert_eq!(b, p.b);
    }

    #[test]
    fn the_urdf_origin_is_the_laser_pose() {
        let urdf = laser_joint_urdf(&params()).unwrap();
        assert!(
            urdf.contains("<origin xyz=\"-0.0058 0.0002 0\" rpy=\"0 0 0.0095\"/>"),
            "{urdf}"
        );
    }

    #[test]
    fn one_origin_per_laser() {
        let lasers = [
            LaserPose {
                topic: Some("/scan_front".into()),
                l_x: 0.1,
                l_y: 0.0,
                l_theta: 0.0,
            },
            LaserPose {
                topic: Some("/scan_rear".into()),
                l_x: -0.2,
                l_y: 0.01,
                l_theta: 3.1,
            },
        ];
        let urdf = laser_joints_urdf(&params(), &lasers).unwrap();
        assert_eq!(urdf.matches("<origin ").count(), 2, "{urdf}");
        assert!(urdf.contains("laser 2 of 2: /scan_rear"), "{urdf}");
        assert!(
            urdf.contains("<origin xyz=\"-0.2 0.01 0\" rpy=\"0 0 3.1\"/>"),
            "{urdf}"
        );
        // One laser: the single origin of the six-parameter fields.
        assert_eq!(
            laser_joints_urdf(&params(), &lasers[..1]).unwrap(),
            laser_joint_urdf(&params()).unwrap()
        );
    }

    #[test]
    fn non_positive_or_non_finite_parameters_are_refused() {
        let mut p = params();
        p.r_l = -0.02;
        assert!(diff_drive_controller_yaml(&p).is_err());
        let mut p = params();
        p.l_theta = f64::NAN;
        assert!(laser_joint_urdf(&p).is_err());
    }
}
