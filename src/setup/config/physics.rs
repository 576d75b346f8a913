//! The typed boundary: where a configuration's values become physics values.
//!
//! A configuration names its NDF, roughness, Smith variant, law of hit normals, facet material
//! and incident direction in the user's terms; the walk, the models, the compensations and the
//! exports take the physics crate's types ([`AnyNdf`], [`Material`], [`Smith`], [`Normals`],
//! directions). This module is the only place that turns the one into the other, and each
//! conversion checks its values on the way, so validation and construction cannot disagree:
//! [`crate::setup::config::Config::validate`] runs these functions to check a configuration,
//! and [`crate::setup::cases::expand`] runs them to build its cases. Adding an NDF or a material
//! is one variant in the physics crate, one configuration field, and one arm here
//! (docs/architecture.md).

use glam::DVec3;
use microsurface::facet::{Conductor, ConductorFresnel, Dielectric, Hammon, Lambertian};
use microsurface::material::Material;
use microsurface::ndf::{AnyNdf, Beckmann, Ggx, Roughness};
use microsurface::normals::Normals;
use microsurface::smith::Smith;
use microsurface::student_t::StudentT;

use super::error::{ConfigError, invalid, missing};
use super::incident::IncidentSide;
use super::material::{FresnelKind, MaterialConfig, fresnel_name};
use super::surface::{NdfKind, NormalsKind, SmithKind};
use super::values::{Alpha, check_channels};

/// The roughest surface a walk supports. A walk makes about `alpha` bounces (order 1152 at
/// alpha 1e3, 105 770 at 1e5 at 60 deg, 64 photons): at 1e6, 14% of the energy passes the
/// 2^20-interaction cap and is lost as runaway, so 1e4 keeps a factor of 100 to it (measured,
/// docs/reliability.md).
pub const MAX_ALPHA: f64 = 1e4;

/// The roughness of an `alpha` entry (`surface.alpha`): each component finite, > 0 and at most
/// [`MAX_ALPHA`].
pub fn roughness(alpha: Alpha) -> Result<Roughness, ConfigError> {
    let (x, y) = alpha.xy();
    for v in [x, y] {
        if !(v.is_finite() && v > 0.0 && v <= MAX_ALPHA) {
            return Err(invalid(
                "surface.alpha",
                v,
                "a roughness > 0 and at most 1e4: a walk makes about alpha bounces, and from alpha ~1e6 on walks \
                 pass the 2^20-interaction cap and are lost (docs/reliability.md)",
            ));
        }
    }
    Ok(Roughness { x, y })
}

/// What a `gamma` entry must be.
const GAMMA_ALLOWED: &str = "a Student-T shape, finite and > 1.5 (at 1.5 and below the mean slope is infinite and \
                             Lambda does not exist; 2 is GGX, large values tend to Beckmann)";

/// The NDF `kind` with roughness `roughness` (§1.2) and, for `student-t`, the shape `gamma`
/// (§1.6): finite and > 1.5, given for `student-t` and only for it.
pub fn ndf(kind: NdfKind, roughness: Roughness, gamma: Option<f64>) -> Result<AnyNdf, ConfigError> {
    match (kind, gamma) {
        (NdfKind::Ggx, None) => Ok(AnyNdf::Ggx(Ggx(roughness))),
        (NdfKind::Beckmann, None) => Ok(AnyNdf::Beckmann(Beckmann(roughness))),
        (NdfKind::StudentT, Some(g)) => {
            StudentT::new(roughness, g).map(AnyNdf::StudentT).ok_or_else(|| invalid("surface.gamma", g, GAMMA_ALLOWED))
        }
        (NdfKind::StudentT, None) => Err(missing("surface.gamma", GAMMA_ALLOWED)),
        (_, Some(g)) => {
            Err(invalid("surface.gamma", g, "only with ndf = \"student-t\": GGX and Beckmann have no shape"))
        }
    }
}

/// The Lambda that drives the height process (§1.4, §2.7).
pub fn smith(kind: SmithKind) -> Smith {
    match kind {
        SmithKind::Exact => Smith::Exact,
        SmithKind::Symmetric => Smith::Symmetric,
    }
}

/// The law of the normals a ray hits (§3.2, §3.3).
pub fn normals(kind: NormalsKind) -> Normals {
    match kind {
        NormalsKind::Vndf => Normals::Visible,
        NormalsKind::HammonRejection => Normals::HammonRejection,
    }
}

/// The direction towards the light (§0) at polar angle `theta_deg` and azimuth `phi_deg`:
/// above the horizon from outside, below from inside.
pub fn incident_direction(theta_deg: f64, phi_deg: f64, side: IncidentSide) -> DVec3 {
    let (st, ct) = theta_deg.to_radians().sin_cos();
    let (sp, cp) = phi_deg.to_radians().sin_cos();
    let z = match side {
        IncidentSide::Outside => ct,
        IncidentSide::Inside => -ct,
    };
    DVec3::new(st * cp, st * sp, z)
}

/// The facet material of a `[material]` table (named `field` in errors: `material` or
/// `material[i]`), in three channels (a one-value parameter in all three), after checking
/// that each parameter its Fresnel mode needs is present, that no other is, and that each is
/// in range (§4.2–§4.5).
pub fn material(field: &str, m: &MaterialConfig) -> Result<Material<3>, ConfigError> {
    let unit = |v: f64| (0.0..=1.0).contains(&v);
    match m {
        MaterialConfig::Conductor { fresnel, f0, eta, k, .. } => {
            // Each parameter: the Fresnel kind that uses it (and needs it), and its range.
            let params = [
                ("f0", f0, FresnelKind::Schlick, unit as fn(f64) -> bool, "a reflectance in [0, 1]"),
                ("eta", eta, FresnelKind::Exact, |v| v > 0.0, "the real part of the index, > 0"),
                ("k", k, FresnelKind::Exact, |v| v >= 0.0, "the extinction coefficient, >= 0"),
            ];
            for (name, value, user, ok, allowed) in params {
                let key = format!("{field}.{name}");
                let allowed = format!("{allowed}, or one per channel [r, g, b]");
                let (kind, user) = (fresnel_name(*fresnel), fresnel_name(user));
                match value {
                    None if kind == user => return Err(missing(key, format!("fresnel = \"{user}\" needs {allowed}"))),
                    Some(c) if kind != user => {
                        let allowed = format!("`{name}` is used only with fresnel = \"{user}\", not \"{kind}\"");
                        return Err(invalid(key, c, allowed));
                    }
                    Some(c) => check_channels(key, *c, ok, &allowed)?,
                    None => {}
                }
            }
            let fresnel = match (fresnel, f0, eta, k) {
                (FresnelKind::None, ..) => ConductorFresnel::None,
                (FresnelKind::Schlick, Some(f0), ..) => ConductorFresnel::Schlick { f0: f0.to_array() },
                (FresnelKind::Exact, _, Some(eta), Some(k)) => {
                    ConductorFresnel::Exact { eta: eta.to_array(), k: k.to_array() }
                }
                // Each parameter a Fresnel kind needs was checked above: none is missing.
                _ => unreachable!("the loop above returns for a missing Fresnel parameter"),
            };
            Ok(Material::Conductor(Conductor { fresnel }))
        }
        MaterialConfig::Dielectric { eta, .. } => {
            if !(eta.is_finite() && *eta > 0.0 && *eta != 1.0) {
                return Err(invalid(
                    format!("{field}.eta"),
                    eta,
                    "a relative index n_inside / n_outside > 0 and != 1 (an index-matched interface is invisible)",
                ));
            }
            Ok(Material::Dielectric(Dielectric { eta: *eta }))
        }
        MaterialConfig::Diffuse { albedo, .. } => {
            check_channels(format!("{field}.albedo"), *albedo, unit, "albedos in [0, 1]")?;
            Ok(Material::Lambertian(Lambertian { albedo: albedo.to_array() }))
        }
        MaterialConfig::Hammon { f0, albedo, .. } => {
            check_channels(format!("{field}.f0"), *f0, unit, "reflectances in [0, 1]")?;
            check_channels(format!("{field}.albedo"), *albedo, unit, "albedos in [0, 1]")?;
            Ok(Material::Hammon(Hammon { f0: f0.to_array(), albedo: albedo.to_array() }))
        }
    }
}
