//! The partial-calibration options `calibrate` and `solve` share: parameters held at
//! known values (`--fix`), Gaussian priors (`--prior`) and `--accept-weak`.

use anyhow::Context;
use odocal_solver::{parse_fix, parse_prior, Constraints};

/// `--fix`, `--prior` and `--accept-weak`.
#[derive(clap::Args, Debug, Default)]
pub struct PartialArgs {
    /// Hold a parameter at a known value and solve the others: NAME=VALUE with NAME
    /// one of r_L, r_R, b, l_x, l_y, l_theta (SI units: m, rad). Repeatable.
    #[arg(long = "fix", value_name = "NAME=VALUE", allow_hyphen_values = true)]
    pub fix: Vec<String>,
    /// Give a parameter a Gaussian prior: NAME=VALUE±SIGMA (or NAME=VALUE+-SIGMA;
    /// SI units). Repeatable.
    #[arg(
        long = "prior",
        value_name = "NAME=VALUE±SIGMA",
        allow_hyphen_values = true
    )]
    pub prior: Vec<String>,
    /// Print the numbers even when some parameters are weakly determined or not
    /// excited (their verdicts say so).
    #[arg(long)]
    pub accept_weak: bool,
}

impl PartialArgs {
    /// The constraints of `--fix` and `--prior`.
    pub fn constraints(&self) -> anyhow::Result<Constraints> {
        let mut c = Constraints::default();
        for text in &self.fix {
            let (name, held) = parse_fix(text).context("--fix")?;
            c.set(&name, held).context("--fix")?;
        }
        for text in &self.prior {
            let (name, prior) = parse_prior(text).context("--prior")?;
            c.set(&name, prior).context("--prior")?;
        }
        Ok(c)
    }
}

/// A refusal that proposes parameters to hold, with the exact command to run: this
/// command's own arguments and the `--fix` flags (`MEASURED` where the value must be
/// measured). Other errors unchanged.
pub fn with_hold_command(e: odocal_pipeline::PipelineError) -> anyhow::Error {
    let holds = e.holds();
    if holds.is_empty() {
        return e.into();
    }
    let mut words: Vec<String> = vec!["odocal".into()];
    words.extend(std::env::args().skip(1).map(|a| shell_word(&a)));
    words.extend(holds.iter().map(|h| h.argument()));
    HoldRefusal {
        measure: holds.iter().any(|h| h.value.is_none()),
        command: words.join(" "),
        refusal: e,
    }
    .into()
}

/// A refusal and the command that calibrates the other parameters with some held.
#[derive(Debug)]
pub struct HoldRefusal {
    /// The pipeline's refusal.
    pub refusal: odocal_pipeline::PipelineError,
    /// The command line to run.
    pub command: String,
    /// Some held value must be measured (`MEASURED` stands in the command).
    pub measure: bool,
}

impl std::fmt::Display for HoldRefusal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let measure = if self.measure {
            " (put the measured value in place of MEASURED)"
        } else {
            ""
        };
        write!(
            f,
            "{}\nto calibrate the other parameters, run{measure}:\n  {}",
            self.refusal, self.command
        )
    }
}

impl std::error::Error for HoldRefusal {}

/// An argument as a POSIX shell word (quoted when it holds anything but plain characters).
pub fn shell_word(a: &str) -> String {
    let plain = !a.is_empty()
        && a.chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_./=,:+@%".contains(c));
    if plain {
        a.to_string()
    } else {
        format!("'{}'", a.replace('\'', "'\\''"))
    }
}
