//! The random walk on the Smith microsurface (Heitz et al. 2016; docs/theory.md §4.1, §4.6).
//!
//! A photon enters from the light's side at the top of the height support (optical depth 0)
//! and alternates free flights in optical depth (§2.4) with facet interactions (§4.2–§4.5)
//! until it escapes. A ray inside a dielectric is walked in the flipped frame (§4.3): its
//! direction is negated and its depth is measured from below, which turns it into an outside
//! problem; a refraction converts the depth to the other side.

use std::hint::select_unpredictable;

use glam::DVec3;
use rand::Rng;

use crate::facet::{Branch, Facet, Interaction, Side};
use crate::height::{Flight, fly, other_side_depth};
use crate::ndf::Ndf;
use crate::normals::Normals;
use crate::random::{exp1, open01};
use crate::smith::Smith;

/// A microsurface: an NDF, the Smith variant driving the free flights and the law of the hit
/// normals. Facet materials plug in independently. (The height distribution does not appear:
/// the walk runs in optical depth, on which no height law has any effect, §2.1.)
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Microsurface<N> {
    /// The distribution of normals with its roughness.
    pub ndf: N,
    /// The Lambda that drives the free flights.
    pub smith: Smith,
    /// The law of the normals a ray hits.
    pub normals: Normals,
}

/// How two-branch interactions and small weights are handled (§4.6).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnergyPolicy {
    /// Follow both branches while the largest channel weight is at least `threshold`;
    /// otherwise (or always, when false) choose one branch at random, without bias.
    pub split: bool,
    /// Below this largest channel weight a path plays Russian roulette: it survives with
    /// probability `max(beta) / threshold` and is reweighted by its inverse. 0 disables it.
    pub threshold: f64,
}

impl EnergyPolicy {
    /// Whether paths never split under this policy with `facet` (the condition of
    /// [`Microsurface::walk_side_by_side`]).
    pub fn never_splits<F: Facet<C>, const C: usize>(&self, facet: &F) -> bool {
        !(self.split && facet.may_split())
    }
}

/// Why a path ended without escaping and without being absorbed (§10, NaN policy).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Loss {
    /// The ray reached infinite optical depth (`u = 0`), from which nothing escapes (§2.7).
    Trapped,
    /// A direction, depth or weight became NaN or infinite.
    Invalid,
    /// The path exceeded [`RUNAWAY_ORDER`] facet interactions.
    Runaway,
}

/// A safety bound on the number of facet interactions of one path. It is a guard against
/// numerical runaway, not a bounce cap: with the true Smith Lambda the probability to reach it
/// is negligible, and any weight stopped here is reported as [`Loss::Runaway`].
pub const RUNAWAY_ORDER: u32 = 1 << 20;

/// Receives what happens to the light of one photon.
pub trait Observer<const C: usize> {
    /// A ray escapes after `order` facet interactions into `side` (the side it travels in),
    /// along `dir`, carrying `weight`.
    fn escape(&mut self, order: u32, side: Side, dir: DVec3, weight: &[f64; C]);
    /// A ray stops for `loss`, carrying `weight`.
    fn lose(&mut self, loss: Loss, weight: &[f64; C]);
    /// A ray hits its `order`-th facet at optical depth `tau` on `side`, travelling along `d`
    /// with `weight`, before the facet acts (for next-event estimation, §4.7).
    fn hit(&mut self, _order: u32, _tau: f64, _side: Side, _d: DVec3, _weight: &[f64; C]) {}
    /// The photon whose escapes and losses were reported since the last call is complete; its
    /// rays made `interactions` facet interactions in all. ([`Microsurface::walk_side_by_side`]
    /// reports it; callers of [`Microsurface::trace`] close photons themselves.)
    fn end_photon(&mut self, _interactions: u64) {}
    /// A whole photon escapes at once: its only ray, with no loss before, after `order` facet
    /// interactions. The same as [`Observer::escape`] then [`Observer::end_photon`].
    fn escape_photon(&mut self, order: u32, side: Side, dir: DVec3, weight: &[f64; C]) {
        self.escape(order, side, dir, weight);
        self.end_photon(u64::from(order));
    }
}

/// A ray of the walk: optical depth on its own side, travel direction, side, weight and
/// number of interactions so far.
#[derive(Clone, Copy, Debug)]
pub struct Ray<const C: usize> {
    tau: f64,
    d: DVec3,
    side: Side,
    beta: [f64; C],
    order: u32,
}

impl<const C: usize> Ray<C> {
    /// A photon arriving from `wi` (towards the light): on the light's side at depth 0, with
    /// unit weight and no interaction yet.
    fn entering(wi: DVec3) -> Self {
        let side = if wi.z >= 0.0 { Side::Outside } else { Side::Inside };
        Ray { tau: 0.0, d: -wi, side, beta: [1.0; C], order: 0 }
    }
}

fn max_channel<const C: usize>(w: &[f64; C]) -> f64 {
    w.iter().copied().fold(0.0, f64::max)
}

/// Finite and not negative, channel by channel (NaN fails both comparisons).
fn weight_is_valid<const C: usize>(w: &[f64; C]) -> bool {
    w.iter().all(|&x| (0.0..=f64::MAX).contains(&x))
}

impl<N: Ndf> Microsurface<N> {
    /// Walks one photon arriving from `wi` (pointing towards the light; `wi_z > 0` from
    /// outside, `wi_z < 0` from inside a dielectric) with unit weight in every channel, and
    /// reports every escape and loss to `observer`. `stack` is scratch space for split branches.
    /// Returns the number of facet interactions of all its rays.
    pub fn trace<F, R, O, const C: usize>(
        &self,
        facet: &F,
        policy: &EnergyPolicy,
        wi: DVec3,
        rng: &mut R,
        stack: &mut Vec<Ray<C>>,
        observer: &mut O,
    ) -> u64
    where
        F: Facet<C>,
        R: Rng + ?Sized,
        O: Observer<C>,
    {
        stack.clear();
        stack.push(Ray::entering(wi));
        let mut interactions = 0;
        while let Some(ray) = stack.pop() {
            interactions += u64::from(self.follow(facet, policy, ray, rng, stack, observer));
        }
        interactions
    }

    /// [`Microsurface::trace`] for a photon that never splits (`policy.never_splits(facet)`,
    /// as [`Microsurface::walk_side_by_side`] requires; panics otherwise): its one ray needs
    /// no scratch space, so a renderer's single-photon call allocates nothing.
    pub fn trace_unsplit<F, R, O, const C: usize>(
        &self,
        facet: &F,
        policy: &EnergyPolicy,
        wi: DVec3,
        rng: &mut R,
        observer: &mut O,
    ) -> u64
    where
        F: Facet<C>,
        R: Rng + ?Sized,
        O: Observer<C>,
    {
        assert!(policy.never_splits(facet), "trace_unsplit cannot split paths");
        // Never pushed to: an empty `Vec` does not allocate.
        let mut no_stack = Vec::new();
        u64::from(self.follow(facet, policy, Ray::entering(wi), rng, &mut no_stack, observer))
    }

    /// Walks `photons` photons arriving from `wi`, [`LANES`] at a time side by side, and
    /// reports each one's escape or loss to `observer`, followed by its end
    /// ([`Observer::end_photon`]). Each photon is walked exactly as by [`Microsurface::trace`];
    /// what differs is the order in which the photons draw their random numbers.
    ///
    /// Why: one photon is a chain of dependent square roots and divisions, and whether a
    /// flight escapes is a coin toss that ends the chain. Side by side, the chains of several
    /// photons overlap, and an escape does not branch: it is recorded into a buffer and its lane
    /// is refilled with the next photon (whose first flight, downward from depth 0, always
    /// hits, at a depth drawn from what is left of the escaping flight's variate,
    /// [`Flight::excess`]) by selection. The buffer is handed to `observer` when it fills.
    ///
    /// Only for paths that never split: a facet with two branches must be walked with
    /// `policy.split` off (a random choice, §4.6). Panics otherwise.
    pub fn walk_side_by_side<F, R, O, const C: usize>(
        &self,
        facet: &F,
        policy: &EnergyPolicy,
        wi: DVec3,
        photons: u64,
        rng: &mut R,
        observer: &mut O,
    ) where
        F: Facet<C>,
        R: Rng + ?Sized,
        O: Observer<C>,
    {
        assert!(policy.never_splits(facet), "walk_side_by_side cannot split paths");
        let fresh = Ray::entering(wi);
        // The first flight, downward from depth 0, always hits: at depth `e / rate`.
        let first_mean_depth = self.smith.rate(&self.ndf, fresh.side.frame(fresh.d)).recip();
        let mut lanes = [fresh; LANES];
        let mut active = [false; LANES];
        let mut unstarted = photons;
        for a in active.iter_mut().take(photons.min(LANES as u64) as usize) {
            *a = true;
            unstarted -= 1;
        }
        let mut escapes = Escapes::new();
        let mut no_stack = Vec::new();
        while active.contains(&true) {
            // Flights. While every lane can be refilled this round, escapes refill without a
            // branch.
            let refill = unstarted >= LANES as u64;
            let mut arrived = [false; LANES];
            for ((ray, active), arrived) in lanes.iter_mut().zip(&mut active).zip(&mut arrived) {
                if !*active {
                    continue;
                }
                let flight = self.fly(ray, exp1(rng));
                escapes.record(flight.escapes, ray);
                if refill {
                    // The next photon's first depth reuses what is left of this flight's
                    // variate once it escaped (a fresh standard exponential, `Flight::excess`);
                    // rounding may leave it a hair below 0.
                    let first_tau = flight.excess.max(0.0) * first_mean_depth;
                    unstarted -= u64::from(flight.escapes);
                    let (first, next) = (Ray { tau: first_tau, ..fresh }, Ray { tau: flight.tau, ..*ray });
                    *ray = select_unpredictable(flight.escapes, first, next);
                } else if flight.escapes {
                    next_photon(&mut unstarted, ray, active, fresh);
                    continue;
                } else {
                    ray.tau = flight.tau;
                }
                *arrived = self.arrive(ray, observer);
                if !*arrived {
                    observer.end_photon(u64::from(ray.order));
                    next_photon(&mut unstarted, ray, active, fresh);
                }
            }
            // The facets' normals, all lanes together (lanes that did not arrive draw too).
            let directions = lanes.map(|ray| ray.side.frame(ray.d));
            let normals = self.normals.sample_lanes(&self.ndf, directions, rng);
            for (((ray, active), arrived), m) in lanes.iter_mut().zip(&mut active).zip(arrived).zip(normals) {
                if arrived && !self.leave(facet, policy, ray, ray.side.frame(m), rng, &mut no_stack, observer) {
                    observer.end_photon(u64::from(ray.order));
                    next_photon(&mut unstarted, ray, active, fresh);
                }
            }
            if escapes.len > ESCAPES - LANES {
                escapes.flush(observer);
            }
        }
        escapes.flush(observer);
    }

    /// Follows one ray until it escapes, is absorbed or lost; split branches go onto `stack`.
    /// Returns the number of facet interactions it made.
    fn follow<F, R, O, const C: usize>(
        &self,
        facet: &F,
        policy: &EnergyPolicy,
        mut ray: Ray<C>,
        rng: &mut R,
        stack: &mut Vec<Ray<C>>,
        observer: &mut O,
    ) -> u32
    where
        F: Facet<C>,
        R: Rng + ?Sized,
        O: Observer<C>,
    {
        let start = ray.order;
        loop {
            let flight = self.fly(&ray, exp1(rng));
            if flight.escapes {
                observer.escape(ray.order, ray.side, ray.d, &ray.beta);
                break;
            }
            ray.tau = flight.tau;
            if !self.arrive(&mut ray, observer) {
                break;
            }
            let m = self.facet_normal(&ray, rng);
            if !self.leave(facet, policy, &mut ray, m, rng, stack, observer) {
                break;
            }
        }
        ray.order - start
    }

    /// The free flight of `ray` with the standard exponential variate `e` (§2.4), in the
    /// flipped frame on the inside (§4.3).
    #[inline]
    fn fly<const C: usize>(&self, ray: &Ray<C>, e: f64) -> Flight {
        let d = ray.side.frame(ray.d);
        fly(ray.tau, d.z > 0.0, self.smith.rate(&self.ndf, d), e)
    }

    /// The arrival of `ray` at the facet it hit at depth `ray.tau`: counts the interaction
    /// and reports it to `observer`. Returns whether the ray can interact; when it cannot, its
    /// loss (trapped, invalid, runaway) was reported to `observer`.
    #[inline]
    fn arrive<O: Observer<C>, const C: usize>(&self, ray: &mut Ray<C>, observer: &mut O) -> bool {
        if ray.tau.is_nan() {
            observer.lose(Loss::Invalid, &ray.beta);
            return false;
        }
        if ray.tau.is_infinite() {
            observer.lose(Loss::Trapped, &ray.beta);
            return false;
        }
        ray.order += 1;
        if ray.order >= RUNAWAY_ORDER {
            observer.lose(Loss::Runaway, &ray.beta);
            return false;
        }
        observer.hit(ray.order, ray.tau, ray.side, ray.d, &ray.beta);
        true
    }

    /// The normal of the facet `ray` hit, in the frame of its side (§3.1, §4.3).
    #[inline]
    fn facet_normal<R: Rng + ?Sized, const C: usize>(&self, ray: &Ray<C>, rng: &mut R) -> DVec3 {
        ray.side.frame(self.normals.sample(&self.ndf, ray.side.frame(ray.d), rng))
    }

    /// The interaction of `ray` with the facet of normal `m` it arrived at (§4.2–§4.6): lets
    /// the facet act, splits or chooses between two branches and plays Russian roulette.
    /// Returns whether the ray goes on (updated in place); when it does not, it was absorbed
    /// or its loss was reported to `observer`.
    #[inline]
    #[allow(clippy::too_many_arguments)] // the walk's context (as for `follow`) plus the normal
    fn leave<F, R, O, const C: usize>(
        &self,
        facet: &F,
        policy: &EnergyPolicy,
        ray: &mut Ray<C>,
        m: DVec3,
        rng: &mut R,
        stack: &mut Vec<Ray<C>>,
        observer: &mut O,
    ) -> bool
    where
        F: Facet<C>,
        R: Rng + ?Sized,
        O: Observer<C>,
    {
        let branch = match facet.interact(-ray.d, m, ray.side, rng) {
            Interaction::One(b) => b,
            Interaction::Two(a, b) => {
                if policy.split && max_channel(&ray.beta) >= policy.threshold {
                    stack.push(continue_with(ray, &b));
                    a
                } else {
                    match choose(&ray.beta, a, b, open01(rng)) {
                        Some(chosen) => chosen,
                        None => return false,
                    }
                }
            }
        };
        *ray = continue_with(ray, &branch);
        if !ray.d.is_finite() || !weight_is_valid(&ray.beta) {
            observer.lose(Loss::Invalid, &ray.beta);
            return false;
        }
        match roulette(&ray.beta, policy.threshold, rng) {
            Some(beta) => {
                ray.beta = beta;
                true
            }
            None => false,
        }
    }
}

/// A lane whose photon ended takes the next unstarted one, `fresh`, or retires when none is left.
#[inline]
fn next_photon<const C: usize>(unstarted: &mut u64, ray: &mut Ray<C>, active: &mut bool, fresh: Ray<C>) {
    if *unstarted > 0 {
        *unstarted -= 1;
        *ray = fresh;
    } else {
        *active = false;
    }
}

/// Photons walked side by side by [`Microsurface::walk_side_by_side`].
pub const LANES: usize = 4;

/// Capacity of the buffer of escapes waiting to be reported.
const ESCAPES: usize = 64;

/// Escapes waiting to be reported: each is a whole photon (paths walked side by side do not
/// split).
struct Escapes<const C: usize> {
    rays: [Ray<C>; ESCAPES],
    len: usize,
}

impl<const C: usize> Escapes<C> {
    fn new() -> Self {
        Self {
            rays: [Ray { tau: 0.0, d: DVec3::ZERO, side: Side::Outside, beta: [0.0; C], order: 0 }; ESCAPES],
            len: 0,
        }
    }

    /// Keeps `ray` if it `escapes`: written either way, kept by advancing the length, so that
    /// an unpredictable escape costs no branch.
    #[inline]
    fn record(&mut self, escapes: bool, ray: &Ray<C>) {
        self.rays[self.len] = *ray;
        self.len += usize::from(escapes);
    }

    /// Reports every kept escape as a whole photon.
    fn flush<O: Observer<C>>(&mut self, observer: &mut O) {
        for ray in &self.rays[..self.len] {
            observer.escape_photon(ray.order, ray.side, ray.d, &ray.beta);
        }
        self.len = 0;
    }
}

/// Russian roulette on a path weight (§4.6): `None` if the path ends (no weight left, or it
/// loses the roulette that weights whose largest channel is below `threshold` play), else the
/// weight to carry on with (divided by the survival probability).
pub(crate) fn roulette<R: Rng + ?Sized, const C: usize>(
    weight: &[f64; C],
    threshold: f64,
    rng: &mut R,
) -> Option<[f64; C]> {
    let largest = max_channel(weight);
    if largest == 0.0 {
        return None;
    }
    if largest >= threshold {
        return Some(*weight);
    }
    let survive = largest / threshold;
    (open01(rng) < survive).then(|| weight.map(|w| w / survive))
}

/// The ray that follows `branch`.
fn continue_with<const C: usize>(ray: &Ray<C>, branch: &Branch<C>) -> Ray<C> {
    Ray {
        tau: if branch.crosses { other_side_depth(ray.tau) } else { ray.tau },
        d: branch.dir,
        side: if branch.crosses { ray.side.other() } else { ray.side },
        beta: std::array::from_fn(|i| ray.beta[i] * branch.weight[i]),
        ..*ray
    }
}

/// Chooses one of two exclusive branches with probability proportional to the weight each
/// would carry (summed over channels), and divides its factor by that probability so the
/// choice is unbiased (§4.6). `None` if neither branch carries weight.
pub(crate) fn choose<const C: usize>(beta: &[f64; C], a: Branch<C>, b: Branch<C>, u: f64) -> Option<Branch<C>> {
    let carried = |br: &Branch<C>| beta.iter().zip(&br.weight).map(|(x, w)| x * w).sum::<f64>();
    let (wa, wb) = (carried(&a), carried(&b));
    let total = wa + wb;
    if total <= 0.0 {
        return None;
    }
    let pa = wa / total;
    let (mut chosen, p) = if u < pa { (a, pa) } else { (b, 1.0 - pa) };
    chosen.weight = chosen.weight.map(|w| w / p);
    Some(chosen)
}
