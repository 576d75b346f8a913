//! Height distributions and the free flight between facet hits (THEORY.md §2.1–§2.4).
//!
//! The walk depends on a height `h` only through `u = C1(h)` (§2.1), so it runs in optical
//! depth `tau = -ln u` (§2.4) and converts to heights through the distribution only when a
//! ray comes to rest. A ray inside a dielectric sees the same surface from below: for the
//! symmetric distributions here, its depth is the depth of `-h`.

use std::f64::consts::{FRAC_1_SQRT_2, SQRT_2};

use statrs::function::erf::{erfc, erfc_inv};

/// A continuous height distribution, symmetric about 0 (§2.1).
pub trait HeightDistribution: Copy + Send + Sync {
    /// Optical depth `tau = -ln C1(h)` of height `h` seen from above (§2.4).
    fn depth(&self, h: f64) -> f64;
    /// The height at optical depth `tau`: `C1^{-1}(e^{-tau})`.
    fn height(&self, tau: f64) -> f64;
    /// The top of the support (`u = 1`, `tau = 0`), where light from outside starts (§2.1).
    fn top(&self) -> f64;
}

/// Uniform heights on [-1, 1], [H16]'s default: `C1(h) = (h + 1) / 2`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct UniformHeight;

impl HeightDistribution for UniformHeight {
    /// `-ln((h + 1) / 2)`, written with `ln_1p` to keep its digits near the top.
    #[inline]
    fn depth(&self, h: f64) -> f64 {
        -(0.5 * (h.clamp(-1.0, 1.0) - 1.0)).ln_1p()
    }

    /// `2 e^{-tau} - 1`, written with `exp_m1` for the same reason.
    #[inline]
    fn height(&self, tau: f64) -> f64 {
        1.0 + 2.0 * (-tau).exp_m1()
    }

    fn top(&self) -> f64 {
        1.0
    }
}

/// Standard normal heights, `C1(h) = (1 + erf(h / sqrt 2)) / 2` (§2.1). The top of the support
/// is `+inf`, where `u = 1` exactly (not [H16]'s `u ≈ 0.99998`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GaussianHeight;

impl HeightDistribution for GaussianHeight {
    /// Uses the tail that does not cancel: `1 - C1(h) = erfc(h / sqrt 2) / 2` for `h > 0`.
    fn depth(&self, h: f64) -> f64 {
        if h > 0.0 {
            -(-0.5 * erfc(h * FRAC_1_SQRT_2)).ln_1p()
        } else {
            -(0.5 * erfc(-h * FRAC_1_SQRT_2)).ln()
        }
    }

    fn height(&self, tau: f64) -> f64 {
        if tau < std::f64::consts::LN_2 {
            // u > 1/2: invert the upper tail 1 - u = -expm1(-tau).
            SQRT_2 * erfc_inv(-2.0 * (-tau).exp_m1())
        } else {
            -SQRT_2 * erfc_inv(2.0 * (-tau).exp())
        }
    }

    fn top(&self) -> f64 {
        f64::INFINITY
    }
}

/// Where a free flight ends (§2.3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Flight {
    /// The ray leaves the microsurface.
    Escape,
    /// The ray hits a facet at this optical depth.
    Hit(f64),
}

/// One free flight from optical depth `tau` (on the ray's own side) for a ray travelling up
/// (`up = true`, towards `tau = 0`) or down, with extinction rate `rate` and a standard
/// exponential variate `e` (§2.4): the depth travelled is `e / rate`; an upward ray escapes
/// when that exceeds `tau`. This is §2.3's `u' = u (1 - U)^{-1/Lambda}` with `e = -ln(1 - U)`.
#[inline]
pub fn fly(tau: f64, up: bool, rate: f64, e: f64) -> Flight {
    let travelled = e / rate;
    if up {
        if travelled > tau { Flight::Escape } else { Flight::Hit(tau - travelled) }
    } else {
        Flight::Hit(tau + travelled)
    }
}
