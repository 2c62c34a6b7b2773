//! A refusal under `--json`: one JSON object on stdout, so that a script reading the
//! output gets the reason instead of nothing. `{"error": the message, "kind": what
//! refused, "suggested_command": the same command with the flag the message asks
//! for}` (the last only when the message asks for one); a refusal of a log paired one
//! scan in a stride also gives `"all_pairs_command"`, the same command with
//! `--all-pairs`, which the message offers first. The exit code stays non-zero.

use crate::heading_refusal::HeadingRefusal;
use crate::partial_args::HoldRefusal;
use odocal_log::LogError;
use odocal_pipeline::PipelineError;
use serde_json::{json, Value};

/// The JSON object describing `error` for the command line `args`.
pub fn error_object(error: &anyhow::Error, args: &[String]) -> Value {
    let hold = error.chain().find_map(|e| e.downcast_ref::<HoldRefusal>());
    let heading = error
        .chain()
        .find_map(|e| e.downcast_ref::<HeadingRefusal>());
    let pipeline = error
        .chain()
        .find_map(|e| e.downcast_ref::<PipelineError>())
        .or(hold.map(|h| &h.refusal))
        .or(heading.map(|h| &h.refusal));
    // Faults named beside a refusal, not as its cause: the refusal's own kind.
    let pipeline = match pipeline {
        Some(PipelineError::AlsoFound { refusal, .. }) => Some(&**refusal),
        other => other,
    };
    let kind = match pipeline {
        Some(PipelineError::Log(_)) => "log",
        Some(PipelineError::TooFewSamples { .. }) => "too_few_samples",
        Some(PipelineError::Solve(_)) => "solve",
        Some(PipelineError::NotDetermined { .. }) => "not_determined",
        Some(PipelineError::DataFault { .. }) => "data_fault",
        // Unwrapped above; only too-few-samples refusals are wrapped.
        Some(PipelineError::AlsoFound { .. }) => "too_few_samples",
        Some(PipelineError::InvalidSetting(_)) => "invalid_setting",
        Some(PipelineError::Implausible(_)) => "implausible",
        None if error.chain().any(|e| e.is::<LogError>()) => "log",
        None if error.chain().any(|e| e.is::<std::io::Error>()) => "io",
        None => "refused",
    };
    let message = format!("{error:#}");
    let mut object = json!({ "error": message, "kind": kind });
    if let Some(h) = heading {
        // A gyro-heading refusal: calibrate from the bag's wheel joint states when it
        // has them; else no command (the message says how to record wheel-only
        // odometry; --accept-weak would only show numbers known to be wrong).
        if let Some(command) = &h.command {
            object["suggested_command"] = command.clone().into();
        }
    } else if let Some(h) = hold {
        // The refusal's own command: the parameters to hold (MEASURED to fill in).
        object["suggested_command"] = h.command.clone().into();
        if let Some((_, command)) = &h.all_pairs {
            object["all_pairs_command"] = command.clone().into();
        }
    } else if message.contains("leave out --use-receive-time")
        && args.iter().any(|a| a == "--use-receive-time")
    {
        // Timing read from when the bag recorded the messages: the way out is the
        // header stamps, not weak numbers.
        let command: Vec<&str> = args
            .iter()
            .map(String::as_str)
            .filter(|a| *a != "--use-receive-time")
            .collect();
        object["suggested_command"] = command.join(" ").into();
    } else if let Some(flag) = suggested_flag(pipeline, &message) {
        let mut command: Vec<&str> = args.iter().map(String::as_str).collect();
        command.push(flag);
        object["suggested_command"] = command.join(" ").into();
    }
    object
}

/// The flag a refusal asks the user to add, when it asks for one.
fn suggested_flag(error: Option<&PipelineError>, message: &str) -> Option<&'static str> {
    let not_determined = match error {
        Some(PipelineError::NotDetermined { .. }) => true,
        Some(PipelineError::DataFault { refusal, .. }) => {
            matches!(**refusal, PipelineError::NotDetermined { .. })
        }
        _ => false,
    };
    if not_determined {
        Some("--accept-weak")
    } else if message.contains("--nominal r_L,r_R,b") {
        Some("--nominal r_L,r_R,b")
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use odocal_pipeline::health::gyro_heading::CAUSE;

    fn heading_refusal(command: Option<&str>) -> anyhow::Error {
        HeadingRefusal {
            refusal: PipelineError::NotDetermined {
                parameters: vec!["b".into()],
                sentence: "all six parameters are well determined".into(),
                diagnosis: Box::new(odocal_pipeline::refusal::Diagnosis {
                    causes: vec![CAUSE.into()],
                    ..Default::default()
                }),
            },
            imu: Vec::new(),
            command: command.map(String::from),
        }
        .into()
    }

    #[test]
    fn a_gyro_heading_refusal_suggests_the_joint_states_or_nothing() {
        let args = ["odocal".to_string(), "calibrate".into()];
        let v = error_object(
            &heading_refusal(Some("odocal calibrate X --joint-states-topic /j")),
            &args,
        );
        assert_eq!(v["kind"], "not_determined");
        assert_eq!(
            v["suggested_command"],
            "odocal calibrate X --joint-states-topic /j"
        );
        assert!(v["error"].as_str().unwrap().contains(CAUSE));
        // Without joint states: no --accept-weak for numbers known to be wrong.
        let v = error_object(&heading_refusal(None), &args);
        assert_eq!(v["kind"], "not_determined");
        assert!(v.get("suggested_command").is_none(), "{v}");
    }
}
