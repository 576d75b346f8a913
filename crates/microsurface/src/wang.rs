//! The position-free multiple-bounce models of Wang et al. 2022 (docs/theory.md §6), evaluated as
//! height-free chains of visible-normal scatterings ([`crate::chain`], §6.5).
//!
//! At vertex `j`, a direction `d_j` pointing away from the surface on its side escapes with a
//! local probability (§6.3, "Reading as local escape probabilities"):
//!
//! * height-correlated: `lambda_{j-1} / (lambda_{j-1} + Lambda(d_j))` after a reflection and
//!   `lambda_{j-1} B(lambda_{j-1}, 1 + Lambda(d_j))` after a refraction, with
//!   `lambda_{j-1} = lambda(d_{j-1})` the depth rate of the arriving direction;
//! * height-uncorrelated: `G1(d_j) = 1 / (1 + Lambda(d_j))`;
//!
//! and a direction into the surface continues with probability 1. Both variants conserve
//! energy exactly, and the correlated one reproduces exact single scattering (§6.3).

use crate::beta::beta;
use crate::chain::Visibility;

/// The shadowing model of the chain (§6.3).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shadowing {
    /// Height-correlated: each vertex restarts at a depth drawn for its arriving direction.
    Correlated,
    /// Height-uncorrelated: escape with the separable masking `G1` of the leaving direction.
    Uncorrelated,
}

impl Visibility for Shadowing {
    /// Wang's models forget the path: nothing to start.
    fn enter(&mut self, _rate: f64) {}

    /// The local escape probability of a direction leaving a vertex reached along a direction
    /// of depth rate `rate_in` (§6.3); 0 into the surface. Upwards, the leaving direction's
    /// depth rate is its `Lambda`.
    fn leave(&mut self, rate_in: f64, lambda_out: f64, up: bool, refracted: bool) -> f64 {
        if !up {
            return 0.0;
        }
        match (self, refracted) {
            (Shadowing::Uncorrelated, _) => 1.0 / (1.0 + lambda_out),
            (Shadowing::Correlated, false) => rate_in / (rate_in + lambda_out),
            (Shadowing::Correlated, true) => rate_in * beta(rate_in, 1.0 + lambda_out),
        }
    }
}
