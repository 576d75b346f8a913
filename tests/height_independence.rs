//! The walk does not depend on the height distribution (THEORY.md §2.1): uniform and Gaussian
//! heights give the same lobes. Two independent runs (different seeds), 300 000 photons each,
//! on a 16 x 32 grid, are compared per order (1, 2, 3 and all) and hemisphere by a two-sample
//! chi-square with per-photon variances; bins with fewer than 10 photons in both runs together
//! are pooled. Family level 0.01, Sidak-corrected over all tests in this file.

mod common;

use common::{bin_counts, mono, simulate, weighted_bins};
use smithwalk::detector::Hemisphere;
use smithwalk::stats::{sidak, two_sample};

fn run(height: &str, seed: u64, material: &str, theta: f64, alpha: &str) -> smithwalk::Simulation {
    let toml = format!(
        "paths = 300_000\nseed = {seed}\n[surface]\nalpha = {alpha}\nheight = \"{height}\"\n[material]\n{material}\n[incident]\ntheta_deg = {theta}\n[detector]\ncos_theta_bins = 16\nphi_bins = 32\nmax_order = 4\n"
    );
    simulate(&toml, 2)
}

#[test]
fn uniform_and_gaussian_heights_give_the_same_lobes() {
    let cases = [
        ("kind = \"conductor\"", 60.0, "0.5", vec![Hemisphere::R]),
        ("kind = \"diffuse\"", 20.0, "1.0", vec![Hemisphere::R]),
        ("kind = \"dielectric\"\neta = 1.5", 45.0, "[[0.7, 0.3]]", vec![Hemisphere::R, Hemisphere::T]),
    ];
    let slots = [0usize, 1, 2, 3];
    let tests = slots.len() * cases.iter().map(|c| c.3.len()).sum::<usize>();
    let level = sidak(0.01, tests);
    for (i, (material, theta, alpha, hemispheres)) in cases.into_iter().enumerate() {
        let uniform = run("uniform", 10 + i as u64, material, theta, alpha);
        let gaussian = run("gaussian", 20 + i as u64, material, theta, alpha);
        let (a, b) = (mono(&uniform, 0), mono(&gaussian, 0));
        for h in hemispheres {
            for slot in slots {
                let counts: Vec<u64> = bin_counts(a, slot, h).iter().zip(bin_counts(b, slot, h)).map(|(x, y)| x + y).collect();
                let test = two_sample(&weighted_bins(a, slot, h), a.photons, &weighted_bins(b, slot, h), b.photons, &counts, 10);
                assert!(test.dof > 10, "{material}: too few cells to test ({})", test.dof);
                assert!(test.p_value > level, "{material} slot {slot} {h:?}: uniform vs gaussian rejected\n{}", test.worst_cells(10));
            }
        }
    }
}
