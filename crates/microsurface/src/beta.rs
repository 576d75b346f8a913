//! The Beta function `B(a, b) = Γ(a) Γ(b) / Γ(a + b)`, the height-correlated masking of a
//! transmission (docs/theory.md §1.5) and of Wang et al.'s refracted vertices (§6.3).
//!
//! Its arguments are `1 + Lambda` of directions, which grow without bound towards the horizon
//! (`Lambda ~ alpha / (2 cot theta)`). `ln Γ(a) + ln Γ(b) - ln Γ(a + b)` then subtracts numbers of
//! size `a ln a` that agree in all but their last digits (at `a = 10^14`, `ln Γ(a) ≈ 3·10^15`
//! and the difference is off by about 0.5, so `B` by a factor of 1.6). With Stirling's series
//! the large parts are combined analytically first, as logarithms of ratios.

use statrs::function::gamma::ln_gamma;

/// Above this argument `ln Γ` is taken from Stirling's series.
const STIRLING_FROM: f64 = 10.0;

/// `ln Γ(x) - [(x - 1/2) ln x - x + ln(2π)/2]`, Stirling's series to its `x^-9` term, for
/// `x >= 10`, where the first term left out, `691 / (360360 x^11)`, is below `2·10^-14`.
fn stirling_remainder(x: f64) -> f64 {
    let r = 1.0 / (x * x);
    (1.0 / 12.0 - r * (1.0 / 360.0 - r * (1.0 / 1260.0 - r * (1.0 / 1680.0 - r / 1188.0)))) / x
}

/// `ln B(a, b)` for `a, b > 0`. Wherever `B` is a normal double its error is that of a few
/// roundings of numbers below about 10^3 (about 10^-13), for any size of either argument.
pub fn ln_beta(a: f64, b: f64) -> f64 {
    let (p, q) = if a <= b { (a, b) } else { (b, a) };
    let sum = p + q;
    if p >= STIRLING_FROM {
        // (p - 1/2) ln(p / (p+q)) + q ln(q / (p+q)) - ln(q) / 2 + ln(2π) / 2, plus remainders.
        let correction = stirling_remainder(p) + stirling_remainder(q) - stirling_remainder(sum);
        (p - 0.5) * (p / sum).ln() + q * (-p / sum).ln_1p() - 0.5 * q.ln()
            + 0.5 * (2.0 * std::f64::consts::PI).ln()
            + correction
    } else if q >= STIRLING_FROM {
        // ln Γ(p) exactly, and ln Γ(q) - ln Γ(p+q) = (q - 1/2) ln(q / (p+q)) - p ln(p+q) + p, plus
        // remainders, whose first and last terms cancel to O(p^2 / q) without loss.
        let correction = stirling_remainder(q) - stirling_remainder(sum);
        ln_gamma(p) + (q - 0.5) * (-p / sum).ln_1p() - p * sum.ln() + p + correction
    } else {
        ln_gamma(p) + ln_gamma(q) - ln_gamma(sum)
    }
}

/// `B(a, b)` for `a, b > 0` ([`ln_beta`]).
pub fn beta(a: f64, b: f64) -> f64 {
    ln_beta(a, b).exp()
}

/// The regularized incomplete Beta function `I_x(a, b) = ∫_0^x t^{a-1} (1-t)^{b-1} dt / B(a, b)`
/// for `a, b > 0`, `0 <= x <= 1`: the Student-t tail of the Student-T NDF's Lambda (theory §1.6).
///
/// Its continued fraction (DLMF 8.17.22), evaluated by the modified Lentz method, converges
/// quickly for `x < (a + 1) / (a + b + 2)`, in about `sqrt(max(a, b))` steps; beyond, the
/// symmetry `I_x(a, b) = 1 - I_{1-x}(b, a)` brings `x` below that point. The prefactor
/// `x^a (1-x)^b / (a B(a, b))` is taken from logarithms so that it neither overflows nor loses
/// the large arguments of [`ln_beta`]. The fraction stops when a step changes it by less than
/// 1e-16 relative.
pub fn regularized_incomplete_beta(x: f64, a: f64, b: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    if x > (a + 1.0) / (a + b + 2.0) {
        return 1.0 - regularized_incomplete_beta(1.0 - x, b, a);
    }
    let prefactor = (a * x.ln() + b * (-x).ln_1p() - a.ln() - ln_beta(a, b)).exp();
    prefactor * incomplete_beta_fraction(x, a, b)
}

/// The continued fraction of [`regularized_incomplete_beta`] (Lentz; Numerical Recipes §6.4's
/// even and odd coefficients), for `x` below `(a + 1) / (a + b + 2)`.
fn incomplete_beta_fraction(x: f64, a: f64, b: f64) -> f64 {
    // Lentz replaces a zero denominator by a tiny number so that the next step recovers.
    const TINY: f64 = 1e-300;
    let guard = |v: f64| if v.abs() < TINY { TINY } else { v };
    let mut c = 1.0;
    let mut d = 1.0 / guard(1.0 - (a + b) * x / (a + 1.0));
    let mut h = d;
    let mut m = 1.0;
    loop {
        let m2 = 2.0 * m;
        let even = m * (b - m) * x / ((a + m2 - 1.0) * (a + m2));
        d = 1.0 / guard(1.0 + even * d);
        c = guard(1.0 + even / c);
        h *= d * c;
        let odd = -(a + m) * (a + b + m) * x / ((a + m2) * (a + m2 + 1.0));
        d = 1.0 / guard(1.0 + odd * d);
        c = guard(1.0 + odd / c);
        let step = d * c;
        h *= step;
        if (step - 1.0).abs() < 1e-16 || m > 1e6 {
            return h;
        }
        m += 1.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn relative(x: f64, y: f64) -> f64 {
        ((x - y) / y).abs()
    }

    /// Closed forms: `B(a, 1) = 1 / a`, `B(a, n) = (n-1)! / (a (a+1) ... (a+n-1))` for integer
    /// `n` (from `Γ(a+n) = Γ(a) a (a+1) ... (a+n-1)`), and `B(1/2, 1/2) = π`, from small to
    /// grazing arguments.
    #[test]
    fn matches_closed_forms_at_every_size() {
        for a in [0.3, 1.0, 2.5, 9.99, 10.0, 37.0, 1e3, 1e8, 1e14, 1e200] {
            assert!(relative(beta(a, 1.0), 1.0 / a) < 1e-12, "B({a}, 1)");
            for n in 2..=12 {
                let product: f64 = (0..n).map(|i| a + f64::from(i)).product();
                let factorial: f64 = (1..n).map(f64::from).product();
                let expected = (factorial.ln() - (0..n).map(|i| (a + f64::from(i)).ln()).sum::<f64>()).exp();
                if product.is_finite() {
                    assert!(relative(expected, factorial / product) < 1e-13, "oracle at {a}, {n}");
                }
                if expected < 1e-290 {
                    // Below the normal doubles (a = 1e200): zero or denormal, as it should be.
                    assert!(beta(a, f64::from(n)) < 1e-280, "B({a}, {n})");
                    continue;
                }
                assert!(relative(beta(a, f64::from(n)), expected) < 1e-11, "B({a}, {n})");
                assert!(relative(beta(f64::from(n), a), expected) < 1e-11, "B({n}, {a})");
            }
        }
        assert!(relative(beta(0.5, 0.5), std::f64::consts::PI) < 1e-14);
    }

    /// Closed forms of the incomplete Beta on both sides of the symmetry switch:
    /// `I_x(a, 1) = x^a`, `I_x(1, b) = 1 - (1-x)^b`, and `I_x(1/2, 1/2) = (2/π) asin(sqrt x)`
    /// (written `1 - (2/π) asin(sqrt(1-x))` above 1/2, where asin is ill-conditioned).
    #[test]
    fn incomplete_beta_matches_closed_forms() {
        for x in [1e-8f64, 0.01, 0.3, 0.5, 0.7, 0.99, 1.0 - 1e-9] {
            for a in [0.5, 1.0, 2.5, 40.0] {
                if x.powf(a) > 1e-300 {
                    assert!(relative(regularized_incomplete_beta(x, a, 1.0), x.powf(a)) < 1e-13, "I_{x}({a}, 1)");
                }
                let expected = -(a * (-x).ln_1p()).exp_m1();
                assert!(relative(regularized_incomplete_beta(x, 1.0, a), expected) < 1e-13, "I_{x}(1, {a})");
            }
            let arcsine = if x <= 0.5 {
                std::f64::consts::FRAC_2_PI * x.sqrt().asin()
            } else {
                1.0 - std::f64::consts::FRAC_2_PI * (1.0 - x).sqrt().asin()
            };
            assert!(relative(regularized_incomplete_beta(x, 0.5, 0.5), arcsine) < 1e-13, "I_{x}(1/2, 1/2)");
        }
    }

    /// Non-integer arguments, where no closed form is at hand: the recurrence
    /// `B(a+1, b) = B(a, b) a / (a + b)` must hold (the computation does not use it), across
    /// the switches to Stirling's series and out to grazing sizes, wherever `B` is a normal
    /// double (`ln B` above -700).
    #[test]
    fn keeps_its_recurrence_at_every_size() {
        for (a, b) in [(0.7, 2.5), (9.5, 3.5), (12.5, 15.5), (300.5, 400.25), (10.5, 1e12 + 0.5), (20.25, 3e14 + 0.5)] {
            assert!(ln_beta(a, b) > -700.0, "B({a}, {b}) is not a normal double");
            let step = beta(a + 1.0, b) / (beta(a, b) * a / (a + b)) - 1.0;
            assert!(step.abs() < 1e-12, "B({a}, {b}): {step:e}");
        }
    }
}
