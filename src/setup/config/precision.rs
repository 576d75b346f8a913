//! The `[precision]` table: a precision target that stops a case early.

use serde::{Deserialize, Serialize};

use super::error::{ConfigError, invalid};

/// A precision target: a case stops at the first round of chunks after which every nonzero
/// albedo of order slots `0..=orders` (both hemispheres, channel 0) has a standard error of at
/// most `target_stderr` and a relative standard error of at most `target_rel_stderr` (each
/// when given; at least one must be); `paths` is then the maximum.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PrecisionConfig {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target_rel_stderr: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target_stderr: Option<f64>,
    #[serde(default = "default_precision_orders")]
    pub orders: usize,
}

fn default_precision_orders() -> usize {
    1
}

impl PrecisionConfig {
    pub(super) fn validate(&self) -> Result<(), ConfigError> {
        if self.target_rel_stderr.is_none() && self.target_stderr.is_none() {
            return Err(invalid("precision", "{}", "a `target_rel_stderr` or a `target_stderr` (or both)"));
        }
        let targets =
            [("precision.target_rel_stderr", self.target_rel_stderr), ("precision.target_stderr", self.target_stderr)];
        for (field, target) in targets {
            if let Some(t) = target
                && !(t.is_finite() && t > 0.0)
            {
                return Err(invalid(field, t, "a standard error > 0"));
            }
        }
        Ok(())
    }
}
