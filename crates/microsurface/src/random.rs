//! Uniform and exponential variates drawn from a raw 64-bit generator.
//!
//! The physics draws from the open interval (0, 1) so that `ln(u)`, `erf_inv(2u - 1)` and
//! friends are always finite.

use rand::Rng;

const TWO_POW_M53: f64 = 1.0 / (1u64 << 53) as f64;

/// A uniform variate in the open interval (0, 1), on a grid of spacing 2^-53.
#[inline]
pub fn open01<R: Rng + ?Sized>(rng: &mut R) -> f64 {
    ((rng.next_u64() >> 11) as f64 + 0.5) * TWO_POW_M53
}

/// A standard exponential variate, `E = -ln U`.
#[inline]
pub fn exp1<R: Rng + ?Sized>(rng: &mut R) -> f64 {
    -open01(rng).ln()
}

/// A uniformly distributed unit vector `(cos phi, sin phi)` in the plane, without trigonometry:
/// a point uniform in the square `[-1, 1]^2`, kept if it falls inside the unit disk (probability
/// pi / 4) away from the centre, then normalised.
#[inline]
pub fn unit_circle<R: Rng + ?Sized>(rng: &mut R) -> (f64, f64) {
    loop {
        let x = 2.0 * open01(rng) - 1.0;
        let y = 2.0 * open01(rng) - 1.0;
        let r2 = x * x + y * y;
        if r2 <= 1.0 && r2 > 1e-12 {
            let inv = 1.0 / r2.sqrt();
            return (x * inv, y * inv);
        }
    }
}
