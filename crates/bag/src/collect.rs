//! What one pass over a bag gathers: every topic with its type, count and time span,
//! and the decoded messages of the topics that may be used (laser scans, joint states,
//! odometry). Other topics are counted from their record headers and never decoded.

use crate::error::{seconds, BagError};
use crate::limits::MAX_DECODED_BYTES;
use crate::messages::{
    decode_joint_state, decode_laser_scan, decode_odometry, header_frame, normalize_type,
    MessageKind, OdometryMsg, ScanFields,
};
use crate::tf::{decode_tf_message, TfTree};
use crate::wire::{Encoding, Wire};
use crate::zstd_input::decompress_message;
use std::collections::HashMap;

/// One topic of a bag.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct TopicStats {
    /// Topic name.
    pub name: String,
    /// Message type as declared (`sensor_msgs/LaserScan`, `sensor_msgs/msg/LaserScan`, …).
    pub type_name: String,
    /// What odocal makes of the type.
    pub kind: MessageKind,
    /// Serialization of its messages.
    pub encoding: Encoding,
    /// Number of messages.
    pub count: u64,
    /// Receive (record) time of the first message (ns).
    pub first_ns: Option<u64>,
    /// Receive (record) time of the last message (ns).
    pub last_ns: Option<u64>,
    /// Bytes of message bodies.
    pub bytes: u64,
}

impl TopicStats {
    /// Messages per second over the topic's time span (`None` with fewer than 2).
    pub fn rate_hz(&self) -> Option<f64> {
        let (a, b) = (self.first_ns?, self.last_ns?);
        (self.count > 1 && b > a).then(|| (self.count - 1) as f64 / ((b - a) as f64 * 1e-9))
    }

    /// Seconds from the first message to the last.
    pub fn span_s(&self) -> f64 {
        match (self.first_ns, self.last_ns) {
            (Some(a), Some(b)) => b.saturating_sub(a) as f64 * 1e-9,
            _ => 0.0,
        }
    }
}

/// A decoded laser scan: its fields, receive time and where its ranges are.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ScanRecord {
    pub(crate) fields: ScanFields,
    pub(crate) receive_ns: u64,
    pub(crate) offset: usize,
    pub(crate) len: usize,
}

/// The decoded scans of one topic, and the messages that could not be decoded.
#[derive(Debug, Default)]
pub(crate) struct ScanTopic {
    /// The first message's `header.frame_id`.
    pub(crate) frame_id: Option<String>,
    pub(crate) records: Vec<ScanRecord>,
    pub(crate) ranges: Vec<f32>,
    pub(crate) undecodable: Skipped,
}

/// Messages of a topic skipped because they are malformed: how many, and the first.
#[derive(Debug, Default, Clone, PartialEq)]
pub(crate) struct Skipped {
    pub(crate) count: u64,
    /// The first one: its index on the topic, receive time (ns) and what was wrong.
    pub(crate) first: Option<(u64, u64, String)>,
}

impl Skipped {
    /// Counts one more skipped message.
    pub(crate) fn add(&mut self, index: u64, receive_ns: u64, why: impl FnOnce() -> String) {
        self.count += 1;
        if self.first.is_none() {
            self.first = Some((index, receive_ns, why()));
        }
    }

    /// Adds the skips of `other` (its first one is later than ours when we have one).
    pub(crate) fn merge(&mut self, other: &Skipped) {
        self.count += other.count;
        if let (None, Some(f)) = (&self.first, &other.first) {
            self.first = Some(f.clone());
        }
    }
}

/// One joint's values in one JointState message (NaN where not given).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct JointValue {
    pub(crate) joint: u32,
    pub(crate) position: f64,
    pub(crate) velocity: f64,
}

/// A decoded JointState message.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct JointRecord {
    pub(crate) stamp_ns: i64,
    pub(crate) receive_ns: u64,
    pub(crate) values: Vec<JointValue>,
}

/// The decoded joint states of one topic, joint names interned.
#[derive(Debug, Default)]
pub(crate) struct JointTopic {
    pub(crate) names: Vec<String>,
    index: HashMap<String, u32>,
    pub(crate) records: Vec<JointRecord>,
}

impl JointTopic {
    fn intern(&mut self, name: &str) -> u32 {
        if let Some(&i) = self.index.get(name) {
            return i;
        }
        let i = self.names.len() as u32;
        self.names.push(name.to_string());
        self.index.insert(name.to_string(), i);
        i
    }

    /// The index of a joint name, when seen.
    pub(crate) fn joint(&self, name: &str) -> Option<u32> {
        self.index.get(name).copied()
    }
}

/// Which topics to decode: `None` decodes every topic of that kind.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DecodeFilter {
    /// Only this LaserScan topic.
    pub scan_topic: Option<String>,
    /// Only this JointState topic.
    pub joint_states_topic: Option<String>,
    /// Only this Odometry topic.
    pub odom_topic: Option<String>,
    /// Odometry-only mode: joint states are not decoded.
    pub odometry_only: bool,
}

/// Everything one pass over a bag gathers.
#[derive(Debug, Default)]
pub struct Collected {
    /// Every topic, in order of first appearance.
    pub topics: Vec<TopicStats>,
    by_name: HashMap<String, usize>,
    decode: Vec<bool>,
    pub(crate) scans: HashMap<usize, ScanTopic>,
    pub(crate) joints: HashMap<usize, JointTopic>,
    pub(crate) odom: HashMap<usize, Vec<(OdometryMsg, u64)>>,
    /// The static transforms of `/tf_static` and `/tf`.
    pub tf: TfTree,
    /// The fixed joints of the robot description (`robot_description`), for the
    /// edges the transform messages lack.
    pub described: Vec<crate::tf::Transform>,
    filter: DecodeFilter,
    /// Files read, in order.
    pub files: Vec<String>,
    /// Bytes of bag files read.
    pub bytes_read: u64,
    /// Notes worth showing once (an unindexed bag, …).
    pub warnings: Vec<String>,
    /// Bytes kept from decoded messages, held under [`MAX_DECODED_BYTES`].
    decoded_bytes: u64,
    /// Each message body is a zstd frame (a ROS 2 bag of `compression_mode: MESSAGE`).
    pub(crate) zstd_messages: bool,
}

impl Collected {
    /// An empty collection decoding what `filter` allows.
    pub(crate) fn new(filter: DecodeFilter) -> Self {
        Collected {
            filter,
            ..Collected::default()
        }
    }

    /// The index of a topic by name.
    pub fn topic_index(&self, name: &str) -> Option<usize> {
        self.by_name.get(name).copied()
    }

    /// Registers a topic (again: split files and ROS 1 connections repeat them) and
    /// returns its index. A topic declared with two different types is an error.
    pub(crate) fn topic(
        &mut self,
        file: &str,
        name: &str,
        type_name: &str,
        encoding: Encoding,
    ) -> Result<usize, BagError> {
        if let Some(&i) = self.by_name.get(name) {
            let t = &self.topics[i];
            if t.type_name != type_name || t.encoding != encoding {
                return Err(BagError::format(
                    file,
                    None,
                    format!(
                        "topic {name} is declared as {} and as {type_name}",
                        t.type_name
                    ),
                    "record each topic with one message type",
                ));
            }
            return Ok(i);
        }
        let kind = MessageKind::of_type(type_name);
        let wanted = match kind {
            MessageKind::LaserScan => &self.filter.scan_topic,
            MessageKind::JointState => &self.filter.joint_states_topic,
            MessageKind::Odometry => &self.filter.odom_topic,
            MessageKind::Transforms | MessageKind::Other => &None,
        };
        let skipped = kind == MessageKind::JointState && self.filter.odometry_only;
        let decode = kind == MessageKind::Transforms
            || is_robot_description(name, type_name)
            || (kind != MessageKind::Other
                && !skipped
                && wanted.as_deref().is_none_or(|w| w == name));
        self.topics.push(TopicStats {
            name: name.to_string(),
            type_name: type_name.to_string(),
            kind,
            encoding,
            count: 0,
            first_ns: None,
            last_ns: None,
            bytes: 0,
        });
        self.decode.push(decode);
        let i = self.topics.len() - 1;
        self.by_name.insert(name.to_string(), i);
        Ok(i)
    }

    /// True when messages of topic `i` are decoded (else only counted).
    pub(crate) fn decodes(&self, i: usize) -> bool {
        self.decode[i]
    }

    /// Counts `count` messages of topic `i` received between `first_ns` and `last_ns`.
    pub(crate) fn count(&mut self, i: usize, count: u64, first_ns: u64, last_ns: u64, bytes: u64) {
        let t = &mut self.topics[i];
        t.count += count;
        t.bytes += bytes;
        t.first_ns = Some(t.first_ns.map_or(first_ns, |f| f.min(first_ns)));
        t.last_ns = Some(t.last_ns.map_or(last_ns, |l| l.max(last_ns)));
    }

    /// One message of topic `i`, received at `receive_ns`: counted, and decoded when
    /// its topic may be used.
    pub(crate) fn message(
        &mut self,
        file: &str,
        i: usize,
        receive_ns: u64,
        body: &[u8],
    ) -> Result<(), BagError> {
        let index = self.topics[i].count;
        self.count(i, 1, receive_ns, receive_ns, body.len() as u64);
        if !self.decode[i] {
            return Ok(());
        }
        let plain;
        let body = if self.zstd_messages {
            plain = match decompress_message(body) {
                Ok(p) => p,
                Err(problem) => {
                    let t = &self.topics[i];
                    return Err(BagError::format(
                        file,
                        None,
                        format!(
                            "topic {}: message {index} (received at {} s): {problem}",
                            t.name,
                            seconds(receive_ns)
                        ),
                        "the bag says each message is zstd-compressed (compression_mode \
                         MESSAGE); the message is damaged",
                    ));
                }
            };
            &plain[..]
        } else {
            body
        };
        let t = &self.topics[i];
        let (kind, encoding) = (t.kind, t.encoding);
        let fail = |error| BagError::Message {
            file: file.to_string(),
            topic: t.name.clone(),
            type_name: t.type_name.clone(),
            index,
            receive_ns,
            error: Box::new(error),
        };
        let kept = match kind {
            MessageKind::LaserScan => {
                let topic = self.scans.entry(i).or_default();
                if topic.frame_id.is_none() {
                    topic.frame_id = Some(header_frame(body, encoding).map_err(fail)?);
                }
                let offset = topic.ranges.len();
                match decode_laser_scan(body, encoding, &mut topic.ranges) {
                    Ok((fields, len)) => {
                        topic.records.push(ScanRecord {
                            fields,
                            receive_ns,
                            offset,
                            len,
                        });
                        4 * len + std::mem::size_of::<ScanRecord>()
                    }
                    // One damaged scan does not spoil the bag: skipped and counted.
                    Err(e) => {
                        topic
                            .undecodable
                            .add(index, receive_ns, || format!("cannot be decoded: {e}"));
                        0
                    }
                }
            }
            MessageKind::JointState => {
                let msg = decode_joint_state(body, encoding).map_err(fail)?;
                let topic = self.joints.entry(i).or_default();
                let n = msg.names.len();
                let given = |v: &[f64], k: usize| {
                    if v.len() == n {
                        v[k]
                    } else {
                        f64::NAN
                    }
                };
                let names_before: usize = topic.names.len();
                let values: Vec<JointValue> = (0..n)
                    .map(|k| JointValue {
                        joint: topic.intern(msg.names[k]),
                        position: given(&msg.position, k),
                        velocity: given(&msg.velocity, k),
                    })
                    .collect();
                let new_names: usize = topic.names[names_before..]
                    .iter()
                    .map(|s| 2 * s.len() + 64)
                    .sum();
                topic.records.push(JointRecord {
                    stamp_ns: msg.stamp_ns,
                    receive_ns,
                    values,
                });
                n * std::mem::size_of::<JointValue>()
                    + std::mem::size_of::<JointRecord>()
                    + new_names
            }
            MessageKind::Odometry => {
                let msg = decode_odometry(body, encoding).map_err(fail)?;
                self.odom.entry(i).or_default().push((msg, receive_ns));
                std::mem::size_of::<(OdometryMsg, u64)>()
            }
            MessageKind::Transforms => {
                let transforms = decode_tf_message(body, encoding).map_err(fail)?;
                let n = transforms.len();
                for t in transforms {
                    self.tf.add(t);
                }
                n * 128
            }
            MessageKind::Other => {
                // Only a robot description is decoded among the other types.
                let xml = Wire::new(body, encoding)
                    .and_then(|mut w| w.string("data"))
                    .map_err(|e| format!("message {index} cannot be decoded: {e}"));
                match xml.and_then(crate::urdf::fixed_joints) {
                    Ok(joints) => self.described = joints,
                    Err(why) => self.warnings.push(format!(
                        "topic {}: {why}; the nominal laser pose is taken from the \
                         static transforms only",
                        t.name
                    )),
                }
                0
            }
        };
        self.decoded_bytes += kept as u64;
        if self.decoded_bytes > MAX_DECODED_BYTES {
            let t = &self.topics[i];
            return Err(BagError::format(
                file,
                None,
                format!(
                    "the decoded messages exceed the memory budget of {} MiB at message {index} \
                     of topic {} (received at {} s)",
                    MAX_DECODED_BYTES >> 20,
                    t.name,
                    seconds(receive_ns)
                ),
                "name the topics to use (--scan-topic, --joint-states-topic, --odom-topic) so \
                 that fewer are decoded, or cut the bag into shorter parts with the ROS tools",
            ));
        }
        Ok(())
    }
}

/// True for a robot description topic: a `std_msgs/String` named `robot_description`
/// (in any namespace), the URDF `robot_state_publisher` latches.
fn is_robot_description(topic: &str, type_name: &str) -> bool {
    normalize_type(type_name) == "std_msgs/String"
        && (topic == "robot_description" || topic.ends_with("/robot_description"))
}
