//! The refusal of odometry-only mode on odometry whose heading is not the wheels'
//! (see `odocal_pipeline::health::gyro_heading`), with the way out the bag offers:
//! its wheel joint states (that mode does not use the odometry), named as the exact
//! command to run; its IMU topics are named as what likely gave the heading.

use crate::partial_args::shell_word;
use odocal_bag::HeadingSources;
use odocal_pipeline::health::gyro_heading::CAUSE;
use odocal_pipeline::PipelineError;

/// A gyro-heading refusal and what the bag offers instead.
#[derive(Debug)]
pub struct HeadingRefusal {
    /// The pipeline's refusal.
    pub refusal: PipelineError,
    /// The IMU topics of the bag.
    pub imu: Vec<String>,
    /// The command that calibrates from the bag's wheel joint states, when it has them.
    pub command: Option<String>,
}

impl std::fmt::Display for HeadingRefusal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.refusal)?;
        if !self.imu.is_empty() {
            write!(
                f,
                "\nthe bag has IMU data ({}): the robot's driver likely integrated the \
                 odometry's heading from it",
                self.imu.join(", ")
            )?;
        }
        if let Some(command) = &self.command {
            write!(
                f,
                "\nthe bag records the wheel joint states: calibrate from them (add \
                 --wheel-joints LEFT,RIGHT if odocal cannot tell the wheel joints apart):\n  \
                 {command}"
            )?;
        }
        Ok(())
    }
}

impl std::error::Error for HeadingRefusal {}

/// True when `e` refuses because the odometry's heading is not the wheels'.
fn is_heading_refusal(e: &PipelineError) -> bool {
    matches!(
        e,
        PipelineError::NotDetermined { .. } | PipelineError::DataFault { .. }
    ) && e.to_string().contains(CAUSE)
}

/// `args` (the command line after the program name) calibrating from `topic`'s wheel
/// joint states instead of the odometry: `--odom-topic` and `--accept-weak` dropped.
pub fn joint_states_command(args: &[String], topic: &str) -> String {
    let mut words: Vec<String> = vec!["odocal".into()];
    let mut skip_value = false;
    for a in args {
        if skip_value {
            skip_value = false;
            continue;
        }
        if a == "--odom-topic" {
            skip_value = true;
            continue;
        }
        if a.starts_with("--odom-topic=") || a == "--accept-weak" {
            continue;
        }
        words.push(shell_word(a));
    }
    words.push("--joint-states-topic".into());
    words.push(shell_word(topic));
    words.join(" ")
}

/// The refusal with the bag's way out when it is a gyro-heading refusal; else `e`.
pub fn with_joint_states_command(
    e: PipelineError,
    sources: Option<&HeadingSources>,
) -> Result<HeadingRefusal, PipelineError> {
    if !is_heading_refusal(&e) {
        return Err(e);
    }
    let args: Vec<String> = std::env::args().skip(1).collect();
    let sources = sources.cloned().unwrap_or_default();
    Ok(HeadingRefusal {
        refusal: e,
        command: sources
            .joint_states
            .first()
            .map(|t| joint_states_command(&args, t)),
        imu: sources.imu,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_command_swaps_the_odometry_for_the_joint_states() {
        let args: Vec<String> = [
            "calibrate",
            "my bag.bag",
            "--odom-topic",
            "/odom",
            "--nominal",
            "0.033,0.033,0.16",
            "--accept-weak",
            "--odom-topic=/x",
        ]
        .map(String::from)
        .to_vec();
        assert_eq!(
            joint_states_command(&args, "/joint_states"),
            "odocal calibrate 'my bag.bag' --nominal 0.033,0.033,0.16 --joint-states-topic \
             /joint_states"
        );
    }
}
