//! The height process of the walk (THEORY.md §2.2–§2.4) against its closed forms.
//!
//! From a height with `u = C1(h)`, a ray travelling along `d` escapes (upward only) with
//! probability `G1(d, h) = u^Lambda(d)` (§2.2); otherwise it stops at `u'` with
//! `P(u' <= x | hit) = (1 - (u/x)^Lambda) / (1 - u^Lambda)` upward and `(x/u)^lambda` downward
//! (§2.3). Each check uses 200 000 flights: escapes by a two-sided binomial z test, next
//! heights by a chi-square over 20 equiprobable bins (expected count 10 000 each, no pooling);
//! all at the Sidak level that keeps the family at 0.01. Heights are converted back to `u`
//! with independent closed forms (uniform: `(h+1)/2`; Gaussian: statrs' normal CDF), so the
//! depth/height conversions of both distributions are tested too.

use microsurface::DVec3;
use microsurface::height::{Flight, GaussianHeight, HeightDistribution, UniformHeight, fly};
use microsurface::ndf::{Beckmann, Ggx, Ndf, Roughness};
use microsurface::random::exp1;
use microsurface::smith::Smith;
use rand_pcg::Pcg64Mcg;
use smithwalk::stats::{WeightedBin, chi_square, sidak};
use statrs::distribution::{ContinuousCDF, Normal};

const FLIGHTS: u64 = 200_000;
const BINS: usize = 20;

fn dir(theta_deg: f64, phi_deg: f64) -> DVec3 {
    let (st, ct) = theta_deg.to_radians().sin_cos();
    let (sp, cp) = phi_deg.to_radians().sin_cos();
    DVec3::new(st * cp, st * sp, ct)
}

/// `u = C1(h)` by an independent formula.
fn cdf_uniform(h: f64) -> f64 {
    (h + 1.0) / 2.0
}
fn cdf_gaussian(h: f64) -> f64 {
    Normal::standard().cdf(h)
}

/// Standard normal two-sided critical value for level `a`.
fn z_critical(a: f64) -> f64 {
    Normal::standard().inverse_cdf(1.0 - a / 2.0)
}

struct Check {
    u: f64,
    theta: f64,
    phi: f64,
}

const CHECKS: [Check; 6] = [
    Check { u: 0.3, theta: 20.0, phi: 0.0 },
    Check { u: 0.8, theta: 70.0, phi: 45.0 },
    Check { u: 0.95, theta: 88.0, phi: 120.0 },
    Check { u: 0.5, theta: 110.0, phi: 10.0 },
    Check { u: 0.9, theta: 160.0, phi: 200.0 },
    Check { u: 0.2, theta: 92.0, phi: 300.0 },
];

fn run<N: Ndf, H: HeightDistribution>(ndf: &N, heights: H, cdf: fn(f64) -> f64, seed: u128, level: f64) {
    let z_crit = z_critical(level);
    for (i, c) in CHECKS.iter().enumerate() {
        let d = dir(c.theta, c.phi);
        let rate = Smith::Exact.rate(ndf, d);
        let lambda = ndf.lambda(d);
        let up = d.z > 0.0;
        // Place the ray at height h with C1(h) = u, through the distribution under test.
        let h = heights.height(-c.u.ln());
        // statrs' erfc_inv is accurate to about 1e-11 here; far below the test's resolution.
        assert!((cdf(h) - c.u).abs() < 1e-9, "height({}) inverts to {}", c.u, cdf(h));
        let tau = heights.depth(h);
        let mut rng = Pcg64Mcg::new(seed + i as u128);
        let mut escapes = 0u64;
        let mut next = Vec::new();
        for _ in 0..FLIGHTS {
            match fly(tau, up, rate, exp1(&mut rng)) {
                Flight::Escape => escapes += 1,
                Flight::Hit(t) => next.push(cdf(heights.height(t))),
            }
        }
        let label = format!("u={} theta={} phi={}", c.u, c.theta, c.phi);
        // Escape probability G1(d, h) = u^Lambda(d) upward, 0 downward (§2.2).
        let p = if up { c.u.powf(lambda) } else { 0.0 };
        if up {
            let n = FLIGHTS as f64;
            let z = (escapes as f64 - n * p) / (n * p * (1.0 - p)).sqrt();
            assert!(z.abs() < z_crit, "{label}: {escapes} escapes, expected {:.1}, z = {z:.2}", n * p);
        } else {
            assert_eq!(escapes, 0, "{label}: a downward ray escaped");
        }
        // Next height: P(u' <= x | hit), inverted at equiprobable bin edges.
        let quantile = |q: f64| {
            if up {
                // 1 - (u/x)^L = q (1 - u^L)  =>  x = u (1 - q (1 - u^L))^(-1/L)
                c.u * (1.0 - q * (1.0 - p)).powf(-1.0 / lambda)
            } else {
                // (x/u)^rate = q
                c.u * q.powf(1.0 / rate)
            }
        };
        let edges: Vec<f64> = (0..=BINS).map(|k| quantile(k as f64 / BINS as f64)).collect();
        let mut counts = vec![0u64; BINS];
        for x in &next {
            let k = edges.partition_point(|e| e <= x).clamp(1, BINS) - 1;
            counts[k] += 1;
        }
        let hits = next.len() as f64;
        let observed: Vec<WeightedBin> =
            counts.iter().map(|&k| WeightedBin { mean: k as f64 / hits, second_moment: k as f64 / hits }).collect();
        let test = chi_square(&observed, &vec![1.0 / BINS as f64; BINS], next.len() as u64, 5.0);
        assert!(test.p_value > level, "{label}: next-height distribution rejected\n{}", test.worst_cells(BINS));
    }
}

#[test]
fn escape_probability_and_next_height_follow_the_smith_height_process() {
    let level = sidak(0.01, 4 * 2 * CHECKS.len());
    let r = Roughness { x: 0.6, y: 0.3 };
    run(&Ggx(r), UniformHeight, cdf_uniform, 1 << 40, level);
    run(&Ggx(r), GaussianHeight, cdf_gaussian, 2 << 40, level);
    run(&Beckmann(r), UniformHeight, cdf_uniform, 3 << 40, level);
    run(&Beckmann(r), GaussianHeight, cdf_gaussian, 4 << 40, level);
}

#[test]
fn limits_of_the_free_flight() {
    // §2.3 limits: straight up always escapes (Lambda = 0), horizontal travel hits at the same
    // depth (rate = inf), straight down has rate 1 (u' = U u).
    let ndf = Ggx(Roughness::isotropic(0.5));
    assert_eq!(Smith::Exact.rate(&ndf, DVec3::Z), 0.0);
    assert_eq!(fly(3.0, true, 0.0, 0.7), Flight::Escape);
    let horizontal = DVec3::new(1.0, 0.0, 0.0);
    assert_eq!(Smith::Exact.rate(&ndf, horizontal), f64::INFINITY);
    assert_eq!(fly(0.4, false, f64::INFINITY, 2.0), Flight::Hit(0.4));
    assert_eq!(Smith::Exact.rate(&ndf, -DVec3::Z), 1.0);
    // Hammon's symmetric Lambda gives a vertical downward ray rate 0 (§2.7): infinite depth.
    assert_eq!(Smith::Symmetric.rate(&ndf, -DVec3::Z), 0.0);
    assert_eq!(fly(0.4, false, 0.0, 1.0), Flight::Hit(f64::INFINITY));
    // Heights at the boundary: the top is depth 0, the bottom infinite depth, both ways round.
    for h in [UniformHeight.top(), GaussianHeight.top()] {
        assert!(h == 1.0 || h == f64::INFINITY);
    }
    assert_eq!(UniformHeight.depth(1.0), 0.0);
    assert_eq!(UniformHeight.depth(-1.0), f64::INFINITY);
    assert_eq!(GaussianHeight.depth(f64::INFINITY), 0.0);
    assert_eq!(GaussianHeight.depth(f64::NEG_INFINITY), f64::INFINITY);
    assert_eq!(UniformHeight.height(0.0), 1.0);
    assert_eq!(GaussianHeight.height(0.0), f64::INFINITY);
    assert_eq!(GaussianHeight.height(f64::INFINITY), f64::NEG_INFINITY);
}
