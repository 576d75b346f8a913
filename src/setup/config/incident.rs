//! The `[incident]` table: the incident polar angles, azimuths and sides.

use serde::{Deserialize, Serialize};

use super::values::{OneOrMany, deserialize_by_name};

#[derive(Clone, Copy, Debug, Serialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum IncidentSide {
    Outside,
    Inside,
}

deserialize_by_name!(IncidentSide: [IncidentSide::Outside, IncidentSide::Inside]);

#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct IncidentConfig {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub theta_deg: Option<OneOrMany<f64>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub theta_rad: Option<OneOrMany<f64>>,
    #[serde(default = "default_phi")]
    pub phi_deg: OneOrMany<f64>,
    #[serde(default = "default_side")]
    pub side: OneOrMany<IncidentSide>,
}

fn default_phi() -> OneOrMany<f64> {
    OneOrMany::One(0.0)
}
fn default_side() -> OneOrMany<IncidentSide> {
    OneOrMany::One(IncidentSide::Outside)
}

impl IncidentConfig {
    /// The incident polar angles in degrees, whichever unit the config used.
    pub fn theta_degrees(&self) -> Vec<f64> {
        match (&self.theta_deg, &self.theta_rad) {
            (Some(d), _) => d.values(),
            (None, Some(r)) => r.values().into_iter().map(f64::to_degrees).collect(),
            (None, None) => vec![],
        }
    }
}
