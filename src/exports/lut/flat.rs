//! The table's nodes at alpha = 0: the flat surface. There light meets one facet, of normal
//! `z`, and leaves: every albedo is the facet's own at the incidence cosine `mu`, all of it in
//! order 1, exactly (no walk, standard error 0). It is the limit of the walk's albedos as
//! alpha -> 0 at a fixed `mu > 0`; at `mu = 0` it is the facet's grazing value (`F = 1`).

use microsurface::fresnel;

use crate::engine::detector::Hemisphere;
use crate::setup::config::{Channels, FresnelKind, IncidentSide, MaterialConfig};

/// The albedo of the flat surface of facet `material` in `hemisphere`, for light from `side` at
/// incidence cosine `mu`, all orders (= order 1): a conductor reflects its Fresnel reflectance
/// (1 for F = 1, docs/theory.md §4.2); a dielectric reflects the Fresnel reflectance at the relative index
/// the light sees (`eta`, or `1 / eta` from inside, 1 under total internal reflection) and
/// transmits the rest (§4.3); Hammon's facet reflects its Schlick reflectance and its diffuse
/// exit carries the rest times the base's albedo (§4.5); a Lambertian facet its albedo (§4.4).
pub fn albedo(material: &MaterialConfig, side: IncidentSide, hemisphere: Hemisphere, mu: f64) -> f64 {
    let reflected = match material {
        MaterialConfig::Conductor { fresnel: FresnelKind::None, .. } => 1.0,
        MaterialConfig::Conductor { fresnel: FresnelKind::Schlick, f0, .. } => {
            fresnel::schlick(f0.map_or(1.0, |f| f.channel(0)), mu)
        }
        MaterialConfig::Conductor { fresnel: FresnelKind::Exact, eta, k, .. } => {
            let channel = |c: &Option<Channels>| c.map_or(0.0, |c| c.channel(0));
            fresnel::conductor(channel(eta), channel(k), mu)
        }
        MaterialConfig::Dielectric { eta, .. } => {
            let seen = match side {
                IncidentSide::Outside => *eta,
                IncidentSide::Inside => 1.0 / eta,
            };
            fresnel::dielectric(seen, mu)
        }
        MaterialConfig::Hammon { f0, albedo, .. } => {
            let f = fresnel::schlick(f0.channel(0), mu);
            f + (1.0 - f) * albedo.channel(0)
        }
        MaterialConfig::Diffuse { albedo, .. } => albedo.channel(0),
    };
    match (hemisphere, material.transmits()) {
        (Hemisphere::R, _) => reflected,
        (Hemisphere::T, true) => 1.0 - reflected,
        (Hemisphere::T, false) => 0.0,
    }
}
