//! The random walk on the Smith microsurface (Heitz et al. 2016; THEORY.md §4.1, §4.6).
//!
//! A photon enters from the light's side at the top of the height support (optical depth 0)
//! and alternates free flights in optical depth (§2.4) with facet interactions (§4.2–§4.5)
//! until it escapes. A ray inside a dielectric is walked in the flipped frame (§4.3): its
//! direction is negated and its depth is measured from below, which turns it into an outside
//! problem; a refraction converts the depth to the other side.

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
#[derive(Clone, Copy, Debug)]
pub struct Microsurface<N> {
    pub ndf: N,
    pub smith: Smith,
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

fn max_channel<const C: usize>(w: &[f64; C]) -> f64 {
    w.iter().copied().fold(0.0, f64::max)
}

fn weight_is_valid<const C: usize>(w: &[f64; C]) -> bool {
    w.iter().all(|x| x.is_finite() && *x >= 0.0)
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
        let side = if wi.z >= 0.0 { Side::Outside } else { Side::Inside };
        stack.clear();
        stack.push(Ray { tau: 0.0, d: -wi, side, beta: [1.0; C], order: 0 });
        let mut interactions = 0;
        while let Some(ray) = stack.pop() {
            interactions += u64::from(self.follow(facet, policy, ray, rng, stack, observer));
        }
        interactions
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
            // The flipped frame (§4.3): on the inside, negate the direction.
            let d = match ray.side {
                Side::Outside => ray.d,
                Side::Inside => -ray.d,
            };
            let rate = self.smith.rate(&self.ndf, d);
            ray.tau = match fly(ray.tau, d.z > 0.0, rate, exp1(rng)) {
                Flight::Escape => {
                    observer.escape(ray.order, ray.side, ray.d, &ray.beta);
                    break;
                }
                Flight::Hit(tau) => tau,
            };
            if ray.tau.is_nan() {
                observer.lose(Loss::Invalid, &ray.beta);
                break;
            }
            if ray.tau.is_infinite() {
                observer.lose(Loss::Trapped, &ray.beta);
                break;
            }
            ray.order += 1;
            if ray.order >= RUNAWAY_ORDER {
                observer.lose(Loss::Runaway, &ray.beta);
                break;
            }
            observer.hit(ray.order, ray.tau, ray.side, ray.d, &ray.beta);
            let m_flipped = self.normals.sample(&self.ndf, d, rng);
            let m = match ray.side {
                Side::Outside => m_flipped,
                Side::Inside => -m_flipped,
            };
            let branch = match facet.interact(-ray.d, m, ray.side, rng) {
                Interaction::One(b) => b,
                Interaction::Two(a, b) => {
                    if policy.split && max_channel(&ray.beta) >= policy.threshold {
                        stack.push(continue_with(&ray, &b));
                        a
                    } else {
                        match choose(&ray.beta, a, b, open01(rng)) {
                            Some(chosen) => chosen,
                            None => break,
                        }
                    }
                }
            };
            ray = continue_with(&ray, &branch);
            if !ray.d.is_finite() || !weight_is_valid(&ray.beta) {
                observer.lose(Loss::Invalid, &ray.beta);
                break;
            }
            match roulette(&ray.beta, policy.threshold, rng) {
                Some(beta) => ray.beta = beta,
                None => break,
            }
        }
        ray.order - start
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
