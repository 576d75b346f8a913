//! Hammon 2017's closed-form fit (`hammon-fit`), checked where it has exact values, and set
//! beside the `hammon` facet simulation.
//!
//! * Smooth limit: with alpha -> 0, F0 = 0 and albedo 1, the fit's diffuse term at normal
//!   incidence integrates to exactly 1 (the 1.05 = 21/20 normalization of the Fresnel-weighted
//!   exit, docs/theory.md §4.5); quadrature over the detector's bins must reproduce that.
//! * Beside the simulation (alpha 0.5, F0 0.02, albedo 0.75, 10^6 photons): the fit is an
//!   approximation fitted to a different walk (symmetric Lambda, rejection normals), so the test
//!   records the measured all-order albedo difference and only asserts it stays below 10 %.

use smithwalk::analysis::models::{HammonFitPart, hammon_fit_bins};
use smithwalk::engine::detector::Grid;
use smithwalk::setup::cases::expand;
use smithwalk::setup::config::Config;

fn case(alpha: f64, f0: f64, albedo: f64, theta: f64) -> (smithwalk::setup::cases::Case, String) {
    let toml = format!(
        "paths = 1_000_000\nseed = 21\n[surface]\nalpha = {alpha}\n[material]\nkind = \"hammon\"\nf0 = {f0}\nalbedo = {albedo}\n[incident]\ntheta_deg = {theta}\n[detector]\ncos_theta_bins = 16\nphi_bins = 32\nmax_order = 3\n"
    );
    (expand(&Config::parse(&toml).unwrap())[0].clone(), toml)
}

#[test]
fn smooth_limit_of_the_fit_is_normalized() {
    let grid = Grid { cos_bins: 16, phi_bins: 32 };
    let (c, _) = case(1e-4, 0.0, 1.0, 0.0);
    let total: f64 = hammon_fit_bins(&c, &grid, HammonFitPart::Single, 1e-12).unwrap().iter().sum();
    // The alpha-weighted rough term and the Schlick specular of F0 = 0 near the mirror
    // direction add at most a few 1e-4.
    assert!((total - 1.0).abs() < 1e-3, "smooth-limit diffuse albedo {total}");
}

#[test]
fn the_fit_beside_the_simulation() {
    let (c, toml) = case(0.5, 0.02, 0.75, 30.0);
    let grid = Grid { cos_bins: 16, phi_bins: 32 };
    let fit: f64 = hammon_fit_bins(&c, &grid, HammonFitPart::All, 1e-12).unwrap().iter().sum();
    let sim = smithwalk::simulate(&Config::parse(&toml).unwrap(), Some(2), false).unwrap();
    let e = smithwalk::io::output::EnergyBalance::from_result(&sim.results[0]);
    let measured = e.reflected[0];
    println!("hammon facet alpha 0.5, 30 deg: simulated albedo {measured:.4}, Hammon's fit {fit:.4}");
    assert!((fit - measured).abs() < 0.1 * measured, "fit {fit} vs simulation {measured}");
}
