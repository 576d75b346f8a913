//! The height process of the walk (docs/theory.md §2.2–§2.4) against its closed forms.
//!
//! From a height with `u = C1(h)`, a ray travelling along `d` escapes (upward only) with
//! probability `G1(d, h) = u^Lambda(d)` (§2.2); otherwise it stops at `u'` with
//! `P(u' <= x | hit) = (1 - (u/x)^Lambda) / (1 - u^Lambda)` upward and `(x/u)^lambda` downward
//! (§2.3), and what is left of an escaping flight's exponential variate is again a standard
//! exponential (§2.4). Each check uses 200 000 flights: escapes by a two-sided binomial z test,
//! next heights and escape excesses by a chi-square over 20 equiprobable bins (thousands of
//! samples per bin, no pooling); all at the Sidak level that keeps the family at 0.01. The
//! walk runs in optical depth `tau = -ln u` (§2.4); `u` is the height's CDF value, so for
//! uniform heights on [-1, 1] the height is `2u - 1` and for Gaussian heights `Phi^{-1}(u)`:
//! the law of `u` is the law of the height for every height distribution (§2.1).

use crate::common;

use common::dir;
use microsurface::DVec3;
use microsurface::height::{Flight, fly, other_side_depth};
use microsurface::ndf::{Beckmann, Ggx, Ndf, Roughness};
use microsurface::random::exp1;
use microsurface::smith::Smith;
use numerics::stats::{WeightedBin, chi_square, sidak};
use rand_pcg::Pcg64Mcg;
use statrs::distribution::{ContinuousCDF, Normal};

const FLIGHTS: u64 = 200_000;
const BINS: usize = 20;

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

fn run<N: Ndf>(ndf: &N, seed: u128, level: f64) {
    let z_crit = z_critical(level);
    for (i, c) in CHECKS.iter().enumerate() {
        let d = dir(c.theta, c.phi);
        let rate = Smith::Exact.rate(ndf, d);
        let lambda = ndf.lambda(d);
        let up = d.z > 0.0;
        let tau = -c.u.ln();
        let mut rng = Pcg64Mcg::new(seed + i as u128);
        let mut escapes = 0u64;
        let mut next = Vec::new();
        let mut excess = Vec::new();
        for _ in 0..FLIGHTS {
            match fly(tau, up, rate, exp1(&mut rng)) {
                Flight { escapes: true, excess: e, .. } => {
                    escapes += 1;
                    excess.push(e);
                }
                Flight { tau: t, .. } => next.push((-t).exp()),
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
        let test = equiprobable(&next, quantile);
        assert!(test.p_value > level, "{label}: next-height distribution rejected\n{}", test.worst_cells(BINS));
        // What is left of an escaping flight's variate is a standard exponential (§2.4, no
        // memory): equiprobable bins with edges -ln(1 - q).
        if up {
            let test = equiprobable(&excess, |q| -(1.0 - q).ln());
            assert!(test.p_value > level, "{label}: excess of escapes rejected\n{}", test.worst_cells(BINS));
        }
    }
}

/// Chi-square of `samples` over `BINS` bins that are equiprobable under the law of quantile
/// function `quantile`.
fn equiprobable(samples: &[f64], quantile: impl Fn(f64) -> f64) -> numerics::stats::ChiSquare {
    let edges: Vec<f64> = (0..=BINS).map(|k| quantile(k as f64 / BINS as f64)).collect();
    let mut counts = [0u64; BINS];
    for x in samples {
        let k = edges.partition_point(|e| e <= x).clamp(1, BINS) - 1;
        counts[k] += 1;
    }
    let n = samples.len() as u64;
    let observed: Vec<WeightedBin> = counts.iter().map(|&k| WeightedBin::of_count(k, n)).collect();
    chi_square(&observed, &[1.0 / BINS as f64; BINS], n, 5.0)
}

#[test]
fn escape_probability_and_next_height_follow_the_smith_height_process() {
    let level = sidak(0.01, 2 * 3 * CHECKS.len());
    let r = Roughness { x: 0.6, y: 0.3 };
    run(&Ggx(r), 1 << 40, level);
    run(&Beckmann(r), 3 << 40, level);
}

#[test]
fn the_free_flight_takes_its_closed_form_limits() {
    // §2.3 limits: straight up always escapes (Lambda = 0), horizontal travel hits at the same
    // depth (rate = inf), straight down has rate 1 (u' = U u).
    let ndf = Ggx(Roughness::isotropic(0.5));
    assert_eq!(Smith::Exact.rate(&ndf, DVec3::Z), 0.0);
    let f = fly(3.0, true, 0.0, 0.7);
    assert!(f.escapes && f.excess == 0.7, "straight up, the whole variate is left: {f:?}");
    let horizontal = DVec3::new(1.0, 0.0, 0.0);
    assert_eq!(Smith::Exact.rate(&ndf, horizontal), f64::INFINITY);
    let f = fly(0.4, false, f64::INFINITY, 2.0);
    assert_eq!((f.escapes, f.tau), (false, 0.4));
    assert_eq!(Smith::Exact.rate(&ndf, -DVec3::Z), 1.0);
    // Hammon's symmetric Lambda gives a vertical downward ray rate 0 (§2.7): infinite depth.
    assert_eq!(Smith::Symmetric.rate(&ndf, -DVec3::Z), 0.0);
    let f = fly(0.4, false, 0.0, 1.0);
    assert_eq!((f.escapes, f.tau), (false, f64::INFINITY));
    // The same point seen from the other side (§4.3): -ln(1 - e^{-tau}), accurate at both ends
    // (closed forms: tau -> 0 gives -ln tau; large tau gives e^{-tau}), and an involution.
    assert!((other_side_depth(1.0) - -(1.0 - (-1.0f64).exp()).ln()).abs() < 1e-15);
    assert!((other_side_depth(1e-300) - 300.0 * std::f64::consts::LN_10).abs() < 1e-12);
    assert!((other_side_depth(700.0) / (-700.0f64).exp() - 1.0).abs() < 1e-15);
    assert_eq!(other_side_depth(0.0), f64::INFINITY);
    assert_eq!(other_side_depth(f64::INFINITY), 0.0);
    for tau in [1e-9, 0.1, 0.69, 0.7, 3.0, 30.0] {
        assert!((other_side_depth(other_side_depth(tau)) / tau - 1.0).abs() < 1e-9, "tau {tau}");
    }
}
