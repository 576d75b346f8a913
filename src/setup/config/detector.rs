//! The `[detector]` table: the direction bins and the order slots.

use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct DetectorConfig {
    #[serde(default = "default_cos_bins")]
    pub cos_theta_bins: usize,
    #[serde(default = "default_phi_bins")]
    pub phi_bins: usize,
    /// Orders `>= max_order` are folded into the last order, "K+". The walk is not capped.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_order: Option<u32>,
}

fn default_cos_bins() -> usize {
    32
}
fn default_phi_bins() -> usize {
    64
}

impl Default for DetectorConfig {
    fn default() -> Self {
        Self { cos_theta_bins: default_cos_bins(), phi_bins: default_phi_bins(), max_order: None }
    }
}
