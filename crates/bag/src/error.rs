//! Errors of the bag reader: each names the file, where in it (byte offset or topic),
//! what was wrong, and what to do.

use crate::wire::WireError;

/// What can go wrong reading a bag.
#[derive(Debug, thiserror::Error)]
pub enum BagError {
    /// The file cannot be opened or read.
    #[error("{file}: {source}")]
    Io {
        /// The file.
        file: String,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// The container is damaged or not what it claims (ROS 1 records, MCAP records,
    /// SQLite tables, metadata.yaml).
    #[error("{file}: {problem}{}; {fix}", at_offset(*.offset))]
    Format {
        /// The file.
        file: String,
        /// Byte offset of the damaged record, when known.
        offset: Option<u64>,
        /// What was found.
        problem: String,
        /// What the user can do.
        fix: String,
    },
    /// A message on a topic that is used cannot be decoded.
    #[error(
        "{file}: topic {topic} ({type_name}): message {index} (received at {} s) cannot be \
         decoded: {error}; \
         the bag is damaged or the topic does not carry the type it declares — choose \
         another topic or repair the bag",
        seconds(*.receive_ns)
    )]
    Message {
        /// The file.
        file: String,
        /// The topic.
        topic: String,
        /// Its declared type.
        type_name: String,
        /// 0-based index of the message on the topic.
        index: u64,
        /// When the bag recorded it (ns).
        receive_ns: u64,
        /// What the decoder found (boxed: keeps every `Result` of the reader small).
        error: Box<WireError>,
    },
    /// Which topic or joints to use cannot be decided, or the chosen ones hold nothing
    /// usable; the text lists the candidates and the flag to choose.
    #[error("{file}: {message}")]
    Choice {
        /// The bag.
        file: String,
        /// The explanation, with every candidate.
        message: String,
    },
}

/// A time in nanoseconds as exact seconds (`12.000000500`).
pub(crate) fn seconds(ns: u64) -> String {
    format!("{}.{:09}", ns / 1_000_000_000, ns % 1_000_000_000)
}

fn at_offset(offset: Option<u64>) -> String {
    match offset {
        Some(o) => format!(" (at byte {o})"),
        None => String::new(),
    }
}

impl BagError {
    /// An I/O error on `file`.
    pub(crate) fn io(file: &str, source: std::io::Error) -> Self {
        BagError::Io {
            file: file.to_string(),
            source,
        }
    }

    /// A damaged or unexpected container.
    pub(crate) fn format(
        file: &str,
        offset: Option<u64>,
        problem: impl Into<String>,
        fix: impl Into<String>,
    ) -> Self {
        BagError::Format {
            file: file.to_string(),
            offset,
            problem: problem.into(),
            fix: fix.into(),
        }
    }

    /// A choice that cannot be made.
    pub(crate) fn choice(file: &str, message: impl Into<String>) -> Self {
        BagError::Choice {
            file: file.to_string(),
            message: message.into(),
        }
    }
}

/// The advice for a bag that ends early.
pub(crate) const TRUNCATED_FIX: &str =
    "the bag is truncated or damaged (was the recording interrupted?); use a complete copy, \
     or cut the readable part into a new bag with the ROS tools";
