//! Placeholder: this subcommand is being written (owned by the helper named in the
//! project plan); it must be replaced before submission.

/// Arguments.
#[derive(clap::Args, Debug)]
pub struct Args {}

/// Runs the subcommand.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("not implemented yet")
}
