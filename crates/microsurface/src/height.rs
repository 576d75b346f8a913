//! The height process of the walk in optical depth (docs/theory.md §2.1–§2.4).
//!
//! The walk depends on a height `h` only through `u = C1(h)` (§2.1), so it runs in optical
//! depth `tau = -ln u` (§2.4): a semi-infinite homogeneous slab in which free paths are
//! exponential. Working in depth never round-trips through `C1^{-1}`, never underflows `u`,
//! and makes the independence of the height distribution exact: any continuous height law
//! gives bit-identical walks. (Heights on [-1, 1] would cap the representable depth at about
//! 37, which Hammon's symmetric Lambda exceeds routinely, §2.7.)

/// Where a free flight ends (§2.3): out of the microsurface, or at a facet at depth `tau`
/// (meaningless for an escape). A pair rather than a choice, so that a walk can act on it
/// without a branch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Flight {
    /// The ray leaves the microsurface.
    pub escapes: bool,
    /// The optical depth of the facet hit, if it does not.
    pub tau: f64,
    /// If it escapes: the part of the exponential variate beyond what the escape took,
    /// `e - rate tau`. The exponential law has no memory, so given the escape this is again a
    /// standard exponential variate, independent of the flight and of all before it: one
    /// draw can serve the next photon (§2.4).
    pub excess: f64,
}

/// One free flight from optical depth `tau` (on the ray's own side) for a ray travelling up
/// (`up = true`, towards `tau = 0`) or down, with extinction rate `rate` and a standard
/// exponential variate `e` (§2.4): the depth travelled is `e / rate`; an upward ray escapes
/// when that exceeds `tau`. This is §2.3's `u' = u (1 - U)^{-1/Lambda}` with `e = -ln(1 - U)`.
#[inline]
pub fn fly(tau: f64, up: bool, rate: f64, e: f64) -> Flight {
    let travelled = e / rate;
    // Whether a ray goes up is a coin toss for the branch predictor: select, do not branch.
    let tau_hit = std::hint::select_unpredictable(up, tau - travelled, tau + travelled);
    Flight { escapes: up && travelled > tau, tau: tau_hit, excess: e - rate * tau }
}

/// The probability that a ray going up with rate `lambda` (`Lambda` of its direction) leaves
/// the microsurface from depth `tau` without another hit, `G1 = u^Lambda = e^{-Lambda tau}`
/// (§2.2): 1 at the top (`tau = 0`, `u = 1`) whatever the rate, even the infinite one of a
/// direction on the horizon, where the product `Lambda tau` has no value.
#[inline]
pub fn escape_probability(lambda: f64, tau: f64) -> f64 {
    if tau == 0.0 { 1.0 } else { (-lambda * tau).exp() }
}

/// The optical depth of the same point seen from the other side of the heightfield (§4.3):
/// `-ln(1 - u)` with `u = e^{-tau}`, evaluated without cancellation at either end.
#[inline]
pub fn other_side_depth(tau: f64) -> f64 {
    if tau > std::f64::consts::LN_2 { -(-(-tau).exp()).ln_1p() } else { -(-(-tau).exp_m1()).ln() }
}
