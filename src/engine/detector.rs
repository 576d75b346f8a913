//! The virtual gonioreflectometer: angular histograms of escaping light per bounce order and
//! hemisphere, with per-photon second moments for standard errors (docs/theory.md §4.7).
//!
//! A chunk's photons, walked in a fixed order by one thread, are summed in f64; when the chunk
//! ends its sums are added to tallies kept in 64.64 fixed point (`i128`). Integer addition is
//! associative, so the totals do not depend on how chunks are distributed over threads,
//! shards or machines: the same photons give bit-identical outputs however the work is split.

use glam::DVec3;
use microsurface::facet::Side;
use microsurface::walk::{Loss, Observer};
use serde::{Deserialize, Serialize};

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
    /// floating point while the chunk was walked (see [`ChunkBin`]).
    fn add_chunk(&mut self, sum: &[f64; C], sum_sq: &[f64; C], photons: u32) {
        for i in 0..C {
            self.sum[i].0 += to_fixed(sum[i]);
            self.sum_sq[i].0 += to_fixed(sum_sq[i]);
        }
        self.count += u64::from(photons);
    }

    /// Adds `n` photons of weight exactly 1 in every channel: `n` times the contribution
    /// `2^64` (1 in fixed point) to each sum, exactly.
    fn add_units(&mut self, n: u32) {
        let units = i128::from(n) << 64;
        for i in 0..C {
            self.sum[i].0 += units;
            self.sum_sq[i].0 += units;
        }
        self.count += u64::from(n);
    }

    fn merge(&mut self, other: &Self) {
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
struct MomentContribution<const C: usize> {
    low: Contribution<C>,
    cube: [i128; C],
    fourth: [i128; C],
}

impl<const C: usize> MomentContribution<C> {
    /// A photon of weight exactly 1 in every channel: every power is 1.
    const UNIT: Self = {
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
    fn add_contribution(&mut self, c: &MomentContribution<C>) {
        self.tally.add_contribution(&c.low);
        for i in 0..C {
            self.sum_cube[i].0 += c.cube[i];
            self.sum_fourth[i].0 += c.fourth[i];
        }
    }

    /// Adds a chunk's sums of powers of per-photon weights (see [`ChunkMoments`]).
    fn add_chunk(&mut self, m: &ChunkMoments<C>) {
        self.tally.add_chunk(&m.sum, &m.sum_sq, m.photons);
        for i in 0..C {
            self.sum_cube[i].0 += to_fixed(m.sum_cube[i]);
            self.sum_fourth[i].0 += to_fixed(m.sum_fourth[i]);
        }
    }

    fn merge(&mut self, other: &Self) {
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

/// The angular grid: bins uniform in |cos theta| and in phi measured from the incident azimuth.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Grid {
    pub cos_bins: usize,
    pub phi_bins: usize,
}

impl Grid {
    pub fn bins(&self) -> usize {
        self.cos_bins * self.phi_bins
    }

    /// `[|cos| lo, |cos| hi]` of a cos index.
    pub fn cos_edges(&self, ic: usize) -> (f64, f64) {
        (ic as f64 / self.cos_bins as f64, (ic + 1) as f64 / self.cos_bins as f64)
    }

    /// `[phi lo, phi hi]` in degrees of a phi index.
    pub fn phi_edges_deg(&self, ip: usize) -> (f64, f64) {
        let w = 360.0 / self.phi_bins as f64;
        (ip as f64 * w, (ip + 1) as f64 * w)
    }

    /// Projected solid angle `∫ |cos theta| dω` of a bin with cos index `ic` (§4.7).
    pub fn projected_solid_angle(&self, ic: usize) -> f64 {
        let (lo, hi) = self.cos_edges(ic);
        std::f64::consts::TAU / self.phi_bins as f64 * 0.5 * (hi * hi - lo * lo)
    }
}

/// Which hemisphere light leaves into, relative to where it came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Hemisphere {
    /// Reflection: back to the side of the light.
    R = 0,
    /// Transmission: to the other side.
    T = 1,
}

/// Histograms and albedo tallies of one order slot (all orders, one order, or "K+").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct OrderTallies<const C: usize> {
    /// Per hemisphere and bin: index `hemisphere * bins + bin`.
    pub bins: Vec<Tally<C>>,
    /// Per hemisphere.
    pub albedo: [Moments<C>; 2],
}

impl<const C: usize> OrderTallies<C> {
    /// Empty tallies for `bins` bins over both hemispheres.
    fn empty(bins: usize) -> Self {
        Self { bins: vec![Tally::default(); bins], albedo: [Moments::default(); 2] }
    }

    fn merge(&mut self, other: &Self) {
        for (a, b) in self.bins.iter_mut().zip(&other.bins) {
            a.merge(b);
        }
        for (a, b) in self.albedo.iter_mut().zip(&other.albedo) {
            a.merge(b);
        }
    }
}

/// Where one escape deposits its weight.
#[derive(Clone, Copy, Debug)]
struct Deposit<const C: usize> {
    slot: usize,
    hemisphere: Hemisphere,
    bin: usize,
    weight: [f64; C],
}

impl<const C: usize> Deposit<C> {
    /// The two places the deposit goes, slot 0 (all orders) and its own slot: per slot, the
    /// bin's index in arrays indexed like the tallies (`slot * 2 bins + hemisphere * bins +
    /// bin`, `bins` a hemisphere's) and the albedo's (`2 slot + hemisphere`).
    #[inline]
    fn keys(&self, bins: usize) -> [(usize, usize); 2] {
        let h = self.hemisphere as usize;
        [0, self.slot].map(|slot| ((2 * slot + h) * bins + self.bin, 2 * slot + h))
    }
}

/// The raw accumulators of one case: everything a detector measured, and all that a shard
/// of a run must keep so that merged shards reproduce the unsplit run exactly.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Tallies<const C: usize> {
    /// Slot 0: all orders together; slot k: order k (the last slot is "K+" with a `max_order`).
    pub orders: Vec<OrderTallies<C>>,
    /// Per photon: escaped plus lost weight (absorbed = 1 - this).
    pub accounted: Moments<C>,
    /// Per photon: weight lost, per [`Loss`] reason (trapped, invalid, runaway).
    pub lost: [Tally<C>; 3],
    pub photons: u64,
    /// Facet interactions of all rays of all photons (the walk's work, for throughput figures).
    pub interactions: u64,
}

impl<const C: usize> Tallies<C> {
    fn new(grid: &Grid) -> Self {
        Self {
            orders: vec![OrderTallies::empty(2 * grid.bins())],
            accounted: Moments::default(),
            lost: [Tally::default(); 3],
            photons: 0,
            interactions: 0,
        }
    }

    /// Adds the photons of other tallies of the same case and grid: exact integer sums.
    pub fn merge(&mut self, other: &Self) {
        while self.orders.len() < other.orders.len() {
            self.orders.push(OrderTallies::empty(other.orders[0].bins.len()));
        }
        for (a, b) in self.orders.iter_mut().zip(&other.orders) {
            a.merge(b);
        }
        self.accounted.merge(&other.accounted);
        for (a, b) in self.lost.iter_mut().zip(&other.lost) {
            a.merge(b);
        }
        self.photons += other.photons;
        self.interactions += other.interactions;
    }
}

/// The "diamond angle" of a planar direction `(x, y)`: a monotone function of its azimuth
/// `atan2(y, x)` taken in `[0, 2 pi)`, onto `[0, 4)`, without trigonometry (one division).
#[inline]
fn diamond_angle(x: f64, y: f64) -> f64 {
    let l1 = x.abs() + y.abs();
    if l1 == 0.0 {
        return 0.0;
    }
    let t = x / l1;
    // `1 - t` for y >= 0, else `3 + t`, without a branch: the sign of y is as likely as not,
    // so a branch would be mispredicted for half the escapes. Both forms are exact.
    let lower = f64::from(u8::from(y < 0.0));
    (1.0 + 2.0 * lower) + (2.0 * lower - 1.0) * t
}

/// Bins escaping directions: |cos theta| directly, and the azimuth relative to the incident
/// azimuth without trigonometry. The diamond angle of the rotated direction is looked up in a
/// table of `4 phi_bins` equal cells, each holding the number of bin edges
/// (`2 pi k / phi_bins`, as diamond angles) at or below its start and the edge inside it, if
/// any (edges are at least `pi / (2 phi_bins)` apart in diamond angle, so a cell holds at
/// most one).
#[derive(Clone, Debug)]
struct Binner {
    grid: Grid,
    /// `(cos phi_i, sin phi_i)` of the incident azimuth.
    rotation: (f64, f64),
    /// Per cell: edges at or below its start, and the edge inside it (`inf` if none).
    cells: Vec<(usize, f64)>,
    /// `cos_bins` and `cells.len() / 4` as floats, the scales from |cos| and diamond angle to
    /// an index.
    cos_scale: f64,
    cell_scale: f64,
}

impl Binner {
    fn new(grid: Grid, rotation: (f64, f64)) -> Self {
        let n = grid.phi_bins;
        let edges: Vec<f64> = (1..n)
            .map(|k| {
                let (s, c) = (std::f64::consts::TAU * k as f64 / n as f64).sin_cos();
                diamond_angle(c, s)
            })
            .collect();
        let count = 4 * n;
        let cells = (0..count)
            .map(|i| {
                let (start, end) = (4.0 * i as f64 / count as f64, 4.0 * (i + 1) as f64 / count as f64);
                let below = edges.partition_point(|&e| e <= start);
                let inside = edges.get(below).copied().filter(|&e| e < end).unwrap_or(f64::INFINITY);
                (below, inside)
            })
            .collect();
        Self { grid, rotation, cells, cos_scale: grid.cos_bins as f64, cell_scale: 0.25 * count as f64 }
    }

    /// Bin index `cos_index * phi_bins + phi_index` of an escaping direction.
    #[inline]
    fn bin(&self, dir: DVec3) -> usize {
        let g = self.grid;
        // Both products are at least 0, where truncation through i64 (one instruction, unlike
        // u64) gives the same index.
        let ic = ((dir.z.abs() * self.cos_scale) as i64 as usize).min(g.cos_bins - 1);
        let (c, s) = self.rotation;
        let p = diamond_angle(c * dir.x + s * dir.y, c * dir.y - s * dir.x);
        let cell = ((p * self.cell_scale) as i64 as usize).min(self.cells.len() - 1);
        let (below, edge) = self.cells[cell];
        let ip = (below + usize::from(p >= edge)).min(g.phi_bins - 1);
        ic * g.phi_bins + ip
    }
}

/// The detector of one case: its geometry, its tallies, and the escapes of the photon in flight.
#[derive(Clone, Debug)]
pub struct Detector<const C: usize> {
    pub grid: Grid,
    binner: Binner,
    incident_side: Side,
    max_order: Option<u32>,
    pub tallies: Tallies<C>,
    /// The photon in flight's escaped weight so far, and its lost weight per [`Loss`] reason.
    escaped: [f64; C],
    pending_loss: [[f64; C]; 3],
    any_loss: bool,
    /// Bin counts of whole photons of weight exactly 1 from [`Observer::escape_photon`], per
    /// slot (`slot * 2 bins + hemisphere * bins + bin`), not yet in the bins' tallies (see
    /// [`Detector::settle`]). On white surfaces nearly every photon is one of these, and
    /// 4-byte counts keep the hot slots' histograms in the L1 cache, where 48-byte tallies
    /// (two `i128` and a count per bin) do not fit.
    unit_hits: Vec<u32>,
    /// Photons counted in `unit_hits`.
    unsettled: u32,
    /// The sums over the photons of the chunk being walked, converted to the tallies' fixed
    /// point when it ends ([`Detector::end_chunk`]).
    chunk: ChunkSums<C>,
    /// The photon in flight's sums per bin and albedo.
    photon: PhotonSums<C>,
}

/// One bin's sums over the photons of the chunk being walked, in floating point: the weight
/// each photon left in the bin, its square, and how many photons reached it. A chunk's
/// photons are walked in a fixed order by one thread, so these sums, and the fixed-point
/// values they are converted to when the chunk ends ([`Detector::end_chunk`]), depend only
/// on the chunk. At 32 bytes (one channel), against the 48 of a [`Tally`], the bins touched
/// by a photon stay in cache more often, and a deposit converts nothing.
#[derive(Clone, Copy, Debug)]
struct ChunkBin<const C: usize> {
    /// The photon in flight's deposits in the bin so far ([`Observer::escape`]; a photon that
    /// was split escapes several times), summed before squaring, so variances stay per photon
    /// (§4.6).
    photon: [f64; C],
    sum: [f64; C],
    sum_sq: [f64; C],
    photons: u32,
    /// Whether the current photon has deposited in the bin.
    reached: bool,
}

impl<const C: usize> Default for ChunkBin<C> {
    fn default() -> Self {
        Self { photon: [0.0; C], sum: [0.0; C], sum_sq: [0.0; C], photons: 0, reached: false }
    }
}

impl<const C: usize> ChunkBin<C> {
    /// Adds one photon's weight `w` in the bin.
    #[inline]
    fn add(&mut self, w: &[f64; C]) {
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
struct ChunkMoments<const C: usize> {
    sum: [f64; C],
    sum_sq: [f64; C],
    sum_cube: [f64; C],
    sum_fourth: [f64; C],
    photons: u32,
}

impl<const C: usize> Default for ChunkMoments<C> {
    fn default() -> Self {
        Self { sum: [0.0; C], sum_sq: [0.0; C], sum_cube: [0.0; C], sum_fourth: [0.0; C], photons: 0 }
    }
}

impl<const C: usize> ChunkMoments<C> {
    /// Adds one photon's weight `w`.
    #[inline]
    fn add(&mut self, w: &[f64; C]) {
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
struct PhotonSums<const C: usize> {
    bins_reached: Vec<usize>,
    albedos: Vec<Sum<C>>,
    albedos_reached: Vec<usize>,
}

impl<const C: usize> Default for PhotonSums<C> {
    fn default() -> Self {
        Self { bins_reached: Vec::new(), albedos: Vec::new(), albedos_reached: Vec::new() }
    }
}

/// A photon's running sum into one tally, and whether any deposit (even of weight 0) reached it.
#[derive(Clone, Copy, Debug)]
struct Sum<const C: usize> {
    weight: [f64; C],
    reached: bool,
}

impl<const C: usize> Default for Sum<C> {
    fn default() -> Self {
        Self { weight: [0.0; C], reached: false }
    }
}

/// Adds `w` to `sums[key]`, noting `key` in `touched` the first time.
#[inline]
fn add_to_sum<const C: usize>(sums: &mut [Sum<C>], touched: &mut Vec<usize>, key: usize, w: &[f64; C]) {
    let sum = &mut sums[key];
    if !sum.reached {
        sum.reached = true;
        touched.push(key);
    }
    accumulate(&mut sum.weight, w);
}

/// A detector's sums over the photons of the chunk being walked: per bin ([`ChunkBin`],
/// indexed like the tallies, `slot * 2 bins + hemisphere * bins + bin`) with the bins reached
/// in the order first reached, per albedo ([`ChunkMoments`], `2 slot + hemisphere`), and of
/// the accounted weight.
#[derive(Clone, Debug)]
struct ChunkSums<const C: usize> {
    bins: Vec<ChunkBin<C>>,
    touched: Vec<usize>,
    albedos: Vec<ChunkMoments<C>>,
    accounted: ChunkMoments<C>,
}

impl<const C: usize> Default for ChunkSums<C> {
    fn default() -> Self {
        Self { bins: Vec::new(), touched: Vec::new(), albedos: Vec::new(), accounted: ChunkMoments::default() }
    }
}

impl<const C: usize> ChunkSums<C> {
    /// Adds one photon's weight `w` in bin `key`.
    #[inline]
    fn add_to_bin(&mut self, key: usize, w: &[f64; C]) {
        let b = &mut self.bins[key];
        if b.photons == 0 {
            self.touched.push(key);
        }
        b.add(w);
    }

    /// Adds the sums to `tallies`, in fixed point; `bins` is the number of bins of a slot over
    /// both hemispheres.
    fn add_to(&self, tallies: &mut Tallies<C>, bins: usize) {
        for &key in &self.touched {
            let b = &self.bins[key];
            tallies.orders[key / bins].bins[key % bins].add_chunk(&b.sum, &b.sum_sq, b.photons);
        }
        for (key, m) in self.albedos.iter().enumerate() {
            if m.photons > 0 {
                tallies.orders[key / 2].albedo[key % 2].add_chunk(m);
            }
        }
        if self.accounted.photons > 0 {
            tallies.accounted.add_chunk(&self.accounted);
        }
    }

    /// Back to no photons, keeping the memory.
    fn clear(&mut self) {
        for key in self.touched.drain(..) {
            self.bins[key] = ChunkBin::default();
        }
        self.albedos.fill(ChunkMoments::default());
        self.accounted = ChunkMoments::default();
    }
}

/// Adds photons of weight 1 counted per bin, `hits[slot * bins + i]`, to the bins' tallies.
fn add_unit_hits<const C: usize>(tallies: &mut Tallies<C>, hits: &[u32], bins: usize) {
    for (order, hits) in tallies.orders.iter_mut().zip(hits.chunks_exact(bins)) {
        for (tally, &n) in order.bins.iter_mut().zip(hits) {
            if n != 0 {
                tally.add_units(n);
            }
        }
    }
}

/// `acc += w`, channel by channel.
#[inline]
fn accumulate<const C: usize>(acc: &mut [f64; C], w: &[f64; C]) {
    for (a, x) in acc.iter_mut().zip(w) {
        *a += x;
    }
}

fn loss_index(loss: Loss) -> usize {
    match loss {
        Loss::Trapped => 0,
        Loss::Invalid => 1,
        Loss::Runaway => 2,
    }
}

impl<const C: usize> Detector<C> {
    /// A detector for light arriving from `wi` (towards the light).
    pub fn new(grid: Grid, wi: DVec3, max_order: Option<u32>) -> Self {
        let horizontal = wi.x.hypot(wi.y);
        let rotation = if horizontal > 0.0 { (wi.x / horizontal, wi.y / horizontal) } else { (1.0, 0.0) };
        Self {
            grid,
            binner: Binner::new(grid, rotation),
            incident_side: if wi.z >= 0.0 { Side::Outside } else { Side::Inside },
            max_order,
            tallies: Tallies::new(&grid),
            escaped: [0.0; C],
            pending_loss: [[0.0; C]; 3],
            any_loss: false,
            unit_hits: Vec::new(),
            unsettled: 0,
            chunk: ChunkSums::default(),
            photon: PhotonSums::default(),
        }
    }

    fn slot(&self, order: u32) -> usize {
        match self.max_order {
            Some(k) => order.min(k) as usize,
            None => order as usize,
        }
    }

    /// The highest order slot with any photon in it.
    pub fn highest_slot(&self) -> usize {
        self.tallies.orders.len() - 1
    }

    /// Whether the last slot holds every order from `max_order` on.
    pub fn is_folded(&self, slot: usize) -> bool {
        self.max_order.is_some_and(|k| slot == k as usize)
    }

    /// Where an escape deposits its weight.
    #[inline]
    fn deposit(&self, order: u32, side: Side, dir: DVec3, weight: &[f64; C]) -> Deposit<C> {
        let hemisphere = if side == self.incident_side { Hemisphere::R } else { Hemisphere::T };
        Deposit { slot: self.slot(order), hemisphere, bin: self.binner.bin(dir), weight: *weight }
    }

    /// Makes room for order slot `slot` in the tallies and in the sums that feed them.
    #[inline]
    fn reach_slot(&mut self, slot: usize) {
        let bins = 2 * self.grid.bins();
        if self.tallies.orders.len() <= slot {
            self.tallies.orders.resize_with(slot + 1, || OrderTallies::empty(bins));
        }
        if self.chunk.bins.len() < (slot + 1) * bins {
            self.chunk.bins.resize((slot + 1) * bins, ChunkBin::default());
            self.photon.albedos.resize(2 * (slot + 1), Sum::default());
            self.chunk.albedos.resize(2 * (slot + 1), ChunkMoments::default());
        }
    }

    /// Counts a finished photon that made `interactions` facet interactions.
    #[inline]
    fn count_photon(&mut self, interactions: u64) {
        self.tallies.photons += 1;
        self.tallies.interactions += interactions;
    }

    /// Adds a photon whose whole weight escaped at once, in deposit `d`, to the chunk's sums:
    /// its bins, albedos and accounted total all get the same weight.
    #[inline]
    fn add_whole_photon(&mut self, d: &Deposit<C>) {
        self.chunk.accounted.add(&d.weight);
        for (bin, albedo) in d.keys(self.grid.bins()) {
            self.chunk.add_to_bin(bin, &d.weight);
            self.chunk.albedos[albedo].add(&d.weight);
        }
    }

    /// Adds a whole photon of weight 1 in every channel: its total and albedo tallies at once,
    /// its bins by count (see `unit_hits`).
    #[inline]
    fn add_unit_photon(&mut self, d: &Deposit<C>) {
        let c = MomentContribution::UNIT;
        self.tallies.accounted.add_contribution(&c);
        let bins = 2 * self.grid.bins();
        if self.unit_hits.len() < (d.slot + 1) * bins {
            self.unit_hits.resize((d.slot + 1) * bins, 0);
        }
        for (bin, albedo) in d.keys(self.grid.bins()) {
            self.tallies.orders[albedo / 2].albedo[albedo % 2].add_contribution(&c);
            self.unit_hits[bin] += 1;
        }
        self.unsettled += 1;
        if self.unsettled == u32::MAX {
            self.settle();
        }
    }

    /// Ends a chunk of photons: converts the bins' floating-point sums over the chunk to the
    /// tallies' fixed point and clears them. Called after every chunk, so that what the
    /// tallies hold does not depend on how chunks are grouped over threads and shards.
    pub fn end_chunk(&mut self) {
        self.chunk.add_to(&mut self.tallies, 2 * self.grid.bins());
        self.chunk.clear();
    }

    /// Ends the chunk ([`Detector::end_chunk`]) and adds the photons of weight 1 counted in
    /// `unit_hits` to their bins' tallies (exact integers, so when does not matter). Until
    /// then the bins lack them (the photon count, albedos and totals do not).
    /// [`Detector::merge`] settles the detector merged into and carries the other's counts
    /// over, so a run's results, which are sums of merged parts, are always settled.
    pub fn settle(&mut self) {
        self.end_chunk();
        if self.unsettled > 0 {
            add_unit_hits(&mut self.tallies, &self.unit_hits, 2 * self.grid.bins());
            self.unit_hits.fill(0);
            self.unsettled = 0;
        }
    }

    /// Adds the photon in flight's sums per bin and per albedo, and its total, to the chunk's
    /// sums, and its losses to the tallies.
    fn add_photon_in_flight(&mut self) {
        for key in self.photon.bins_reached.drain(..) {
            let b = &mut self.chunk.bins[key];
            let photon = std::mem::replace(&mut b.photon, [0.0; C]);
            b.reached = false;
            self.chunk.add_to_bin(key, &photon);
        }
        for key in self.photon.albedos_reached.drain(..) {
            let sum = std::mem::take(&mut self.photon.albedos[key]);
            self.chunk.albedos[key].add(&sum.weight);
        }
        let mut total = self.escaped;
        if self.any_loss {
            for (tally, w) in self.tallies.lost.iter_mut().zip(&self.pending_loss) {
                tally.add(w);
                accumulate(&mut total, w);
            }
            self.pending_loss = [[0.0; C]; 3];
            self.any_loss = false;
        }
        self.chunk.accounted.add(&total);
    }

    /// Adds another detector's photons of the same case (those of its chunk in progress too),
    /// and settles this one.
    pub fn merge(&mut self, other: &Self) {
        self.settle();
        self.tallies.merge(&other.tallies);
        other.chunk.add_to(&mut self.tallies, 2 * self.grid.bins());
        if other.unsettled > 0 {
            add_unit_hits(&mut self.tallies, &other.unit_hits, 2 * self.grid.bins());
        }
    }
}

impl<const C: usize> Observer<C> for Detector<C> {
    #[inline]
    fn escape(&mut self, order: u32, side: Side, dir: DVec3, weight: &[f64; C]) {
        let d = self.deposit(order, side, dir, weight);
        self.reach_slot(d.slot);
        accumulate(&mut self.escaped, weight);
        let photon = &mut self.photon;
        for (bin, albedo) in d.keys(self.grid.bins()) {
            let b = &mut self.chunk.bins[bin];
            if !b.reached {
                b.reached = true;
                photon.bins_reached.push(bin);
            }
            accumulate(&mut b.photon, weight);
            add_to_sum(&mut photon.albedos, &mut photon.albedos_reached, albedo, weight);
        }
    }

    fn lose(&mut self, loss: Loss, weight: &[f64; C]) {
        accumulate(&mut self.pending_loss[loss_index(loss)], weight);
        self.any_loss = true;
    }

    /// Closes the current photon, which made `interactions` facet interactions: adds its
    /// per-bin, per-order and total contributions.
    fn end_photon(&mut self, interactions: u64) {
        self.count_photon(interactions);
        self.add_photon_in_flight();
        self.escaped = [0.0; C];
    }

    #[inline]
    fn escape_photon(&mut self, order: u32, side: Side, dir: DVec3, weight: &[f64; C]) {
        let d = self.deposit(order, side, dir, weight);
        self.reach_slot(d.slot);
        self.count_photon(u64::from(order));
        if *weight == [1.0; C] { self.add_unit_photon(&d) } else { self.add_whole_photon(&d) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
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

    /// The trigonometric reference: `floor(phi n / 2 pi)` of `phi = atan2` in `[0, 2 pi)`.
    fn reference_phi_bin(n: usize, x: f64, y: f64) -> (usize, f64) {
        let phi = y.atan2(x).rem_euclid(std::f64::consts::TAU);
        let u = phi * n as f64 / std::f64::consts::TAU;
        ((u as usize).min(n - 1), (u - u.round()).abs())
    }

    #[test]
    fn azimuth_bins_agree_with_atan2() {
        // 10^5 random directions per grid and rotation; directions within 1e-9 of a bin edge
        // (in units of bins) are skipped, where rounding may legitimately go either way. The
        // axes and the diagonals, where the diamond angle changes branch, are checked exactly.
        let mut rng = Pcg64Mcg::seed_from_u64(5);
        for n in [1, 2, 3, 7, 64, 360, 1000] {
            for phi_i in [0.0_f64, 0.3, 2.0, -2.5] {
                let rotation = (phi_i.cos(), phi_i.sin());
                let binner = Binner::new(Grid { cos_bins: 4, phi_bins: n }, rotation);
                let check = |d: DVec3| {
                    let (c, s) = rotation;
                    let (x, y) = (c * d.x + s * d.y, c * d.y - s * d.x);
                    let (want, distance) = reference_phi_bin(n, x, y);
                    if n == 1 || distance > 1e-9 {
                        assert_eq!(binner.bin(d) % n, want, "n {n}, phi_i {phi_i}, d {d:?}");
                    }
                };
                for _ in 0..100_000 {
                    let phi = std::f64::consts::TAU * microsurface::random::open01(&mut rng);
                    let z = 2.0 * microsurface::random::open01(&mut rng) - 1.0;
                    let r = (1.0 - z * z).sqrt();
                    check(DVec3::new(r * phi.cos(), r * phi.sin(), z));
                }
                for k in 0..8 {
                    let a = phi_i + std::f64::consts::FRAC_PI_4 * k as f64 + 1e-6;
                    check(DVec3::new(a.cos(), a.sin(), 0.0));
                }
            }
        }
    }

    /// Photons of weight 1 are counted per bin and added to the bins when the detector settles
    /// or is merged: the tallies must then equal those of the general path (`escape` and
    /// `end_photon`, which sums every weight), the oracle here, exactly, for a mix of unit and
    /// other weights, several orders and both hemispheres, merged in pieces. The other weights
    /// are multiples of 1/64, whose sums and powers up to the fourth are exact in floating
    /// point here, so any grouping of the sums gives the same bits.
    #[test]
    fn photons_of_unit_weight_counted_per_bin_equal_the_general_path() {
        let grid = Grid { cos_bins: 8, phi_bins: 16 };
        let wi = DVec3::new(0.5, 0.0, 0.75_f64.sqrt());
        let mut rng = Pcg64Mcg::seed_from_u64(8);
        let mut general = Detector::<1>::new(grid, wi, Some(3));
        let mut whole = Detector::<1>::new(grid, wi, Some(3));
        let mut pieces = Detector::<1>::new(grid, wi, Some(3));
        let mut settled = Detector::<1>::new(grid, wi, Some(3));
        for n in 0..20_000 {
            let z = 2.0 * microsurface::random::open01(&mut rng) - 1.0;
            let phi = std::f64::consts::TAU * microsurface::random::open01(&mut rng);
            let r = (1.0 - z * z).sqrt();
            let dir = DVec3::new(r * phi.cos(), r * phi.sin(), z);
            let side = if z > 0.0 { Side::Outside } else { Side::Inside };
            let order = 1 + (rng.next_u64() % 5) as u32;
            let weight = if n % 7 == 3 { [f64::from(16 + (rng.next_u32() % 32)) / 64.0] } else { [1.0] };
            general.escape(order, side, dir, &weight);
            general.end_photon(u64::from(order));
            whole.escape_photon(order, side, dir, &weight);
            settled.escape_photon(order, side, dir, &weight);
            if n % 5000 == 4999 {
                pieces.merge(&whole);
                whole = Detector::new(grid, wi, Some(3));
            }
        }
        general.settle();
        assert!(general.tallies == pieces.tallies, "merged pieces differ from the general path");
        assert!(general.tallies != settled.tallies, "the bins lack the unit photons before settling");
        settled.settle();
        assert!(general.tallies == settled.tallies, "the settled detector differs from the general path");
    }
}
