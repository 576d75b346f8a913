//! Hammon 2017's two departures from the Smith walk, measured against the independent Monte
//! Carlo values of docs/theory.md §2.7 and §3.3 (10^6 samples there, SE <= 5e-4): conductor F = 1,
//! isotropic GGX. Our runs use 10^6 photons; tolerance 4 combined standard errors.
//!
//! * `smith = "symmetric"` (§2.7): single scattering vanishes at normal incidence, and rays
//!   that reach the bottom of the height support are trapped (reported as lost weight).
//! * `normals = "hammon-rejection"` (§3.3): the order-1 albedo changes with the incident angle.

use crate::common;

use common::{albedo, mono, simulate};
use smithwalk::engine::detector::Hemisphere;
use smithwalk::io::output::EnergyBalance;

fn e1(surface_extra: &str, alpha: f64, theta: f64, seed: u64) -> (f64, f64, EnergyBalance) {
    let toml = format!(
        "paths = 1_000_000\nseed = {seed}\n[surface]\nalpha = {alpha}\n{surface_extra}\n[material]\nkind = \"conductor\"\n[incident]\ntheta_deg = {theta}\n[detector]\ncos_theta_bins = 1\nphi_bins = 1\nmax_order = 8\n"
    );
    let sim = simulate(&toml, 2);
    let (e, se) = albedo(mono(&sim, 0), 1, Hemisphere::R);
    (e, se, EnergyBalance::from_result(&sim.results[0]))
}

fn close(measured: f64, se: f64, reference: f64) -> bool {
    (measured - reference).abs() <= 4.0 * (se * se + 5e-4 * 5e-4).sqrt()
}

#[test]
fn symmetric_lambda_kills_single_scattering_at_normal_incidence() {
    // (alpha, theta, E1 with Lambda_H) from §2.7.
    let table = [
        (0.5, 0.0, 0.0),
        (0.5, 10.0, 0.0730),
        (0.5, 30.0, 0.2478),
        (0.5, 60.0, 0.4825),
        (1.0, 30.0, 0.1183),
        (1.0, 60.0, 0.3332),
    ];
    for (i, (alpha, theta, reference)) in table.into_iter().enumerate() {
        let (e, se, balance) = e1("smith = \"symmetric\"", alpha, theta, 600 + i as u64);
        assert!(close(e, se, reference), "alpha {alpha} theta {theta}: E1 = {e} +- {se}, reference {reference}");
        // Every unit of energy is accounted for: escaped or lost (trapped), none invalid.
        assert_eq!(balance.lost_invalid[0], 0.0);
        let total = balance.reflected[0] + balance.lost();
        assert!((total - 1.0).abs() < 1e-12, "alpha {alpha} theta {theta}: escaped + lost = {total}");
    }
}

#[test]
fn hammon_rejection_normals_change_single_scattering() {
    // (theta, E1 with Hammon's normals) at alpha 0.5 from §3.3 item 2.
    let table = [(10.0, 0.6841), (30.0, 0.6630), (60.0, 0.6134), (80.0, 0.6896)];
    for (i, (theta, reference)) in table.into_iter().enumerate() {
        let (e, se, balance) = e1("normals = \"hammon-rejection\"", 0.5, theta, 700 + i as u64);
        assert!(close(e, se, reference), "theta {theta}: E1 = {e} +- {se}, reference {reference}");
        assert_eq!(balance.lost(), 0.0);
        assert_eq!(balance.reflected[0], 1.0, "white furnace with Hammon normals");
    }
}
