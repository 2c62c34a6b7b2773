//! The arguments of every command that reads a log: the file and how to read it.
//! `calibrate`, `match` and `info` flatten this one struct, so each reading option
//! exists on every such command. The input is a Carmen/JSON log or a ROS bag (ROS 1
//! `.bag`, ROS 2 directory, `.mcap`, `.db3`), told apart by content.

use crate::hashing_thread::Checksum;
use crate::open_input::{is_bag_file, read_text_log};
use crate::terminal::errln;
use odocal_bag::{read_bag, read_bag_lasers, BagOptions, Clock, NominalLaser, TopicChoice};
use odocal_log::{Log, Mode, ReadOptions};
use std::path::PathBuf;

/// The input log and the options of reading it.
#[derive(clap::Args, Debug, Clone)]
pub struct ReadArgs {
    /// The log: Carmen-style text, the original package's JSON log, or a ROS bag (ROS 1
    /// .bag, ROS 2 bag directory or its metadata.yaml, .mcap or .db3). A text log may be
    /// a pipe or FIFO, or `-` for standard input; a bag must be a file or directory.
    #[arg(value_parser = log_path)]
    pub log: PathBuf,
    /// Bag: the sensor_msgs/LaserScan topic (default: the only one). Repeat it for a
    /// robot with several lasers (`calibrate` and `match`): each topic is one laser
    /// with its own ℓ, sweep timing and clock offset; the wheels are shared.
    #[arg(long, value_name = "TOPIC")]
    pub scan_topic: Vec<String>,
    /// Bag: the sensor_msgs/JointState topic with the wheel joints (default: the only one).
    #[arg(long, value_name = "TOPIC")]
    pub joint_states_topic: Option<String>,
    /// Bag: the nav_msgs/Odometry topic; selects the odometry-only mode (needs --nominal).
    #[arg(long, value_name = "TOPIC")]
    pub odom_topic: Option<String>,
    /// Bag: the left and right wheel joint names (default: the only joints named like a
    /// left and a right wheel). `LEFT,RIGHT` or `LEFT RIGHT`.
    #[arg(long, value_name = "LEFT,RIGHT", value_delimiter = ',', num_args = 1..=2)]
    pub wheel_joints: Option<Vec<String>>,
    /// Bag: stamp messages with the bag's record time instead of their header stamp.
    #[arg(long)]
    pub use_receive_time: bool,
    /// Encoder ticks per wheel revolution (overrides the log's PARAM).
    #[arg(long, value_name = "X")]
    pub ticks_per_rev: Option<f64>,
    /// Encoder counter modulus, e.g. 65536 (overrides the log's PARAM).
    #[arg(long, value_name = "M")]
    pub encoder_modulus: Option<f64>,
    /// Minimum valid range in metres (overrides the log's PARAM).
    #[arg(long, value_name = "METRES")]
    pub min_range: Option<f64>,
    /// Seconds between two consecutive rays of a scan, the sweep (overrides the log's
    /// PARAM laser_front_laser_time_increment); ray 0 is taken at the scan's timestamp.
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub time_increment: Option<f64>,
    /// Skip malformed lines (counted and reported) instead of stopping at the first.
    #[arg(long)]
    pub lenient: bool,
    /// Compute a text log's SHA-256 while reading it (for the provenance that
    /// `calibrate` records in its outputs); not a command-line option.
    #[arg(skip)]
    pub checksum: bool,
}

impl ReadArgs {
    /// The reader options these arguments ask for.
    pub fn read_options(&self) -> ReadOptions {
        ReadOptions {
            mode: if self.lenient {
                Mode::Lenient
            } else {
                Mode::Strict
            },
            ticks_per_revolution: self.ticks_per_rev,
            encoder_modulus: self.encoder_modulus,
            min_range: self.min_range,
            time_increment: self.time_increment,
        }
    }

    /// The bag reading options these arguments ask for; an error when `--wheel-joints`
    /// does not name exactly two joints.
    pub fn bag_options(&self) -> anyhow::Result<BagOptions> {
        Ok(BagOptions {
            choice: TopicChoice {
                scan_topic: self.scan_topic.first().cloned(),
                joint_states_topic: self.joint_states_topic.clone(),
                odom_topic: self.odom_topic.clone(),
                wheel_joints: self.wheel_joints()?,
            },
            clock: if self.use_receive_time {
                Clock::Receive
            } else {
                Clock::Header
            },
            read: self.read_options(),
        })
    }

    /// The two joints of `--wheel-joints` (left, right), or an error naming what was given.
    fn wheel_joints(&self) -> anyhow::Result<Option<(String, String)>> {
        match self.wheel_joints.as_deref() {
            None => Ok(None),
            Some([left, right]) if !left.is_empty() && !right.is_empty() => {
                Ok(Some((left.clone(), right.clone())))
            }
            Some(given) => anyhow::bail!(
                "--wheel-joints takes two joint names, the left and the right wheel's: \
                 `--wheel-joints LEFT,RIGHT` (e.g. --wheel-joints \
                 wheel_left_joint,wheel_right_joint); got {} value(s): {:?}",
                given.len(),
                given
            ),
        }
    }

    /// True when the input is a ROS bag (by content) in a file or directory.
    pub fn is_bag(&self) -> anyhow::Result<bool> {
        is_bag_file(&self.log)
    }

    /// Reads the log or bag, strict unless `--lenient`, with the command-line overrides.
    /// For a bag, what was chosen and why goes to stderr.
    pub fn read_log(&self) -> anyhow::Result<Log> {
        Ok(self.read_input()?.log)
    }

    /// [`ReadArgs::read_log`], with what the same single read tells besides the log:
    /// the SHA-256 and size of a text log, the nominal laser pose of a bag's static
    /// transforms.
    pub fn read_input(&self) -> anyhow::Result<ReadInput> {
        if self.is_bag()? {
            if self.ticks_per_rev.is_some() || self.encoder_modulus.is_some() {
                anyhow::bail!(
                    "{}: --ticks-per-rev and --encoder-modulus apply to Carmen logs; a bag's \
                     wheel joints are read in radians",
                    self.log.display()
                );
            }
            if self.scan_topic.len() > 1 {
                anyhow::bail!(
                    "{}: several --scan-topic ({}) are read by `odocal calibrate` and \
                     `odocal match`, one laser each; here give one",
                    self.log.display(),
                    self.scan_topic.join(", ")
                );
            }
            let bag =
                read_bag(&self.log, &self.bag_options()?).map_err(|e| anyhow::anyhow!("{e}"))?;
            for r in &bag.selection.reasons {
                errln!("{r}");
            }
            // What `info` notes about the bag (skipped messages, no index, …).
            for w in &bag.log.stats.warnings {
                errln!("warning: {w}");
            }
            return Ok(ReadInput {
                heading_sources: Some(odocal_bag::heading_sources(&bag.topics)),
                log: bag.log,
                checksum: None,
                nominal_laser: bag.nominal_laser,
                scan_topic: Some(bag.selection.scan_topic),
            });
        }
        let bag_flags = !self.scan_topic.is_empty()
            || self.joint_states_topic.is_some()
            || self.odom_topic.is_some()
            || self.wheel_joints.is_some()
            || self.use_receive_time;
        if bag_flags {
            anyhow::bail!(
                "{}: --scan-topic, --joint-states-topic, --odom-topic, --wheel-joints and \
                 --use-receive-time apply to ROS bags; this file is not one",
                self.log.display()
            );
        }
        let (log, checksum) = read_text_log(&self.log, &self.read_options(), self.checksum)?;
        Ok(ReadInput {
            log,
            checksum,
            nominal_laser: None,
            heading_sources: None,
            scan_topic: None,
        })
    }

    /// [`ReadArgs::read_input`] once per laser: with several `--scan-topic` and a bag,
    /// one input per topic from one read of the bag (in the order given); else the one
    /// input.
    pub fn read_input_lasers(&self) -> anyhow::Result<Vec<ReadInput>> {
        if self.scan_topic.len() < 2 || !self.is_bag()? {
            return Ok(vec![self.read_input()?]);
        }
        if self.ticks_per_rev.is_some() || self.encoder_modulus.is_some() {
            return self.read_input().map(|i| vec![i]);
        }
        let bags = read_bag_lasers(&self.log, &self.bag_options()?, &self.scan_topic)
            .map_err(|e| anyhow::anyhow!("{e}"))?;
        if let Some(first) = bags.first() {
            for w in &first.log.stats.warnings {
                errln!("warning: {w}");
            }
        }
        Ok(bags
            .into_iter()
            .map(|bag| {
                for r in &bag.selection.reasons {
                    errln!("{r}");
                }
                ReadInput {
                    heading_sources: Some(odocal_bag::heading_sources(&bag.topics)),
                    log: bag.log,
                    checksum: None,
                    nominal_laser: bag.nominal_laser,
                    scan_topic: Some(bag.selection.scan_topic),
                }
            })
            .collect())
    }
}

/// What [`ReadArgs::read_input`] read.
pub struct ReadInput {
    /// The log (a bag's messages in the log model).
    pub log: Log,
    /// SHA-256 (hex) and size of a text log, computed on the one pass that read it
    /// when [`ReadArgs::checksum`] asks for it (`None` for a bag: see
    /// `sha256_of_input`).
    pub checksum: Option<Checksum>,
    /// The laser's pose from a bag's static transforms, when it has them.
    pub nominal_laser: Option<NominalLaser>,
    /// A bag's joint-state and IMU topics (for the odometry-only heading refusal).
    pub heading_sources: Option<odocal_bag::HeadingSources>,
    /// A bag's scan topic (`None` for a text log).
    pub scan_topic: Option<String>,
}

/// The input path as given, except that a ROS 2 bag's `metadata.yaml` stands for its
/// bag directory (the bag is the directory, not the YAML file).
fn log_path(arg: &str) -> Result<PathBuf, String> {
    let path = PathBuf::from(arg);
    let is_metadata = path.file_name().is_some_and(|n| n == "metadata.yaml");
    match path.parent() {
        Some(dir) if is_metadata && path.is_file() => Ok(if dir.as_os_str().is_empty() {
            PathBuf::from(".")
        } else {
            dir.to_path_buf()
        }),
        _ => Ok(path),
    }
}
