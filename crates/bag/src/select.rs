//! Choosing what to calibrate from: the laser topic, the wheel source (joint states
//! with their two wheel joints, or odometry), automatically when unambiguous, else
//! from the command-line flags. Every refusal lists the candidates and the flag.

use crate::collect::{Collected, JointTopic, TopicStats};
use crate::error::BagError;
use crate::messages::MessageKind;

/// The choices the user made on the command line (all optional).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TopicChoice {
    /// `--scan-topic`.
    pub scan_topic: Option<String>,
    /// `--joint-states-topic`.
    pub joint_states_topic: Option<String>,
    /// `--odom-topic` (odometry-only mode).
    pub odom_topic: Option<String>,
    /// `--wheel-joints LEFT,RIGHT`.
    pub wheel_joints: Option<(String, String)>,
}

/// Where the wheel rotations come from.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[serde(tag = "source", rename_all = "snake_case")]
pub enum WheelSource {
    /// Two joints of a JointState topic.
    JointStates {
        /// The topic.
        topic: String,
        /// The left wheel joint.
        left: String,
        /// The right wheel joint.
        right: String,
        /// True when positions were empty and velocities were integrated.
        integrated_velocities: bool,
    },
    /// Poses of an Odometry topic (odometry-only mode: needs the nominal parameters).
    Odometry {
        /// The topic.
        topic: String,
    },
}

/// What `calibrate` uses from a bag, and why.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Selection {
    /// The LaserScan topic.
    pub scan_topic: String,
    /// The wheels.
    pub wheels: WheelSource,
    /// One sentence per choice: why this topic or joint.
    pub reasons: Vec<String>,
}

/// `  /scan  sensor_msgs/LaserScan  600 messages  10.0 Hz` for each topic.
pub(crate) fn topic_lines<'a>(topics: impl Iterator<Item = &'a TopicStats>) -> String {
    let mut s = String::new();
    for t in topics {
        let rate = match t.rate_hz() {
            Some(r) => format!("{r:.1} Hz"),
            None => "-".into(),
        };
        s += &format!(
            "\n  {}  {}  {} messages  {rate}",
            t.name, t.type_name, t.count
        );
    }
    s
}

fn of_kind(c: &Collected, kind: MessageKind) -> impl Iterator<Item = &TopicStats> {
    c.topics.iter().filter(move |t| t.kind == kind)
}

fn listing(c: &Collected, kind: MessageKind) -> String {
    if of_kind(c, kind).next().is_none() {
        format!(
            "the bag has no {} topic; its topics are:{}",
            kind.type_name(),
            if c.topics.is_empty() {
                "\n  (none)".to_string()
            } else {
                topic_lines(c.topics.iter())
            }
        )
    } else {
        format!(
            "{} topics in the bag:{}",
            kind.type_name(),
            topic_lines(of_kind(c, kind))
        )
    }
}

/// The topic of `kind` to use: the one named by `flag` (checked), else the only one
/// with messages. `Ok(None)` when there is none.
pub(crate) fn choose_topic(
    file: &str,
    c: &Collected,
    kind: MessageKind,
    flag: &str,
    given: Option<&str>,
) -> Result<Option<usize>, BagError> {
    if let Some(name) = given {
        let Some(i) = c.topic_index(name) else {
            return Err(BagError::choice(
                file,
                format!(
                    "{flag} {name}: no such topic; {}\nchoose one with {flag} TOPIC",
                    listing(c, kind)
                ),
            ));
        };
        let t = &c.topics[i];
        if t.kind != kind {
            return Err(BagError::choice(
                file,
                format!(
                    "{flag} {name}: the topic has type {}, {flag} needs {}; {}\nchoose one with \
                     {flag} TOPIC",
                    t.type_name,
                    kind.type_name(),
                    listing(c, kind)
                ),
            ));
        }
        if t.count == 0 {
            return Err(BagError::choice(
                file,
                format!(
                    "{flag} {name}: the topic has 0 messages in this bag; {}\nchoose one with \
                     messages with {flag} TOPIC, or check that the recording captured it",
                    listing(c, kind)
                ),
            ));
        }
        return Ok(Some(i));
    }
    let with_messages: Vec<usize> = (0..c.topics.len())
        .filter(|&i| c.topics[i].kind == kind && c.topics[i].count > 0)
        .collect();
    match with_messages.as_slice() {
        [] => Ok(None),
        [i] => Ok(Some(*i)),
        _ => Err(BagError::choice(
            file,
            format!(
                "several {} topics; {}\nchoose one with {flag} TOPIC",
                kind.type_name(),
                listing(c, kind)
            ),
        )),
    }
}

/// The two wheel joints of a JointState topic.
enum Wheels {
    Pair(String, String),
    /// No joint looks like a wheel.
    None,
    /// Wheel-like joints that cannot be paired: the explanation.
    Ambiguous(String),
}

fn wheel_joints(topic: &JointTopic, given: Option<&(String, String)>) -> Wheels {
    let names = &topic.names;
    if let Some((l, r)) = given {
        let missing: Vec<&str> = [l, r]
            .into_iter()
            .filter(|n| topic.joint(n).is_none())
            .map(|s| s.as_str())
            .collect();
        if missing.is_empty() {
            return Wheels::Pair(l.clone(), r.clone());
        }
        return Wheels::Ambiguous(format!(
            "--wheel-joints names {} which the topic does not have; its joints: {}",
            missing.join(", "),
            names.join(", ")
        ));
    }
    let side = |s: &str| -> Vec<&String> {
        names
            .iter()
            .filter(|n| {
                let n = n.to_lowercase();
                n.contains(s) && n.contains("wheel")
            })
            .collect()
    };
    let (lefts, rights) = (side("left"), side("right"));
    match (lefts.as_slice(), rights.as_slice()) {
        ([], []) => Wheels::None,
        ([l], [r]) => Wheels::Pair((*l).clone(), (*r).clone()),
        _ => Wheels::Ambiguous(format!(
            "cannot tell the two drive wheels apart: {} left and {} right wheel joint(s) among \
             the joints {}; choose them with --wheel-joints LEFT,RIGHT",
            lefts.len(),
            rights.len(),
            names.join(", ")
        )),
    }
}

/// True when the wheel messages of `topic` carry no positions but velocities.
fn velocities_only(topic: &JointTopic, left: u32) -> bool {
    let mut any = false;
    for rec in &topic.records {
        if let Some(v) = rec.values.iter().find(|v| v.joint == left) {
            if v.position.is_finite() {
                return false;
            }
            any |= v.velocity.is_finite();
        }
    }
    any
}

/// Chooses the scan topic and the wheel source.
pub(crate) fn select(
    file: &str,
    c: &Collected,
    choice: &TopicChoice,
) -> Result<Selection, BagError> {
    let mut reasons = Vec::new();
    let scan = choose_topic(
        file,
        c,
        MessageKind::LaserScan,
        "--scan-topic",
        choice.scan_topic.as_deref(),
    )?;
    let Some(scan) = scan else {
        return Err(BagError::choice(
            file,
            format!(
                "no laser scans: {}\ncalibration needs sensor_msgs/LaserScan messages \
                 (choose the topic with --scan-topic)",
                listing(c, MessageKind::LaserScan)
            ),
        ));
    };
    let scan_topic = c.topics[scan].name.clone();
    reasons.push(if choice.scan_topic.is_some() {
        format!("laser: {scan_topic} (--scan-topic)")
    } else {
        format!("laser: {scan_topic}, the only LaserScan topic with messages")
    });

    let odometry = |reasons: &mut Vec<String>, why: &str| -> Result<WheelSource, BagError> {
        let odom = choose_topic(
            file,
            c,
            MessageKind::Odometry,
            "--odom-topic",
            choice.odom_topic.as_deref(),
        )?;
        match odom {
            Some(i) => {
                let topic = c.topics[i].name.clone();
                reasons.push(format!("wheels: odometry-only mode from {topic} ({why})"));
                Ok(WheelSource::Odometry { topic })
            }
            None => Err(BagError::choice(
                file,
                format!(
                    "laser scans on {scan_topic} but no wheel data: no sensor_msgs/JointState \
                     with wheel joints and no nav_msgs/Odometry with messages; its topics \
                     are:{}\nrecord the wheel joint states (/joint_states) or the odometry \
                     (/odom) with the scans, or name them with --joint-states-topic / \
                     --odom-topic",
                    topic_lines(c.topics.iter())
                ),
            )),
        }
    };

    if choice.odom_topic.is_some() {
        let wheels = odometry(&mut reasons, "--odom-topic")?;
        return Ok(Selection {
            scan_topic,
            wheels,
            reasons,
        });
    }
    let joints_flag = "--joint-states-topic";
    let candidates: Vec<usize> = match choice.joint_states_topic.as_deref() {
        Some(name) => choose_topic(file, c, MessageKind::JointState, joints_flag, Some(name))?
            .into_iter()
            .collect(),
        None => (0..c.topics.len())
            .filter(|&i| c.topics[i].kind == MessageKind::JointState && c.topics[i].count > 0)
            .collect(),
    };
    let mut usable = Vec::new();
    let mut problems = Vec::new();
    for &i in &candidates {
        let Some(topic) = c.joints.get(&i) else {
            continue;
        };
        match wheel_joints(topic, choice.wheel_joints.as_ref()) {
            Wheels::Pair(l, r) => usable.push((i, l, r)),
            Wheels::Ambiguous(why) => problems.push(format!("{}: {why}", c.topics[i].name)),
            Wheels::None => {
                if choice.joint_states_topic.is_some() {
                    problems.push(format!(
                        "{}: no joint named like a left and a right wheel among {}; choose them \
                         with --wheel-joints LEFT,RIGHT",
                        c.topics[i].name,
                        topic.names.join(", ")
                    ));
                }
            }
        }
    }
    match usable.as_slice() {
        [(i, l, r)] => {
            let topic = c.topics[*i].name.clone();
            let joints = &c.joints[i];
            let integrated = joints
                .joint(l)
                .is_some_and(|left| velocities_only(joints, left));
            reasons.push(format!(
                "wheels: joints {l} (left) and {r} (right) of {topic}{}{}",
                if choice.wheel_joints.is_some() {
                    " (--wheel-joints)"
                } else {
                    ", the only left and right wheel joints"
                },
                if integrated {
                    "; the messages carry no positions: wheel velocities are integrated \
                     (trapezoid rule)"
                } else {
                    ""
                }
            ));
            Ok(Selection {
                scan_topic,
                wheels: WheelSource::JointStates {
                    topic,
                    left: l.clone(),
                    right: r.clone(),
                    integrated_velocities: integrated,
                },
                reasons,
            })
        }
        [] if problems.is_empty() => {
            let wheels = odometry(&mut reasons, "no wheel joint states in the bag")?;
            Ok(Selection {
                scan_topic,
                wheels,
                reasons,
            })
        }
        [] => Err(BagError::choice(file, problems.join("\n"))),
        _ => Err(BagError::choice(
            file,
            format!(
                "several JointState topics have wheel joints:{}\nchoose one with {joints_flag} \
                 TOPIC",
                topic_lines(usable.iter().map(|(i, _, _)| &c.topics[*i]))
            ),
        )),
    }
}
