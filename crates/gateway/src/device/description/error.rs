//! [`DescriptionError`]: a device list or description that cannot be used, naming the file,
//! the TOML key path (`message[2].field[3].source`) and the problem.

use std::path::{Path, PathBuf};

use thiserror::Error;

/// A device list or description refused.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[non_exhaustive]
pub enum DescriptionError {
    /// The file could not be read.
    #[error("{}: cannot read: {message}", file.display())]
    Read {
        /// The file.
        file: PathBuf,
        /// The system's message.
        message: String,
    },
    /// The file is not TOML of the expected shape (an unknown key, a wrong type).
    #[error("{}: not a valid {what}: {message}", file.display())]
    Syntax {
        /// The file.
        file: PathBuf,
        /// `device list` or `device description`.
        what: &'static str,
        /// The TOML parser's message (with line and column).
        message: String,
    },
    /// A value that is refused.
    #[error("{}: `{key}`: {problem}", file.display())]
    Invalid {
        /// The file.
        file: PathBuf,
        /// The TOML key path.
        key: String,
        /// What is wrong, with the valid choices where they are few.
        problem: String,
    },
}

impl DescriptionError {
    /// An [`DescriptionError::Invalid`].
    pub fn invalid(file: &Path, key: impl Into<String>, problem: impl Into<String>) -> Self {
        DescriptionError::Invalid {
            file: file.to_owned(),
            key: key.into(),
            problem: problem.into(),
        }
    }

    /// The file named.
    pub fn file(&self) -> &Path {
        match self {
            DescriptionError::Read { file, .. }
            | DescriptionError::Syntax { file, .. }
            | DescriptionError::Invalid { file, .. } => file,
        }
    }
}
