//! Lee et al. 2018's V-groove model (`lee2018`, docs/theory.md §14) in the detector's bins, order
//! by order: another microsurface than Smith's (symmetric specular V-grooves whose walls follow
//! the NDF), so `compare` measures how far it is from the walk, slot by slot.

use std::ops::RangeInclusive;

use glam::DVec3;
use microsurface::material::Material;
use microsurface::ndf::AnyNdf;
use microsurface::vgroove::orders_lobe;

use crate::analysis::models::{LobeIntegrals, MAX_BIN_EVALUATIONS, integrate_bins, specular_peak};
use crate::engine::detector::{Grid, Hemisphere};
use crate::setup::cases::Case;
use crate::setup::config::IncidentSide;

/// The highest order the model's lobes hold: a path of more bounces needs walls steeper than
/// `pi/2 - pi/(2 * 64)` (88.6 deg, §14.2), which hold `alpha^2 / (alpha^2 + tan^2 88.6 deg)` of
/// the light at normal incidence on GGX (6e-4 at alpha 1, 1.5e-4 at 0.5): orders beyond it are
/// left out, the price of an evaluation that grows with the square of the orders summed.
pub const MAX_ORDER: usize = 64;

/// Why the model does not describe `case`, or `None` where it does: its walls are mirrors
/// (conductors), its grooves follow an isotropic GGX or Beckmann NDF, and light comes from above.
pub fn lee2018_unavailable(case: &Case) -> Option<&'static str> {
    let roughness = case.roughness();
    if !matches!(case.material, Material::Conductor(_)) {
        Some("not a conductor")
    } else if matches!(case.surface.ndf, AnyNdf::StudentT(_)) {
        Some("Student-T NDF")
    } else if roughness.x != roughness.y {
        Some("anisotropic")
    } else if case.side != IncidentSide::Outside {
        Some("light from inside")
    } else {
        None
    }
}

/// The orders that order slot `slot` holds: all (up to [`MAX_ORDER`]) for slot 0, from the
/// slot on for the run's folded slot `folded` ("K+"), the slot's own order otherwise.
pub fn slot_orders(slot: usize, folded: Option<usize>) -> RangeInclusive<usize> {
    match slot {
        0 => 1..=MAX_ORDER,
        s if folded == Some(s) => s..=MAX_ORDER,
        s => s..=s,
    }
}

/// Expected energy per photon of the orders `orders` of the model in every reflection bin of
/// `case` in colour channel `channel` (that channel's Fresnel), each bin to `tolerance(bin)`
/// within [`MAX_BIN_EVALUATIONS`] evaluations and graded towards the mirror direction (where
/// order 1 peaks and every higher order has its integrable peak, §14.2); `None` where the model
/// does not apply ([`lee2018_unavailable`]).
pub fn lee2018_lobe_bins(
    case: &Case,
    grid: &Grid,
    orders: RangeInclusive<usize>,
    channel: usize,
    tolerance: &(dyn Fn(usize) -> f64 + Sync),
) -> Option<LobeIntegrals> {
    if lee2018_unavailable(case).is_some() {
        return None;
    }
    let Material::Conductor(conductor) = case.material else { return None };
    let fresnel = move |c: f64| conductor.fresnel.reflectance(channel, c);
    let bins = |lobe: &(dyn Fn(DVec3) -> f64 + Sync)| {
        integrate_bins(
            case,
            grid,
            Hemisphere::R,
            (specular_peak(case, Hemisphere::R), tolerance, MAX_BIN_EVALUATIONS),
            lobe,
        )
    };
    let wi = case.wi;
    match case.surface.ndf {
        AnyNdf::Ggx(ndf) => Some(bins(&|wo| orders_lobe(&ndf, wi, wo, orders.clone(), fresnel))),
        AnyNdf::Beckmann(ndf) => Some(bins(&|wo| orders_lobe(&ndf, wi, wo, orders.clone(), fresnel))),
        AnyNdf::StudentT(_) => None,
    }
}
