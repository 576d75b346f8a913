//! Order 1 of the walk for light arriving from inside a dielectric against exact single
//! scattering with the sides swapped (docs/theory.md §4.3, §5): seen from below, in the frame
//! flipped by `d -> -d`, the microsurface is the same Smith microsurface and the ray sees
//! the relative index `1 / eta`. So with `wi' = -wi`, `wo' = -wo`:
//!
//! * reflection back inside: `single::reflection(wi', wo')` with Fresnel `F(1 / eta, ·)`;
//! * transmission to the outside: `single::transmission(wi', wo', 1 / eta)` with the same
//!   Fresnel (`G2` the Beta function of the two Lambdas, total internal reflection where
//!   `F = 1`).
//!
//! The formulas are evaluated here, bin by bin, by adaptive quadrature (abs. tolerance
//! 1e-10) over each bin of the detector's grid (uniform in |cos theta|, phi from the incident
//! azimuth); nothing of `models.rs` is used (it declines light from inside).
//!
//! Three cases (GGX below the critical angle, anisotropic GGX beyond it, Beckmann), 10^6
//! photons each (fixed seeds), 8 x 16 bins per hemisphere: a chi-square per hemisphere with
//! per-photon variances, cells with an expected count below 5 pooled, and a z test of each
//! order-1 albedo against the bins' sum; all 12 tests at the Sidak level keeping the family
//! at 0.01.
//!
//! Wrong physics it catches (planted, seen to fail, reverted): the outside `eta` used inside in
//! `Dielectric::interact` (GGX 0.5 at 20 deg, reflection: chi-square 579112 on 128 dof, E1
//! 0.0287 against 0.0926). Before this test only the inside rows of one reference table saw
//! it. Runtime: about 19 s on 2 cores.

mod common;

use std::f64::consts::TAU;

use common::{albedo, mono, simulate, two_sided_z, weighted_bins};
use microsurface::DVec3;
use microsurface::fresnel;
use microsurface::ndf::{Beckmann, Ggx, Ndf, Roughness};
use microsurface::single;
use smithwalk::analysis::quadrature::integrate_2d;
use smithwalk::analysis::stats::{chi_square, sidak};
use smithwalk::engine::detector::{Grid, Hemisphere};

const ETA: f64 = 1.5;

/// The order-1 lobe `f_1 |cos theta_o|` for light from inside along `wi` (`wi_z < 0`) leaving
/// along `wo`, by the outside formulas in the flipped frame.
fn inside_lobe<N: Ndf>(ndf: &N, wi: DVec3, wo: DVec3) -> f64 {
    let (wi, wo) = (-wi, -wo);
    let eta = 1.0 / ETA;
    let f = |c: f64| fresnel::dielectric(eta, c);
    if wo.z > 0.0 { single::reflection(ndf, wi, wo, f) } else { single::transmission(ndf, wi, wo, eta, f) }
}

/// Expected order-1 energy per photon in every bin of `hemisphere` (R: back inside, `z < 0`;
/// T: out, `z > 0`), index `cos * phi_bins + phi`, phi from the incident azimuth.
fn expected_bins<N: Ndf>(ndf: &N, wi: DVec3, grid: &Grid, hemisphere: Hemisphere) -> Vec<f64> {
    let phi_i = wi.y.atan2(wi.x);
    let sign = match hemisphere {
        Hemisphere::R => -1.0,
        Hemisphere::T => 1.0,
    };
    let dphi = TAU / grid.phi_bins as f64;
    (0..grid.bins())
        .map(|bin| {
            let (ic, ip) = (bin / grid.phi_bins, bin % grid.phi_bins);
            let lobe = |u: f64, phi: f64| {
                let s = (1.0 - u * u).max(0.0).sqrt();
                let (sp, cp) = (phi + phi_i).sin_cos();
                inside_lobe(ndf, wi, DVec3::new(s * cp, s * sp, sign * u))
            };
            integrate_2d(lobe, grid.cos_edges(ic), (ip as f64 * dphi, (ip + 1) as f64 * dphi), 1e-10).0
        })
        .collect()
}

#[test]
fn order_one_from_inside_matches_single_scattering_with_the_sides_swapped() {
    // (ndf, alpha, theta_i, phi_i)
    let cases = [("ggx", "0.5", 20.0, 0.0), ("ggx", "[[0.6, 0.3]]", 50.0, 30.0), ("beckmann", "0.4", 35.0, 0.0)];
    let level = sidak(0.01, 4 * cases.len());
    let z_limit = two_sided_z(level);
    for (i, (ndf, alpha, theta, phi)) in cases.into_iter().enumerate() {
        let toml = format!(
            "paths = 1_000_000\nseed = {}\n[surface]\nndf = \"{ndf}\"\nalpha = {alpha}\n[material]\nkind = \"dielectric\"\neta = {ETA}\n[incident]\ntheta_deg = {theta}\nphi_deg = {phi}\nside = \"inside\"\n[detector]\ncos_theta_bins = 8\nphi_bins = 16\nmax_order = 2\n",
            700 + i
        );
        let sim = simulate(&toml, 2);
        let case = &sim.cases[0];
        let wi = case.incident_direction();
        assert!(wi.z < 0.0, "light from inside");
        let roughness = Roughness { x: case.alpha_x, y: case.alpha_y };
        let d = mono(&sim, 0);
        for h in [Hemisphere::R, Hemisphere::T] {
            let expected = if ndf == "ggx" {
                expected_bins(&Ggx(roughness), wi, &d.grid, h)
            } else {
                expected_bins(&Beckmann(roughness), wi, &d.grid, h)
            };
            let label = format!("{ndf} {alpha} inside at {theta} deg {h:?}");
            let test = chi_square(&weighted_bins(d, 1, h), &expected, d.tallies.photons, 5.0);
            let (e1, se) = albedo(d, 1, h);
            let total: f64 = expected.iter().sum();
            let z = (e1 - total) / se;
            println!(
                "{label}: chi2 {:.1} dof {} p {:.3e}; E1 {e1:.5} +- {se:.5} vs {total:.5}, z {z:.2}",
                test.statistic, test.dof, test.p_value
            );
            assert!(total > 0.01, "{label}: the case must carry light at order 1 ({total})");
            assert!(test.p_value > level, "{label}: order-1 histogram rejected\n{}", test.worst_cells(10));
            assert!(z.abs() < z_limit, "{label}: E1 = {e1} +- {se}, single scattering {total}, z = {z:.2}");
        }
    }
}
