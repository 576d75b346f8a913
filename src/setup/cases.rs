//! Expansion of a configuration into cases: the cartesian product of every sweep.

use glam::DVec3;
use itertools::iproduct;
use serde::Serialize;

use crate::setup::config::{Config, HeightKind, IncidentSide, MaterialConfig, NdfKind, NormalsKind, SmithKind};

/// One measurement: a surface, a facet material and an incident direction.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Case {
    pub index: usize,
    pub ndf: NdfKind,
    pub alpha_x: f64,
    pub alpha_y: f64,
    pub height: HeightKind,
    pub smith: SmithKind,
    pub normals: NormalsKind,
    pub material: MaterialConfig,
    pub theta_i_deg: f64,
    pub phi_i_deg: f64,
    pub side: IncidentSide,
}

impl Case {
    /// The direction towards the light (§0): above the horizon from outside, below from inside.
    pub fn incident_direction(&self) -> DVec3 {
        let (st, ct) = self.theta_i_deg.to_radians().sin_cos();
        let (sp, cp) = self.phi_i_deg.to_radians().sin_cos();
        let z = match self.side {
            IncidentSide::Outside => ct,
            IncidentSide::Inside => -ct,
        };
        DVec3::new(st * cp, st * sp, z)
    }

    /// Whether the exact position-free form (docs/theory.md §7.1) describes this case's walk: facets
    /// that reflect on one side, the true Smith Lambda and visible normals (the chain's laws).
    pub fn position_free_applies(&self) -> bool {
        !self.material.transmits() && self.smith == SmithKind::Exact && self.normals == NormalsKind::Vndf
    }
}

/// The number of cases of a configuration, without expanding it (saturating: a validated
/// config has at most [`crate::setup::config::MAX_CASES`]).
pub fn count(config: &Config) -> u64 {
    let s = &config.surface;
    let i = &config.incident;
    let thetas = i.theta_deg.as_ref().or(i.theta_rad.as_ref()).map_or(0, |t| t.as_slice().len());
    [
        s.ndf.as_slice().len(),
        s.alpha.as_slice().len(),
        s.height.as_slice().len(),
        s.smith.as_slice().len(),
        s.normals.as_slice().len(),
        config.material.as_slice().len(),
        i.side.as_slice().len(),
        thetas,
        i.phi_deg.as_slice().len(),
    ]
    .into_iter()
    .fold(1u64, |n, len| n.saturating_mul(len as u64))
}

/// The cases of a configuration, in the order ndf, alpha, height, smith, normals, material,
/// side, theta, phi (the last varies fastest). The index of a case is its position.
pub fn expand(config: &Config) -> Vec<Case> {
    let s = &config.surface;
    let i = &config.incident;
    let product = iproduct!(
        s.ndf.values(),
        s.alpha.values(),
        s.height.values(),
        s.smith.values(),
        s.normals.values(),
        config.material.values(),
        i.side.values(),
        i.theta_degrees(),
        i.phi_deg.values()
    );
    product
        .enumerate()
        .map(|(index, (ndf, alpha, height, smith, normals, material, side, theta_i_deg, phi_i_deg))| {
            let (alpha_x, alpha_y) = alpha.xy();
            Case { index, ndf, alpha_x, alpha_y, height, smith, normals, material, theta_i_deg, phi_i_deg, side }
        })
        .collect()
}
