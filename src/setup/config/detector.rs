//! The `[detector]` table: the direction bins and the order slots.

use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct DetectorConfig {
    #[serde(default = "default_cos_bins")]
    pub cos_theta_bins: usize,
    #[serde(default = "default_phi_bins")]
    pub phi_bins: usize,
    /// Orders `>= max_order` are folded into the last order, "K+" ([`DEFAULT_MAX_ORDER`] when
    /// the config leaves it out). The walk is not capped. `None` (no fold, one slot per order
    /// reached) only where code builds a detector for a walk it bounds itself.
    #[serde(default = "default_max_order", skip_serializing_if = "Option::is_none")]
    pub max_order: Option<u32>,
}

/// The order folded by default: orders 1 to 63 get a slot each, every order from 64 on the
/// slot "64+". It bounds the order slots, and so a run's memory, for surfaces that scatter
/// light thousands of times (a diffuse facet at alpha 100); an explicit `max_order` may be larger.
pub const DEFAULT_MAX_ORDER: u32 = 64;

fn default_max_order() -> Option<u32> {
    Some(DEFAULT_MAX_ORDER)
}

fn default_cos_bins() -> usize {
    32
}
fn default_phi_bins() -> usize {
    64
}

impl Default for DetectorConfig {
    fn default() -> Self {
        Self { cos_theta_bins: default_cos_bins(), phi_bins: default_phi_bins(), max_order: default_max_order() }
    }
}
