//! The exact position-free form of the walk (docs/theory.md §7.1; Bitterli and d'Eon 2022): the
//! collision depths of a path of directions integrated out analytically, for facets that
//! reflect on one side (conductor, Lambertian, Hammon).
//!
//! Along a fixed path of directions the depth of the `j`-th collision has a sub-density
//! `psi_j(tau) = sum_i c_i e^{-beta_i tau}` over the optical depth of §2.4, whose mass is the
//! probability of reaching that collision. The light enters along `d_0` of depth rate
//! `lambda_0`: `psi_1 = lambda_0 e^{-lambda_0 tau}`. Leaving a collision along `d` of rate
//! `lambda`:
//!
//! * upwards, the light escapes with probability `E = sum_i c_i / (beta_i + lambda)`, and
//!   collides again at `psi' = sum_i lambda c_i / (beta_i + lambda) e^{-beta_i tau}`, of mass
//!   `1 - E` times the old one;
//! * downwards, it always collides again, at
//!   `psi' = sum_i lambda c_i / (lambda - beta_i) (e^{-beta_i tau} - e^{-lambda tau})`.
//!
//! The probability of escaping at the last step of a path (the survival fractions `1 - E` of
//! its earlier upward steps times the last `E`) is the product of its rates times the
//! depth factor `S` of docs/theory.md §7.1. Run on the chain of [`crate::chain`], which draws the
//! directions as the walk does, this estimates exactly the walk's per-order lobes, without
//! heights and with the escape event replaced by its probability. The profile is kept
//! normalised to mass 1, so `E` is the fraction of the chain's current weight that escapes.
//! Dielectrics do not collapse to one slab (the depth coordinates of the two sides differ);
//! a refraction gives NaN, which the chain reports as an invalid loss.

use crate::chain::Visibility;

/// Rates closer than this (relative) are separated before a downward step divides by their
/// difference (§7.1, numerics); the perturbation is far below any statistical error.
const MIN_GAP: f64 = 1e-7;

/// The depth sub-density of the next collision along the path so far, as a sum of
/// exponentials `(c_i, beta_i)` of mass `sum_i c_i / beta_i = 1`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DepthProfile {
    terms: Vec<(f64, f64)>,
}

impl DepthProfile {
    /// The probability that light at the profile's collision leaving upwards with depth rate
    /// `lambda` escapes.
    fn escape(&self, lambda: f64) -> f64 {
        self.terms.iter().map(|&(c, beta)| c / (beta + lambda)).sum::<f64>()
    }

    /// Rescales the profile to mass 1 (it is exactly 1 in exact arithmetic after a downward
    /// step, and `1 - E` after an upward one).
    fn normalise(&mut self) {
        let mass: f64 = self.terms.iter().map(|&(c, beta)| c / beta).sum();
        if mass > 0.0 && mass.is_finite() {
            self.terms.iter_mut().for_each(|t| t.0 /= mass);
        } else {
            self.terms.clear();
        }
    }

    /// Leaves the profile's collision upwards with rate `lambda`; returns the escape probability.
    pub fn up(&mut self, lambda: f64) -> f64 {
        if lambda.is_infinite() {
            // Horizontal travel: the next collision is at the same depth, nothing escapes.
            return 0.0;
        }
        let escape = self.escape(lambda).clamp(0.0, 1.0);
        for t in &mut self.terms {
            t.0 *= lambda / (t.1 + lambda);
        }
        self.normalise();
        escape
    }

    /// Leaves the profile's collision downwards with rate `lambda`.
    pub fn down(&mut self, lambda: f64) {
        if lambda.is_infinite() {
            return;
        }
        let mut lambda = lambda;
        while self.terms.iter().any(|&(_, beta)| (lambda - beta).abs() < MIN_GAP * lambda) {
            lambda *= 1.0 + 10.0 * MIN_GAP;
        }
        let mut new = 0.0;
        for t in &mut self.terms {
            let k = lambda / (lambda - t.1);
            new -= k * t.0;
            t.0 *= k;
        }
        self.terms.push((new, lambda));
        self.normalise();
    }
}

impl Visibility for DepthProfile {
    fn enter(&mut self, rate: f64) {
        self.terms.clear();
        self.terms.push((rate, rate));
    }

    fn leave(&mut self, _rate_in: f64, lambda: f64, up: bool, refracted: bool) -> f64 {
        if refracted {
            return f64::NAN;
        }
        if up {
            self.up(lambda)
        } else {
            self.down(lambda);
            0.0
        }
    }
}
