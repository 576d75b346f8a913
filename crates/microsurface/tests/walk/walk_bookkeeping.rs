//! The walk's bookkeeping (docs/theory.md §4.6, §10): no physics is checked here, only that
//! weight is carried, counted and stopped as the walk's contract says. Exact assertions, no
//! statistics (fixed seeds).
//!
//! * Channels are carried apart and every random choice divides them alike: with Lambertian
//!   facets of albedos `rho_c`, every escape of order `k` carries `rho_c^k` times a factor
//!   common to all channels; Russian roulette looks at the largest channel only, so a path
//!   whose largest channel keeps weight 1 is never reweighted.
//! * A random choice between two branches is proportional to the weight each carries, so the
//!   path keeps the sum of the two (§4.6).
//! * A path that never escapes is stopped as a runaway after 2^20 interactions; a facet
//!   that returns a non-finite direction, or a weight that is infinite, negative or NaN, stops
//!   the path as an invalid loss carrying its weight; next-event estimation passes such a
//!   loss on to its sink.
//! * A facet says it may split exactly when its interaction returns two branches (the
//!   side-by-side walk relies on it).
//! * A depth profile whose light has all escaped lets nothing escape any more (§7.1).
//! * The interactions a photon returns are the hits of all its rays, split or not.
//! * Side by side, every photon asked for is walked and ended exactly once, for any number of
//!   photons (none, fewer than the lanes, not a multiple of them).

use microsurface::DVec3;
use microsurface::chain::Visibility;
use microsurface::facet::{
    Branch, Conductor, ConductorFresnel, Dielectric, Facet, Hammon, Interaction, Lambertian, Side,
};
use microsurface::ndf::{Ggx, Ndf, Roughness};
use microsurface::nee::NextEvent;
use microsurface::normals::Normals;
use microsurface::position_free::DepthProfile;
use microsurface::smith::Smith;
use microsurface::walk::{EnergyPolicy, Loss, Microsurface, Observer, RUNAWAY_ORDER};
use rand::{Rng, RngExt};
use rand_pcg::Pcg64Mcg;

const SURFACE: Microsurface<Ggx> =
    Microsurface { ndf: Ggx(Roughness { x: 0.5, y: 0.5 }), smith: Smith::Exact, normals: Normals::Visible };
const SPLIT: EnergyPolicy = EnergyPolicy { split: true, threshold: 0.1 };

/// Everything a walk reports, in order.
#[derive(Default)]
struct Record<const C: usize> {
    escapes: Vec<(u32, [f64; C])>,
    losses: Vec<(Loss, [f64; C])>,
    ended: u64,
    hits: u64,
}

impl<const C: usize> Observer<C> for Record<C> {
    fn escape(&mut self, order: u32, _side: Side, _dir: DVec3, weight: &[f64; C]) {
        self.escapes.push((order, *weight));
    }
    fn lose(&mut self, loss: Loss, weight: &[f64; C]) {
        self.losses.push((loss, *weight));
    }
    fn end_photon(&mut self, _interactions: u64) {
        self.ended += 1;
    }
    fn hit(&mut self, _order: u32, _tau: f64, _side: Side, _d: DVec3, _weight: &[f64; C]) {
        self.hits += 1;
    }
}

fn trace<F: Facet<C>, const C: usize>(facet: &F, policy: &EnergyPolicy, photons: u64) -> (Record<C>, u64) {
    let (mut record, mut rng, mut stack) = (Record::default(), Pcg64Mcg::new(81), Vec::new());
    let mut interactions = 0;
    for _ in 0..photons {
        interactions += SURFACE.trace(facet, policy, DVec3::new(0.6, 0.0, 0.8), &mut rng, &mut stack, &mut record);
    }
    (record, interactions)
}

#[test]
fn channels_are_carried_apart_and_scaled_alike() {
    let rho = [0.9, 0.5, 0.2];
    let (record, interactions) = trace(&Lambertian { albedo: rho }, &SPLIT, 20_000);
    assert!(record.losses.is_empty());
    assert!(record.escapes.iter().any(|&(k, _)| k >= 5), "no high orders reached");
    let mut orders = 0;
    for &(k, w) in &record.escapes {
        orders += u64::from(k);
        for c in 1..3 {
            let expected = w[0] * (rho[c] / rho[0]).powi(k as i32);
            assert!((w[c] - expected).abs() <= 1e-12 * expected, "order {k}: {w:?}");
        }
    }
    // One ray a photon (a Lambertian facet never splits): the interactions are the orders.
    assert_eq!(interactions, orders);
}

#[test]
fn roulette_looks_at_the_largest_channel_only() {
    // Channel 0 keeps weight 1, the others fall below the threshold at once: no roulette.
    let (record, _) = trace(&Lambertian { albedo: [1.0, 0.01, 0.001] }, &SPLIT, 5_000);
    assert!(record.losses.is_empty());
    for &(k, w) in &record.escapes {
        assert_eq!(w[0], 1.0, "order {k}: the path was reweighted: {w:?}");
    }
    // With every channel below the threshold, paths survive with probability rho / 0.1 and
    // carry 0.1 from then on (here, from the first facet on).
    let (record, _) = trace(&Lambertian { albedo: [0.05] }, &SPLIT, 5_000);
    assert!(!record.escapes.is_empty());
    assert!(record.escapes.iter().all(|&(_, w)| (w[0] - 0.1).abs() < 1e-15), "roulette weights");
}

/// A facet that always offers the same interaction, one branch or two.
struct Offers(Interaction<1>);

impl Facet<1> for Offers {
    fn interact<R: Rng + ?Sized>(&self, _w: DVec3, _m: DVec3, _side: Side, _rng: &mut R) -> Interaction<1> {
        self.0
    }
    fn may_split(&self) -> bool {
        matches!(self.0, Interaction::Two(..))
    }
    fn phase<N: Ndf, R: Rng + ?Sized>(&self, _: &N, _: DVec3, _: DVec3, _: Side, _: bool, _: &mut R) -> [f64; 1] {
        unreachable!("not used by the walk")
    }
}

/// A facet that always returns `branch`.
fn always(branch: Branch<1>) -> Offers {
    Offers(Interaction::One(branch))
}

#[test]
fn a_path_that_never_escapes_is_a_runaway() {
    // Straight down after every facet: no flight ever escapes.
    let down = always(Branch { dir: DVec3::NEG_Z, weight: [1.0], crosses: false });
    let (record, interactions) = trace(&down, &SPLIT, 2);
    assert!(record.escapes.is_empty());
    assert_eq!(record.losses, vec![(Loss::Runaway, [1.0]); 2]);
    // Hits are counted: the 2^20-th is stopped before its facet acts.
    assert_eq!(interactions, 2 * u64::from(RUNAWAY_ORDER));
}

#[test]
fn a_non_finite_direction_or_an_invalid_weight_is_an_invalid_loss() {
    let cases = [
        (DVec3::new(f64::NAN, 0.0, 1.0), 1.0),
        (DVec3::new(0.0, f64::INFINITY, 1.0), 1.0),
        (DVec3::Z, f64::INFINITY),
        (DVec3::Z, -0.5),
        (DVec3::Z, f64::NAN),
    ];
    for (dir, weight) in cases {
        let (record, interactions) = trace(&always(Branch { dir, weight: [weight], crosses: false }), &SPLIT, 3);
        assert!(record.escapes.is_empty(), "{dir}, {weight}: escaped");
        assert_eq!(record.losses.len(), 3, "{dir}, {weight}");
        for &(loss, w) in &record.losses {
            assert_eq!(loss, Loss::Invalid, "{dir}, {weight}");
            assert!(w[0] == weight || (w[0].is_nan() && weight.is_nan()), "{dir}, {weight}: lost {w:?}");
        }
        assert_eq!(interactions, 3, "{dir}, {weight}: one interaction a photon");
    }
}

#[test]
fn side_by_side_walks_and_ends_every_photon_once() {
    let facet = Lambertian { albedo: [1.0] };
    let never = EnergyPolicy { split: false, threshold: 0.1 };
    for photons in [0, 1, 3, 4, 5, 64, 67, 1001] {
        let mut record = Record::default();
        SURFACE.walk_side_by_side(
            &facet,
            &never,
            DVec3::new(0.6, 0.0, 0.8),
            photons,
            &mut Pcg64Mcg::new(82),
            &mut record,
        );
        assert_eq!(record.ended, photons, "{photons} photons");
        assert_eq!(record.escapes.len() as u64, photons, "{photons} photons: one escape each");
        assert!(record.escapes.iter().all(|&(k, w)| k >= 1 && w == [1.0]), "{photons} photons");
    }
}

#[test]
fn next_event_estimation_passes_losses_on() {
    let facet = always(Branch { dir: DVec3::new(f64::NAN, 0.0, 1.0), weight: [1.0], crosses: false });
    let (mut sink, mut rng, mut stack) = (Record::default(), Pcg64Mcg::new(83), Vec::new());
    let mut nee_rng = Pcg64Mcg::new(84);
    let mut nee = NextEvent {
        ndf: &SURFACE.ndf,
        normals: SURFACE.normals,
        facet: &Lambertian { albedo: [1.0] },
        sink: &mut sink,
        rng: &mut nee_rng,
        samples: 1,
    };
    SURFACE.trace(&facet, &SPLIT, DVec3::new(0.6, 0.0, 0.8), &mut rng, &mut stack, &mut nee);
    assert_eq!(sink.losses, vec![(Loss::Invalid, [1.0])]);
}

/// Whether `facet` returned two branches in 1000 interactions at random incidences.
fn splits<F: Facet<1>>(facet: &F) -> bool {
    let mut rng = Pcg64Mcg::new(85);
    (0..1000).any(|_| {
        let m = DVec3::new(rng.random_range(-0.5..0.5), rng.random_range(-0.5..0.5), 1.0).normalize();
        let w = (m + DVec3::new(rng.random_range(-0.5..0.5), rng.random_range(-0.5..0.5), 0.0)).normalize();
        matches!(facet.interact(w, m, Side::Outside, &mut rng), Interaction::Two(..))
    })
}

#[test]
fn a_facet_may_split_exactly_when_it_returns_two_branches() {
    let conductor = Conductor::<1> { fresnel: ConductorFresnel::Exact { eta: [0.2], k: [3.0] } };
    let lambertian = Lambertian { albedo: [0.5] };
    let hammon = Hammon { f0: [0.04], albedo: [0.5] };
    let dielectric = Dielectric { eta: 1.5 };
    assert!(!conductor.may_split() && !splits(&conductor));
    assert!(!Facet::<1>::may_split(&lambertian) && !splits(&lambertian));
    assert!(Facet::<1>::may_split(&hammon) && splits(&hammon));
    assert!(Facet::<1>::may_split(&dielectric) && splits(&dielectric));
    // The side-by-side walk takes exactly the policies and facets that never split.
    let never = EnergyPolicy { split: false, threshold: 0.1 };
    assert!(SPLIT.never_splits(&conductor) && SPLIT.never_splits(&lambertian));
    assert!(!SPLIT.never_splits(&hammon) && !SPLIT.never_splits::<_, 1>(&dielectric));
    assert!(never.never_splits(&hammon) && never.never_splits::<_, 1>(&dielectric));
}

#[test]
fn a_depth_profile_whose_light_escaped_lets_nothing_escape() {
    // Straight up (Lambda = 0 for GGX) everything escapes; what is left has no mass.
    let mut profile = DepthProfile::default();
    profile.enter(1.3);
    profile.down(2.0);
    assert_eq!(profile.up(0.0), 1.0);
    for lambda in [0.0, 0.5, 3.0] {
        assert_eq!(profile.up(lambda), 0.0, "after everything escaped, up({lambda})");
    }
}

#[test]
fn the_interactions_of_split_photons_are_their_hits() {
    // A split ray carries its parent's order on; the count a photon returns is the hits of all
    // its rays, not their orders.
    let (record, interactions) = trace::<_, 1>(&Dielectric { eta: 1.5 }, &SPLIT, 2_000);
    assert!(record.escapes.len() > 3_000, "the photons split");
    assert_eq!(interactions, record.hits);
}

#[test]
fn a_random_choice_is_proportional_to_the_weight_carried() {
    // §4.6: branch a (factor 0.3) is chosen with probability 0.3 / 0.5 and b (0.2) with
    // 0.2 / 0.5, each divided by its probability: whichever is chosen, the path carries 0.5
    // of its weight on, so an escape of order k carries exactly 0.5^k (no roulette here).
    // a heads down (always hits again), b up at 80 deg (often hits again).
    let pair = Offers(Interaction::Two(
        Branch { dir: DVec3::new(0.3, 0.0, -1.0).normalize(), weight: [0.3], crosses: false },
        Branch { dir: DVec3::new(-5.7, 0.0, 1.0).normalize(), weight: [0.2], crosses: false },
    ));
    let (record, _) = trace(&pair, &EnergyPolicy { split: false, threshold: 0.0 }, 5_000);
    assert!(record.escapes.iter().any(|&(k, _)| k >= 3), "no high orders reached");
    for &(k, w) in &record.escapes {
        let expected = 0.5f64.powi(k as i32);
        assert!((w[0] - expected).abs() <= 1e-14 * expected, "order {k}: {w:?}, expected {expected}");
    }
}
