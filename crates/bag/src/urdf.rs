//! The fixed joints of a robot's URDF, as `robot_state_publisher` would publish them on
//! `/tf_static`: each `<joint type="fixed">`'s `<origin xyz rpy>` is the transform from
//! its parent link to its child link. Read from a bag's `robot_description` (a
//! `std_msgs/String`, latched), for the edges `/tf_static` lacks.

use crate::tf::Transform;

/// Largest robot description parsed (bytes): 8 MiB, far above a URDF with hundreds of
/// links (meshes are referenced by file name, not inlined).
pub const MAX_DESCRIPTION_BYTES: usize = 8 << 20;

/// Most XML nodes parsed: bounds the parser's memory whatever the text holds.
const MAX_NODES: u32 = 1 << 20;

/// The transforms of the fixed joints of the URDF `xml`; an error in words (not XML,
/// not a `<robot>`, a fixed joint without its links or with an unreadable origin).
pub fn fixed_joints(xml: &str) -> Result<Vec<Transform>, String> {
    if xml.len() > MAX_DESCRIPTION_BYTES {
        return Err(format!(
            "the robot description is {} bytes, more than the {} MiB read",
            xml.len(),
            MAX_DESCRIPTION_BYTES >> 20
        ));
    }
    let options = roxmltree::ParsingOptions {
        allow_dtd: false,
        nodes_limit: MAX_NODES,
        ..Default::default()
    };
    let doc = roxmltree::Document::parse_with_options(xml, options)
        .map_err(|e| format!("the robot description is not valid XML: {e}"))?;
    let robot = doc.root_element();
    if !robot.has_tag_name("robot") {
        return Err(format!(
            "the robot description's root element is <{}>, not a URDF <robot>",
            robot.tag_name().name()
        ));
    }
    robot
        .children()
        .filter(|n| n.has_tag_name("joint") && n.attribute("type") == Some("fixed"))
        .map(|joint| {
            let name = joint.attribute("name").unwrap_or("(unnamed)");
            let link = |tag: &str| {
                joint
                    .children()
                    .find(|n| n.has_tag_name(tag))
                    .and_then(|n| n.attribute("link"))
                    .map(str::to_string)
                    .ok_or_else(|| format!("fixed joint {name} has no <{tag} link=\"…\"/>"))
            };
            let origin = joint.children().find(|n| n.has_tag_name("origin"));
            let triple = |attr: &str| match origin.and_then(|o| o.attribute(attr)) {
                None => Ok([0.0; 3]),
                Some(text) => three_numbers(text).ok_or_else(|| {
                    format!("fixed joint {name}: origin {attr}=\"{text}\" is not three numbers")
                }),
            };
            let [x, y, z] = triple("xyz")?;
            let rpy = triple("rpy")?;
            Ok(Transform {
                parent: link("parent")?,
                child: link("child")?,
                translation: [x, y, z],
                rotation: quaternion_of_rpy(rpy),
            })
        })
        .collect()
}

/// Three finite numbers separated by white space.
fn three_numbers(text: &str) -> Option<[f64; 3]> {
    let v: Vec<f64> = text
        .split_whitespace()
        .map(|t| t.parse::<f64>().ok().filter(|x| x.is_finite()))
        .collect::<Option<_>>()?;
    <[f64; 3]>::try_from(v).ok()
}

/// The quaternion (x, y, z, w) of URDF's roll, pitch, yaw: rotations about the fixed
/// x, y and z axes in that order (R = Rz(yaw) · Ry(pitch) · Rx(roll)).
fn quaternion_of_rpy([roll, pitch, yaw]: [f64; 3]) -> [f64; 4] {
    let (sr, cr) = (roll / 2.0).sin_cos();
    let (sp, cp) = (pitch / 2.0).sin_cos();
    let (sy, cy) = (yaw / 2.0).sin_cos();
    [
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
        cr * cp * cy + sr * sp * sy,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    const URDF: &str = r#"<?xml version="1.0"?>
<robot name="r">
  <!-- a comment -->
  <link name="base_link"/><link name="base_scan"/><link name="wheel"/>
  <joint name="scan_joint" type="fixed">
    <parent link="base_link"/><child link="base_scan"/>
    <origin xyz="-0.032 0.004 0.172" rpy="0 0 0.01"/>
  </joint>
  <joint name="wheel_joint" type="continuous">
    <parent link="base_link"/><child link="wheel"/>
  </joint>
</robot>"#;

    #[test]
    fn fixed_joints_become_transforms() {
        let t = fixed_joints(URDF).unwrap();
        assert_eq!(t.len(), 1, "only the fixed joint");
        assert_eq!(
            (t[0].parent.as_str(), t[0].child.as_str()),
            ("base_link", "base_scan")
        );
        assert_eq!(t[0].translation, [-0.032, 0.004, 0.172]);
        let [x, y, z, w] = t[0].rotation;
        assert!(x.abs() < 1e-15 && y.abs() < 1e-15);
        assert!((2.0 * z.atan2(w) - 0.01).abs() < 1e-12);
    }

    #[test]
    fn roll_pitch_yaw_compose_about_fixed_axes() {
        // Roll π/2 then yaw π/2 (fixed axes): the x axis goes to y.
        let [x, y, z, w] = quaternion_of_rpy([
            std::f64::consts::FRAC_PI_2,
            0.0,
            std::f64::consts::FRAC_PI_2,
        ]);
        // Rotate (1, 0, 0): v' = v + 2w(q×v) + 2 q×(q×v).
        let q = [x, y, z];
        let cross = |a: [f64; 3], b: [f64; 3]| {
            [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ]
        };
        let v = [1.0, 0.0, 0.0];
        let c = cross(q, v);
        let cc = cross(q, c);
        let r: Vec<f64> = (0..3)
            .map(|i| v[i] + 2.0 * w * c[i] + 2.0 * cc[i])
            .collect();
        assert!(
            (r[0]).abs() < 1e-12 && (r[1] - 1.0).abs() < 1e-12 && r[2].abs() < 1e-12,
            "{r:?}"
        );
    }

    #[test]
    fn bad_descriptions_are_errors_in_words() {
        let cases = [
            ("<robot", "not valid XML"),
            ("<sdf/>", "not a URDF"),
            (
                r#"<robot><joint name="j" type="fixed"><parent link="a"/></joint></robot>"#,
                "no <child",
            ),
            (
                r#"<robot><joint name="j" type="fixed"><parent link="a"/><child link="b"/><origin xyz="1 2"/></joint></robot>"#,
                "not three numbers",
            ),
            (
                r#"<!DOCTYPE robot [<!ENTITY a "aaaa">]><robot/>"#,
                "not valid XML",
            ),
        ];
        for (xml, expected) in cases {
            let e = fixed_joints(xml).unwrap_err();
            assert!(e.contains(expected), "{xml}: {e}");
        }
        let huge = " ".repeat(MAX_DESCRIPTION_BYTES + 1);
        assert!(fixed_joints(&huge).unwrap_err().contains("MiB"));
    }
}
