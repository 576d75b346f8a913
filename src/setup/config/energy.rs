//! The `[energy]` table: how two-branch interactions and small weights are handled (§4.6).

use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct EnergyConfig {
    #[serde(default = "default_split")]
    pub split: bool,
    #[serde(default = "default_threshold")]
    pub threshold: f64,
}

fn default_split() -> bool {
    true
}
fn default_threshold() -> f64 {
    0.1
}

impl Default for EnergyConfig {
    fn default() -> Self {
        Self { split: default_split(), threshold: default_threshold() }
    }
}
