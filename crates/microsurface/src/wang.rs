//! The position-free multiple-bounce models of Wang et al. 2022 (THEORY.md §6), evaluated as
//! a height-free chain of visible-normal scatterings (§6.5).
//!
//! The chain uses the walk's own facet interactions and visible normals; only the visibility
//! differs. At vertex `j`, a direction `d_j` pointing away from the surface on its side escapes
//! with a local probability (§6.3, "Reading as local escape probabilities"):
//!
//! * height-correlated: `lambda_{j-1} / (lambda_{j-1} + Lambda(d_j))` after a reflection and
//!   `lambda_{j-1} B(lambda_{j-1}, 1 + Lambda(d_j))` after a refraction, with
//!   `lambda_{j-1} = lambda(d_{j-1})` the depth rate of the arriving direction;
//! * height-uncorrelated: `G1(d_j) = 1 / (1 + Lambda(d_j))`;
//!
//! and a direction into the surface continues with probability 1. The escaping fraction of the
//! chain's weight is deposited at order `j`; the rest continues. Two-branch facets always
//! choose one branch at random (no splitting); weights below the policy's threshold play
//! Russian roulette as in the walk. Both variants conserve energy
//! exactly, and the correlated one reproduces exact single scattering (§6.3).

use glam::DVec3;
use rand::Rng;
use statrs::function::gamma::ln_gamma;

use crate::facet::{Facet, Interaction, Side};
use crate::ndf::Ndf;
use crate::random::open01;
use crate::walk::{EnergyPolicy, Loss, Observer, RUNAWAY_ORDER, choose, roulette};

/// The shadowing model of the chain (§6.3).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shadowing {
    /// Height-correlated: each vertex restarts at a depth drawn for its arriving direction.
    Correlated,
    /// Height-uncorrelated: escape with the separable masking `G1` of the leaving direction.
    Uncorrelated,
}

/// The Beta function `B(a, b)`.
fn beta(a: f64, b: f64) -> f64 {
    (ln_gamma(a) + ln_gamma(b) - ln_gamma(a + b)).exp()
}

impl Shadowing {
    /// Probability that a direction `up` (pointing away from the surface, in the frame of its
    /// own side) escapes right after a vertex reached along a direction of depth rate
    /// `rate_in`; `refracted` tells whether the vertex changed side (§6.3).
    fn escape<N: Ndf>(self, ndf: &N, rate_in: f64, up: DVec3, refracted: bool) -> f64 {
        let lambda_out = ndf.lambda(up);
        match (self, refracted) {
            (Shadowing::Uncorrelated, _) => 1.0 / (1.0 + lambda_out),
            (Shadowing::Correlated, false) => rate_in / (rate_in + lambda_out),
            (Shadowing::Correlated, true) => rate_in * beta(rate_in, 1.0 + lambda_out),
        }
    }

    /// Walks one photon arriving from `wi` (towards the light) through the chain and deposits
    /// the escaping weight of every order into `observer`, like the random walk does. Returns
    /// the number of facet interactions.
    #[allow(clippy::too_many_arguments)]
    pub fn trace<N, F, R, O, const C: usize>(
        self,
        ndf: &N,
        facet: &F,
        policy: &EnergyPolicy,
        wi: DVec3,
        rng: &mut R,
        observer: &mut O,
    ) -> u64
    where
        N: Ndf,
        F: Facet<C>,
        R: Rng + ?Sized,
        O: Observer<C>,
    {
        let mut side = if wi.z >= 0.0 { Side::Outside } else { Side::Inside };
        let mut d = -wi;
        let mut weight = [1.0; C];
        let mut order = 0u32;
        loop {
            // The own-side frame (§4.3): inside, directions are flipped.
            let flip = |v: DVec3, s: Side| if s == Side::Outside { v } else { -v };
            let d_own = flip(d, side);
            // Depth rate of the arriving direction (true Smith, §2.4).
            let rate_in = if d_own.z > 0.0 { ndf.lambda(d_own) } else { 1.0 + ndf.lambda(-d_own) };
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
            if !d.is_finite() || weight.iter().any(|w| !w.is_finite()) {
                observer.lose(Loss::Invalid, &weight);
                return u64::from(order);
            }
            let d_new_own = flip(d, side);
            if d_new_own.z > 0.0 {
                let p = self.escape(ndf, rate_in, d_new_own, branch.crosses);
                observer.escape(order, side, d, &weight.map(|w| w * p));
                weight = weight.map(|w| w * (1.0 - p));
            }
            match roulette(&weight, policy.threshold, rng) {
                Some(w) => weight = w,
                None => return u64::from(order),
            }
        }
    }
}
