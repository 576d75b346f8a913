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
    let wi = case.incident_direction();
    let phi_i = case.phi_i_deg.to_radians();
    let sign = match hemisphere {
        Hemisphere::R => 1.0,
        Hemisphere::T => -1.0,
    };
    if hemisphere == Hemisphere::T && !case.material.transmits() {
        return vec![0.0; grid.bins()];
    }
    let dphi = TAU / grid.phi_bins as f64;
    let mut out = Vec::with_capacity(grid.bins());
    for ic in 0..grid.cos_bins {
        let (lo, hi) = grid.cos_edges(ic);
        for ip in 0..grid.phi_bins {
            let phi = (ip as f64 * dphi, (ip + 1) as f64 * dphi);
            let lobe = |u: f64, p: f64| single_lobe(ndf, &case.material, wi, direction(u, p, phi_i, sign));
            out.push(integrate_2d(lobe, (lo, hi), phi, abs_tol).0);
        }
    }
    out
}
