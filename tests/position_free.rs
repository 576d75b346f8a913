//! The exact position-free form (docs/theory.md §7.1): the walk with its collision depths
//! integrated out, run on the height-free chain.
//!
//! What the lobe comparison checks: the depth process of the walk (free flights, escapes),
//! against its analytic integral. The chain draws its directions with the walk's own
//! `Ndf::sample_visible` and `Facet::interact`, so a sampler or facet bug shared by both
//! passes that part; the per-order albedos against docs/theory.md §9.4's table do not share them.
//!
//! * The depth profile against closed forms of §6.3 and §7.1 (one and two bounces, the
//!   down-up-down-up pattern of §7.3, equal rates), and against a direct simulation of the
//!   depth process for a longer pattern (10^6 samples, within 4 SE).
//! * Per-order albedos, conductor F = 1, isotropic GGX, against docs/theory.md §9.4's table (walk,
//!   2*10^6 photons, SE <= 4e-4, rounded to 4 decimals), 10^6 chains here, within 4 combined
//!   standard errors.
//! * Lobes of orders 1, 2, 3, 4 and all against the walk's histograms for conductor (F = 1 and
//!   exact Fresnel, anisotropic), Lambertian and Hammon facets, GGX and Beckmann: two-sample
//!   chi-square with per-photon variances, 10^6 photons each, 8 x 16 bins, pooling bins with
//!   fewer than 10 histogram photons, at least 8 cells left; per-order albedos 1 to 5 by z
//!   test; the family at Sidak level 0.01.

mod common;

use common::{CONDUCTOR_ORDERS, assert_lobes_agree, check_orders, mono, simulate_with, two_sided_z};
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;
use smithwalk::analysis::stats::sidak;
use smithwalk::engine::detector::Hemisphere;
use smithwalk::engine::run::Estimator;
use smithwalk::io::output::EnergyBalance;
use smithwalk::microsurface::chain::Visibility;
use smithwalk::microsurface::position_free::DepthProfile;
use smithwalk::microsurface::random::exp1;

/// Follows a pattern of depth rates (first: the entering direction, down; then `(rate, up)`)
/// and returns the absolute probability of escaping at each upward step.
fn escapes(entry: f64, steps: &[(f64, bool)]) -> Vec<f64> {
    let mut profile = DepthProfile::default();
    profile.enter(entry);
    let mut alive = 1.0;
    let mut out = Vec::new();
    for &(rate, up) in steps {
        if up {
            let p = profile.up(rate);
            out.push(alive * p);
            alive *= 1.0 - p;
        } else {
            profile.down(rate);
        }
    }
    out
}

#[test]
fn depth_profile_matches_closed_forms_and_a_direct_simulation() {
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * b.abs().max(1e-300);
    let (l0, l1, l2) = (1.3, 0.7, 0.4);
    // k = 1: lambda_0 S with S = G2 = 1 / (lambda_0 + lambda_1).
    assert!(close(escapes(l0, &[(l1, true)])[0], l0 / (l0 + l1)));
    // k = 2 (§6.3 table): d_1 up, S = 1 / ((l0 + l1)(l0 + l2)); d_1 down, S = 1 / ((l1 + l2)(l0 + l2)).
    assert!(close(escapes(l0, &[(l1, true), (l2, true)])[1], l0 * l1 / ((l0 + l1) * (l0 + l2))));
    assert!(close(escapes(l0, &[(l1, false), (l2, true)])[0], l0 * l1 / ((l1 + l2) * (l0 + l2))));
    // Down-up-down-up with (1.3, 0.7, 2.1, 0.4) (§7.1 pattern, §7.3): S = 0.1176.
    let (a, b, c, d): (f64, f64, f64, f64) = (1.3, 0.7, 2.1, 0.4);
    let s = 1.0 / ((a + b) * (a + d) * (c + d));
    assert!((s - 0.1176).abs() < 5e-5);
    assert!(close(escapes(a, &[(b, true), (c, false), (d, true)])[1], a * b * c * s));
    // Equal rates on a downward step (the perturbed branch): d, d, u has
    // S = 1 / ((l0 + l2)(l1 + l2)), no singularity at l0 = l1.
    let got = escapes(1.5, &[(1.5, false), (0.6, true)])[0];
    let want = 1.5 * 1.5 / ((1.5 + 0.6) * (1.5 + 0.6));
    assert!((got - want).abs() < 1e-6 * want, "{got} vs {want}");

    // A longer pattern against the depth process simulated directly (§2.4): the light enters
    // down with rate 0.9; upward steps escape if their flight exceeds the depth.
    let pattern = [(0.3, true), (1.7, false), (0.5, false), (2.2, true), (0.8, false), (0.6, true), (0.25, true)];
    let exact = escapes(0.9, &pattern);
    let n = 1_000_000;
    let mut counts = vec![0u64; exact.len()];
    let mut rng = Pcg64Mcg::seed_from_u64(77);
    for _ in 0..n {
        let mut tau = exp1(&mut rng) / 0.9;
        let mut k = 0;
        for &(rate, up) in &pattern {
            let flight = exp1(&mut rng) / rate;
            if up {
                if flight > tau {
                    counts[k] += 1;
                    break;
                }
                tau -= flight;
                k += 1;
            } else {
                tau += flight;
            }
        }
    }
    for (k, (&count, &p)) in counts.iter().zip(&exact).enumerate() {
        let se = (p * (1.0 - p) / n as f64).sqrt();
        let observed = count as f64 / n as f64;
        println!("up step {k}: simulated {observed:.5}, exponential sums {p:.5}");
        assert!((observed - p).abs() < 4.0 * se, "up step {k}: simulated {observed} vs {p} (SE {se})");
    }
}

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
