//! Next-event estimation of the walk's lobes (Heitz et al. 2016 `eval`, THEORY.md §4.7).
//!
//! At the `k`-th hit of a ray (depth `tau`, incident `w = -d`, weight `beta`) the lobe of
//! order `k` towards `wo` gets `beta p(w -> wo) G1(wo, tau)`: the facet's phase function
//! times the probability that `wo` escapes from that depth (`e^{-Lambda(wo) tau}` on the ray's
//! side, or from the other side's depth after a refraction). This is a second, independent
//! estimator of the same quantity as the escape histogram, order by order.

use std::f64::consts::PI;

use glam::DVec3;
use rand::Rng;

use crate::facet::{Facet, Side};
use crate::height::other_side_depth;
use crate::ndf::Ndf;
use crate::random::open01;
use crate::walk::{Loss, Observer};

/// The phase function times the escape probability towards `wo` (pointing away from the
/// surface, real frame) from a hit at depth `tau` on `side`, incident along travel direction
/// `d`: the order's cosine-weighted lobe contribution per unit weight, and the side `wo`
/// leaves into.
pub fn contribution<N, F, R, const C: usize>(
    ndf: &N,
    facet: &F,
    tau: f64,
    side: Side,
    d: DVec3,
    wo: DVec3,
    rng: &mut R,
) -> ([f64; C], Side)
where
    N: Ndf,
    F: Facet<C>,
    R: Rng + ?Sized,
{
    let flip = |v: DVec3, s: Side| if s == Side::Outside { v } else { -v };
    let (w_own, wo_own) = (flip(-d, side), flip(wo, side));
    let (crosses, exit_side, exit_tau) =
        if wo_own.z > 0.0 { (false, side, tau) } else { (true, side.other(), other_side_depth(tau)) };
    let up = flip(wo, exit_side);
    let escape = (-ndf.lambda(up) * exit_tau).exp();
    let phase = facet.phase(ndf, w_own, wo_own, side, crosses, rng);
    (phase.map(|p| p * escape), exit_side)
}

/// An observer that turns every hit of a walk into next-event deposits: `samples` outgoing
/// directions drawn uniformly on the sphere, each weighted by `4 pi / samples` and deposited
/// into `sink` at the hit's order, so the sink's bin sums estimate the same bin integrals as
/// the escape histogram. Escapes of the walk itself are ignored; losses are passed on.
pub struct NextEvent<'a, N, F, O, R> {
    pub ndf: &'a N,
    pub facet: &'a F,
    pub sink: &'a mut O,
    /// The estimator's own random stream, kept across photons.
    pub rng: &'a mut R,
    pub samples: u32,
}

impl<N, F, O, R, const C: usize> Observer<C> for NextEvent<'_, N, F, O, R>
where
    N: Ndf,
    F: Facet<C>,
    O: Observer<C>,
    R: Rng,
{
    fn escape(&mut self, _order: u32, _side: Side, _dir: DVec3, _weight: &[f64; C]) {}

    fn lose(&mut self, loss: Loss, weight: &[f64; C]) {
        self.sink.lose(loss, weight);
    }

    fn hit(&mut self, order: u32, tau: f64, side: Side, d: DVec3, weight: &[f64; C]) {
        let scale = 4.0 * PI / f64::from(self.samples);
        for _ in 0..self.samples {
            let z = 2.0 * open01(self.rng) - 1.0;
            let (s, c) = (2.0 * PI * open01(self.rng)).sin_cos();
            let r = (1.0 - z * z).max(0.0).sqrt();
            let wo = DVec3::new(r * c, r * s, z);
            let (value, exit) = contribution(self.ndf, self.facet, tau, side, d, wo, self.rng);
            let deposit = std::array::from_fn(|i| weight[i] * value[i] * scale);
            self.sink.escape(order, exit, wo, &deposit);
        }
    }
}
