//! The message types odocal reads, decoded from ROS 1 or CDR bodies:
//! `sensor_msgs/LaserScan`, `sensor_msgs/JointState`, `nav_msgs/Odometry` (and the
//! transforms of `tf2_msgs/TFMessage`, in [`crate::tf`]).

use crate::wire::{Encoding, Wire, WireError};

/// What a topic's message type is to odocal.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum MessageKind {
    /// `sensor_msgs/LaserScan`.
    LaserScan,
    /// `sensor_msgs/JointState`.
    JointState,
    /// `nav_msgs/Odometry`.
    Odometry,
    /// `tf2_msgs/TFMessage` (ROS 1 also `tf/tfMessage`).
    Transforms,
    /// Anything else: counted, never decoded.
    Other,
}

impl MessageKind {
    /// The kind of a type name, ROS 1 (`sensor_msgs/LaserScan`) or ROS 2
    /// (`sensor_msgs/msg/LaserScan`) spelling.
    pub fn of_type(type_name: &str) -> MessageKind {
        match normalize_type(type_name).as_str() {
            "sensor_msgs/LaserScan" => MessageKind::LaserScan,
            "sensor_msgs/JointState" => MessageKind::JointState,
            "nav_msgs/Odometry" => MessageKind::Odometry,
            "tf2_msgs/TFMessage" | "tf/tfMessage" => MessageKind::Transforms,
            _ => MessageKind::Other,
        }
    }

    /// The ROS 1 type name this kind stands for.
    pub fn type_name(self) -> &'static str {
        match self {
            MessageKind::LaserScan => "sensor_msgs/LaserScan",
            MessageKind::JointState => "sensor_msgs/JointState",
            MessageKind::Odometry => "nav_msgs/Odometry",
            MessageKind::Transforms => "tf2_msgs/TFMessage",
            MessageKind::Other => "(other)",
        }
    }
}

/// `pkg/msg/Type` → `pkg/Type` (ROS 2 spelling to ROS 1 spelling).
pub fn normalize_type(type_name: &str) -> String {
    type_name.replacen("/msg/", "/", 1)
}

/// The fields of a `sensor_msgs/LaserScan` besides its ranges.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScanFields {
    /// Header stamp (ns).
    pub stamp_ns: i64,
    /// Angle of the first ray (rad).
    pub angle_min: f32,
    /// Angle of the last ray (rad).
    pub angle_max: f32,
    /// Angle between rays (rad; negative for clockwise scanners).
    pub angle_increment: f32,
    /// Time between rays (s).
    pub time_increment: f32,
    /// Time between scans (s).
    pub scan_time: f32,
    /// Minimum valid range (m).
    pub range_min: f32,
    /// Maximum valid range (m).
    pub range_max: f32,
}

/// Decodes a LaserScan, appending its ranges to `ranges`; returns the other fields
/// and the number of ranges.
pub(crate) fn decode_laser_scan(
    body: &[u8],
    encoding: Encoding,
    ranges: &mut Vec<f32>,
) -> Result<(ScanFields, usize), WireError> {
    let mut w = Wire::new(body, encoding)?;
    let stamp_ns = w.header_stamp_ns()?;
    let fields = ScanFields {
        stamp_ns,
        angle_min: w.f32("angle_min")?,
        angle_max: w.f32("angle_max")?,
        angle_increment: w.f32("angle_increment")?,
        time_increment: w.f32("time_increment")?,
        scan_time: w.f32("scan_time")?,
        range_min: w.f32("range_min")?,
        range_max: w.f32("range_max")?,
    };
    let before = ranges.len();
    let n = match w.f32_seq_into("ranges", ranges) {
        Ok(n) => n,
        Err(e) => {
            ranges.truncate(before);
            return Err(e);
        }
    };
    if let Err(e) = w.skip_f32_seq("intensities") {
        ranges.truncate(before);
        return Err(e);
    }
    Ok((fields, n))
}

/// The `header.frame_id` of a message that starts with a header (a LaserScan's frame).
pub(crate) fn header_frame(body: &[u8], encoding: Encoding) -> Result<String, WireError> {
    Ok(Wire::new(body, encoding)?.header()?.1.to_string())
}

/// A decoded `sensor_msgs/JointState` (effort is not kept).
#[derive(Debug, Clone, PartialEq)]
pub struct JointStateMsg<'a> {
    /// Header stamp (ns).
    pub stamp_ns: i64,
    /// Joint names.
    pub names: Vec<&'a str>,
    /// Positions (rad), empty or one per name.
    pub position: Vec<f64>,
    /// Velocities (rad/s), empty or one per name.
    pub velocity: Vec<f64>,
}

/// Decodes a JointState.
pub(crate) fn decode_joint_state(
    body: &[u8],
    encoding: Encoding,
) -> Result<JointStateMsg<'_>, WireError> {
    let mut w = Wire::new(body, encoding)?;
    let stamp_ns = w.header_stamp_ns()?;
    let names = w.strings("name")?;
    let position = w.f64_seq("position")?;
    let velocity = w.f64_seq("velocity")?;
    // `effort` follows; it is not used, but its length must be sane.
    w.f64_seq("effort")?;
    Ok(JointStateMsg {
        stamp_ns,
        names,
        position,
        velocity,
    })
}

/// The planar part of a `nav_msgs/Odometry`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OdometryMsg {
    /// Header stamp (ns).
    pub stamp_ns: i64,
    /// Position x (m).
    pub x: f64,
    /// Position y (m).
    pub y: f64,
    /// Heading (rad) from the orientation quaternion.
    pub yaw: f64,
    /// Forward velocity (m/s).
    pub v: f64,
    /// Turn rate (rad/s).
    pub w: f64,
}

/// Decodes an Odometry message.
pub(crate) fn decode_odometry(body: &[u8], encoding: Encoding) -> Result<OdometryMsg, WireError> {
    let mut w = Wire::new(body, encoding)?;
    let stamp_ns = w.header_stamp_ns()?;
    w.string("child_frame_id")?;
    let x = w.f64("pose.pose.position.x")?;
    let y = w.f64("pose.pose.position.y")?;
    w.f64("pose.pose.position.z")?;
    let qx = w.f64("pose.pose.orientation.x")?;
    let qy = w.f64("pose.pose.orientation.y")?;
    let qz = w.f64("pose.pose.orientation.z")?;
    let qw = w.f64("pose.pose.orientation.w")?;
    w.skip_f64s("pose.covariance", 36)?;
    let v = w.f64("twist.twist.linear.x")?;
    w.f64("twist.twist.linear.y")?;
    w.f64("twist.twist.linear.z")?;
    w.f64("twist.twist.angular.x")?;
    w.f64("twist.twist.angular.y")?;
    let wz = w.f64("twist.twist.angular.z")?;
    w.skip_f64s("twist.covariance", 36)?;
    let yaw = (2.0 * (qw * qz + qx * qy)).atan2(1.0 - 2.0 * (qy * qy + qz * qz));
    Ok(OdometryMsg {
        stamp_ns,
        x,
        y,
        yaw,
        v,
        w: wz,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn type_names_of_both_generations_are_recognized() {
        assert_eq!(
            MessageKind::of_type("sensor_msgs/msg/LaserScan"),
            MessageKind::LaserScan
        );
        assert_eq!(
            MessageKind::of_type("sensor_msgs/JointState"),
            MessageKind::JointState
        );
        assert_eq!(
            MessageKind::of_type("nav_msgs/msg/Odometry"),
            MessageKind::Odometry
        );
        assert_eq!(
            MessageKind::of_type("sensor_msgs/Image"),
            MessageKind::Other
        );
    }

    fn ros1_scan(n: u32) -> Vec<u8> {
        let mut b = Vec::new();
        b.extend(1u32.to_le_bytes()); // seq
        b.extend(10u32.to_le_bytes()); // sec
        b.extend(5u32.to_le_bytes()); // nsec
        b.extend(4u32.to_le_bytes());
        b.extend(b"lase");
        for v in [-1.0f32, 1.0, 0.5, 0.0, 0.1, 0.02, 4.0] {
            b.extend(v.to_le_bytes());
        }
        b.extend(n.to_le_bytes());
        for i in 0..n {
            b.extend((i as f32).to_le_bytes());
        }
        b.extend(0u32.to_le_bytes());
        b
    }

    #[test]
    fn a_ros1_laser_scan_decodes_and_a_truncated_one_does_not() {
        let body = ros1_scan(5);
        let mut ranges = Vec::new();
        let (f, n) = decode_laser_scan(&body, Encoding::Ros1, &mut ranges).unwrap();
        assert_eq!(n, 5);
        assert_eq!(f.stamp_ns, 10_000_000_005);
        assert_eq!(ranges, vec![0.0, 1.0, 2.0, 3.0, 4.0]);
        for cut in 0..body.len() {
            let mut r = Vec::new();
            assert!(decode_laser_scan(&body[..cut], Encoding::Ros1, &mut r).is_err());
            assert!(r.is_empty());
        }
    }
}
