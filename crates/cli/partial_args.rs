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
