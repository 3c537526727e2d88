//! The configuration's error type. It lives beside the schema reader, below every model, so that
//! a model's own schema (`<kind>/schema.rs`) reports a located error without naming the
//! configuration that assembles it.

use std::path::PathBuf;

use crate::validate::ParamError;

use super::{At, SchemaError};

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
    /// The document's shape does not match the schema: an unknown or missing key, or a value of
    /// the wrong type or length (the schema reader's own error, with its message).
    #[error(transparent)]
    Schema(#[from] SchemaError),
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
            ConfigError::Schema(e) => Some(e.field()),
            ConfigError::Timing { field, .. }
            | ConfigError::InitialPoint { field, .. }
            | ConfigError::Gravity { field, .. }
            | ConfigError::WrenchSchedule { field, .. }
            | ConfigError::Invalid { field, .. } => Some(field),
            ConfigError::Param { source, .. } => param_field(source),
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
