//! Where a log's records came from, and the one formatter every message pointing into
//! the log uses: a text log's records are found by line number, a bag's by topic,
//! message number and stamp.

/// One of a log's streams of records.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stream {
    /// The wheel records ([`crate::EncoderRecord`]): `ENCODER` lines, or the joint
    /// states of a bag.
    Wheels,
    /// The scans ([`crate::ScanMeta`]).
    Scans,
    /// The firmware odometry ([`crate::OdomRecord`]): `ODOM` lines, or a bag's
    /// `nav_msgs/Odometry` topic.
    Odometry,
}

/// Which clock a bag's records were stamped with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BagClock {
    /// The messages' header stamps (the default).
    HeaderStamp,
    /// The times the bag recorded the messages (`--use-receive-time`).
    ReceiveTime,
}

/// Where a log's records came from.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub enum Origin {
    /// A text log (Carmen or JSON): a record's `line` is its 1-based line number.
    #[default]
    Text,
    /// A ROS bag: a record's `line` is one more than the index of its message on its
    /// topic (messages are counted from 0 in messages, as the bag warnings count them).
    Bag {
        /// The `sensor_msgs/LaserScan` topic the scans were read from.
        scan_topic: String,
        /// The topic the wheel records (joint states) or odometry were read from.
        wheel_topic: String,
        /// The clock that stamped the records.
        clock: BagClock,
    },
}

impl Origin {
    /// True when the log was read from a ROS bag.
    pub fn is_bag(&self) -> bool {
        matches!(self, Origin::Bag { .. })
    }

    /// The stream's name in messages: `encoder`, `laser`, `odometry` for a text log,
    /// the topic for a bag.
    pub fn stream(&self, stream: Stream) -> &str {
        match (self, stream) {
            (Origin::Text, Stream::Wheels) => "encoder",
            (Origin::Text, Stream::Scans) => "laser",
            (Origin::Text, Stream::Odometry) => "odometry",
            (Origin::Bag { scan_topic, .. }, Stream::Scans) => scan_topic,
            (Origin::Bag { wheel_topic, .. }, _) => wheel_topic,
        }
    }

    /// What the stream's records are called, plural: `ENCODER records`, `scans`,
    /// `ODOM records` for a text log, `TOPIC messages` for a bag.
    pub fn records(&self, stream: Stream) -> String {
        match (self, stream) {
            (Origin::Text, Stream::Wheels) => "ENCODER records".into(),
            (Origin::Text, Stream::Scans) => "scans".into(),
            (Origin::Text, Stream::Odometry) => "ODOM records".into(),
            (Origin::Bag { .. }, _) => format!("{} messages", self.stream(stream)),
        }
    }

    /// Where the record numbered `line` and stamped `t` (s) is, in words its reader can
    /// find: `line 302` in a text log; `/joint_states message 301 (header stamp
    /// 1190000006.020 s)` in a bag (the message's index on its topic, from 0).
    pub fn at(&self, stream: Stream, line: u64, t: f64) -> String {
        match self {
            Origin::Text => format!("line {line}"),
            Origin::Bag { clock, .. } => {
                let clock = match clock {
                    BagClock::HeaderStamp => "header stamp",
                    BagClock::ReceiveTime => "receive time",
                };
                format!(
                    "{} message {} ({clock} {t:.3} s)",
                    self.stream(stream),
                    line.saturating_sub(1)
                )
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bag() -> Origin {
        Origin::Bag {
            scan_topic: "/scan".into(),
            wheel_topic: "/joint_states".into(),
            clock: BagClock::HeaderStamp,
        }
    }

    #[test]
    fn a_text_log_is_pointed_into_by_line() {
        let o = Origin::Text;
        assert_eq!(o.at(Stream::Wheels, 302, 6.02), "line 302");
        assert_eq!(o.records(Stream::Wheels), "ENCODER records");
        assert_eq!(o.stream(Stream::Scans), "laser");
    }

    #[test]
    fn a_bag_is_pointed_into_by_topic_message_and_stamp() {
        let o = bag();
        assert_eq!(
            o.at(Stream::Scans, 357, 1190000012.3454),
            "/scan message 356 (header stamp 1190000012.345 s)"
        );
        assert_eq!(o.records(Stream::Wheels), "/joint_states messages");
        assert_eq!(o.stream(Stream::Odometry), "/joint_states");
    }
}
