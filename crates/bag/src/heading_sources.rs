//! What else in a bag bears on odometry-only mode: the wheel joint states (with them
//! the calibration does not need the odometry at all) and IMU topics (a hint that the
//! odometry's heading may be a gyro's rather than the wheels'; never proof alone).

use crate::collect::TopicStats;
use crate::messages::{normalize_type, MessageKind};

/// Topics with messages that tell how a bag's odometry heading may have been made.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct HeadingSources {
    /// `sensor_msgs/JointState` topics with messages.
    pub joint_states: Vec<String>,
    /// `sensor_msgs/Imu` topics with messages.
    pub imu: Vec<String>,
}

/// The joint-state and IMU topics among `topics` that have messages, in bag order.
pub fn heading_sources(topics: &[TopicStats]) -> HeadingSources {
    let with = |keep: &dyn Fn(&TopicStats) -> bool| -> Vec<String> {
        topics
            .iter()
            .filter(|t| t.count > 0 && keep(t))
            .map(|t| t.name.clone())
            .collect()
    };
    HeadingSources {
        joint_states: with(&|t| t.kind == MessageKind::JointState),
        imu: with(&|t| normalize_type(&t.type_name) == "sensor_msgs/Imu"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wire::Encoding;

    fn topic(name: &str, type_name: &str, count: u64) -> TopicStats {
        TopicStats {
            name: name.into(),
            type_name: type_name.into(),
            kind: MessageKind::of_type(type_name),
            encoding: Encoding::Cdr,
            count,
            first_ns: None,
            last_ns: None,
            bytes: 0,
        }
    }

    #[test]
    fn joint_states_and_imu_topics_with_messages_are_listed_in_either_spelling() {
        let topics = [
            topic("/scan", "sensor_msgs/msg/LaserScan", 10),
            topic("/imu", "sensor_msgs/msg/Imu", 100),
            topic("/imu_raw", "sensor_msgs/Imu", 0),
            topic("/mobile_base/sensors/imu_data", "sensor_msgs/Imu", 5),
            topic("/joint_states", "sensor_msgs/JointState", 50),
            topic("/odom", "nav_msgs/msg/Odometry", 50),
        ];
        let s = heading_sources(&topics);
        assert_eq!(s.joint_states, ["/joint_states"]);
        assert_eq!(s.imu, ["/imu", "/mobile_base/sensors/imu_data"]);
        assert_eq!(heading_sources(&topics[..1]), HeadingSources::default());
    }
}
