//! Errors of the simulator: bad configuration, unknown names, I/O.

use std::path::PathBuf;

/// Everything that can go wrong while configuring or running a simulation.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// A preset, world or trajectory name that does not exist.
    #[error("unknown {what} '{name}' (known: {known})")]
    UnknownName {
        /// What kind of name ("preset", "world", "trajectory").
        what: &'static str,
        /// The name given.
        name: String,
        /// The accepted names, comma-separated.
        known: String,
    },
    /// A configuration value outside its meaningful range.
    #[error("invalid simulation setting {field} = {value}: {expected}")]
    InvalidConfig {
        /// The setting's name (as in the configuration / command line).
        field: &'static str,
        /// The offending value, printed.
        value: String,
        /// What was expected.
        expected: &'static str,
    },
    /// The planner could not place the robot (no free space with the clearance).
    #[error("cannot place the robot in world '{world}': {reason}")]
    NoFreeSpace {
        /// The world's name.
        world: String,
        /// What was looked for.
        reason: String,
    },
    /// A Table I file that cannot be read or parsed.
    #[error("table file {path}: {message}")]
    TableFile {
        /// The file.
        path: PathBuf,
        /// What is wrong (with the row when known).
        message: String,
    },
    /// Writing the log or the ground truth failed.
    #[error("writing simulation output: {0}")]
    Io(#[from] std::io::Error),
}
