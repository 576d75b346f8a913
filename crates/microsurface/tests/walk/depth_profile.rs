//! The exact position-free form's depth profile (docs/theory.md §6.3, §7.1): the sub-density of
//! the next collision's depth along a fixed path of directions, as a sum of exponentials.
//!
//! * Against closed forms of §6.3 and §7.1 (one and two bounces, the down-up-down-up pattern of
//!   §7.3, equal rates on a downward step, where the profile separates them), to 1e-9
//!   relative (1e-6 for the perturbed equal rates).
//! * Against a direct simulation of the depth process (§2.4) for a longer pattern: 10^6
//!   samples, each escape probability within 4 binomial standard errors (7 tests; fixed seed).

use microsurface::chain::Visibility;
use microsurface::position_free::DepthProfile;
use microsurface::random::exp1;
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;

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
