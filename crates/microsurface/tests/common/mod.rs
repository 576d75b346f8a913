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

/// `∫ f(w) dw` over the upper hemisphere by the midpoint rule in `(s, phi)`, `cos theta = 1 - s^2`,
/// `n x 2n` nodes: the substitution keeps the rule's error small where a lobe has an integrable
/// `1 / sin theta` peak at the pole (the V-grooves' orders >= 2 at normal incidence).
pub fn hemisphere_midpoint(n: usize, mut f: impl FnMut(DVec3) -> f64) -> f64 {
    let mut sum = 0.0;
    for i in 0..n {
        let s = (i as f64 + 0.5) / n as f64;
        let u = 1.0 - s * s;
        let r = (1.0 - u * u).sqrt();
        for j in 0..2 * n {
            let (sp, cp) = (std::f64::consts::TAU * (j as f64 + 0.5) / (2 * n) as f64).sin_cos();
            sum += 2.0 * s * f(DVec3::new(r * cp, r * sp, u));
        }
    }
    sum * std::f64::consts::TAU / (2 * n * n) as f64
}

/// The table of an isotropic NDF's D(theta_m) at angles `step_deg` apart from 0 to 90 degrees,
/// multiplied by `factor` (a table may be in any unit), as a tabulated NDF.
pub fn table_of<N: microsurface::ndf::Ndf>(ndf: &N, step_deg: f64, factor: f64) -> microsurface::tabulated::Tabulated {
    let n = (90.0 / step_deg).round() as usize;
    let theta: Vec<f64> = (0..=n).map(|i| 90.0 * i as f64 / n as f64).collect();
    let d: Vec<f64> = theta.iter().map(|&t| factor * ndf.d(dir(t, 0.0))).collect();
    microsurface::tabulated::Tabulated::new(&theta, &d).expect("a table of an analytic NDF")
}
