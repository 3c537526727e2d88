//! The configuration's error type. It lives beside the schema reader, below every model, so that
//! a model's own schema (`<kind>/schema.rs`) reports a located error without naming the
//! configuration that assembles it.

use std::path::PathBuf;

use crate::validate::ParamError;

use super::{in_table, At, SchemaError};

/// A configuration that cannot be used. The message always starts with the TOML path of the
/// offending field (except for I/O and syntax errors, which name the file or the line).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ConfigError {
    /// The file could not be read.
    #[error("cannot read config file `{}`: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
    /// The text is not valid TOML.
    #[error("TOML syntax error at line {line}, column {column}: {message}")]
    Syntax {
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// What the TOML parser reported.
        message: String,
    },
    /// A key that the schema does not have.
    #[error("{field}: unknown key ({message}){at}")]
    UnknownKey {
        /// TOML path of the unknown key.
        field: String,
        /// What the TOML parser reported (lists the expected keys).
        message: String,
        /// Position of the key.
        at: At,
    },
    /// A required key is absent.
    #[error("{field}: missing required key{}", in_table(at))]
    MissingKey {
        /// TOML path of the missing key.
        field: String,
        /// Position of the table that lacks it.
        at: At,
    },
    /// A value of the wrong type or shape (e.g. a string for a number, 2 elements for 3).
    #[error("{field}: invalid value: {message}{at}")]
    InvalidValue {
        /// TOML path of the value.
        field: String,
        /// What the TOML parser reported.
        message: String,
        /// Position of the value.
        at: At,
    },
    /// A parameter rejected by the dynamics' validation (non-finite, non-positive, inertia,
    /// DCM, panel geometry, …).
    #[error("{source}{at}")]
    Param {
        /// The validation error; it names the field.
        #[source]
        source: ParamError,
        /// Position of the value.
        at: At,
    },
    /// A duration that is not a whole number of nanoseconds or of RK4 steps, or a step that does
    /// not divide the frame period.
    #[error("{field}: {problem}{at}")]
    Timing {
        /// TOML path (`simulation.step_s`, `simulation.frame_hz`, `wrench_schedule[i].t_s`).
        field: String,
        /// What is wrong.
        problem: String,
        /// Position of the value.
        at: At,
    },
    /// The initial translational state does not name exactly one point (CoM or B).
    #[error("{field}: {problem}{at}")]
    InitialPoint {
        /// TOML path (`initial` or one of its keys).
        field: String,
        /// What is wrong.
        problem: String,
        /// Position.
        at: At,
    },
    /// Unknown gravity model name, or a parameter the chosen model does not take or needs.
    #[error("{field}: {problem}{at}")]
    Gravity {
        /// TOML path (`gravity.model`, `gravity.j2`, …).
        field: String,
        /// What is wrong.
        problem: String,
        /// Position.
        at: At,
    },
    /// Wrench schedule rows out of order.
    #[error("{field}: {problem}{at}")]
    WrenchSchedule {
        /// TOML path (`wrench_schedule[i].t_s`).
        field: String,
        /// What is wrong.
        problem: String,
        /// Position.
        at: At,
    },
    /// Any other invalid value (e.g. duplicate panel pair names).
    #[error("{field}: {problem}{at}")]
    Invalid {
        /// TOML path.
        field: String,
        /// What is wrong.
        problem: String,
        /// Position.
        at: At,
    },
}

impl ConfigError {
    /// The TOML path of the offending field, if the error is about one.
    pub fn field(&self) -> Option<&str> {
        match self {
            ConfigError::Io { .. } | ConfigError::Syntax { .. } => None,
            ConfigError::UnknownKey { field, .. }
            | ConfigError::MissingKey { field, .. }
            | ConfigError::InvalidValue { field, .. }
            | ConfigError::Timing { field, .. }
            | ConfigError::InitialPoint { field, .. }
            | ConfigError::Gravity { field, .. }
            | ConfigError::WrenchSchedule { field, .. }
            | ConfigError::Invalid { field, .. } => Some(field),
            ConfigError::Param { source, .. } => param_field(source),
        }
    }
}

impl From<SchemaError> for ConfigError {
    fn from(e: SchemaError) -> Self {
        match e {
            SchemaError::UnknownKey { field, message, at } => {
                ConfigError::UnknownKey { field, message, at }
            }
            SchemaError::MissingKey { field, at } => ConfigError::MissingKey { field, at },
            SchemaError::InvalidValue { field, message, at } => {
                ConfigError::InvalidValue { field, message, at }
            }
        }
    }
}

impl From<ParamError> for ConfigError {
    fn from(source: ParamError) -> Self {
        ConfigError::Param {
            source,
            at: At(None),
        }
    }
}

/// The field path a [`ParamError`] names, if any.
pub(crate) fn param_field(e: &ParamError) -> Option<&str> {
    match e {
        ParamError::NotFinite { field }
        | ParamError::NotPositive { field, .. }
        | ParamError::Negative { field, .. }
        | ParamError::NotSymmetric { field, .. }
        | ParamError::NotPositiveDefinite { field, .. }
        | ParamError::TriangleInequality { field, .. }
        | ParamError::NotOrthonormal { field, .. }
        | ParamError::DExceedsLength { field, .. }
        | ParamError::NotUnit { field, .. }
        | ParamError::Exceeds { field, .. }
        | ParamError::Invalid { field, .. } => Some(field),
        _ => None,
    }
}
