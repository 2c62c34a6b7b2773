//! From a raw log to calibrated parameters: synchronization of encoders and scans,
//! parallel scan matching, solving, and the report.

#![deny(missing_docs)]

pub mod sync;
