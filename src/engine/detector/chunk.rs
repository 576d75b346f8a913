//! The floating-point sums over the photons of the chunk being walked, and over the photon in
//! flight, that feed the fixed-point tallies when the chunk ends.

/// One bin's sums over the photons of the chunk being walked, in floating point: the weight
/// each photon left in the bin, its square, and how many photons reached it. A chunk's
/// photons are walked in a fixed order by one thread, so these sums, and the fixed-point
/// values they are converted to when the chunk ends ([`Detector::end_chunk`](super::Detector::end_chunk)), depend only
/// on the chunk. At 32 bytes (one channel), against the 48 of a [`Tally`](super::tally::Tally), the bins touched
/// by a photon stay in cache more often, and a deposit converts nothing.
#[derive(Clone, Copy, Debug)]
pub(super) struct ChunkBin<const C: usize> {
    /// The photon in flight's deposits in the bin so far ([`Observer::escape`]; a photon that
    /// was split escapes several times), summed before squaring, so variances stay per photon
    /// (§4.6).
    pub(super) photon: [f64; C],
    pub(super) sum: [f64; C],
    pub(super) sum_sq: [f64; C],
    pub(super) photons: u32,
    /// Whether the current photon has deposited in the bin.
    pub(super) reached: bool,
}

impl<const C: usize> Default for ChunkBin<C> {
    fn default() -> Self {
        Self { photon: [0.0; C], sum: [0.0; C], sum_sq: [0.0; C], photons: 0, reached: false }
    }
}

impl<const C: usize> ChunkBin<C> {
    /// Adds one photon's weight `w` in the bin.
    #[inline]
    pub(super) fn add(&mut self, w: &[f64; C]) {
        for ((sum, sum_sq), &x) in self.sum.iter_mut().zip(&mut self.sum_sq).zip(w) {
            *sum += x;
            *sum_sq += x * x;
        }
        self.photons += 1;
    }
}

/// An albedo's or the accounted weight's sums over the photons of the chunk being walked, in
/// floating point like [`ChunkBin`]'s: the first four powers of each photon's weight, for the
/// standard error and the VOV (§9.5), and the number of photons.
#[derive(Clone, Copy, Debug)]
pub(super) struct ChunkMoments<const C: usize> {
    pub(super) sum: [f64; C],
    pub(super) sum_sq: [f64; C],
    pub(super) sum_cube: [f64; C],
    pub(super) sum_fourth: [f64; C],
    pub(super) photons: u32,
}

impl<const C: usize> Default for ChunkMoments<C> {
    fn default() -> Self {
        Self { sum: [0.0; C], sum_sq: [0.0; C], sum_cube: [0.0; C], sum_fourth: [0.0; C], photons: 0 }
    }
}

impl<const C: usize> ChunkMoments<C> {
    /// Adds one photon's weight `w`.
    #[inline]
    pub(super) fn add(&mut self, w: &[f64; C]) {
        for (i, &x) in w.iter().enumerate() {
            let sq = x * x;
            self.sum[i] += x;
            self.sum_sq[i] += sq;
            self.sum_cube[i] += sq * x;
            self.sum_fourth[i] += sq * sq;
        }
        self.photons += 1;
    }
}

/// What the photon in flight has deposited so far, summed as it escapes (a photon that was
/// split escapes several times, and its deposits per bin and per albedo are summed before
/// squaring, so variances stay per photon, §4.6): the bins it reached (their sums are the
/// `photon` field of [`ChunkBin`]), in the order first reached, and its sums per hemisphere
/// of every slot (`2 slot + hemisphere`) with the ones reached. Summing at each escape, not
/// when the photon ends, lets the bins' memory traffic overlap the walk's arithmetic. Every
/// sum is back to zero when the photon is done, so no photon allocates.
#[derive(Clone, Debug)]
pub(super) struct PhotonSums<const C: usize> {
    pub(super) bins_reached: Vec<usize>,
    pub(super) albedos: Vec<Sum<C>>,
    pub(super) albedos_reached: Vec<usize>,
}

impl<const C: usize> Default for PhotonSums<C> {
    fn default() -> Self {
        Self { bins_reached: Vec::new(), albedos: Vec::new(), albedos_reached: Vec::new() }
    }
}

/// A photon's running sum into one tally, and whether any deposit (even of weight 0) reached it.
#[derive(Clone, Copy, Debug)]
pub(super) struct Sum<const C: usize> {
    pub(super) weight: [f64; C],
    pub(super) reached: bool,
}

impl<const C: usize> Default for Sum<C> {
    fn default() -> Self {
        Self { weight: [0.0; C], reached: false }
    }
}

/// Adds `w` to `sums[key]`, noting `key` in `touched` the first time.
#[inline]
pub(super) fn add_to_sum<const C: usize>(sums: &mut [Sum<C>], touched: &mut Vec<usize>, key: usize, w: &[f64; C]) {
    let sum = &mut sums[key];
    if !sum.reached {
        sum.reached = true;
        touched.push(key);
    }
    accumulate(&mut sum.weight, w);
}

/// `acc += w`, channel by channel.
#[inline]
pub(super) fn accumulate<const C: usize>(acc: &mut [f64; C], w: &[f64; C]) {
    for (a, x) in acc.iter_mut().zip(w) {
        *a += x;
    }
}
