//! The checks on `--report`, `--out` and `match --out` made before any work, so a run
//! that could not write its results fails in a second, not after the calibration: an
//! output is never the input (by device and inode, whatever the name), and never
//! something other than what it replaces (a device, a directory where a file is
//! expected, a directory of other files).

use anyhow::Context;
use odocal_pipeline::{check_replaceable_dir, check_replaceable_file, InputFiles};
use odocal_report::is_output_name;
use std::path::Path;

/// Fails when the file `output` may not be written for a run reading `input`.
pub fn check_file_output(output: &Path, input: &Path) -> anyhow::Result<()> {
    input_files(input)?.refuse_as_output_file(output, input)?;
    check_replaceable_file(output)?;
    Ok(())
}

/// Fails when the results directory `output` may not be written for a run reading
/// `input`.
pub fn check_dir_output(output: &Path, input: &Path) -> anyhow::Result<()> {
    input_files(input)?.refuse_as_output_dir(output, input)?;
    check_replaceable_dir(output, &is_output_name)?;
    Ok(())
}

/// The input's files.
fn input_files(input: &Path) -> anyhow::Result<InputFiles> {
    InputFiles::of(input).with_context(|| format!("cannot look at the input {}", input.display()))
}
