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

/// The table of an isotropic NDF's D(theta_m) at angles `step_deg` apart from 0 to 90 degrees,
/// multiplied by `factor` (a table may be in any unit), as a tabulated NDF.
pub fn table_of<N: microsurface::ndf::Ndf>(ndf: &N, step_deg: f64, factor: f64) -> microsurface::tabulated::Tabulated {
    let n = (90.0 / step_deg).round() as usize;
    let theta: Vec<f64> = (0..=n).map(|i| 90.0 * i as f64 / n as f64).collect();
    let d: Vec<f64> = theta.iter().map(|&t| factor * ndf.d(dir(t, 0.0))).collect();
    microsurface::tabulated::Tabulated::new(&theta, &d).expect("a table of an analytic NDF")
}
