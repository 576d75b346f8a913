//! Height-free chains of visible-normal scatterings (docs/theory.md §6.5, §7.1): the position-free
//! models of the walk's lobes.
//!
//! A chain follows one path of directions `d_0, d_1, ...` drawn exactly as the walk draws them
//! (visible normals, the facet's interaction), but without heights: what escapes after each
//! vertex is decided by a [`Visibility`] model. At vertex `j`, a direction pointing away from
//! the surface on its side lets the model's fraction of the chain's weight escape at order
//! `j`; the rest continues. Two-branch facets always choose one branch at random (no
//! splitting); weights below the policy's threshold play Russian roulette as in the walk.

use glam::DVec3;
use rand::Rng;

use crate::facet::{Facet, Interaction, Side};
use crate::ndf::Ndf;
use crate::random::open01;
use crate::smith::Smith;
use crate::walk::{EnergyPolicy, Loss, Observer, RUNAWAY_ORDER, choose, roulette};

/// What escapes after each vertex of a chain: the alternatives are Wang et al.'s local models
/// ([`crate::wang::Shadowing`]), the exact depth profile ([`crate::position_free`]) and the path
/// term of Cui et al.'s released code ([`crate::cui`]).
pub trait Visibility {
    /// Starts a photon that enters along a direction of depth rate `rate` (§2.4).
    fn enter(&mut self, rate: f64);

    /// The fraction of the chain's weight that escapes when it leaves a vertex along a
    /// direction of depth rate `rate_out`, pointing away from the surface on its side (`up`)
    /// or into it, having arrived along a direction of depth rate `rate_in`; `refracted` tells
    /// whether the vertex changed side. A direction into the surface escapes nothing.
    fn leave(&mut self, rate_in: f64, rate_out: f64, up: bool, refracted: bool) -> f64;

    /// The fraction of the chain's weight that goes on after the last [`Visibility::leave`],
    /// which let `escaped` escape: by default what did not escape (light that escapes leaves
    /// the chain). A model whose escapes do not deplete the path ([`crate::cui`]) says otherwise.
    fn carried(&self, escaped: f64) -> f64 {
        1.0 - escaped
    }
}

/// What escapes after each vertex, channel by channel of the chain's weight: one
/// [`Visibility`] for every channel (any `V: Visibility`), or one model per channel, so that
/// one chain of directions serves several models at once.
pub trait Escapes<const C: usize> {
    /// Starts a photon: [`Visibility::enter`] of every channel's model.
    fn start(&mut self, rate: f64);

    /// The fraction of each channel's weight that escapes: [`Visibility::leave`] per channel.
    fn escaping(&mut self, rate_in: f64, rate_out: f64, up: bool, refracted: bool) -> [f64; C];

    /// The fraction of each channel's weight that goes on: [`Visibility::carried`] per channel.
    fn carrying(&self, escaped: &[f64; C]) -> [f64; C];
}

impl<V: Visibility, const C: usize> Escapes<C> for V {
    fn start(&mut self, rate: f64) {
        self.enter(rate);
    }

    fn escaping(&mut self, rate_in: f64, rate_out: f64, up: bool, refracted: bool) -> [f64; C] {
        [self.leave(rate_in, rate_out, up, refracted); C]
    }

    fn carrying(&self, escaped: &[f64; C]) -> [f64; C] {
        escaped.map(|p| self.carried(p))
    }
}

/// Walks one photon arriving from `wi` (towards the light) through the chain with `visibility`
/// and deposits the escaping weight of every order into `observer`, like the random walk does.
/// Returns the number of facet interactions.
///
/// The directions do not depend on the visibility, so channels with different models are
/// unbiased estimators of each model: only the weights differ, and Russian roulette (on the
/// largest channel) and the choice between two branches divide every channel by the same
/// probability.
#[allow(clippy::too_many_arguments)]
pub fn trace<V, N, F, R, O, const C: usize>(
    visibility: &mut V,
    ndf: &N,
    facet: &F,
    policy: &EnergyPolicy,
    wi: DVec3,
    rng: &mut R,
    observer: &mut O,
) -> u64
where
    V: Escapes<C>,
    N: Ndf,
    F: Facet<C>,
    R: Rng + ?Sized,
    O: Observer<C>,
{
    let mut side = if wi.z >= 0.0 { Side::Outside } else { Side::Inside };
    let mut d = -wi;
    let mut weight = [1.0; C];
    let mut order = 0u32;
    // The own-side frame (§4.3): inside, directions are flipped.
    let flip = |v: DVec3, s: Side| if s == Side::Outside { v } else { -v };
    // Depth rate of the arriving direction (true Smith, §2.4); each leaving direction's rate
    // is the next vertex's arriving one.
    let mut rate_in = Smith::Exact.rate(ndf, flip(d, side));
    visibility.start(rate_in);
    loop {
        let d_own = flip(d, side);
        let m = flip(ndf.sample_visible(-d_own, rng), side);
        order += 1;
        if order >= RUNAWAY_ORDER {
            observer.lose(Loss::Runaway, &weight);
            return u64::from(order);
        }
        let branch = match facet.interact(-d, m, side, rng) {
            Interaction::One(b) => b,
            Interaction::Two(a, b) => match choose(&weight, a, b, open01(rng)) {
                Some(chosen) => chosen,
                None => return u64::from(order),
            },
        };
        for (w, f) in weight.iter_mut().zip(&branch.weight) {
            *w *= f;
        }
        if branch.crosses {
            side = side.other();
        }
        d = branch.dir;
        let d_out = flip(d, side);
        let rate_out = Smith::Exact.rate(ndf, d_out);
        let p = visibility.escaping(rate_in, rate_out, d_out.z > 0.0, branch.crosses);
        rate_in = rate_out;
        if !d.is_finite() || p.iter().chain(&weight).any(|x| !x.is_finite()) {
            observer.lose(Loss::Invalid, &weight);
            return u64::from(order);
        }
        if p.iter().any(|&p| p > 0.0) {
            observer.escape(order, side, d, &std::array::from_fn(|c| weight[c] * p[c]));
        }
        let carried = visibility.carrying(&p);
        weight = std::array::from_fn(|c| weight[c] * carried[c]);
        match roulette(&weight, policy.threshold, rng) {
            Some(w) => weight = w,
            None => return u64::from(order),
        }
    }
}
