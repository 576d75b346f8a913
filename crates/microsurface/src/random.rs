//! Uniform and exponential variates drawn from a raw 64-bit generator.
//!
//! The physics draws from the open interval (0, 1) so that `ln(u)`, `erf_inv(2u - 1)` and
//! friends are always finite.

use rand::Rng;
use rand_distr::Distribution;

const TWO_POW_M53: f64 = 1.0 / (1u64 << 53) as f64;

/// The largest double below 1, `1 - 2^-53`.
const BELOW_ONE: f64 = 1.0 - TWO_POW_M53;

/// A uniform variate in the open interval (0, 1): `(k + 1/2) 2^-53` for the draw's top 53 bits
/// `k`, rounded to the nearest double. Above 1/2, where doubles are 2^-53 apart, these are
/// ties that go to even, so the values there lie on a grid of 2^-52, two draws each; the last,
/// `1 - 2^-54`, would round to 1 and is taken as `1 - 2^-53` (a Lambertian exit would
/// otherwise leave along the horizon).
#[inline]
pub fn open01<R: Rng + ?Sized>(rng: &mut R) -> f64 {
    (((rng.next_u64() >> 11) as f64 + 0.5) * TWO_POW_M53).min(BELOW_ONE)
}

/// A standard exponential variate, drawn by the ziggurat method (Marsaglia & Tsang 2000):
/// exact in distribution, and without a logarithm for all but about 1% of the draws.
#[inline]
pub fn exp1<R: Rng + ?Sized>(rng: &mut R) -> f64 {
    rand_distr::Exp1.sample(rng)
}

/// A standard normal variate, drawn by the ziggurat method (Marsaglia & Tsang 2000): exact in
/// distribution, mostly without a logarithm.
#[inline]
pub fn normal1<R: Rng + ?Sized>(rng: &mut R) -> f64 {
    rand_distr::StandardNormal.sample(rng)
}

/// Sectors of the azimuth table: the top `SECTOR_BITS` bits of a draw pick a sector of the
/// circle, the next 53 bits the offset inside it.
const SECTOR_BITS: u32 = 8;
const SECTORS: usize = 1 << SECTOR_BITS;
const SECTOR_ANGLE: f64 = std::f64::consts::TAU / SECTORS as f64;

/// `(cos, sin)` of the sector starts `2 pi k / 256`, built at compile time: Taylor series on
/// the first octant (angles up to pi / 4, where the terms beyond `x^24` are below 10^-25), the other
/// octants by the exact symmetries `(c, s) -> (s, c)` and quarter turns.
static SECTOR_START: [(f64, f64); SECTORS] = sector_starts();

const fn sector_starts() -> [(f64, f64); SECTORS] {
    /// `(cos x, sin x)` for `0 <= x <= pi / 4` by their Maclaurin series to `x^24`, in Horner form.
    const fn first_octant(x: f64) -> (f64, f64) {
        let x2 = x * x;
        let (mut c, mut s) = (1.0, 1.0);
        let mut n = 12;
        while n > 0 {
            c = 1.0 - c * x2 / ((2 * n - 1) * (2 * n)) as f64;
            s = 1.0 - s * x2 / ((2 * n) * (2 * n + 1)) as f64;
            n -= 1;
        }
        (c, x * s)
    }
    let quarter = SECTORS / 4;
    let mut table = [(0.0, 0.0); SECTORS];
    let mut k = 0;
    while k < SECTORS {
        let j = k % quarter;
        let (c, s) = if 2 * j <= quarter {
            first_octant(j as f64 * SECTOR_ANGLE)
        } else {
            let (c, s) = first_octant((quarter - j) as f64 * SECTOR_ANGLE);
            (s, c)
        };
        table[k] = match k / quarter {
            0 => (c, s),
            1 => (-s, c),
            2 => (-c, -s),
            _ => (s, -c),
        };
        k += 1;
    }
    table
}

/// A uniformly distributed azimuth as the unit vector `(cos phi, sin phi)`, from one 64-bit
/// draw, without trigonometry or branches: `phi = 2 pi (k + f) / 256` with the sector `k` from
/// the top 8 bits and `f` in [0, 1) from the next 53, so `phi` is uniform on a grid of 2^61
/// points. The sector start comes from a table and the rotation by `d = 2 pi f / 256 < 0.025`
/// from the Taylor polynomials of `cos d` and `sin d`, whose first omitted terms
/// (`d^8 / 8!`, `d^9 / 9!`) are below 10^-17.
#[inline]
pub fn azimuth<R: Rng + ?Sized>(rng: &mut R) -> (f64, f64) {
    let bits = rng.next_u64();
    let (c0, s0) = SECTOR_START[(bits >> (64 - SECTOR_BITS)) as usize];
    let d = ((bits << SECTOR_BITS) >> 11) as f64 * (TWO_POW_M53 * SECTOR_ANGLE);
    let d2 = d * d;
    let cos_d = 1.0 - d2 * (1.0 / 2.0 - d2 * (1.0 / 24.0 - d2 * (1.0 / 720.0)));
    let sin_d = d * (1.0 - d2 * (1.0 / 6.0 - d2 * (1.0 / 120.0 - d2 * (1.0 / 5040.0))));
    (c0 * cos_d - s0 * sin_d, s0 * cos_d + c0 * sin_d)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    /// `(cos, sin)` of the table's angle `(k mod 64) 2 pi / 256 + (k div 64) pi / 2` (whole
    /// quarter turns, by the symmetries) from the library functions, evaluated at the nearest
    /// f64 angle and corrected to first order for the difference: the rounding of `k a`
    /// (recovered exactly by a fused multiply-add) plus `pi / 2 - f64(pi / 2) = 6.123e-17`
    /// (fdlibm's `pio2_lo`) per quarter turn.
    fn library_sector_start(k: u64) -> (f64, f64) {
        const PIO2_LO: f64 = 6.123_233_995_736_766e-17;
        let phi = k as f64 * SECTOR_ANGLE;
        let offset = (k as f64).mul_add(SECTOR_ANGLE, -phi) + (k / 64) as f64 * PIO2_LO;
        (phi.cos() - phi.sin() * offset, phi.sin() + phi.cos() * offset)
    }

    #[test]
    fn sector_starts_match_the_library_cosine_and_sine() {
        for (k, &(c, s)) in SECTOR_START.iter().enumerate() {
            let (cos, sin) = library_sector_start(k as u64);
            assert!((c - cos).abs() <= 2.3e-16 && (s - sin).abs() <= 2.3e-16, "sector {k}: {} {}", c - cos, s - sin);
        }
    }

    /// A generator that always returns the same 64 bits.
    struct Fixed(u64);
    impl rand::TryRng for Fixed {
        type Error = std::convert::Infallible;
        fn try_next_u32(&mut self) -> Result<u32, Self::Error> {
            Ok(self.0 as u32)
        }
        fn try_next_u64(&mut self) -> Result<u64, Self::Error> {
            Ok(self.0)
        }
        fn try_fill_bytes(&mut self, _: &mut [u8]) -> Result<(), Self::Error> {
            unimplemented!()
        }
    }

    /// `open01` of the smallest draw is half a grid step above 0, so `ln(u)` is finite.
    #[test]
    fn open01_of_the_smallest_draw_is_positive() {
        assert_eq!(open01(&mut Fixed(0)), 0.5 * TWO_POW_M53);
    }

    /// `open01` of the largest draw is below 1, so `ln(1 - u)` stays finite and `sqrt(1 - u)` positive;
    /// the draw below it keeps its own value, `1 - 3 2^-54` rounded to even, `1 - 2^-52`.
    #[test]
    fn open01_of_the_largest_draw_is_below_one() {
        assert_eq!(open01(&mut Fixed(u64::MAX)), 1.0 - TWO_POW_M53);
        assert_eq!(open01(&mut Fixed(u64::MAX - (1 << 11))), 1.0 - 2.0 * TWO_POW_M53);
    }

    /// Against `cos` and `sin` of the angle the bits encode, at draws that hit every sector,
    /// both sector edges and the middle.
    #[test]
    fn azimuth_is_the_cosine_and_sine_of_the_encoded_angle() {
        let mut random = rand_pcg::Pcg64Mcg::seed_from_u64(3);
        let offsets = [0u64, 1 << 55, (1 << 56) - 1, random.next_u64() >> 8, random.next_u64() >> 8];
        for k in 0..SECTORS as u64 {
            let (start_cos, start_sin) = library_sector_start(k);
            for &offset in &offsets {
                let d = (offset >> 3) as f64 * TWO_POW_M53 * SECTOR_ANGLE;
                let cos = start_cos * d.cos() - start_sin * d.sin();
                let sin = start_sin * d.cos() + start_cos * d.sin();
                let (c, s) = azimuth(&mut Fixed((k << 56) | offset));
                assert!(
                    (c - cos).abs() <= 4e-16 && (s - sin).abs() <= 4e-16,
                    "sector {k}, offset {offset:#x}: {c} {s}"
                );
            }
        }
    }

    /// Pearson chi-square of 10^6 draws of `atan2(s, c)` in 64 equal sectors against the
    /// uniform law (expected 15625 per bin, 63 degrees of freedom, level 10^-3, fixed seed).
    #[test]
    fn azimuths_are_uniform() {
        use statrs::distribution::{ChiSquared, ContinuousCDF};
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(11);
        let (n, bins) = (1_000_000, 64);
        let mut counts = vec![0u64; bins];
        for _ in 0..n {
            let (c, s) = azimuth(&mut rng);
            let phi = s.atan2(c).rem_euclid(std::f64::consts::TAU);
            counts[((phi / std::f64::consts::TAU * bins as f64) as usize).min(bins - 1)] += 1;
        }
        let expected = n as f64 / bins as f64;
        let chi2: f64 = counts.iter().map(|&o| (o as f64 - expected).powi(2) / expected).sum();
        let p = ChiSquared::new((bins - 1) as f64).unwrap().sf(chi2);
        assert!(p > 1e-3, "chi2 = {chi2}, p = {p}");
    }
}
