//! Uniform and exponential variates drawn from a raw 64-bit generator.
//!
//! The physics draws from the open interval (0, 1) so that `ln(u)`, `erf_inv(2u - 1)` and
//! friends are always finite.

use rand::Rng;
use rand_distr::Distribution;

const TWO_POW_M53: f64 = 1.0 / (1u64 << 53) as f64;

/// A uniform variate in the open interval (0, 1), on a grid of spacing 2^-53.
#[inline]
pub fn open01<R: Rng + ?Sized>(rng: &mut R) -> f64 {
    ((rng.next_u64() >> 11) as f64 + 0.5) * TWO_POW_M53
}

/// A standard exponential variate, drawn by the ziggurat method (Marsaglia & Tsang 2000):
/// exact in distribution, and without a logarithm for all but about 1% of the draws.
#[inline]
pub fn exp1<R: Rng + ?Sized>(rng: &mut R) -> f64 {
    rand_distr::Exp1.sample(rng)
}

/// A uniformly distributed unit vector `(cos phi, sin phi)` in the plane, without trigonometry
/// or square root (von Neumann 1951): a point `(x, y)` uniform in the unit disk, drawn by
/// rejection from the square `[-1, 1]^2` (probability pi / 4) away from the centre, has a
/// uniform polar angle `theta`, so `phi = 2 theta` is uniform too, with
/// `(cos 2 theta, sin 2 theta) = (x^2 - y^2, 2 x y) / (x^2 + y^2)`.
#[inline]
pub fn unit_circle<R: Rng + ?Sized>(rng: &mut R) -> (f64, f64) {
    loop {
        let x = 2.0 * open01(rng) - 1.0;
        let y = 2.0 * open01(rng) - 1.0;
        let r2 = x * x + y * y;
        if r2 <= 1.0 && r2 > 1e-12 {
            let inv = 1.0 / r2;
            return ((x * x - y * y) * inv, 2.0 * x * y * inv);
        }
    }
}
