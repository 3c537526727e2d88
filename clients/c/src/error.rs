//! The return codes of `flexdyn_client.h` and the error that carries one with its message.

/// A return code (`FLEXDYN_*` in the header).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(i32)]
pub enum Code {
    /// `FLEXDYN_OK`.
    Ok = 0,
    /// `FLEXDYN_EMPTY`: a poll found nothing.
    Empty = 1,
    /// `FLEXDYN_ENDED`: a wait found nothing queued and the server has said the run ended.
    Ended = 2,
    /// `FLEXDYN_ERR_TIMEOUT`.
    Timeout = -1,
    /// `FLEXDYN_ERR_ARGUMENT`.
    Argument = -2,
    /// `FLEXDYN_ERR_ZENOH`.
    Zenoh = -3,
    /// `FLEXDYN_ERR_DECODE`.
    Decode = -4,
    /// `FLEXDYN_ERR_CAPACITY`.
    Capacity = -5,
    /// `FLEXDYN_ERR_USAGE`.
    Usage = -6,
    /// `FLEXDYN_ERR_CONFIG`.
    Config = -7,
    /// `FLEXDYN_ERR_INTERNAL`.
    Internal = -8,
    /// `FLEXDYN_ERR_ABSENT`.
    Absent = -9,
    /// `FLEXDYN_ERR_CLOSED`.
    Closed = -10,
}

/// A failed call: its code and the one-line message `flexdyn_last_error` returns.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Error {
    /// The code returned to C.
    pub code: Code,
    /// What went wrong.
    pub message: String,
}

impl Error {
    /// An error with `code` and `message`.
    pub fn new(code: Code, message: impl Into<String>) -> Self {
        Self {
            code,
            message: message.into(),
        }
    }

    /// A Zenoh failure while doing `what`.
    pub fn zenoh(what: &str, e: impl std::fmt::Display) -> Self {
        let message = flexdyn_proto::client::transport::clean_zenoh_message(&e.to_string());
        Self::new(Code::Zenoh, format!("{what}: {message}"))
    }
}

impl std::fmt::Display for Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Error {}
