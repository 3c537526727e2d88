//! A configuration from a file or the embedded default, and its errors prefixed with the file's
//! name: the one loader that `flexdyn run`, `simulate` and `check-config` share.

use std::path::Path;

use super::{ConfigError, SimConfig, DEFAULT_CONFIG_TOML};

/// Loads `path`, or the embedded default ([`DEFAULT_CONFIG_TOML`]) if `None`.
pub fn load_config(path: Option<&Path>) -> Result<SimConfig, ConfigError> {
    match path {
        Some(p) => SimConfig::from_file(p),
        None => SimConfig::from_toml_str(DEFAULT_CONFIG_TOML),
    }
}

/// The message of `e` for a configuration read from `file` (`None`: the embedded default):
/// `FILE: field: problem (line L, column C)`. An I/O error already names the file.
pub fn config_message(file: Option<&Path>, e: &ConfigError) -> String {
    match (file, e) {
        (Some(f), e) if !matches!(e, ConfigError::Io { .. }) => format!("{}: {e}", f.display()),
        _ => e.to_string(),
    }
}
