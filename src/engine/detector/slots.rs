//! A case's tallies per order slot (all orders, each order, "K+") and hemisphere, where one
//! escape deposits, and the exact merge of tallies of the same case.

use serde::{Deserialize, Serialize};

use super::grid::{Grid, Hemisphere};
use super::tally::{Moments, Tally};

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
    pub(super) fn empty(bins: usize) -> Self {
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
pub(super) struct Deposit<const C: usize> {
    pub(super) slot: usize,
    pub(super) hemisphere: Hemisphere,
    pub(super) bin: usize,
    pub(super) weight: [f64; C],
}

impl<const C: usize> Deposit<C> {
    /// The two places the deposit goes, slot 0 (all orders) and its own slot: per slot, the
    /// bin's index in arrays indexed like the tallies (`slot * 2 bins + hemisphere * bins +
    /// bin`, `bins` a hemisphere's) and the albedo's (`2 slot + hemisphere`).
    #[inline]
    pub(super) fn keys(&self, bins: usize) -> [(usize, usize); 2] {
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
    /// Per photon: weight lost, per [`Loss`](microsurface::walk::Loss) reason (trapped, invalid, runaway).
    pub lost: [Tally<C>; 3],
    pub photons: u64,
    /// Facet interactions of all rays of all photons (the walk's work, for throughput figures).
    pub interactions: u64,
}

impl<const C: usize> Tallies<C> {
    pub(super) fn new(grid: &Grid) -> Self {
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
