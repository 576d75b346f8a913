//! Helpers shared by the physics crate's tests (and, through `#[path]`, by the top crate's
//! tests/common, so that they exist once).
#![allow(dead_code)]

use microsurface::DVec3;

/// The unit direction at polar angle `theta_deg` and azimuth `phi_deg` (degrees).
pub fn dir(theta_deg: f64, phi_deg: f64) -> DVec3 {
    let (st, ct) = theta_deg.to_radians().sin_cos();
    let (sp, cp) = phi_deg.to_radians().sin_cos();
    DVec3::new(st * cp, st * sp, ct)
}

/// The two-sided standard-normal quantile for a test at `level`: `|z|` beyond it rejects.
pub fn two_sided_z(level: f64) -> f64 {
    statrs::distribution::ContinuousCDF::inverse_cdf(&statrs::distribution::Normal::standard(), 1.0 - level / 2.0)
}
