//! Whole walks, order by order, against oracles that do not share the code under test
//! (docs/theory.md §4, §5, §6.3, §7.1, §9): here, beside the physics, so that a mutant of the
//! walk, the chains, next-event estimation or single scattering is rebuilt and judged in
//! seconds (docs/mutation.md).
//!
//! Every estimate is a histogram of escaping energy per photon on a 6 x 12 grid per
//! hemisphere, uniform in |cos theta_o| and in the absolute azimuth, per order class (orders
//! 1, 2, 3, 4 and up, and all orders), with the per-photon second moments.
//!
//! * **Order 1 against exact single scattering** (§5), integrated over each bin by adaptive
//!   quadrature: conductors (exact and Schlick Fresnel), the dielectric from outside (both
//!   hemispheres) and from inside, where the formulas hold with the sides swapped (§4.3: in
//!   the flipped frame `d -> -d` the ray sees the same microsurface and the index `1 / eta`;
//!   one case beyond the critical angle). Shares the NDF, Lambda and Fresnel with the walk,
//!   which have their own oracles (identities.rs, visible_normals.rs), not the sampler, the
//!   facets' interaction, the flights or the energy policy.
//! * **Orders 2 and up against the exact position-free form** (§7.1): the chain with the
//!   depth profile integrated out analytically estimates the same lobes without heights.
//!   The two share the sampler and the facets' interaction (checked at order 1 above and in
//!   phase_normalization.rs), not the flights, the depth bookkeeping or the escape events.
//! * **Next-event estimation against the escape histogram** (§4.7), the dielectric from both
//!   sides, 4 and 3 directions a hit: what it checks is the depth and escape part, and `Facet::phase` against `interact`.
//! * **Side by side against one at a time** (`walk_side_by_side` against `trace`, no splitting).
//! * **Energy** (§4.6): a dielectric absorbs nothing, so R + T of all orders is 1 in
//!   expectation with splitting, with the random choice between branches and with Russian
//!   roulette; any bias in their weights shows.
//! * **Wang et al.'s chains at order 1** (§6.3): the height-correlated chain reproduces exact
//!   single scattering (reflection and, through its Beta-function escape, refraction); the
//!   uncorrelated one the separable `G1(wi) G1(wo)` form; both conserve energy.
//!
//! Tests: chi-square (against exact expectations) or two-sample chi-square (two estimates,
//! per-photon variances at the common mean) per lobe, cells expected to hold fewer than 5
//! photons' worth of energy pooled; z tests for the albedos. All tests of one function at the
//! Sidak level keeping that function's family at 0.01. Fixed seeds throughout.

use crate::common;

use std::f64::consts::TAU;

use common::{dir, two_sided_z};
use microsurface::DVec3;
use microsurface::chain::{self, Visibility};
use microsurface::facet::{Conductor, ConductorFresnel, Dielectric, Facet, Hammon, Lambertian, Side};
use microsurface::fresnel;
use microsurface::ndf::{Beckmann, Ggx, Ndf, Roughness};
use microsurface::nee::NextEvent;
use microsurface::normals::Normals;
use microsurface::position_free::DepthProfile;
use microsurface::single;
use microsurface::smith::Smith;
use microsurface::walk::{EnergyPolicy, Loss, Microsurface, Observer};
use microsurface::wang::Shadowing;
use numerics::quadrature::integrate_2d;
use numerics::stats::{ChiSquare, WeightedBin, chi_square, sidak, two_sample_at_null};
use rand_pcg::Pcg64Mcg;

const COS_BINS: usize = 6;
const PHI_BINS: usize = 12;
const BINS: usize = COS_BINS * PHI_BINS;
/// Order classes: 1, 2, 3, 4 and up, all.
const CLASSES: usize = 5;
const ALL: usize = CLASSES - 1;
/// Slots per side and class: the bins, then the albedo.
const SLOTS: usize = BINS + 1;

/// The bin of an escape direction: |cos theta| and the absolute azimuth.
fn bin_of(d: DVec3) -> usize {
    let ic = ((d.z.abs() * COS_BINS as f64) as usize).min(COS_BINS - 1);
    let phi = d.y.atan2(d.x).rem_euclid(TAU);
    ic * PHI_BINS + ((phi / TAU * PHI_BINS as f64) as usize).min(PHI_BINS - 1)
}

/// Per-photon sums of escaping energy, and of their squares, per side, order class and bin.
#[derive(Default)]
struct Tally {
    photon: Vec<f64>,
    touched: Vec<usize>,
    sum: Vec<f64>,
    sum_sq: Vec<f64>,
    photons: u64,
    /// Whether an escape without light fails the test: the walk and the chains report only
    /// escapes that carry light (the program's detector counts the photons reaching each
    /// bin); next-event deposits may underflow to 0.
    strict: bool,
}

impl Tally {
    fn new() -> Self {
        let n = 2 * CLASSES * SLOTS;
        Tally { photon: vec![0.0; n], sum: vec![0.0; n], sum_sq: vec![0.0; n], strict: true, ..Default::default() }
    }

    fn slot(side: Side, class: usize, bin: usize) -> usize {
        (side as usize * CLASSES + class) * SLOTS + bin
    }

    fn add(&mut self, slot: usize, w: f64) {
        if self.photon[slot] == 0.0 {
            self.touched.push(slot);
        }
        self.photon[slot] += w;
    }

    /// Ends the current photon: its sums go into the tallies.
    fn close(&mut self) {
        for &s in &self.touched {
            let w = std::mem::take(&mut self.photon[s]);
            self.sum[s] += w;
            self.sum_sq[s] += w * w;
        }
        self.touched.clear();
        self.photons += 1;
    }

    fn moments(&self, side: Side, class: usize) -> Vec<WeightedBin> {
        let n = self.photons as f64;
        let s = Tally::slot(side, class, 0);
        (s..s + BINS).map(|i| WeightedBin { mean: self.sum[i] / n, second_moment: self.sum_sq[i] / n }).collect()
    }

    /// R + T of all orders and its z score against 1. R and T of one photon are not
    /// independent: the standard error of their sum is at most the sum of theirs, which is used.
    fn total_z(&self) -> (f64, f64) {
        let ((r, sr), (t, st)) = (self.albedo(Side::Outside, ALL), self.albedo(Side::Inside, ALL));
        (r + t, (r + t - 1.0) / (sr + st))
    }

    /// The albedo of an order class on a side: mean and standard error per photon.
    fn albedo(&self, side: Side, class: usize) -> (f64, f64) {
        let (n, s) = (self.photons as f64, Tally::slot(side, class, BINS));
        let mean = self.sum[s] / n;
        (mean, ((self.sum_sq[s] / n - mean * mean) / (n - 1.0)).max(0.0).sqrt())
    }
}

impl Observer<1> for Tally {
    fn escape(&mut self, order: u32, side: Side, dir: DVec3, weight: &[f64; 1]) {
        assert!(weight[0] > 0.0 || !self.strict, "an escape without light at order {order}");
        let class = (order as usize).clamp(1, 4) - 1;
        let bin = bin_of(dir);
        for c in [class, ALL] {
            self.add(Tally::slot(side, c, bin), weight[0]);
            self.add(Tally::slot(side, c, BINS), weight[0]);
        }
    }

    /// No case here loses light (§10): a loss fails the test at once, also when a broken walk
    /// never ends a path and reports it as runaway only after 2^20 interactions.
    fn lose(&mut self, loss: Loss, weight: &[f64; 1]) {
        panic!("{loss:?}: weight {} lost", weight[0]);
    }

    /// The side-by-side walk ends its photons itself; the other walks' callers call
    /// [`Tally::close`].
    fn end_photon(&mut self, _interactions: u64) {
        self.close();
    }
}

/// One case of the walk: the surface, the facet, the energy policy and the light's direction.
struct Walk<N, F> {
    surface: Microsurface<N>,
    facet: F,
    policy: EnergyPolicy,
    wi: DVec3,
}

impl<N: Ndf, F: Facet<1>> Walk<N, F> {
    fn new(ndf: N, facet: F, policy: EnergyPolicy, wi: DVec3) -> Self {
        Walk { surface: Microsurface { ndf, smith: Smith::Exact, normals: Normals::Visible }, facet, policy, wi }
    }

    /// `photons` photons walked one at a time.
    fn trace(&self, photons: u64, seed: u128) -> Tally {
        let (mut tally, mut rng, mut stack) = (Tally::new(), Pcg64Mcg::new(seed), Vec::new());
        for _ in 0..photons {
            self.surface.trace(&self.facet, &self.policy, self.wi, &mut rng, &mut stack, &mut tally);
            tally.close();
        }
        tally
    }

    /// `photons` photons walked side by side.
    fn side_by_side(&self, photons: u64, seed: u128) -> Tally {
        let (mut tally, mut rng) = (Tally::new(), Pcg64Mcg::new(seed));
        self.surface.walk_side_by_side(&self.facet, &self.policy, self.wi, photons, &mut rng, &mut tally);
        tally
    }

    /// `photons` photons estimated by next-event estimation at every hit, `samples` directions
    /// each.
    fn next_event(&self, photons: u64, samples: u32, seed: u128) -> Tally {
        let (mut tally, mut rng, mut stack) =
            (Tally { strict: false, ..Tally::new() }, Pcg64Mcg::new(seed), Vec::new());
        let mut nee_rng = Pcg64Mcg::new(seed ^ 0x5eed);
        for _ in 0..photons {
            let mut nee = NextEvent {
                ndf: &self.surface.ndf,
                normals: self.surface.normals,
                facet: &self.facet,
                sink: &mut tally,
                rng: &mut nee_rng,
                samples,
            };
            self.surface.trace(&self.facet, &self.policy, self.wi, &mut rng, &mut stack, &mut nee);
            tally.close();
        }
        tally
    }

    /// `photons` height-free chains with the visibility `visibility`.
    fn chain<V: Visibility>(&self, mut visibility: V, photons: u64, seed: u128) -> Tally {
        let (mut tally, mut rng) = (Tally::new(), Pcg64Mcg::new(seed));
        for _ in 0..photons {
            chain::trace(&mut visibility, &self.surface.ndf, &self.facet, &self.policy, self.wi, &mut rng, &mut tally);
            tally.close();
        }
        tally
    }
}

/// Bin integrals `∫∫ lobe(wo) d|cos theta_o| dphi_o` over the hemisphere `side` (outside: `z > 0`).
fn bin_integrals(side: Side, lobe: impl Fn(DVec3) -> f64) -> Vec<f64> {
    let sign = if side == Side::Outside { 1.0 } else { -1.0 };
    let f = |u: f64, phi: f64| {
        let s = (1.0 - u * u).max(0.0).sqrt();
        lobe(DVec3::new(s * phi.cos(), s * phi.sin(), sign * u))
    };
    (0..BINS)
        .map(|b| {
            let (ic, ip) = (b / PHI_BINS, b % PHI_BINS);
            let u = (ic as f64 / COS_BINS as f64, (ic + 1) as f64 / COS_BINS as f64);
            let phi = (ip as f64 * TAU / PHI_BINS as f64, (ip + 1) as f64 * TAU / PHI_BINS as f64);
            integrate_2d(f, u, phi, 1e-9).0
        })
        .collect()
}

/// Exact single scattering `f_1 |cos theta_o|` (§5) of light from `wi` into `wo`, with facets
/// of conductor reflectance `conductor` or, without it, a dielectric of index `eta`. Light from
/// inside (`wi_z < 0`) is handled in the flipped frame, where the index is `1 / eta` (§4.3).
fn single_lobe<N: Ndf>(ndf: &N, wi: DVec3, wo: DVec3, conductor: Option<&dyn Fn(f64) -> f64>, eta: f64) -> f64 {
    let (wi, wo, eta) = if wi.z > 0.0 { (wi, wo, eta) } else { (-wi, -wo, 1.0 / eta) };
    let dielectric = |c: f64| fresnel::dielectric(eta, c);
    match conductor {
        Some(f) => single::reflection(ndf, wi, wo, f),
        None if wo.z > 0.0 => single::reflection(ndf, wi, wo, dielectric),
        None => single::transmission(ndf, wi, wo, eta, dielectric),
    }
}

fn report(label: &str, test: &ChiSquare) {
    println!("{label}: chi2 {:.1} dof {} p {:.3e}", test.statistic, test.dof, test.p_value);
}

/// Asserts that the order-1 lobe and albedo of `tally` on `side` match `expected` bin integrals.
fn assert_order_one(tally: &Tally, side: Side, expected: &[f64], level: f64, label: &str) {
    let test = chi_square(&tally.moments(side, 0), expected, tally.photons, 5.0);
    report(label, &test);
    assert!(test.dof >= 8, "{label}: too few cells ({})", test.dof);
    assert!(test.p_value > level, "{label}: order-1 lobe rejected\n{}", test.worst_cells(10));
    let (e1, se) = tally.albedo(side, 0);
    let total: f64 = expected.iter().sum();
    let z = (e1 - total) / se;
    println!("{label}: E1 {e1:.5} +- {se:.5}, single scattering {total:.5}");
    assert!(total > 0.01, "{label}: the case must carry light at order 1 ({total})");
    assert!(z.abs() < two_sided_z(level), "{label}: E1 = {e1} +- {se}, single scattering {total}, z = {z:.2}");
}

/// Asserts that two independent estimates agree on every order class's lobe and albedo on `side`.
fn assert_same_lobes(a: &Tally, b: &Tally, side: Side, level: f64, label: &str) {
    for class in 0..CLASSES {
        let label = format!("{label}, {side:?}, order class {}", class + 1);
        let test = two_sample_at_null(&a.moments(side, class), a.photons, &b.moments(side, class), b.photons, 5.0);
        report(&label, &test);
        assert!(test.p_value > level, "{label}: lobes differ\n{}", test.worst_cells(10));
        let ((ea, sa), (eb, sb)) = (a.albedo(side, class), b.albedo(side, class));
        let z = (ea - eb) / (sa * sa + sb * sb).sqrt();
        assert!(z.abs() < two_sided_z(level), "{label}: albedo {ea} +- {sa} against {eb} +- {sb}, z = {z:.2}");
    }
}

const SPLIT: EnergyPolicy = EnergyPolicy { split: true, threshold: 0.1 };
const CHOOSE: EnergyPolicy = EnergyPolicy { split: false, threshold: 0.1 };
const PHOTONS: u64 = 400_000;

#[test]
fn order_one_matches_exact_single_scattering() {
    let level = sidak(0.01, 2 * 9);
    let gold = |c: f64| fresnel::conductor(0.2, 3.0, c);
    let schlick = |c: f64| fresnel::schlick(0.5, c);

    let ggx = Ggx(Roughness::isotropic(0.5));
    let conductor = Conductor::<1> { fresnel: ConductorFresnel::Exact { eta: [0.2], k: [3.0] } };
    let tally = Walk::new(ggx, conductor, SPLIT, dir(40.0, 0.0)).trace(PHOTONS, 1);
    let expected = bin_integrals(Side::Outside, |wo| single_lobe(&ggx, dir(40.0, 0.0), wo, Some(&gold), 1.0));
    assert_order_one(&tally, Side::Outside, &expected, level, "GGX conductor");

    let beckmann = Beckmann(Roughness { x: 0.6, y: 0.3 });
    let schlick_facet = Conductor::<1> { fresnel: ConductorFresnel::Schlick { f0: [0.5] } };
    let wi = dir(70.0, 30.0);
    let tally = Walk::new(beckmann, schlick_facet, SPLIT, wi).trace(PHOTONS, 2);
    let expected = bin_integrals(Side::Outside, |wo| single_lobe(&beckmann, wi, wo, Some(&schlick), 1.0));
    assert_order_one(&tally, Side::Outside, &expected, level, "Beckmann Schlick conductor");

    // The dielectric from outside (a random branch at each facet), and from inside below and
    // beyond the critical angle (41.8 deg for 1 / 1.5).
    let dielectric = Dielectric { eta: 1.5 };
    let cases: [(Ggx, DVec3, EnergyPolicy, &str); 3] = [
        (Ggx(Roughness { x: 0.6, y: 0.3 }), dir(50.0, 30.0), CHOOSE, "outside"),
        (Ggx(Roughness::isotropic(0.5)), dir(160.0, 0.0), SPLIT, "inside"),
        (Ggx(Roughness { x: 0.6, y: 0.3 }), dir(130.0, 30.0), SPLIT, "inside beyond the critical angle"),
    ];
    for (i, (ndf, wi, policy, name)) in cases.into_iter().enumerate() {
        let tally = Walk::new(ndf, dielectric, policy, wi).trace(PHOTONS, 3 + i as u128);
        for side in [Side::Outside, Side::Inside] {
            let expected = bin_integrals(side, |wo| single_lobe(&ndf, wi, wo, None, 1.5));
            assert_order_one(&tally, side, &expected, level, &format!("dielectric from {name}, {side:?}"));
        }
    }
    let inside = Walk::new(Beckmann(Roughness::isotropic(0.4)), dielectric, SPLIT, dir(145.0, 0.0));
    let tally = inside.trace(PHOTONS, 6);
    let expected = bin_integrals(Side::Inside, |wo| single_lobe(&inside.surface.ndf, inside.wi, wo, None, 1.5));
    assert_order_one(&tally, Side::Inside, &expected, level, "Beckmann dielectric from inside, Inside");
}

#[test]
fn orders_two_and_up_match_the_exact_position_free_form() {
    let level = sidak(0.01, 3 * 2 * CLASSES);
    let conductor = Conductor::<1> { fresnel: ConductorFresnel::Exact { eta: [0.2], k: [3.0] } };
    let gold = Walk::new(Ggx(Roughness { x: 0.7, y: 0.4 }), conductor, SPLIT, dir(60.0, 20.0));
    let chains = gold.chain(DepthProfile::default(), PHOTONS, 11);
    assert_same_lobes(&gold.trace(PHOTONS, 12), &chains, Side::Outside, level, "GGX conductor");
    let white = Walk::new(Ggx(Roughness::isotropic(1.0)), Lambertian::<1> { albedo: [0.8] }, SPLIT, dir(0.0, 0.0));
    let chains = white.chain(DepthProfile::default(), PHOTONS, 13);
    assert_same_lobes(&white.trace(PHOTONS, 14), &chains, Side::Outside, level, "Lambertian");
    let hammon = Hammon::<1> { f0: [0.04], albedo: [0.8] };
    let plastic = Walk::new(Beckmann(Roughness::isotropic(0.5)), hammon, SPLIT, dir(30.0, 0.0));
    let chains = plastic.chain(DepthProfile::default(), PHOTONS, 15);
    assert_same_lobes(&plastic.trace(PHOTONS, 16), &chains, Side::Outside, level, "Hammon");
}

#[test]
fn next_event_matches_the_escape_histogram() {
    let level = sidak(0.01, 2 * 2 * 2 * CLASSES);
    let dielectric = Dielectric { eta: 1.5 };
    // 4 directions a hit are drawn on lanes, 3 one at a time.
    for (i, (wi, samples)) in [(dir(50.0, 30.0), 4), (dir(150.0, 0.0), 3)].into_iter().enumerate() {
        let walk = Walk::new(Ggx(Roughness { x: 0.6, y: 0.3 }), dielectric, SPLIT, wi);
        let escapes = walk.trace(PHOTONS, 21 + i as u128);
        let nee = walk.next_event(PHOTONS / 4, samples, 23 + i as u128);
        for side in [Side::Outside, Side::Inside] {
            assert_same_lobes(
                &escapes,
                &nee,
                side,
                level,
                &format!("dielectric at {:.0} deg", wi.z.acos().to_degrees()),
            );
        }
    }
}

#[test]
fn side_by_side_walks_photons_as_one_at_a_time() {
    let level = sidak(0.01, 4 * 2 * CLASSES);
    let ggx = Ggx(Roughness { x: 0.7, y: 0.4 });
    let conductor = Conductor::<1> { fresnel: ConductorFresnel::Exact { eta: [0.2], k: [3.0] } };
    let gold = Walk::new(ggx, conductor, SPLIT, dir(60.0, 20.0));
    assert_same_lobes(&gold.trace(PHOTONS, 31), &gold.side_by_side(PHOTONS, 32), Side::Outside, level, "conductor");
    let white =
        Walk::new(Beckmann(Roughness::isotropic(0.8)), Lambertian::<1> { albedo: [0.8] }, SPLIT, dir(10.0, 0.0));
    assert_same_lobes(&white.trace(PHOTONS, 33), &white.side_by_side(PHOTONS, 34), Side::Outside, level, "Lambertian");
    let glass = Walk::new(ggx, Dielectric { eta: 1.5 }, CHOOSE, dir(140.0, 60.0));
    let (one, lanes) = (glass.trace(PHOTONS, 35), glass.side_by_side(PHOTONS, 36));
    for side in [Side::Outside, Side::Inside] {
        assert_same_lobes(&one, &lanes, side, level, "dielectric from inside");
    }
}

#[test]
fn a_dielectric_returns_all_light_under_every_energy_policy() {
    // (policy, light from outside or inside); roulette is played below each threshold.
    let policies = [
        EnergyPolicy { split: true, threshold: 0.1 },
        EnergyPolicy { split: true, threshold: 0.6 },
        EnergyPolicy { split: false, threshold: 0.6 },
        EnergyPolicy { split: false, threshold: 0.0 },
    ];
    let level = sidak(0.01, 2 * policies.len());
    for (i, policy) in policies.into_iter().enumerate() {
        for (j, wi) in [dir(75.0, 0.0), dir(120.0, 0.0)].into_iter().enumerate() {
            let tally = Walk::new(Ggx(Roughness::isotropic(0.3)), Dielectric { eta: 1.5 }, policy, wi)
                .trace(PHOTONS / 4, 41 + 2 * i as u128 + j as u128);
            let (total, z) = tally.total_z();
            println!("{policy:?} at {wi}: R + T = {total}, z = {z:.2}");
            assert!(z.abs() < two_sided_z(level), "{policy:?} at {wi}: R + T = {total}, z = {z:.2}");
        }
    }
}

#[test]
fn wangs_chains_at_order_one_are_single_scattering_and_conserve_energy() {
    let level = sidak(0.01, 4 * 2 + 2);
    let ggx = Ggx(Roughness { x: 0.6, y: 0.3 });
    let (wi, eta) = (dir(50.0, 30.0), 1.5);
    let glass = Walk::new(ggx, Dielectric { eta }, CHOOSE, wi);
    let correlated = glass.chain(Shadowing::Correlated, PHOTONS, 51);
    let uncorrelated = glass.chain(Shadowing::Uncorrelated, PHOTONS, 52);
    let g1 = |w: DVec3| 1.0 / (1.0 + ggx.lambda(w));
    for side in [Side::Outside, Side::Inside] {
        let exact = bin_integrals(side, |wo| single_lobe(&ggx, wi, wo, None, eta));
        assert_order_one(&correlated, side, &exact, level, &format!("correlated chain, {side:?}"));
        // Separable masking-shadowing: the height-correlated G2 of §5 replaced by G1(wi) G1(wo).
        let separable = bin_integrals(side, |wo| {
            let exact = single_lobe(&ggx, wi, wo, None, eta);
            let g2 =
                if wo.z > 0.0 { single::g2_reflection(&ggx, wi, wo) } else { single::g2_transmission(&ggx, wi, wo) };
            if exact > 0.0 { exact / g2 * g1(wi) * g1(wo * wo.z.signum()) } else { 0.0 }
        });
        assert_order_one(&uncorrelated, side, &separable, level, &format!("uncorrelated chain, {side:?}"));
    }
    for (name, tally) in [("correlated", &correlated), ("uncorrelated", &uncorrelated)] {
        let (total, z) = tally.total_z();
        assert!(z.abs() < two_sided_z(level), "{name}: R + T = {total}, z = {z:.2}");
    }
}

#[test]
#[should_panic(expected = "cannot split")]
fn side_by_side_refuses_a_dielectric_that_would_split() {
    // Its lanes have nowhere to keep a second branch: splitting there would drop light.
    Walk::new(Ggx(Roughness::isotropic(0.5)), Dielectric { eta: 1.5 }, SPLIT, dir(30.0, 0.0)).side_by_side(10, 61);
}

#[test]
fn the_position_free_form_reports_refraction_as_an_invalid_loss() {
    // §7.1: the depth profile has no form for a change of side; the chain must stop the
    // refracted light as an invalid loss, not carry a NaN on.
    #[derive(Default)]
    struct Outcome {
        escaped: f64,
        invalid: f64,
    }
    impl Observer<1> for Outcome {
        fn escape(&mut self, order: u32, _: Side, d: DVec3, weight: &[f64; 1]) {
            assert!(d.is_finite() && weight[0].is_finite() && weight[0] > 0.0, "order {order}: {d}, {weight:?}");
            self.escaped += weight[0];
        }
        fn lose(&mut self, loss: Loss, weight: &[f64; 1]) {
            assert_eq!(loss, Loss::Invalid);
            self.invalid += weight[0];
        }
    }
    let (mut outcome, mut rng) = (Outcome::default(), Pcg64Mcg::new(71));
    let ndf = Ggx(Roughness::isotropic(0.5));
    for _ in 0..10_000 {
        chain::trace(
            &mut DepthProfile::default(),
            &ndf,
            &Dielectric { eta: 1.5 },
            &CHOOSE,
            dir(30.0, 0.0),
            &mut rng,
            &mut outcome,
        );
    }
    // Most light refracts at the first facet (the order-1 reflection is about 4%).
    let n = 10_000.0;
    println!("escaped {}, invalid {} per photon", outcome.escaped / n, outcome.invalid / n);
    assert!(
        outcome.invalid / n > 0.8 && outcome.escaped / n < 0.2,
        "escaped {}, invalid {}",
        outcome.escaped,
        outcome.invalid
    );
}

#[test]
fn single_scattering_has_no_lobe_on_the_wrong_side() {
    // §5: reflection needs both directions above, transmission the light above and the
    // detector below; the formulas return 0 elsewhere, not a value of the wrong geometry.
    let ndf = Ggx(Roughness::isotropic(0.5));
    let f = |c: f64| fresnel::dielectric(1.5, c);
    let (up, down) = (dir(30.0, 0.0), dir(140.0, 170.0));
    assert!(single::reflection(&ndf, up, dir(40.0, 180.0), f) > 0.0);
    assert!(single::transmission(&ndf, up, down, 1.5, f) > 0.0);
    for (wi, wo) in [(up, down), (down, up), (down, dir(40.0, 180.0))] {
        assert_eq!(single::reflection(&ndf, wi, wo, f), 0.0, "reflection {wi} -> {wo}");
    }
    for (wi, wo) in [(up, dir(40.0, 180.0)), (down, down), (down, up)] {
        assert_eq!(single::transmission(&ndf, wi, wo, 1.5, f), 0.0, "transmission {wi} -> {wo}");
    }
    // Light from inside (eta = 1/1.5) at 80 deg and a detector at 80 deg opposite, both above:
    // there the refraction half vector exists (wi·wo = -0.94 < -eta, and wi·h = 0.85 is below
    // the critical angle), so only the horizon test keeps the lobe off the light's side.
    let inside = |c: f64| fresnel::dielectric(1.0 / 1.5, c);
    assert_eq!(single::transmission(&ndf, dir(80.0, 0.0), dir(80.0, 180.0), 1.0 / 1.5, inside), 0.0);
}

/// Student-T surfaces (§1.6, §3.4) against the same oracles as GGX and Beckmann: order 1
/// against exact single scattering (an anisotropic heavy-tailed conductor, a dielectric from
/// outside, both hemispheres), orders 2 and up against the exact position-free form, and the
/// furnace: a conductor with F = 1 reflects everything (its albedo is 1 with zero variance
/// per photon when the walk splits: every photon escapes with weight 1) and a lossless
/// dielectric returns R + T = 1 within its z test. 400 000 photons a case (the dielectric
/// furnace 100 000); pooling and levels as in the file's header, the family of this
/// function at 0.01.
#[test]
fn student_t_walks_match_their_oracles() {
    use microsurface::student_t::StudentT;
    let level = sidak(0.01, 3 + CLASSES + 1);
    let gold = |c: f64| fresnel::conductor(0.2, 3.0, c);
    let conductor = Conductor::<1> { fresnel: ConductorFresnel::Exact { eta: [0.2], k: [3.0] } };

    let heavy = StudentT::new(Roughness { x: 0.6, y: 0.3 }, 1.6).unwrap();
    let wi = dir(50.0, 30.0);
    let walk = Walk::new(heavy, conductor, SPLIT, wi);
    let tally = walk.trace(PHOTONS, 51);
    let expected = bin_integrals(Side::Outside, |wo| single_lobe(&heavy, wi, wo, Some(&gold), 1.0));
    assert_order_one(&tally, Side::Outside, &expected, level, "Student-T 1.6 conductor");
    let chains = walk.chain(DepthProfile::default(), PHOTONS, 52);
    assert_same_lobes(&tally, &chains, Side::Outside, level, "Student-T 1.6 conductor, orders 2 and up");

    let ndf = StudentT::new(Roughness::isotropic(0.5), 4.0).unwrap();
    let wi = dir(60.0, 0.0);
    let tally = Walk::new(ndf, Dielectric { eta: 1.5 }, SPLIT, wi).trace(PHOTONS, 53);
    for side in [Side::Outside, Side::Inside] {
        let expected = bin_integrals(side, |wo| single_lobe(&ndf, wi, wo, None, 1.5));
        assert_order_one(&tally, side, &expected, level, &format!("Student-T 4 dielectric, {side:?}"));
    }

    let white = Conductor::<1> { fresnel: ConductorFresnel::Schlick { f0: [1.0] } };
    let rough = StudentT::new(Roughness::isotropic(1.0), 2.5).unwrap();
    let tally = Walk::new(rough, white, SPLIT, dir(70.0, 0.0)).trace(PHOTONS / 4, 54);
    let (total, _) = tally.total_z();
    println!("Student-T 2.5 F = 1 conductor at 70 deg: albedo {total}");
    assert!((total - 1.0).abs() < 1e-12, "F = 1 conductor: albedo {total}");
    let tally = Walk::new(rough, Dielectric { eta: 1.5 }, CHOOSE, dir(75.0, 0.0)).trace(PHOTONS / 4, 55);
    let (total, z) = tally.total_z();
    println!("Student-T 2.5 dielectric at 75 deg: R + T = {total}, z = {z:.2}");
    assert!(z.abs() < two_sided_z(level), "dielectric: R + T = {total}, z = {z:.2}");
}

/// Tabulated surfaces (§1.7, §3.5), tables of GGX (roughness 0.5) and Student-T (gamma 3,
/// roughness 0.5) at the recommended step, against the analytic NDFs' oracles (the tables
/// reproduce D and Lambda to a relative 4e-5, §1.7, tabulated.rs in the distributions tests,
/// far below what these counts resolve; the tables' own D, with a kink every 0.25 degree, would
/// make the bin quadrature a hundred times slower): order 1 of a conductor (the GGX table)
/// and of a dielectric from outside, both hemispheres (the Student-T table), against exact
/// single scattering; orders 2 and up of the conductor against the exact position-free form
/// on the same table; and the furnace (a conductor with F = 1 reflects everything, albedo 1
/// with zero variance when the walk splits) on a GGX table of roughness 1 at 70 degrees and a
/// Beckmann one of roughness 0.3 at 80 degrees. 400 000 photons a case (the furnace 100 000);
/// pooling and levels as in the file's header, the family of this function at 0.01.
#[test]
fn tabulated_walks_match_their_oracles() {
    use common::table_of;
    use microsurface::student_t::StudentT;
    use microsurface::tabulated::RECOMMENDED_STEP_DEG;
    let level = sidak(0.01, 3 + CLASSES + 1);
    let gold = |c: f64| fresnel::conductor(0.2, 3.0, c);
    let conductor = Conductor::<1> { fresnel: ConductorFresnel::Exact { eta: [0.2], k: [3.0] } };

    let ggx = Ggx(Roughness::isotropic(0.5));
    let wi = dir(50.0, 30.0);
    let walk = Walk::new(table_of(&ggx, RECOMMENDED_STEP_DEG, 1.0), conductor, SPLIT, wi);
    let tally = walk.trace(PHOTONS, 61);
    let expected = bin_integrals(Side::Outside, |wo| single_lobe(&ggx, wi, wo, Some(&gold), 1.0));
    assert_order_one(&tally, Side::Outside, &expected, level, "GGX 0.5 table, conductor");
    let chains = walk.chain(DepthProfile::default(), PHOTONS, 62);
    assert_same_lobes(&tally, &chains, Side::Outside, level, "GGX 0.5 table, conductor, orders 2 and up");

    let student_t = StudentT::new(Roughness::isotropic(0.5), 3.0).unwrap();
    let wi = dir(60.0, 0.0);
    let table = table_of(&student_t, RECOMMENDED_STEP_DEG, 1.0);
    let tally = Walk::new(table, Dielectric { eta: 1.5 }, SPLIT, wi).trace(PHOTONS, 63);
    for side in [Side::Outside, Side::Inside] {
        let expected = bin_integrals(side, |wo| single_lobe(&student_t, wi, wo, None, 1.5));
        assert_order_one(&tally, side, &expected, level, &format!("Student-T 3 table, dielectric, {side:?}"));
    }

    let white = Conductor::<1> { fresnel: ConductorFresnel::Schlick { f0: [1.0] } };
    for (table, theta, label) in [
        (table_of(&Ggx(Roughness::isotropic(1.0)), RECOMMENDED_STEP_DEG, 1.0), 70.0, "GGX 1 table"),
        (table_of(&Beckmann(Roughness::isotropic(0.3)), RECOMMENDED_STEP_DEG, 1.0), 80.0, "Beckmann 0.3 table"),
    ] {
        let tally = Walk::new(table, white, SPLIT, dir(theta, 0.0)).trace(PHOTONS / 4, 64);
        let (total, _) = tally.total_z();
        println!("{label}, F = 1 conductor at {theta} deg: albedo {total}");
        assert!((total - 1.0).abs() < 1e-12, "{label}, F = 1 conductor: albedo {total}");
    }
}
