//! One public error type, grouped by who is at fault.

use std::fmt;

/// Everything that can go wrong in the codec.
///
/// The variants say whose fault it is: the input (a file or stream that is
/// malformed or hostile), the caller (a bad parameter), a [`crate::Limits`]
/// budget, or the operating system.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The input is malformed: `what` names the input ("PLY file", "stream", …).
    #[error("invalid {what}: {detail}")]
    Input { what: &'static str, detail: String },
    /// The mesh is valid input but cannot be encoded as asked (e.g. non-manifold with repair off).
    #[error("unsupported mesh: {0}")]
    Unsupported(String),
    /// A caller-supplied option is out of range.
    #[error("invalid parameter: {0}")]
    Parameter(String),
    /// Decoding or importing would exceed the configured budget.
    #[error("limit exceeded: {0}")]
    Limit(String),
    #[error(transparent)]
    Io(#[from] std::io::Error),
}

impl Error {
    /// Malformed input; `what` names it ("PLY file", "stream", …).
    pub fn input(what: &'static str, detail: impl fmt::Display) -> Self {
        Error::Input {
            what,
            detail: detail.to_string(),
        }
    }

    pub(crate) fn stream(detail: impl fmt::Display) -> Self {
        Self::input("stream", detail)
    }
}

pub type Result<T, E = Error> = std::result::Result<T, E>;
