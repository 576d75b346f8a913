//! Configuration errors: which field, which value, and what is allowed.

use std::fmt;

/// A configuration error: which field, which value, and what is allowed.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    /// The cause is part of the message and not the error's `source`, so that a chain of
    /// errors (`{:#}`) prints it once.
    #[error("cannot read config {path}: {cause}")]
    Read { path: String, cause: std::io::Error },
    #[error("config {path} is not valid: {message}")]
    Parse { path: String, message: String },
    #[error("`{field}` = {value} is not allowed: {allowed}")]
    Invalid { field: String, value: String, allowed: String },
    /// A required table or key that is absent; `place` is empty or says where it belongs.
    #[error("`{field}` is missing{place}: {allowed}")]
    Missing { field: String, place: String, allowed: String },
    /// Two keys that say the same thing in different ways, of which one at most may be given.
    #[error("`{first}` and `{second}` are both given: give one of them")]
    Exclusive { first: String, second: String },
}

impl ConfigError {
    /// The error as found in the config `path` (a file, `<text>` or `<dict>`): errors of its
    /// text or values name it; an unreadable file already does.
    pub fn in_source(self, path: &str) -> Self {
        match self {
            ConfigError::Parse { message, .. } => ConfigError::Parse { path: path.into(), message },
            ConfigError::Read { .. } => self,
            _ => ConfigError::Parse { path: path.into(), message: self.to_string() },
        }
    }
}

impl ConfigError {
    /// The error as caused by the command-line `option` that overrode its field: a value the
    /// user typed on the command line is named as they typed it.
    pub fn from_option(self, option: &str) -> Self {
        match self {
            ConfigError::Invalid { value, allowed, .. } => {
                ConfigError::Invalid { field: option.into(), value, allowed }
            }
            e => e,
        }
    }
}

pub(crate) fn invalid(field: impl Into<String>, value: impl fmt::Display, allowed: impl Into<String>) -> ConfigError {
    ConfigError::Invalid { field: field.into(), value: value.to_string(), allowed: allowed.into() }
}

/// A required table or key that is absent, with what it should be.
pub(super) fn missing(field: impl Into<String>, allowed: impl Into<String>) -> ConfigError {
    ConfigError::Missing { field: field.into(), place: String::new(), allowed: allowed.into() }
}
