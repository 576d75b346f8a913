//! The virtual gonioreflectometer: angular histograms of escaping light per bounce order and
//! hemisphere, with per-photon second moments for standard errors (docs/theory.md §4.7).
//!
//! A chunk's photons, walked in a fixed order by one thread, are summed in f64; when the chunk
//! ends its sums are added to tallies kept in 64.64 fixed point (`i128`). Integer addition is
//! associative, so the totals do not depend on how chunks are distributed over threads,
//! shards or machines: the same photons give bit-identical outputs however the work is split.

mod chunk;
mod grid;
mod slots;
mod tally;

use glam::DVec3;
use microsurface::facet::Side;
use microsurface::walk::{Loss, Observer};

use self::chunk::{ChunkBin, ChunkMoments, PhotonSums, Sum, accumulate, add_to_sum};
use self::grid::Binner;
pub use self::grid::{Grid, Hemisphere};
use self::slots::Deposit;
pub use self::slots::{OrderTallies, Tallies};
use self::tally::MomentContribution;
pub use self::tally::{Fixed, Moments, Tally};

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

fn loss_index(loss: Loss) -> usize {
    match loss {
        Loss::Trapped => 0,
        Loss::Invalid => 1,
        Loss::Runaway => 2,
    }
}

impl<const C: usize> Detector<C> {
    /// Bytes per bin of one hemisphere of one order slot of a detector that walks: the bin's
    /// tally, its sums over the chunk and its count of photons of weight 1 (what
    /// [`crate::engine::resources::MemoryEstimate`] counts).
    pub fn bytes_per_bin() -> u64 {
        (std::mem::size_of::<Tally<C>>() + std::mem::size_of::<ChunkBin<C>>() + std::mem::size_of::<u32>()) as u64
    }
    /// Bytes per bin of one hemisphere of one order slot in a checkpoint or shard file, at
    /// most: postcard writes each integer of the bin's tally as a varint of at most 19 bytes
    /// for 16 (`i128`) and 10 for 8 (`u64`), so within 5/4 of the tally's size in memory.
    pub fn saved_bytes_per_bin() -> u64 {
        (std::mem::size_of::<Tally<C>>() as u64 * 5).div_ceil(4)
    }

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
