//! Expansion of a configuration into cases: the cartesian product of every sweep, each case
//! carrying the physics values of [`crate::setup::config::physics`].

use glam::DVec3;
use itertools::iproduct;
use microsurface::material::Material;
use microsurface::ndf::{AnyNdf, Ndf, Roughness};
use microsurface::normals::Normals;
use microsurface::smith::Smith;
use microsurface::walk::Microsurface;

use crate::setup::config::physics;
use crate::setup::config::{Config, ConfigError, HeightKind, IncidentSide, MaterialConfig};

/// One measurement: a surface, a facet material and an incident direction, as physics values.
#[derive(Clone, Debug, PartialEq)]
pub struct Case {
    pub index: usize,
    /// The NDF with its roughness, the Lambda of the height process and the law of hit normals.
    pub surface: Microsurface<AnyNdf>,
    /// The height distribution, for the tables: the walk runs in optical depth, on which no
    /// height law has any effect (§2.1).
    pub height: HeightKind,
    /// The facets' micro-BSDF in three channels (a one-value parameter in all three).
    pub material: Material<3>,
    /// The `[material]` table as the configuration gave it, for reports and labels (the
    /// physics reads [`Case::material`]).
    pub material_spec: MaterialConfig,
    pub theta_i_deg: f64,
    pub phi_i_deg: f64,
    pub side: IncidentSide,
    /// The direction towards the light (§0).
    pub wi: DVec3,
}

impl Case {
    /// The material's label for tables: the user's `name`, or the kind and its parameters.
    pub fn material_label(&self) -> String {
        self.material_spec.label()
    }

    /// The roughness (alpha_x, alpha_y) of the NDF.
    pub fn roughness(&self) -> Roughness {
        self.surface.ndf.roughness()
    }

    /// The shape of a Student-T NDF (theory §1.6); `None` for the others.
    pub fn gamma(&self) -> Option<f64> {
        match self.surface.ndf {
            AnyNdf::StudentT(ndf) => Some(ndf.gamma()),
            _ => None,
        }
    }

    /// Whether the exact position-free form (docs/theory.md §7.1) describes this case's walk: facets
    /// that reflect on one side, the true Smith Lambda and visible normals (the chain's laws).
    pub fn position_free_applies(&self) -> bool {
        !self.material.transmits() && self.surface.smith == Smith::Exact && self.surface.normals == Normals::Visible
    }

    /// Whether Cui et al.'s released model (docs/theory.md §7.3) describes this case: conductors,
    /// where the position-free form applies (the released code is a rough-conductor BRDF).
    pub fn cui_released_applies(&self) -> bool {
        matches!(self.material, Material::Conductor(_)) && self.position_free_applies()
    }
}

/// The cases of a configuration, in the order ndf, alpha, height, smith, normals, material,
/// side, theta, phi (the last varies fastest). The index of a case is its position. Each
/// value is checked as it is converted, so a configuration that was not validated gives the
/// error that [`Config::validate`] would.
pub fn expand(config: &Config) -> Result<Vec<Case>, ConfigError> {
    let s = &config.surface;
    let i = &config.incident;
    let roughnesses = s.alpha.values().into_iter().map(physics::roughness).collect::<Result<Vec<_>, _>>()?;
    let materials = config
        .material_fields()
        .map(|(field, m)| Ok((physics::material(&field, m)?, m.clone())))
        .collect::<Result<Vec<_>, ConfigError>>()?;
    let product = iproduct!(
        s.ndf_shapes(),
        roughnesses,
        s.height.values(),
        s.smith.values(),
        s.normals.values(),
        materials,
        i.side.values(),
        i.theta_degrees(),
        i.phi_deg.values()
    );
    let cases = product.enumerate().map(
        |(
            index,
            ((ndf, gamma), roughness, height, smith, normals, (material, material_spec), side, theta_i_deg, phi_i_deg),
        )| {
            let surface = Microsurface {
                ndf: physics::ndf(ndf, roughness, gamma)?,
                smith: physics::smith(smith),
                normals: physics::normals(normals),
            };
            let wi = physics::incident_direction(theta_i_deg, phi_i_deg, side);
            Ok(Case { index, surface, height, material, material_spec, theta_i_deg, phi_i_deg, side, wi })
        },
    );
    cases.collect()
}
