//! The robot's static transforms (`tf2_msgs/TFMessage` on `/tf_static`, and on `/tf`
//! those that never change; the fixed joints of `robot_description` for the edges
//! these lack), and the nominal laser pose they give: the transform from
//! the base frame (`base_link`, else `base_footprint`, else the root of the tree) to
//! the scan's `frame_id`, projected on the plane (x, y, yaw).

use crate::wire::{Encoding, Wire, WireError};
use std::collections::HashMap;

/// Frames kept at most: a tree larger than this is not a robot's body.
pub const MAX_FRAMES: usize = 4096;

/// One `geometry_msgs/TransformStamped`: `child` at `translation`, `rotation`
/// (quaternion x, y, z, w) in `parent`.
#[derive(Debug, Clone, PartialEq)]
pub struct Transform {
    /// The parent frame (`header.frame_id`).
    pub parent: String,
    /// The child frame.
    pub child: String,
    /// Translation (m).
    pub translation: [f64; 3],
    /// Rotation quaternion (x, y, z, w).
    pub rotation: [f64; 4],
}

/// Decodes a `tf2_msgs/TFMessage` (or ROS 1 `tf/tfMessage`): its transforms.
pub(crate) fn decode_tf_message(
    body: &[u8],
    encoding: Encoding,
) -> Result<Vec<Transform>, WireError> {
    let mut w = Wire::new(body, encoding)?;
    // Each TransformStamped takes at least its 7 float64 (56 bytes).
    let n = w.length("transforms", 56)?;
    let mut out = Vec::with_capacity(n);
    for _ in 0..n {
        let (_, parent) = w.header()?;
        let child = w.string("transforms.child_frame_id")?;
        let mut v = [0.0; 7];
        for x in &mut v {
            *x = w.f64("transforms.transform")?;
        }
        out.push(Transform {
            parent: parent.to_string(),
            child: child.to_string(),
            translation: [v[0], v[1], v[2]],
            rotation: [v[3], v[4], v[5], v[6]],
        });
    }
    Ok(out)
}

/// tf frame ids may carry a leading `/` (ROS 1); the tree compares them without it.
fn strip_slash(frame: &str) -> &str {
    frame.strip_prefix('/').unwrap_or(frame)
}

/// One edge of the tree and whether it ever changed.
#[derive(Debug, Clone)]
struct Edge {
    transform: Transform,
    varies: bool,
    /// From the robot description (URDF), not from a transform message.
    described: bool,
}

/// The static part of a bag's transform tree, child frame → edge.
#[derive(Debug, Clone, Default)]
pub struct TfTree {
    edges: HashMap<String, Edge>,
    /// Frames dropped because the tree reached [`MAX_FRAMES`].
    pub dropped: u64,
}

impl TfTree {
    /// Adds a transform seen in a message; one that differs from an earlier value of the
    /// same edge marks it as moving (a moving edge is not part of the robot's body).
    pub(crate) fn add(&mut self, mut t: Transform) {
        t.parent = strip_slash(&t.parent).to_string();
        t.child = strip_slash(&t.child).to_string();
        if let Some(e) = self.edges.get_mut(&t.child) {
            let same = e.transform.parent == t.parent
                && e.transform
                    .translation
                    .iter()
                    .chain(&e.transform.rotation)
                    .zip(t.translation.iter().chain(&t.rotation))
                    .all(|(a, b)| (a - b).abs() <= 1e-9);
            e.varies |= !same;
            return;
        }
        if self.edges.len() >= MAX_FRAMES {
            self.dropped += 1;
            return;
        }
        self.edges.insert(
            t.child.clone(),
            Edge {
                transform: t,
                varies: false,
                described: false,
            },
        );
    }

    /// Adds the fixed joints of the robot description for the frames no transform
    /// message gave (the messages are what the robot published: they win).
    pub(crate) fn add_described(&mut self, joints: Vec<Transform>) {
        for mut t in joints {
            t.parent = strip_slash(&t.parent).to_string();
            t.child = strip_slash(&t.child).to_string();
            if self.edges.contains_key(&t.child) {
                continue;
            }
            if self.edges.len() >= MAX_FRAMES {
                self.dropped += 1;
                continue;
            }
            self.edges.insert(
                t.child.clone(),
                Edge {
                    transform: t,
                    varies: false,
                    described: true,
                },
            );
        }
    }

    /// The nominal pose of `laser_frame` in the base frame, when the static tree
    /// links them.
    pub fn nominal_laser(&self, laser_frame: &str) -> Option<NominalLaser> {
        let laser_frame = strip_slash(laser_frame);
        // The chain laser → … → root through edges that never moved.
        let mut chain: Vec<&Transform> = Vec::new();
        let mut described: Vec<bool> = Vec::new();
        let mut frame = laser_frame;
        while let Some(e) = self.edges.get(frame).filter(|e| !e.varies) {
            if chain.len() > self.edges.len() {
                return None; // a cycle
            }
            chain.push(&e.transform);
            described.push(e.described);
            frame = &e.transform.parent;
        }
        let parents: Vec<&str> = chain.iter().map(|t| t.parent.as_str()).collect();
        let base_at = ["base_link", "base_footprint"]
            .iter()
            .find_map(|b| parents.iter().position(|p| p == b))
            .or_else(|| chain.len().checked_sub(1))?;
        let base_frame = parents[base_at].to_string();
        let source = match (
            described[..=base_at].iter().any(|d| *d),
            described[..=base_at].iter().all(|d| *d),
        ) {
            (false, _) => "/tf_static",
            (true, true) => "robot_description",
            (true, false) => "/tf_static and robot_description",
        };
        // Compose base → … → laser: the chain's edges from the base down.
        let (mut t, mut q) = ([0.0; 3], [0.0, 0.0, 0.0, 1.0]);
        for edge in chain[..=base_at].iter().rev() {
            let moved = rotate(q, edge.translation);
            t = [t[0] + moved[0], t[1] + moved[1], t[2] + moved[2]];
            q = multiply(q, normalized(edge.rotation)?);
        }
        let [x, y, z, w] = q;
        let yaw = (2.0 * (w * z + x * y)).atan2(1.0 - 2.0 * (y * y + z * z));
        // Roll and pitch beyond a degree make the planar pose misleading.
        let tilt = (2.0 * (x * x + y * y)).min(1.0).asin();
        Some(NominalLaser {
            source: source.to_string(),
            base_frame,
            laser_frame: laser_frame.to_string(),
            x: t[0],
            y: t[1],
            theta: yaw,
            z: t[2],
            tilt,
        })
    }
}

/// The laser's pose in the base frame as the bag's static transforms give it.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct NominalLaser {
    /// Where the transforms came from: `/tf_static` (the static transform messages),
    /// `robot_description` (the URDF's fixed joints), or both.
    pub source: String,
    /// The base frame the pose is relative to.
    pub base_frame: String,
    /// The scan's frame.
    pub laser_frame: String,
    /// Forward offset (m).
    pub x: f64,
    /// Leftward offset (m).
    pub y: f64,
    /// Yaw (rad, counter-clockwise).
    pub theta: f64,
    /// Height (m; not used by the planar calibration).
    pub z: f64,
    /// Angle between the laser's axis and the vertical (rad; roll and pitch).
    pub tilt: f64,
}

/// A unit quaternion, or `None` when `q` is not finite or is zero.
fn normalized(q: [f64; 4]) -> Option<[f64; 4]> {
    let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
    (n.is_finite() && n > 1e-9).then(|| q.map(|x| x / n))
}

/// Hamilton product `a · b` of quaternions (x, y, z, w).
fn multiply(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    let [ax, ay, az, aw] = a;
    let [bx, by, bz, bw] = b;
    [
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    ]
}

/// `v` rotated by the unit quaternion `q`.
fn rotate(q: [f64; 4], v: [f64; 3]) -> [f64; 3] {
    let p = multiply(
        multiply(q, [v[0], v[1], v[2], 0.0]),
        [-q[0], -q[1], -q[2], q[3]],
    );
    [p[0], p[1], p[2]]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn edge(parent: &str, child: &str, t: [f64; 3], yaw: f64) -> Transform {
        Transform {
            parent: parent.into(),
            child: child.into(),
            translation: t,
            rotation: [0.0, 0.0, (yaw / 2.0).sin(), (yaw / 2.0).cos()],
        }
    }

    #[test]
    fn the_chain_from_base_link_to_the_laser_is_composed() {
        let mut tree = TfTree::default();
        tree.add(edge("odom", "base_footprint", [1.0, 2.0, 0.0], 0.3));
        tree.add(edge("odom", "base_footprint", [1.5, 2.0, 0.0], 0.4)); // it moves
        tree.add(edge("base_footprint", "base_link", [0.0, 0.0, 0.01], 0.0));
        tree.add(edge(
            "base_link",
            "mount",
            [0.1, 0.0, 0.2],
            std::f64::consts::FRAC_PI_2,
        ));
        tree.add(edge("/mount", "/laser", [0.05, 0.0, 0.0], 0.1));
        let n = tree.nominal_laser("laser").unwrap();
        assert_eq!(n.base_frame, "base_link");
        assert!(
            (n.x - 0.1).abs() < 1e-12 && (n.y - 0.05).abs() < 1e-12,
            "{n:?}"
        );
        assert!((n.theta - (std::f64::consts::FRAC_PI_2 + 0.1)).abs() < 1e-12);
        assert!((n.z - 0.2).abs() < 1e-12 && n.tilt.abs() < 1e-12);
        assert!(tree.nominal_laser("camera").is_none());
    }

    #[test]
    fn without_base_link_the_root_of_the_static_tree_is_the_base() {
        let mut tree = TfTree::default();
        tree.add(edge("chassis", "laser", [0.2, -0.1, 0.0], -0.5));
        let n = tree.nominal_laser("laser").unwrap();
        assert_eq!(n.base_frame, "chassis");
        assert!((n.x - 0.2).abs() < 1e-12 && (n.theta + 0.5).abs() < 1e-12);
    }
}
