//! Next-event estimation of the walk's lobes (Heitz et al. 2016 `eval`, docs/theory.md §4.7).
//!
//! At the `k`-th hit of a ray (depth `tau`, incident `w = -d`, weight `beta`) the lobe of
//! order `k` towards `wo` gets `beta p(w -> wo) G1(wo, tau)`: the facet's phase function
//! times the probability that `wo` escapes from that depth (`e^{-Lambda(wo) tau}` on the ray's
//! side, or from the other side's depth after a refraction). [`contribution`] is this point
//! evaluation; [`NextEvent`] integrates it over the detector's bins with directions drawn
//! from the phase function itself. Either way it is a second estimator of the same quantity as
//! the escape histogram, order by order: the escape event is replaced by its probability.

use glam::DVec3;
use rand::Rng;

use crate::facet::{Branch, Facet, Interaction, Side};
use crate::height::{escape_probability, other_side_depth};
use crate::ndf::Ndf;
use crate::normals::Normals;
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
    if wo_own.z == 0.0 {
        // Along the horizon light leaves into neither side: no escape from below the top, and
        // a set of directions of measure zero at the top.
        return ([0.0; C], side);
    }
    let (crosses, exit_side, exit_tau) =
        if wo_own.z > 0.0 { (false, side, tau) } else { (true, side.other(), other_side_depth(tau)) };
    let up = flip(wo, exit_side);
    let escape = escape_probability(ndf.lambda(up), exit_tau);
    let phase = facet.phase(ndf, w_own, wo_own, side, crosses, rng);
    (phase.map(|p| p * escape), exit_side)
}

/// An observer that turns every hit of a walk into next-event deposits into `sink` at the hit's
/// order, so the sink's bin sums estimate the same bin integrals as the escape histogram.
///
/// Each hit draws `samples` outgoing directions from the phase function: a facet normal from
/// the surface's law of hit normals, then the facet's interaction with every branch kept.
/// The point evaluation divided by the density of its direction is then the branch weight
/// times the escape probability, so every deposit is at most the ray's weight. (Directions
/// drawn uniformly on the sphere would divide by the projected area `A(w)` of the incident
/// direction, which vanishes as `w` goes below the horizon from the second hit on: unbiased,
/// but with effectively infinite variance.) Escapes of the walk itself are ignored; losses
/// are passed on.
pub struct NextEvent<'a, N, F, O, R> {
    /// The microsurface's NDF.
    pub ndf: &'a N,
    /// The law of the hit normals, for the phase function's directions.
    pub normals: Normals,
    /// The facets' micro-BSDF.
    pub facet: &'a F,
    /// Where the deposits go, at the hit's order.
    pub sink: &'a mut O,
    /// The estimator's own random stream, kept across photons.
    pub rng: &'a mut R,
    /// Outgoing directions drawn per hit.
    pub samples: u32,
}

impl<N: Ndf, F, O, R> NextEvent<'_, N, F, O, R> {
    /// Deposits every branch of the facet interaction with normal `m` of a ray travelling
    /// along `d` into a hit at depth `tau` on `side`.
    fn scatter<const C: usize>(&mut self, order: u32, tau: f64, side: Side, d: DVec3, m: DVec3, beta: &[f64; C])
    where
        F: Facet<C>,
        R: Rng,
        O: Observer<C>,
    {
        match self.facet.interact(-d, m, side, self.rng) {
            Interaction::One(b) => self.deposit(order, tau, side, &b, beta),
            Interaction::Two(a, b) => {
                self.deposit(order, tau, side, &a, beta);
                self.deposit(order, tau, side, &b, beta);
            }
        }
    }

    /// Deposits `beta * branch weight * P(escape)` of one branch leaving a hit at depth `tau` on
    /// `side`; a branch heading deeper into its side cannot escape before another hit.
    fn deposit<const C: usize>(&mut self, order: u32, tau: f64, side: Side, branch: &Branch<C>, beta: &[f64; C])
    where
        O: Observer<C>,
    {
        let (exit_side, exit_tau) = if branch.crosses { (side.other(), other_side_depth(tau)) } else { (side, tau) };
        let up = if exit_side == Side::Outside { branch.dir } else { -branch.dir };
        if up.z.is_nan() || up.z <= 0.0 {
            return;
        }
        let escape = escape_probability(self.ndf.lambda(up), exit_tau) / f64::from(self.samples);
        let deposit = std::array::from_fn(|i| beta[i] * branch.weight[i] * escape);
        self.sink.escape(order, exit_side, branch.dir, &deposit);
    }
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
        // The hit normal is drawn in the flipped frame of the ray's side (§4.3), as the walk
        // does; four at a time where there are as many, so that their draws overlap.
        let sign = if side == Side::Outside { 1.0 } else { -1.0 };
        let mut left = self.samples;
        while left >= 4 {
            for m in self.normals.sample_lanes(self.ndf, [sign * d; 4], self.rng) {
                self.scatter(order, tau, side, d, sign * m, weight);
            }
            left -= 4;
        }
        for _ in 0..left {
            let m = sign * self.normals.sample(self.ndf, sign * d, self.rng);
            self.scatter(order, tau, side, d, m, weight);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::facet::{Conductor, ConductorFresnel, Dielectric, Lambertian};
    use crate::ndf::{Ggx, Roughness};
    use rand::SeedableRng;

    /// Horizontal and barely-above-horizon `wo` at depth 0, just below it and deep: the
    /// escape probability is in [0, 1] (1 at depth 0, where every upward direction is
    /// unmasked, §2.2; 0 exactly along the horizon below the top), never NaN or infinite.
    #[test]
    fn grazing_and_horizontal_directions_give_finite_contributions() {
        let ndf = Ggx(Roughness { x: 0.5, y: 0.5 });
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(1);
        let d = DVec3::new(0.3, 0.1, -1.0).normalize();
        let subnormal = f64::MIN_POSITIVE / 4.0;
        let outgoing = [
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, -0.0),
            DVec3::new(1.0, 0.0, subnormal),
            DVec3::new(1.0, 0.0, -subnormal),
            DVec3::new(1.0, 0.0, 1e-300),
        ];
        for tau in [0.0, 1e-300, 0.3, 40.0] {
            for wo in outgoing {
                for side in [Side::Outside, Side::Inside] {
                    let values = [
                        contribution(
                            &ndf,
                            &Conductor::<1> { fresnel: ConductorFresnel::None },
                            tau,
                            side,
                            d,
                            wo,
                            &mut rng,
                        )
                        .0,
                        contribution(&ndf, &Lambertian { albedo: [1.0] }, tau, side, d, wo, &mut rng).0,
                        contribution::<_, _, _, 1>(&ndf, &Dielectric { eta: 1.5 }, tau, side, d, wo, &mut rng).0,
                    ];
                    for v in values {
                        assert!(v[0].is_finite() && v[0] >= 0.0, "tau {tau}, wo {wo}, {side:?}: {v:?}");
                    }
                }
            }
        }
    }
}
