//! Exact single scattering (docs/theory.md §5): the expected order-1 output of the walk with the
//! true Smith Lambda and visible normals. All functions return the cosine-weighted lobe
//! `f_1(wi, wo) |cos theta_o|` (§0), with `wi` towards the light and `wo` towards the
//! detector, both pointing away from the surface, in the frame where the light is outside.

use crate::beta::beta;
use crate::ndf::Ndf;
use glam::DVec3;

/// Height-correlated masking-shadowing of a reflection, `1 / (1 + Lambda_i + Lambda_o)` (§1.5).
pub fn g2_reflection<N: Ndf>(ndf: &N, wi: DVec3, wo: DVec3) -> f64 {
    1.0 / (1.0 + ndf.lambda(wi) + ndf.lambda(wo))
}

/// Height-correlated masking-shadowing of a transmission, `B(1 + Lambda(wi), 1 + Lambda(-wo))`
/// (§1.5; the Beta function).
pub fn g2_transmission<N: Ndf>(ndf: &N, wi: DVec3, wo: DVec3) -> f64 {
    beta(1.0 + ndf.lambda(wi), 1.0 + ndf.lambda(-wo))
}

/// Mirror-facet reflection (§5): `F(wi·h) D(h) G2 / (4 |wi_z|)` for `wi`, `wo` above the
/// horizon, with `fresnel` the facet reflectance as a function of `wi·h`.
pub fn reflection<N: Ndf>(ndf: &N, wi: DVec3, wo: DVec3, fresnel: impl Fn(f64) -> f64) -> f64 {
    if wi.z <= 0.0 || wo.z <= 0.0 {
        return 0.0;
    }
    let h = (wi + wo).normalize();
    fresnel(wi.dot(h)) * ndf.d(h) * g2_reflection(ndf, wi, wo) / (4.0 * wi.z)
}

/// Dielectric transmission in its power-conserving form (§5, \[W07\] Eq. 21 with `G2^T`):
/// `wi` above, `wo` below, `eta = eta_o / eta_i`; `fresnel` is the reflectance at `wi·h`.
pub fn transmission<N: Ndf>(ndf: &N, wi: DVec3, wo: DVec3, eta: f64, fresnel: impl Fn(f64) -> f64) -> f64 {
    if wi.z <= 0.0 || wo.z >= 0.0 {
        return 0.0;
    }
    let mut h = -(wi + eta * wo).normalize();
    if h.z < 0.0 {
        h = -h;
    }
    let (ci, co) = (wi.dot(h), wo.dot(h));
    if !(ci > 0.0 && co < 0.0) {
        return 0.0;
    }
    let denom = ci + eta * co;
    ci * -co / wi.z * eta * eta * (1.0 - fresnel(ci)) * ndf.d(h) * g2_transmission(ndf, wi, wo) / (denom * denom)
}
