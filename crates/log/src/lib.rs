//! Reading and writing robot logs for odometry/laser calibration.
//!
//! The main format is the Carmen-style text log with wheel encoder ticks described in
//! `docs/log-format.md` (PARAM, ENCODER, RAWLASER1, ROBOTLASER1, FLASER, ODOM). The
//! reader streams the file line by line, stores ranges as `f32` and keeps one angle
//! table per distinct scan geometry, so memory is about the size of the ranges.
//!
//! Also read: the original calibration package's raw JSON logs and its tuple files
//! (streams of JSON objects, several of which may share a line).
//!
//! Data flows one way: text → [`Log`] (encoder records, scans, parameters, statistics).

#![deny(missing_docs)]

mod builder;
mod carmen;
mod error;
mod json_log;
mod json_stream;
mod line_batch;
mod line_reader;
mod model;
mod number;
mod options;
mod origin;
mod printable;
mod range_prescan;
mod read;
mod summary;
mod tokens;
mod tuple;
mod wheel_angles;
mod writer;

pub use carmen::read_carmen_from;
pub use error::{LogError, MissingData};
pub use json_log::read_json_log_from;
pub use line_reader::MAX_LINE_BYTES;
pub use model::*;
pub use options::{Mode, ReadOptions};
pub use origin::{BagClock, Origin, Stream};
pub use printable::{json_text, needs_escape, printable, terminal_text};
pub use read::{detect_format, read_log, read_log_from, LogFormat};
pub use summary::{sensor_value, GeometrySummary, LogSummary, SkippedLine};
pub use tokens::MAX_COUNT;
pub use tuple::{read_tuples, read_tuples_from, write_tuple, TupleRecord};
pub use wheel_angles::{
    encoders_from_odometry, ticks_of_angle, wheel_rotations, NominalWheels,
    WHEEL_TICKS_PER_REVOLUTION,
};
pub use writer::{write_log, LogWriter, RobotLaserPoses};
