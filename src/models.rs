//! Analytic models evaluated in the detector's bins. For now: exact single scattering of
//! mirror and dielectric facets (THEORY.md §5), integrated over each bin by adaptive
//! quadrature (§4.7: evaluating at bin centres is biased for peaked lobes).

use std::f64::consts::TAU;

use glam::DVec3;
use microsurface::fresnel;
use microsurface::ndf::{Beckmann, Ggx, Ndf, Roughness};
use microsurface::single;

use crate::cases::Case;
use crate::config::{FresnelKind, IncidentSide, MaterialConfig, NdfKind, NormalsKind, SmithKind};
use crate::detector::{Grid, Hemisphere};
use crate::quadrature::integrate_2d;

/// The outgoing direction of a bin coordinate: `|cos theta| = u`, azimuth `phi` from the
/// incident azimuth `phi_i`, in the hemisphere of `sign`.
fn direction(u: f64, phi: f64, phi_i: f64, sign: f64) -> DVec3 {
    let s = (1.0 - u * u).max(0.0).sqrt();
    let (sp, cp) = (phi + phi_i).sin_cos();
    DVec3::new(s * cp, s * sp, sign * u)
}

/// The order-1 cosine-weighted lobe `f_1 |cos theta_o|` of a case at `wo`, channel 0.
fn single_lobe<N: Ndf>(ndf: &N, material: &MaterialConfig, wi: DVec3, wo: DVec3) -> f64 {
    match material {
        MaterialConfig::Conductor { fresnel: kind, f0, eta, k, .. } => {
            let f = |c: f64| match kind {
                FresnelKind::None => 1.0,
                FresnelKind::Schlick => fresnel::schlick(f0.expect("validated").to_array::<1>()[0], c),
                FresnelKind::Exact => fresnel::conductor(
                    eta.expect("validated").to_array::<1>()[0],
                    k.expect("validated").to_array::<1>()[0],
                    c,
                ),
            };
            single::reflection(ndf, wi, wo, f)
        }
        MaterialConfig::Dielectric { eta, .. } => {
            let eta = *eta;
            if wo.z > 0.0 {
                single::reflection(ndf, wi, wo, |c| fresnel::dielectric(eta, c))
            } else {
                single::transmission(ndf, wi, wo, eta, |c| fresnel::dielectric(eta, c))
            }
        }
        MaterialConfig::Diffuse { .. } | MaterialConfig::Hammon { .. } => f64::NAN,
    }
}

/// Expected order-1 energy per photon in every bin of `hemisphere` (index `cos * phi_bins +
/// phi`), or `None` where the closed form does not apply (diffuse or Hammon facets, Hammon's
/// Smith or normals, light from inside).
pub fn single_scattering_bins(case: &Case, grid: &Grid, hemisphere: Hemisphere, abs_tol: f64) -> Option<Vec<f64>> {
    if case.smith != SmithKind::Exact
        || case.normals != NormalsKind::Vndf
        || case.side != IncidentSide::Outside
        || matches!(case.material, MaterialConfig::Diffuse { .. } | MaterialConfig::Hammon { .. })
    {
        return None;
    }
    let roughness = Roughness { x: case.alpha_x, y: case.alpha_y };
    Some(match case.ndf {
        NdfKind::Ggx => bins_for(&Ggx(roughness), case, grid, hemisphere, abs_tol),
        NdfKind::Beckmann => bins_for(&Beckmann(roughness), case, grid, hemisphere, abs_tol),
    })
}

fn bins_for<N: Ndf>(ndf: &N, case: &Case, grid: &Grid, hemisphere: Hemisphere, abs_tol: f64) -> Vec<f64> {
    if hemisphere == Hemisphere::T && !case.material.transmits() {
        return vec![0.0; grid.bins()];
    }
    let wi = case.incident_direction();
    integrate_bins(case, grid, hemisphere, abs_tol, |wo| single_lobe(ndf, &case.material, wi, wo))
}

/// Integrates a cosine-weighted lobe `wo -> f(wi, wo) |cos theta_o|` over every bin of
/// `hemisphere` (index `cos * phi_bins + phi`; phi from the incident azimuth).
fn integrate_bins(
    case: &Case,
    grid: &Grid,
    hemisphere: Hemisphere,
    abs_tol: f64,
    lobe: impl Fn(DVec3) -> f64,
) -> Vec<f64> {
    let phi_i = case.phi_i_deg.to_radians();
    let sign = match hemisphere {
        Hemisphere::R => 1.0,
        Hemisphere::T => -1.0,
    };
    let dphi = TAU / grid.phi_bins as f64;
    let mut out = Vec::with_capacity(grid.bins());
    for ic in 0..grid.cos_bins {
        let (lo, hi) = grid.cos_edges(ic);
        for ip in 0..grid.phi_bins {
            let phi = (ip as f64 * dphi, (ip + 1) as f64 * dphi);
            out.push(integrate_2d(|u, p| lobe(direction(u, p, phi_i, sign)), (lo, hi), phi, abs_tol).0);
        }
    }
    out
}

/// Which part of Hammon's fit to evaluate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HammonFitPart {
    /// Order 1: the specular term and the single-scattering diffuse term.
    Single,
    /// All orders: the above plus the multiple-scattering diffuse term.
    All,
}

/// Hammon 2017's closed-form fit of his `hammon` facet simulation ("GGX Diffuse
/// Approximation" and "Smith: Approximate GGX G2" slides; §4.5), as a cosine-weighted lobe
/// for `wi`, `wo` above the horizon, isotropic GGX `alpha`, Schlick `f0`, diffuse `albedo`:
/// specular `F(L·H) D(H) / (2 lerp(2 NL NV, NL + NV, alpha))`; diffuse
/// `albedo (single + albedo multi)` with `facing = 0.5 + 0.5 L·V`,
/// `rough = facing (0.9 - 0.4 facing) (0.5 + N·H) / N·H`,
/// `smooth = 1.05 (1 - (1 - NL)^5)(1 - (1 - NV)^5)`, `single = lerp(smooth, rough, alpha) / pi`,
/// `multi = 0.1159 alpha`. An approximate comparator: Hammon fitted it to his own simulation,
/// which used the symmetric Lambda and his rejection normals (§2.7, §3.3).
pub fn hammon_fit_lobe(alpha: f64, f0: f64, albedo: f64, wi: DVec3, wo: DVec3, part: HammonFitPart) -> f64 {
    if wi.z <= 0.0 || wo.z <= 0.0 {
        return 0.0;
    }
    let lerp = |a: f64, b: f64, t: f64| a + (b - a) * t;
    let (nl, nv) = (wi.z, wo.z);
    let h = (wi + wo).normalize();
    let ggx = Ggx(Roughness::isotropic(alpha));
    let specular = fresnel::schlick(f0, wi.dot(h)) * ggx.d(h) / (2.0 * lerp(2.0 * nl * nv, nl + nv, alpha));
    let facing = 0.5 + 0.5 * wi.dot(wo);
    let rough = facing * (0.9 - 0.4 * facing) * (0.5 + h.z) / h.z;
    let smooth = 1.05 * (1.0 - (1.0 - nl).powi(5)) * (1.0 - (1.0 - nv).powi(5));
    let single = lerp(smooth, rough, alpha) / std::f64::consts::PI;
    let multi = match part {
        HammonFitPart::Single => 0.0,
        HammonFitPart::All => 0.1159 * alpha,
    };
    (specular + albedo * (single + albedo * multi)) * nv
}

/// Expected energy per photon of Hammon's fit in every reflection bin of a `hammon` case
/// (isotropic GGX, light from outside; channel 0), or `None` where it does not apply.
pub fn hammon_fit_bins(case: &Case, grid: &Grid, part: HammonFitPart, abs_tol: f64) -> Option<Vec<f64>> {
    let MaterialConfig::Hammon { f0, albedo, .. } = &case.material else { return None };
    if case.ndf != NdfKind::Ggx || case.alpha_x != case.alpha_y || case.side != IncidentSide::Outside {
        return None;
    }
    let (f0, albedo) = (f0.to_array::<1>()[0], albedo.to_array::<1>()[0]);
    let wi = case.incident_direction();
    Some(integrate_bins(case, grid, Hemisphere::R, abs_tol, |wo| {
        hammon_fit_lobe(case.alpha_x, f0, albedo, wi, wo, part)
    }))
}
