//! The exact position-free form (docs/theory.md §7.1): the walk with its collision depths
//! integrated out, run on the height-free chain.
//!
//! What the lobe comparison checks: the depth process of the walk (free flights, escapes),
//! against its analytic integral. The chain draws its directions with the walk's own
//! `Ndf::sample_visible` and `Facet::interact`, so a sampler or facet bug shared by both
//! passes that part; the per-order albedos against docs/theory.md §9.4's table do not share them.
//!
//! * (The depth profile against closed forms and a direct simulation of the depth process:
//!   the physics crate's depth_profile.rs.)
//! * Per-order albedos, conductor F = 1, isotropic GGX, against docs/theory.md §9.4's table (walk,
//!   2*10^6 photons, SE <= 4e-4, rounded to 4 decimals), 10^6 chains here, within 4 combined
//!   standard errors.
//! * Lobes of orders 1, 2, 3, 4 and all against the walk's histograms for conductor (F = 1 and
//!   exact Fresnel, anisotropic), Lambertian and Hammon facets, GGX and Beckmann: two-sample
//!   chi-square with per-photon variances, 10^6 photons each, 8 x 16 bins, pooling bins with
//!   fewer than 10 histogram photons, at least 8 cells left; per-order albedos 1 to 5 by z
//!   test; the family at Sidak level 0.01.

use crate::common;

use common::{CONDUCTOR_ORDERS, assert_lobes_agree, check_orders, mono, simulate_with, two_sided_z};
use smithwalk::analysis::stats::sidak;
use smithwalk::engine::detector::Hemisphere;
use smithwalk::engine::run::Estimator;
use smithwalk::io::output::EnergyBalance;

#[test]
fn per_order_albedos_match_the_walk_table() {
    for (i, (alpha, theta, row)) in CONDUCTOR_ORDERS.into_iter().enumerate() {
        let toml = format!(
            "paths = 1_000_000\nseed = {}\n[surface]\nalpha = {alpha}\n[material]\nkind = \"conductor\"\n[incident]\ntheta_deg = {theta}\n[detector]\ncos_theta_bins = 1\nphi_bins = 1\nmax_order = 8\n",
            3000 + i
        );
        let sim = simulate_with(&toml, Estimator::PositionFree);
        let balance = EnergyBalance::from_result(&sim.results[0]);
        assert!((balance.reflected[0] - 1.0).abs() < 5e-4, "white furnace: {}", balance.reflected[0]);
        check_orders(mono(&sim, 0), Hemisphere::R, &row, 2e6, &format!("alpha {alpha} theta {theta}"));
    }
}

#[test]
fn lobes_of_every_order_match_the_walk() {
    let cases: [(&str, &str, &str); 5] = [
        ("ndf = \"ggx\"\nalpha = 0.5", "kind = \"conductor\"", "theta_deg = 60"),
        (
            "ndf = \"ggx\"\nalpha = [[0.9, 0.3]]",
            "kind = \"conductor\"\nfresnel = \"exact\"\neta = 0.2\nk = 3.0",
            "theta_deg = 70\nphi_deg = 30",
        ),
        ("ndf = \"ggx\"\nalpha = 1.0", "kind = \"diffuse\"\nalbedo = 0.9", "theta_deg = 60"),
        ("ndf = \"ggx\"\nalpha = 0.7", "kind = \"hammon\"\nf0 = 0.04\nalbedo = 0.8", "theta_deg = 50"),
        (
            "ndf = \"beckmann\"\nalpha = [[1.2, 0.8]]",
            "kind = \"conductor\"\nfresnel = \"exact\"\neta = 0.2\nk = 3.0",
            "theta_deg = 20\nphi_deg = 30",
        ),
    ];
    let slots = [0usize, 1, 2, 3, 4];
    let orders = 1..=5usize;
    let level = sidak(0.01, cases.len() * (slots.len() + orders.clone().count()));
    let z_limit = two_sided_z(level);
    for (i, (surface, material, incident)) in cases.into_iter().enumerate() {
        let toml = |seed: u64| {
            format!(
                "paths = 1_000_000\nseed = {seed}\n[surface]\n{surface}\n[material]\n{material}\n[incident]\n{incident}\n[detector]\ncos_theta_bins = 8\nphi_bins = 16\nmax_order = 6\n"
            )
        };
        let walk = simulate_with(&toml(3100 + i as u64), Estimator::Walk);
        let chain = simulate_with(&toml(3200 + i as u64), Estimator::PositionFree);
        let label = format!("case {i}");
        assert_lobes_agree(
            mono(&walk, 0),
            mono(&chain, 0),
            Hemisphere::R,
            &slots,
            orders.clone(),
            level,
            z_limit,
            &label,
        );
    }
}

#[test]
fn dielectric_cases_are_left_to_the_walk() {
    let toml = "paths = 10000\n[surface]\nalpha = 0.5\n[material]\nkind = \"dielectric\"\neta = 1.5\n[incident]\ntheta_deg = 30\n";
    let sim = simulate_with(toml, Estimator::PositionFree);
    let balance = EnergyBalance::from_result(&sim.results[0]);
    assert_eq!((balance.reflected[0], balance.transmitted[0], balance.lost()), (0.0, 0.0, 0.0));
}
