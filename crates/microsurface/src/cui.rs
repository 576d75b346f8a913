//! Cui et al. 2023's multiple-bounce model for conductors as its released code computes it
//! (docs/theory.md §7.3): the exact position-free estimator of §7.1 with the depth factor `S` of
//! a path replaced by the path term of the code's unidirectional estimator (`SegmentTerm` in
//! `roughconductor_mb_new_release.cpp`).
//!
//! That estimator (`evalPT_new`) weights a path of directions `d_0, ..., d_k` (`d_0` the
//! incident one, down; `d_k` the outgoing one, up) with `prod F_j * prod_{j<k} lambda_j * T`,
//! the vertex terms and rates of §7.1 and `T` the path term of [`path_term`]; the directions
//! are drawn by visible normals, the last one evaluated in closed form rather than drawn. Its
//! expectation is §7.1's with `T` in place of `S`, which is what [`ReleasedPath`] estimates on
//! the chain of [`crate::chain`], whose directions are drawn by the same laws (the last one
//! drawn too: the same integral, another estimator of it). `T` equals `S` for paths with one
//! down-to-up turn and not for two or more turns (§7.3); a conductor's paths have one turn (a
//! reflection keeps an upward direction upward), so on them the model is exact.

use crate::chain::Visibility;
use crate::position_free::DepthProfile;

/// The released code's path term `T` of a path `d_0, ..., d_k`: `steps` are `(rate, up)` of
/// `d_0, ..., d_{k-1}` (`d_0` down) and `last` the rate of the outgoing direction `d_k` (up).
///
/// Each downward step `i` (rate `l_i`) carries an end factor `1 / (last + l_i)` and an
/// accumulator `g_i`, zero when the step is taken. An upward step of rate `u` sets the newest
/// downward step's accumulator to `1 / (u + l_N)` if it is the path's first upward step and
/// divides it by `u + l_N` otherwise (so an accumulator started at zero after the first turn
/// stays zero: the two-turn discrepancy of §7.3); then, from the newest but one back to the
/// first, `g_i <- (g_i + g_{i+1}) / (u + l_i)`. The term is the product of the end factors if
/// no step is upward, else `e_1 (g_1 + e_2 (g_2 + ... + e_N g_N))`. NaN if `d_0` is not down.
pub fn path_term(steps: &[(f64, bool)], last: f64) -> f64 {
    // (rate, end factor, accumulator) of every downward step so far.
    let mut downs: Vec<(f64, f64, f64)> = Vec::new();
    let mut turned = false;
    for &(rate, up) in steps {
        if !up {
            downs.push((rate, 1.0 / (last + rate), 0.0));
            continue;
        }
        let Some(newest) = downs.last_mut() else { return f64::NAN };
        newest.2 = if turned { newest.2 } else { 1.0 } / (rate + newest.0);
        turned = true;
        for i in (0..downs.len() - 1).rev() {
            downs[i].2 = (downs[i].2 + downs[i + 1].2) / (rate + downs[i].0);
        }
    }
    if downs.is_empty() {
        return f64::NAN;
    }
    if !turned {
        return downs.iter().map(|d| d.1).product();
    }
    downs.iter().rev().fold(0.0, |inner, &(_, end, acc)| end * (acc + inner))
}

/// [`path_term`] as a [`Visibility`] of the chain: at an upward direction `d_k`, the chain's
/// weight receives the released estimator's `prod_{j<k} lambda_j * T` as the escaping
/// fraction of what it carries.
///
/// The released estimator does not deplete a path when light escapes (each order's term is
/// evaluated afresh), so what the chain carries on is free; it carries on the exact walk's
/// survival (the [`DepthProfile`]'s `1 - E` at each upward step), so that Russian roulette ends
/// its chains as it ends the exact model's, and divides each escape by the survival so far.
/// For conductors (one-sided facets that reflect): a refraction gives NaN, which the chain
/// reports as an invalid loss.
#[derive(Clone, Debug, Default)]
pub struct ReleasedPath {
    /// `(rate, up)` of the path's directions so far.
    steps: Vec<(f64, bool)>,
    /// The product of their rates.
    rates: f64,
    /// The exact depth profile, for the survival the chain carries.
    profile: DepthProfile,
    /// The survival so far, and the fraction of it that the last vertex carried on.
    alive: f64,
    carry: f64,
}

impl Visibility for ReleasedPath {
    fn enter(&mut self, rate: f64) {
        self.steps.clear();
        self.steps.push((rate, false));
        self.rates = rate;
        self.profile.enter(rate);
        self.alive = 1.0;
        self.carry = 1.0;
    }

    fn leave(&mut self, _rate_in: f64, lambda: f64, up: bool, refracted: bool) -> f64 {
        if refracted {
            return f64::NAN;
        }
        self.carry = 1.0;
        if lambda.is_infinite() {
            // Horizontal travel (probability zero): the vertex is left out of the path, as the
            // depth profile leaves it (the next collision is at the same depth).
            return 0.0;
        }
        let mut escaped = 0.0;
        if up {
            escaped = self.rates * path_term(&self.steps, lambda) / self.alive;
            self.carry = 1.0 - self.profile.up(lambda);
            self.alive *= self.carry;
        } else {
            self.profile.down(lambda);
        }
        self.steps.push((lambda, up));
        self.rates *= lambda;
        escaped
    }

    fn carried(&self, _escaped: f64) -> f64 {
        self.carry
    }
}
