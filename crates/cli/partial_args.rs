//! The partial-calibration options `calibrate` and `solve` share: parameters held at
//! known values (`--fix`), Gaussian priors (`--prior`) and `--accept-weak`.

use anyhow::Context;
use odocal_solver::{parse_fix, parse_prior, Constraint, Constraints};

/// `--fix`, `--prior` and `--accept-weak`.
#[derive(clap::Args, Debug, Default)]
pub struct PartialArgs {
    /// Hold a parameter at a known value and solve the others: NAME=VALUE with NAME
    /// one of r_L, r_R, b, l_x, l_y, l_theta (SI units: m, rad). Repeatable. With
    /// several lasers (`calibrate`), l_x@K=VALUE names laser K's (from 1, in the order
    /// of the --scan-topic or of the logs' own lasers); l_x alone is laser 1's.
    #[arg(long = "fix", value_name = "NAME=VALUE", allow_hyphen_values = true)]
    pub fix: Vec<String>,
    /// Give a parameter a Gaussian prior: NAME=VALUE±SIGMA (or NAME=VALUE+-SIGMA;
    /// SI units). Repeatable. l_x@K=VALUE±SIGMA: laser K's, as with --fix.
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

/// Held parameters and priors of a calibration with one or several lasers.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LaserConstraints {
    /// The wheels' and the first laser's.
    pub shared: Constraints,
    /// Per laser after the first (`more[0]`: laser 2's), its (ℓx, ℓy, ℓθ); lasers
    /// beyond the vector are free.
    pub more: Vec<[Constraint; 3]>,
}

impl PartialArgs {
    /// The constraints of `--fix` and `--prior` for one laser; `NAME@K` (another
    /// laser's) is an error that says where it applies.
    pub fn constraints(&self) -> anyhow::Result<Constraints> {
        let all = self.laser_constraints()?;
        if let Some(k) = all
            .more
            .iter()
            .position(|c| c.iter().any(|c| *c != Constraint::Free))
        {
            anyhow::bail!(
                "--fix/--prior NAME@{}: a laser number names one of several lasers of \
                 `odocal calibrate` (repeated --scan-topic, or --own-laser); here there is \
                 one laser: drop the @{}",
                k + 2,
                k + 2
            );
        }
        Ok(all.shared)
    }

    /// The constraints of `--fix` and `--prior` with laser numbers: `NAME@K=…` (K
    /// from 1) puts laser K's ℓ parameter, `NAME=…` and `NAME@1=…` the wheels' or
    /// the first laser's.
    pub fn laser_constraints(&self) -> anyhow::Result<LaserConstraints> {
        let mut all = LaserConstraints::default();
        for (flag, texts) in [("--fix", &self.fix), ("--prior", &self.prior)] {
            for text in texts {
                let (laser, plain) = split_laser(text).context(flag)?;
                let (name, constraint) = if flag == "--fix" {
                    parse_fix(&plain)
                } else {
                    parse_prior(&plain)
                }
                .context(flag)?;
                if laser <= 1 {
                    all.shared.set(&name, constraint).context(flag)?;
                    continue;
                }
                let i = odocal_solver::parameter_index(&name).unwrap_or(0);
                if i < 3 {
                    anyhow::bail!(
                        "{flag} '{text}': the wheels are shared by every laser; give \
                         {name} without @{laser}"
                    );
                }
                if all.more.len() < laser - 1 {
                    all.more.resize(laser - 1, [Constraint::Free; 3]);
                }
                let slot = &mut all.more[laser - 2][i - 3];
                if *slot != Constraint::Free {
                    anyhow::bail!("{flag} '{text}': {name} of laser {laser} is held or given a prior more than once");
                }
                *slot = constraint;
            }
        }
        Ok(all)
    }
}

/// `NAME@K=REST` as `(K, "NAME=REST")`; `(0, text)` without `@K`. K is a laser's
/// number from 1.
fn split_laser(text: &str) -> anyhow::Result<(usize, String)> {
    let Some((name, rest)) = text.split_once('=') else {
        return Ok((0, text.to_string()));
    };
    let Some((base, laser)) = name.split_once('@') else {
        return Ok((0, text.to_string()));
    };
    match laser.trim().parse::<usize>() {
        Ok(k) if k >= 1 => Ok((k, format!("{base}={rest}"))),
        _ => anyhow::bail!(
            "'{text}': after @ comes the laser's number from 1 (e.g. l_x@2=-0.12 holds \
             laser 2's ℓx), got '{laser}'"
        ),
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
    // Paired one scan in `stride`: every pair the log holds may determine the
    // parameters without holding any (the real MinesRover logs, driven forward only,
    // do; docs/benchmarks.md, stop 43).
    let stride = e.stride();
    let all_pairs = (stride > 1
        && stride <= odocal_pipeline::phases::MAX_PHASES
        && !words.iter().any(|w| w == "--all-pairs"))
    .then(|| format!("{} --all-pairs", words.join(" ")));
    words.extend(holds.iter().map(|h| h.argument()));
    HoldRefusal {
        measure: holds.iter().any(|h| h.value.is_none()),
        command: words.join(" "),
        all_pairs: all_pairs.map(|command| (stride, command)),
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
    /// With scans paired one in a stride above 1: the stride and the command that
    /// uses every scan pair the log holds instead of holding parameters.
    pub all_pairs: Option<(usize, String)>,
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
        )?;
        if let Some((stride, command)) = &self.all_pairs {
            write!(
                f,
                "\nor first, to use every scan pair the log holds (the scans {stride} apart \
                 from every scan, not one in {stride}: {stride}× the matching), which may \
                 determine them all without holding any, run:\n  {command}"
            )?;
        }
        Ok(())
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
