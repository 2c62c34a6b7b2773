//! ROS bags in, odocal's log model out.
//!
//! Reads ROS 1 bags (format 2.0; uncompressed, bz2 and lz4 chunks), ROS 2 bags (a
//! directory with `metadata.yaml` and its `.mcap` or `.db3` files in order, or one
//! `.mcap` or `.db3` file), recognised by content. One streaming pass counts every
//! topic and decodes only `sensor_msgs/LaserScan`, `sensor_msgs/JointState` and
//! `nav_msgs/Odometry` messages (ROS 1 serialization or CDR, either byte order, every
//! field bounds-checked); other topics (camera images, …) are counted from their record
//! headers and never decoded or kept. Memory: one chunk plus the decoded scans.
//!
//! The chosen topics become an [`odocal_log::Log`], exactly what a Carmen log is read
//! into: scans (header stamp by default, record time on request) with their geometry
//! and sweep timing, wheel angles as encoder records at
//! [`odocal_log::WHEEL_TICKS_PER_REVOLUTION`] ticks per turn, or odometry poses as
//! `ODOM` records for the odometry-only mode.

#![deny(missing_docs)]

mod collect;
mod detect;
mod error;
mod heading_sources;
pub mod limits;
mod mcap_source;
mod messages;
mod metadata;
mod ros1;
mod scan_check;
mod select;
mod sqlite_source;
pub mod tf;
mod to_log;
pub mod urdf;
mod wire;
mod zstd_input;

pub use collect::{Collected, DecodeFilter, TopicStats};
pub use detect::{bag_format_of_head, detect_bag, BagFormat};
pub use error::BagError;
pub use heading_sources::{heading_sources, HeadingSources};
pub use messages::{normalize_type, MessageKind, ScanFields};
pub use select::{Selection, TopicChoice, WheelSource};
pub use tf::NominalLaser;
pub use to_log::Clock;
pub use wire::{Encoding, WireError};

use odocal_log::{Log, ReadOptions};
use std::path::Path;

/// How to read a bag: which topics and joints, which clock, and the reading overrides
/// shared with Carmen logs (minimum range, time increment).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BagOptions {
    /// Topic and joint choices (all automatic when `None`).
    pub choice: TopicChoice,
    /// Header stamps (default) or record times.
    pub clock: Clock,
    /// `--min-range` and `--time-increment` apply to bags too.
    pub read: ReadOptions,
}

/// A bag read for calibration.
#[derive(Debug)]
pub struct BagLog {
    /// The container format.
    pub format: BagFormat,
    /// The chosen topics as a log.
    pub log: Log,
    /// What was chosen and why.
    pub selection: Selection,
    /// The laser's pose in the base frame from the bag's static transforms, when they
    /// link the scan's frame to the base.
    pub nominal_laser: Option<NominalLaser>,
    /// Every topic of the bag.
    pub topics: Vec<TopicStats>,
    /// Bytes of bag files read.
    pub bytes_read: u64,
}

/// One streaming pass over the bag at `path`: every topic counted, the messages of the
/// topics `filter` allows decoded.
pub fn scan_bag(path: &Path, filter: DecodeFilter) -> Result<(BagFormat, Collected), BagError> {
    let name = path.display().to_string();
    let format = detect_bag(path)
        .map_err(|e| BagError::io(&name, e))?
        .ok_or_else(|| {
            BagError::format(
                &name,
                Some(0),
                "not a ROS bag (no ROS 1 `#ROSBAG V2.0` line, MCAP magic, SQLite header or \
                 metadata.yaml)",
                "give a .bag, .mcap or .db3 file or a ROS 2 bag directory",
            )
        })?;
    let mut out = Collected::new(filter);
    match format {
        BagFormat::Ros1 => ros1::read_ros1(path, &mut out)?,
        BagFormat::Mcap => mcap_source::read_mcap(path, &name, &mut out)?,
        BagFormat::Db3 => sqlite_source::read_db3(path, &name, &mut out)?,
        BagFormat::Ros2Directory => {
            let meta = metadata::read_metadata(path)?;
            out.zstd_messages = meta.compression == metadata::Compression::Message;
            for file in &meta.files {
                let fname = file.display().to_string();
                // A FILE-compressed bag is read from a decompressed temporary copy.
                let copy = match meta.compression {
                    metadata::Compression::File => Some(zstd_input::decompress_file(file)?),
                    _ => None,
                };
                let readable = copy.as_ref().map_or(file.as_path(), |c| c.path.as_path());
                match detect_bag(readable).map_err(|e| BagError::io(&fname, e))? {
                    Some(BagFormat::Mcap) => mcap_source::read_mcap(readable, &fname, &mut out)?,
                    Some(BagFormat::Db3) => sqlite_source::read_db3(readable, &fname, &mut out)?,
                    _ => {
                        return Err(BagError::format(
                            &fname,
                            Some(0),
                            "a file of the bag directory is neither MCAP nor SQLite",
                            "check the bag with `ros2 bag info`",
                        ))
                    }
                }
            }
        }
    }
    Ok((format, out))
}

/// The decode filter that `choice` implies: a named topic restricts its kind; odometry
/// mode skips joint states.
fn filter_of(choice: &TopicChoice) -> DecodeFilter {
    DecodeFilter {
        scan_topic: choice.scan_topic.clone(),
        joint_states_topic: choice.joint_states_topic.clone(),
        odom_topic: choice.odom_topic.clone(),
        odometry_only: choice.odom_topic.is_some() && choice.joint_states_topic.is_none(),
    }
}

/// Reads the bag at `path` for calibration: one pass, then the topic choice, then the
/// log. Errors name the file, the topic and what to do.
pub fn read_bag(path: &Path, opts: &BagOptions) -> Result<BagLog, BagError> {
    let name = path.display().to_string();
    let (format, collected) = scan_bag(path, filter_of(&opts.choice))?;
    bag_log(&name, format, &collected, &opts.choice, opts)
}

/// The log of `collected` for the topics `choice` selects: the topic choice, then
/// the log, with the scan topic's nominal pose.
fn bag_log(
    name: &str,
    format: BagFormat,
    collected: &Collected,
    choice: &TopicChoice,
    opts: &BagOptions,
) -> Result<BagLog, BagError> {
    let selection = select::select(name, collected, choice)?;
    let log = to_log::build_log(name, collected, &selection, opts.clock, &opts.read)?;
    Ok(BagLog {
        format,
        log,
        nominal_laser: nominal_laser(collected, &selection.scan_topic),
        selection,
        topics: collected.topics.clone(),
        bytes_read: collected.bytes_read,
    })
}

/// Reads the bag at `path` once for several lasers: one [`BagLog`] per topic of
/// `scan_topics`, in that order, each with the same wheel data and its own scans,
/// sweep timing and nominal pose (the other choices of `opts` apply to every one;
/// its `scan_topic` is ignored). One pass over the bag decodes every scan topic.
pub fn read_bag_lasers(
    path: &Path,
    opts: &BagOptions,
    scan_topics: &[String],
) -> Result<Vec<BagLog>, BagError> {
    let name = path.display().to_string();
    let choice = TopicChoice {
        scan_topic: None,
        ..opts.choice.clone()
    };
    let (format, collected) = scan_bag(path, filter_of(&choice))?;
    scan_topics
        .iter()
        .map(|topic| {
            let choice = TopicChoice {
                scan_topic: Some(topic.clone()),
                ..choice.clone()
            };
            bag_log(&name, format, &collected, &choice, opts)
        })
        .collect()
}

/// The nominal pose of the laser of `scan_topic` from the static transforms.
fn nominal_laser(c: &Collected, scan_topic: &str) -> Option<NominalLaser> {
    let frame = c
        .topic_index(scan_topic)
        .and_then(|i| c.scans.get(&i))
        .and_then(|s| s.frame_id.as_deref())?;
    let mut tree = c.tf.clone();
    tree.add_described(c.described.clone());
    tree.nominal_laser(frame)
}

/// The laser geometry of a scan topic as its first message declares it.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct LaserInfo {
    /// The topic.
    pub topic: String,
    /// Rays per scan.
    pub rays: usize,
    /// The first message's fields.
    pub fields: ScanFieldsInfo,
}

/// [`ScanFields`] in the units a reader expects (rad, s, m).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ScanFieldsInfo {
    /// Angle of the first ray (rad).
    pub angle_min: f64,
    /// Angle of the last ray (rad).
    pub angle_max: f64,
    /// Angle between rays (rad; negative: clockwise).
    pub angle_increment: f64,
    /// Time between rays (s).
    pub time_increment: f64,
    /// Time between scans (s).
    pub scan_time: f64,
    /// Minimum valid range (m).
    pub range_min: f64,
    /// Maximum valid range (m).
    pub range_max: f64,
}

/// What `odocal info` tells about a bag.
#[derive(Debug)]
pub struct BagInfo {
    /// The container format.
    pub format: BagFormat,
    /// Every topic.
    pub topics: Vec<TopicStats>,
    /// Geometry of every LaserScan topic with messages.
    pub lasers: Vec<LaserInfo>,
    /// Joint names of every JointState topic with messages.
    pub joints: Vec<(String, Vec<String>)>,
    /// What `calibrate` would use (or why it cannot decide), and the log it would read.
    pub calibration: Result<(Selection, Log), BagError>,
    /// The chosen laser's pose in the base frame from the static transforms.
    pub nominal_laser: Option<NominalLaser>,
    /// Bytes of bag files read.
    pub bytes_read: u64,
    /// Notes from reading.
    pub warnings: Vec<String>,
}

/// Describes the bag at `path`: topics, laser geometries, joint names, and what
/// calibration would use with `opts`.
pub fn inspect_bag(path: &Path, opts: &BagOptions) -> Result<BagInfo, BagError> {
    let name = path.display().to_string();
    let (format, c) = scan_bag(path, filter_of(&opts.choice))?;
    let mut lasers = Vec::new();
    let mut joints = Vec::new();
    for (i, t) in c.topics.iter().enumerate() {
        if let Some(first) = c.scans.get(&i).and_then(|s| s.records.first()) {
            let f = &first.fields;
            lasers.push(LaserInfo {
                topic: t.name.clone(),
                rays: first.len,
                fields: ScanFieldsInfo {
                    angle_min: f.angle_min as f64,
                    angle_max: f.angle_max as f64,
                    angle_increment: f.angle_increment as f64,
                    time_increment: f.time_increment as f64,
                    scan_time: f.scan_time as f64,
                    range_min: f.range_min as f64,
                    range_max: f.range_max as f64,
                },
            });
        }
        if let Some(j) = c.joints.get(&i) {
            joints.push((t.name.clone(), j.names.clone()));
        }
    }
    let calibration = select::select(&name, &c, &opts.choice).and_then(|sel| {
        let log = to_log::build_log(&name, &c, &sel, opts.clock, &opts.read)?;
        Ok((sel, log))
    });
    let nominal_laser = calibration
        .as_ref()
        .ok()
        .and_then(|(sel, _)| nominal_laser(&c, &sel.scan_topic));
    Ok(BagInfo {
        format,
        nominal_laser,
        topics: c.topics.clone(),
        lasers,
        joints,
        calibration,
        bytes_read: c.bytes_read,
        warnings: c.warnings.clone(),
    })
}
