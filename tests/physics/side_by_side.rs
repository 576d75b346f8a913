//! Photons walked side by side (`Microsurface::walk_side_by_side`, the measurement's walk for
//! paths that never split) against the plain walk (`Microsurface::trace`): the same random
//! walk (docs/theory.md §4) with the random numbers drawn in another order, so the two must
//! measure the same lobes.
//!
//! An equivalence test, not an oracle: both walks share the flights, `Normals::sample` and
//! `Facet::interact`, so physics wrong in those passes it. It catches what differs between
//! the two walks: the lanes, the refill of escaped photons from the excess variate, the
//! buffering of escapes and the order of the random draws.
//!
//! Seven cases cover every part of a lane's step: GGX and anisotropic Beckmann conductors
//! (F = 1 and Schlick with absorption and roulette), Lambertian facets, a dielectric and
//! Hammon's facet with their two branches chosen at random (split off), Hammon's rejection
//! sampler of normals, and Hammon's symmetric Lambda near normal incidence (§2.7, deep first
//! hits). Each runs 3*10^5 photons per walk (independent seeds) on an 8 x 16 grid with orders
//! folded from 6:
//!
//! * lobes of orders 1, 2 and all together, per hemisphere: two-sample chi-square with
//!   per-photon variances, pooling bins with fewer than 10 photons, at least 8 cells left;
//! * albedos of orders 1 to 4 per hemisphere: two-sample z test;
//!
//! all at the Sidak level that keeps the family of 56 tests at 0.01.
//!
//! A second test checks the bookkeeping exactly: every photon ends once, with its facet
//! interactions, whatever the photon count (fewer photons than lanes, not a multiple of the
//! lanes), and with F = 1 every photon's unit weight escapes or is lost: all of it escapes
//! with the true Smith Lambda, and all of it is trapped at once with Hammon's at normal
//! incidence (a vertical downward ray has rate 0, §2.7).

use crate::common;

use common::{assert_lobes_agree, dir, two_sided_z};
use smithwalk::analysis::stats::sidak;
use smithwalk::engine::detector::{Detector, Grid, Hemisphere};
use smithwalk::engine::run::chunk_rng;
use smithwalk::microsurface::DVec3;
use smithwalk::microsurface::facet::{Conductor, ConductorFresnel, Dielectric, Facet, Hammon, Lambertian, Side};
use smithwalk::microsurface::ndf::{Beckmann, Ggx, Ndf, Roughness};
use smithwalk::microsurface::normals::Normals;
use smithwalk::microsurface::smith::Smith;
use smithwalk::microsurface::walk::{EnergyPolicy, Loss, Microsurface, Observer};

const PHOTONS: u64 = 300_000;
const GRID: Grid = Grid { cos_bins: 8, phi_bins: 16 };
/// Splitting is off: the cases with two branches choose one at random (§4.6).
const POLICY: EnergyPolicy = EnergyPolicy { split: false, threshold: 0.1 };
const SLOTS: [usize; 3] = [0, 1, 2];
const ORDERS: std::ops::RangeInclusive<usize> = 1..=4;

/// Walks `PHOTONS` photons both ways into two detectors.
fn both_walks<N: Ndf, F: Facet<1>>(surface: &Microsurface<N>, facet: &F, wi: DVec3, seed: u64) -> [Detector<1>; 2] {
    let mut plain = Detector::new(GRID, wi, Some(6));
    let mut rng = chunk_rng(seed, 0, 0);
    let mut stack = Vec::new();
    for _ in 0..PHOTONS {
        let interactions = surface.trace(facet, &POLICY, wi, &mut rng, &mut stack, &mut plain);
        plain.end_photon(interactions);
    }
    let mut side_by_side = Detector::new(GRID, wi, Some(6));
    surface.walk_side_by_side(facet, &POLICY, wi, PHOTONS, &mut chunk_rng(seed, 1, 0), &mut side_by_side);
    // A detector's sums (and photons of unit weight) reach its tallies when it settles.
    plain.settle();
    side_by_side.settle();
    [plain, side_by_side]
}

fn surface<N: Ndf>(ndf: N, smith: Smith, normals: Normals) -> Microsurface<N> {
    Microsurface { ndf, smith, normals }
}

#[test]
fn photons_walked_side_by_side_measure_the_lobes_of_the_plain_walk() {
    let ggx = |a: f64| Ggx(Roughness::isotropic(a));
    let white = Conductor::<1> { fresnel: ConductorFresnel::None };
    let schlick = Conductor { fresnel: ConductorFresnel::Schlick { f0: [0.3] } };
    let cases: Vec<(&str, [Detector<1>; 2], &[Hemisphere])> = vec![
        (
            "ggx conductor F=1 a=0.5 60deg",
            both_walks(&surface(ggx(0.5), Smith::Exact, Normals::Visible), &white, dir(60.0, 0.0), 1),
            &[Hemisphere::R],
        ),
        (
            "beckmann (0.9, 0.4) Schlick 0.3, 70deg phi 30",
            both_walks(
                &surface(Beckmann(Roughness { x: 0.9, y: 0.4 }), Smith::Exact, Normals::Visible),
                &schlick,
                dir(70.0, 30.0),
                2,
            ),
            &[Hemisphere::R],
        ),
        (
            "ggx Lambertian 0.8 a=1 0deg",
            both_walks(
                &surface(ggx(1.0), Smith::Exact, Normals::Visible),
                &Lambertian { albedo: [0.8] },
                dir(0.0, 0.0),
                3,
            ),
            &[Hemisphere::R],
        ),
        (
            "ggx dielectric 1.5 a=0.5 40deg, chosen branches",
            both_walks(&surface(ggx(0.5), Smith::Exact, Normals::Visible), &Dielectric { eta: 1.5 }, dir(40.0, 0.0), 4),
            &[Hemisphere::R, Hemisphere::T],
        ),
        (
            "ggx Hammon facet a=0.7 50deg, chosen branches",
            both_walks(
                &surface(ggx(0.7), Smith::Exact, Normals::Visible),
                &Hammon { f0: [0.04], albedo: [0.8] },
                dir(50.0, 0.0),
                5,
            ),
            &[Hemisphere::R],
        ),
        (
            "ggx conductor a=0.7 30deg, Hammon's rejection normals",
            both_walks(&surface(ggx(0.7), Smith::Exact, Normals::HammonRejection), &white, dir(30.0, 0.0), 6),
            &[Hemisphere::R],
        ),
        (
            "ggx conductor a=0.5 10deg, symmetric Lambda",
            both_walks(&surface(ggx(0.5), Smith::Symmetric, Normals::Visible), &white, dir(10.0, 0.0), 7),
            &[Hemisphere::R],
        ),
    ];
    let hemispheres: usize = cases.iter().map(|c| c.2.len()).sum();
    let level = sidak(0.01, hemispheres * (SLOTS.len() + ORDERS.count()));
    let z_limit = two_sided_z(level);
    for (label, [plain, side_by_side], hemispheres) in &cases {
        assert_eq!(plain.tallies.photons, PHOTONS, "{label}");
        assert_eq!(side_by_side.tallies.photons, PHOTONS, "{label}");
        for &h in *hemispheres {
            assert_lobes_agree(side_by_side, plain, h, &SLOTS, ORDERS, level, z_limit, label);
        }
    }
}

/// Counts photons, their interactions, and the weight that escaped or was lost.
#[derive(Default)]
struct Ledger {
    photons: u64,
    interactions: u64,
    escaped: f64,
    lost: f64,
    open: f64,
}

impl Observer<1> for Ledger {
    fn escape(&mut self, _order: u32, _side: Side, _dir: DVec3, weight: &[f64; 1]) {
        self.escaped += weight[0];
        self.open += weight[0];
    }
    fn lose(&mut self, _loss: Loss, weight: &[f64; 1]) {
        self.lost += weight[0];
        self.open += weight[0];
    }
    fn end_photon(&mut self, interactions: u64) {
        self.photons += 1;
        self.interactions += interactions;
        assert_eq!(self.open, 1.0, "a photon of unit weight ends with all of it accounted for");
        self.open = 0.0;
    }
}

#[test]
fn every_photon_walked_side_by_side_ends_once_with_its_weight_and_interactions() {
    let white = Conductor::<1> { fresnel: ConductorFresnel::None };
    for smith in [Smith::Exact, Smith::Symmetric] {
        let surface = surface(Ggx(Roughness::isotropic(1.0)), smith, Normals::Visible);
        for photons in [0, 1, 3, 4, 5, 17, 1000, 16_384] {
            let mut ledger = Ledger::default();
            surface.walk_side_by_side(&white, &POLICY, DVec3::Z, photons, &mut chunk_rng(9, 0, photons), &mut ledger);
            let n = photons as f64;
            assert_eq!(ledger.photons, photons, "{smith:?}");
            match smith {
                Smith::Exact => {
                    assert_eq!((ledger.escaped, ledger.lost), (n, 0.0));
                    // At normal incidence on alpha = 1 a photon makes 2.3 interactions on
                    // average (docs/theory.md §9.4 orders): a broken count would be far off.
                    if photons >= 1000 {
                        let mean = ledger.interactions as f64 / n;
                        assert!((2.2..2.4).contains(&mean), "{mean} interactions per photon");
                    }
                }
                Smith::Symmetric => {
                    assert_eq!((ledger.escaped, ledger.lost, ledger.interactions), (0.0, n, 0));
                }
            }
        }
    }
}

#[test]
#[should_panic(expected = "cannot split")]
fn walking_side_by_side_refuses_paths_that_split() {
    let surface = surface(Ggx(Roughness::isotropic(0.5)), Smith::Exact, Normals::Visible);
    let split = EnergyPolicy { split: true, threshold: 0.1 };
    surface.walk_side_by_side(
        &Dielectric { eta: 1.5 },
        &split,
        DVec3::Z,
        10,
        &mut chunk_rng(1, 0, 0),
        &mut Ledger::default(),
    );
}
