//! The fixed-point tallies: sums of per-photon weights and their powers in 64.64 fixed point
//! (`i128`), added chunk by chunk and merged exactly, with the mean, standard error and VOV
//! they give.

use serde::{Deserialize, Serialize};

use super::chunk::ChunkMoments;

/// A sum in 64.64 fixed point. Conversion truncates below 2^-64, a relative error far below
/// any statistical error this tool reports.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Fixed(i128);

const FIXED_ONE: f64 = 18_446_744_073_709_551_616.0; // 2^64

impl Fixed {
    pub fn to_f64(self) -> f64 {
        self.0 as f64 / FIXED_ONE
    }

    fn merge(&mut self, other: Fixed) {
        self.0 += other.0;
    }
}

/// `x * 2^64` truncated, built from the bits of `x` (a float-to-`i128` cast is a slow library
/// call on common targets).
#[inline]
fn to_fixed(x: f64) -> i128 {
    let bits = x.to_bits();
    let exponent = ((bits >> 52) & 0x7ff) as i32;
    if exponent == 0 || bits >> 63 != 0 {
        return 0;
    }
    let mantissa = ((bits & ((1u64 << 52) - 1)) | (1u64 << 52)) as i128;
    // x = mantissa * 2^(exponent - 1075); scaled by 2^64.
    let shift = exponent - 1075 + 64;
    if shift >= 0 {
        mantissa << shift.min(73)
    } else if shift > -64 {
        mantissa >> -shift
    } else {
        0
    }
}

/// Sum, sum of squares (per photon) and number of photons of one quantity, per channel.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Tally<const C: usize> {
    #[serde(with = "per_channel")]
    pub sum: [Fixed; C],
    #[serde(with = "per_channel")]
    pub sum_sq: [Fixed; C],
    pub count: u64,
}

/// Serde for `[Fixed; C]` (serde's own array support does not cover a generic length).
mod per_channel {
    use serde::de::Error;
    use serde::{Deserialize, Deserializer, Serializer};

    use super::Fixed;

    pub fn serialize<S: Serializer, const C: usize>(values: &[Fixed; C], s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(values)
    }

    pub fn deserialize<'de, D: Deserializer<'de>, const C: usize>(d: D) -> Result<[Fixed; C], D::Error> {
        let values = Vec::<Fixed>::deserialize(d)?;
        let n = values.len();
        values.try_into().map_err(|_| D::Error::custom(format!("{n} channels where {C} were expected")))
    }
}

impl<const C: usize> Default for Tally<C> {
    fn default() -> Self {
        Self { sum: [Fixed::default(); C], sum_sq: [Fixed::default(); C], count: 0 }
    }
}

/// One photon's contribution to a tally in fixed point: per channel, the weight and its square.
/// Converted once, it can be added to every tally the photon reaches.
#[derive(Clone, Copy, Debug)]
struct Contribution<const C: usize> {
    sum: [i128; C],
    sum_sq: [i128; C],
}

impl<const C: usize> Contribution<C> {
    #[inline]
    fn of(w: &[f64; C]) -> Self {
        Self { sum: w.map(to_fixed), sum_sq: w.map(|x| to_fixed(x * x)) }
    }
}

impl<const C: usize> Tally<C> {
    /// Adds one photon's total contribution.
    #[inline]
    pub fn add(&mut self, w: &[f64; C]) {
        self.add_contribution(&Contribution::of(w));
    }

    #[inline]
    fn add_contribution(&mut self, c: &Contribution<C>) {
        for i in 0..C {
            self.sum[i].0 += c.sum[i];
            self.sum_sq[i].0 += c.sum_sq[i];
        }
        self.count += 1;
    }

    /// Adds the sums of weights and squared weights of `photons` photons of a chunk, kept in
    /// floating point while the chunk was walked (see [`ChunkBin`](super::chunk::ChunkBin)).
    pub(super) fn add_chunk(&mut self, sum: &[f64; C], sum_sq: &[f64; C], photons: u32) {
        for i in 0..C {
            self.sum[i].0 += to_fixed(sum[i]);
            self.sum_sq[i].0 += to_fixed(sum_sq[i]);
        }
        self.count += u64::from(photons);
    }

    /// Adds `n` photons of weight exactly 1 in every channel: `n` times the contribution
    /// `2^64` (1 in fixed point) to each sum, exactly.
    pub(super) fn add_units(&mut self, n: u32) {
        let units = i128::from(n) << 64;
        for i in 0..C {
            self.sum[i].0 += units;
            self.sum_sq[i].0 += units;
        }
        self.count += u64::from(n);
    }

    pub(super) fn merge(&mut self, other: &Self) {
        for (a, b) in self.sum.iter_mut().zip(&other.sum).chain(self.sum_sq.iter_mut().zip(&other.sum_sq)) {
            a.merge(*b);
        }
        self.count += other.count;
    }

    /// The mean per photon over `photons` photons and its standard error (sample variance of
    /// the per-photon contributions, zeros included), for channel `c`.
    pub fn mean_and_stderr(&self, photons: u64, c: usize) -> (f64, f64) {
        let n = photons as f64;
        let mean = self.sum[c].to_f64() / n;
        let var = ((self.sum_sq[c].to_f64() / n - mean * mean) * n / (n - 1.0)).max(0.0);
        (mean, (var / n).sqrt())
    }
}

/// A tally that also keeps the per-photon third and fourth powers, for the variance of its
/// variance (VOV, docs/theory.md §9.5). Kept for albedos and the energy balance, where a user
/// reads one number and needs to know whether its standard error can be trusted; the bins,
/// many thousands per lobe, keep plain [`Tally`]s.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Moments<const C: usize> {
    pub tally: Tally<C>,
    #[serde(with = "per_channel")]
    pub sum_cube: [Fixed; C],
    #[serde(with = "per_channel")]
    pub sum_fourth: [Fixed; C],
}

/// One photon's contribution to a [`Moments`] tally in fixed point: its [`Contribution`] and
/// the third and fourth powers of its weight.
#[derive(Clone, Copy, Debug)]
pub(super) struct MomentContribution<const C: usize> {
    low: Contribution<C>,
    cube: [i128; C],
    fourth: [i128; C],
}

impl<const C: usize> MomentContribution<C> {
    /// A photon of weight exactly 1 in every channel: every power is 1.
    pub(super) const UNIT: Self = {
        const ONE: i128 = 1 << 64;
        Self { low: Contribution { sum: [ONE; C], sum_sq: [ONE; C] }, cube: [ONE; C], fourth: [ONE; C] }
    };
}

impl<const C: usize> Default for Moments<C> {
    fn default() -> Self {
        Self { tally: Tally::default(), sum_cube: [Fixed::default(); C], sum_fourth: [Fixed::default(); C] }
    }
}

impl<const C: usize> Moments<C> {
    #[inline]
    pub(super) fn add_contribution(&mut self, c: &MomentContribution<C>) {
        self.tally.add_contribution(&c.low);
        for i in 0..C {
            self.sum_cube[i].0 += c.cube[i];
            self.sum_fourth[i].0 += c.fourth[i];
        }
    }

    /// Adds a chunk's sums of powers of per-photon weights (see [`ChunkMoments`]).
    pub(super) fn add_chunk(&mut self, m: &ChunkMoments<C>) {
        self.tally.add_chunk(&m.sum, &m.sum_sq, m.photons);
        for i in 0..C {
            self.sum_cube[i].0 += to_fixed(m.sum_cube[i]);
            self.sum_fourth[i].0 += to_fixed(m.sum_fourth[i]);
        }
    }

    pub(super) fn merge(&mut self, other: &Self) {
        self.tally.merge(&other.tally);
        for (a, b) in
            self.sum_cube.iter_mut().zip(&other.sum_cube).chain(self.sum_fourth.iter_mut().zip(&other.sum_fourth))
        {
            a.merge(*b);
        }
    }

    /// [`Tally::mean_and_stderr`].
    pub fn mean_and_stderr(&self, photons: u64, c: usize) -> (f64, f64) {
        self.tally.mean_and_stderr(photons, c)
    }

    /// The relative variance of the variance of the mean over `photons` photons, channel `c`
    /// (MCNP's VOV, §9.5): `sum (x - m)^4 / (sum (x - m)^2)^2 - 1/N`, with the central sums
    /// expanded in the raw ones. 0 where the photons do not vary.
    pub fn vov(&self, photons: u64, c: usize) -> f64 {
        let n = photons as f64;
        let s1 = self.tally.sum[c].to_f64();
        let (s2, s3, s4) = (self.tally.sum_sq[c].to_f64(), self.sum_cube[c].to_f64(), self.sum_fourth[c].to_f64());
        let m = s1 / n;
        let second = s2 - n * m * m;
        let fourth = s4 - 4.0 * m * s3 + 6.0 * m * m * s2 - 3.0 * n * m.powi(4);
        // Rounding leaves `second` at about 1e-16 s2 where every photon carries the mean.
        if second <= 1e-12 * s2 || n < 2.0 {
            return 0.0;
        }
        (fourth / (second * second) - 1.0 / n).max(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_pcg::Pcg64Mcg;

    /// The VOV from two-pass central moments of the sample itself.
    fn vov_two_pass(x: &[f64]) -> f64 {
        let n = x.len() as f64;
        let m = x.iter().sum::<f64>() / n;
        let (c2, c4) = x.iter().fold((0.0, 0.0), |(a, b), &v| (a + (v - m).powi(2), b + (v - m).powi(4)));
        c4 / (c2 * c2) - 1.0 / n
    }

    /// The moments of weights `x`, summed as the detector sums them: in floating point over
    /// chunks (of 1000 photons here), converted to fixed point at each chunk's end.
    fn in_chunks(x: &[f64]) -> Moments<1> {
        let mut m = Moments::<1>::default();
        for chunk in x.chunks(1000) {
            let mut sums = ChunkMoments::<1>::default();
            for &v in chunk {
                sums.add(&[v]);
            }
            m.add_chunk(&sums);
        }
        m
    }

    #[test]
    fn vov_matches_central_moments_and_the_bernoulli_closed_form() {
        // Weights spread over four decades, as splitting and roulette make them, and a few
        // large ones: the raw-sum expansion against the two-pass central moments.
        let mut rng = Pcg64Mcg::seed_from_u64(11);
        let x: Vec<f64> = (0..20_000)
            .map(|i| if i % 997 == 0 { 3.0 } else { 10f64.powf(-4.0 * microsurface::random::open01(&mut rng)) })
            .collect();
        let t = in_chunks(&x);
        let (got, want) = (t.vov(x.len() as u64, 0), vov_two_pass(&x));
        assert!((got - want).abs() < 1e-9 * want, "VOV {got} against two-pass {want}");
        // Weights 0 or 1 with mean p: (1 - 2p)^2 / (N p (1 - p)) (docs/theory.md §9.5), and
        // photons of weight 1 counted as units give the same.
        let (n, ones) = (1000u64, 37u64);
        let mut units = in_chunks(&vec![0.0; (n - ones) as usize]);
        for _ in 0..ones {
            units.add_contribution(&MomentContribution::UNIT);
        }
        let p = ones as f64 / n as f64;
        let closed = (1.0 - 2.0 * p).powi(2) / (n as f64 * p * (1.0 - p));
        assert!((units.vov(n, 0) - closed).abs() < 1e-12, "{} against {closed}", units.vov(n, 0));
        // Every photon the same: no variance, VOV 0 (not 0/0).
        let same = in_chunks(&[0.25; 100]);
        assert_eq!(same.vov(100, 0), 0.0);
    }
}
