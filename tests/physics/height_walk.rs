//! Height independence, measured (docs/theory.md §2.1, §2.3; README): a reference random walk that
//! samples actual heights agrees with smithwalk's optical-depth walk per order and per bin,
//! for uniform heights on [-1, 1] and for Gaussian heights.
//!
//! The reference walk is written here from Heitz et al. 2016 §4 in height form, independently
//! of `microsurface::walk` and `microsurface::height`: a ray at height `h` travelling along `d`
//! with the full-sphere Smith `Lambda(d)` (negative, at most -1, downwards) draws `U` and
//! moves to `h' = C1^{-1}(C1(h) (1 - U)^{-1/Lambda(d)})`; upwards, `C1(h') >= 1` is an escape
//! (probability `G1(d, h) = C1(h)^Lambda`). `C1` is the height law's CDF: `(h + 1) / 2` for the
//! uniform law, `Phi(h)` for the Gaussian one, both inverted explicitly, so every flight
//! round-trips through heights. A ray inside a dielectric walks the flipped surface: its
//! height is `-h` in its own frame, where a symmetric law has the same `C1`. It uses the NDF
//! (`D`, `Lambda`, visible-normal sampler) and the facets of the crate, tested elsewhere, and
//! chooses between two branches with probability proportional to their weights (no split, no
//! roulette).
//!
//! Seven runs of five cases (conductor F = 1, Lambertian, dielectric from outside and
//! inside; GGX and Beckmann; both height laws), 10^6 photons in each walk (fixed, different
//! seeds), 8 x 16 bins, orders folded from 5: per hemisphere the lobes of orders 1 to 4 (1 and
//! 2 for the dielectric, whose higher reflected orders are too sparse) and all together by a
//! two-sample chi-square with per-photon variances (bins with fewer than 10 photons in the
//! reference walk pooled, at least 8 cells), and the albedos of orders 1 to 4 (dielectric: 1
//! to 3) by a z test; the family (all tests) at the Sidak level 0.01.
//!
//! Wrong physics it catches (planted one at a time, seen to fail, reverted): downward flights
//! with the rate `Lambda(mirror image)` instead of `1 + Lambda` (the wrong Smith identity in
//! `smith.rs`: case 0, all orders, chi-square 476389 on 128 dof); free flights 2% too long in
//! `height.rs` (case 4, order-1 transmission, z = -3.95: caught, narrowly). It shares the
//! facets with the walk, so a facet bug (the outside `eta` used inside) passes it; that is
//! the job of the physics crate's walk_lobes.rs. Runtime: about 11 s on 2 cores.

use crate::common;

use common::{assert_lobes_agree, mono, simulate, two_sided_z};
use microsurface::DVec3;
use microsurface::facet::{Conductor, ConductorFresnel, Dielectric, Facet, Interaction, Lambertian, Side};
use microsurface::ndf::{Beckmann, Ggx, Ndf, Roughness};
use microsurface::random::open01;
use microsurface::walk::{Loss, Observer};
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;
use smithwalk::analysis::stats::sidak;
use smithwalk::engine::detector::{Detector, Hemisphere};
use statrs::distribution::{ContinuousCDF, Normal};

const PHOTONS: u64 = 1_000_000;
const MAX_ORDER: u32 = 5;
/// Interactions after which the reference gives up on a path (never reached in these cases).
const CAP: u32 = 10_000;

/// A height law: its CDF `C1` and the inverse.
#[derive(Clone, Copy, Debug)]
enum Law {
    Uniform,
    Gaussian,
}

impl Law {
    fn c1(self, h: f64) -> f64 {
        match self {
            Law::Uniform => ((h + 1.0) / 2.0).clamp(0.0, 1.0),
            Law::Gaussian => Normal::standard().cdf(h),
        }
    }

    fn c1_inv(self, u: f64) -> f64 {
        match self {
            Law::Uniform => 2.0 * u - 1.0,
            Law::Gaussian => Normal::standard().inverse_cdf(u),
        }
    }

    /// The top of the support, where a photon enters.
    fn top(self) -> f64 {
        match self {
            Law::Uniform => 1.0,
            Law::Gaussian => f64::INFINITY,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Law::Uniform => "uniform",
            Law::Gaussian => "gaussian",
        }
    }
}

/// One photon of the reference walk from `wi` (towards the light), reported to `observer`.
fn reference_photon<N: Ndf, F: Facet<1>, O: Observer<1>>(
    ndf: &N,
    facet: &F,
    law: Law,
    wi: DVec3,
    rng: &mut Pcg64Mcg,
    observer: &mut O,
) {
    let mut side = if wi.z > 0.0 { Side::Outside } else { Side::Inside };
    let own = |v: DVec3, s: Side| if s == Side::Outside { v } else { -v };
    let mut d = -wi;
    // Height in the frame of the ray's side.
    let mut h = law.top();
    let mut weight = 1.0;
    let mut order = 0;
    loop {
        let d_own = own(d, side);
        let lambda = ndf.lambda(d_own);
        let u = law.c1(h) * (1.0 - open01(rng)).powf(-1.0 / lambda);
        if d_own.z > 0.0 && u >= 1.0 {
            observer.escape(order, side, d, &[weight]);
            break;
        }
        h = law.c1_inv(u);
        if u.is_nan() || u <= 0.0 || h.is_nan() {
            observer.lose(Loss::Trapped, &[weight]);
            break;
        }
        order += 1;
        if order > CAP {
            observer.lose(Loss::Runaway, &[weight]);
            break;
        }
        let m = own(ndf.sample_visible(-d_own, rng), side);
        let branch = match facet.interact(-d, m, side, rng) {
            Interaction::One(b) => b,
            Interaction::Two(a, b) => {
                let total = a.weight[0] + b.weight[0];
                let mut chosen = if open01(rng) * total < a.weight[0] { a } else { b };
                chosen.weight[0] = total;
                chosen
            }
        };
        weight *= branch.weight[0];
        d = branch.dir;
        if branch.crosses {
            side = side.other();
            h = -h;
        }
        if weight == 0.0 {
            break;
        }
    }
    observer.end_photon(u64::from(order));
}

fn reference<N: Ndf, F: Facet<1>>(
    ndf: &N,
    facet: &F,
    law: Law,
    template: &Detector<1>,
    wi: DVec3,
    seed: u64,
) -> Detector<1> {
    let mut detector = Detector::new(template.grid, wi, Some(MAX_ORDER));
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    for _ in 0..PHOTONS {
        reference_photon(ndf, facet, law, wi, &mut rng, &mut detector);
    }
    detector.settle();
    detector
}

struct Case {
    ndf: &'static str,
    alpha: (f64, f64),
    material: &'static str,
    incident: &'static str,
    /// The height laws the case runs with, each a run of its own.
    laws: &'static [Law],
}

const CASES: [Case; 5] = [
    Case {
        ndf: "ggx",
        alpha: (0.5, 0.5),
        material: "kind = \"conductor\"",
        incident: "theta_deg = 30",
        laws: &[Law::Uniform],
    },
    Case {
        ndf: "ggx",
        alpha: (1.0, 0.5),
        material: "kind = \"conductor\"",
        incident: "theta_deg = 70\nphi_deg = 20",
        laws: &[Law::Gaussian],
    },
    Case {
        ndf: "beckmann",
        alpha: (0.8, 0.8),
        material: "kind = \"diffuse\"\nalbedo = 0.9",
        incident: "theta_deg = 10",
        laws: &[Law::Uniform, Law::Gaussian],
    },
    Case {
        ndf: "ggx",
        alpha: (0.6, 0.6),
        material: "kind = \"dielectric\"\neta = 1.5",
        incident: "theta_deg = 40",
        laws: &[Law::Gaussian, Law::Uniform],
    },
    Case {
        ndf: "beckmann",
        alpha: (0.5, 0.5),
        material: "kind = \"dielectric\"\neta = 1.5",
        incident: "theta_deg = 30\nside = \"inside\"",
        laws: &[Law::Gaussian],
    },
];

#[test]
fn a_walk_in_actual_heights_measures_what_the_optical_depth_walk_measures() {
    // Conductor and Lambertian: lobes of orders 1 to 4, all together, albedos 1 to 4; dielectric
    // (whose reflected orders beyond 2 hold too few reference photons for 8 cells): lobes of
    // orders 1, 2 and all together, albedos 1 to 3, per hemisphere.
    let (opaque, dielectric) = ((vec![0usize, 1, 2, 3, 4], 1..=4usize), (vec![0usize, 1, 2], 1..=3usize));
    let runs = || CASES.iter().flat_map(|c| c.laws.iter().map(move |&law| (c, law)));
    let tests: usize = runs().map(|(c, _)| if c.material.contains("dielectric") { 2 * (3 + 3) } else { 5 + 4 }).sum();
    let level = sidak(0.01, tests);
    let z_limit = two_sided_z(level);
    for (i, (c, law)) in runs().enumerate() {
        let toml = format!(
            "paths = {PHOTONS}\nseed = {}\n[surface]\nndf = \"{}\"\nalpha = [[{}, {}]]\nheight = \"{}\"\n[material]\n{}\n[incident]\n{}\n[detector]\ncos_theta_bins = 8\nphi_bins = 16\nmax_order = {MAX_ORDER}\n",
            1600 + i,
            c.ndf,
            c.alpha.0,
            c.alpha.1,
            law.name(),
            c.material,
            c.incident
        );
        let sim = simulate(&toml, 2);
        let walk = mono(&sim, 0);
        let wi = sim.cases[0].wi;
        let roughness = Roughness { x: c.alpha.0, y: c.alpha.1 };
        let seed = 1700 + i as u64;
        let reference = match (c.ndf, c.material) {
            ("ggx", m) => by_material(Ggx(roughness), m, law, walk, wi, seed),
            (_, m) => by_material(Beckmann(roughness), m, law, walk, wi, seed),
        };
        assert_eq!(reference.tallies.photons, PHOTONS);
        let (hemispheres, (slots, orders)): (&[Hemisphere], _) = if c.material.contains("dielectric") {
            (&[Hemisphere::R, Hemisphere::T], dielectric.clone())
        } else {
            (&[Hemisphere::R], opaque.clone())
        };
        for &h in hemispheres {
            let label =
                format!("case {i} ({} {:?} {} {}, {} heights)", c.ndf, c.alpha, c.material, c.incident, law.name());
            // Pooled by the reference's counts: its photons carry whole weights, the split walk's many
            // small ones, so sparse bins are judged on the sample that has fewer photons there.
            assert_lobes_agree(&reference, walk, h, &slots, orders.clone(), level, z_limit, &label);
        }
    }
}

/// The reference detector of a case's material on `ndf`.
fn by_material<N: Ndf>(ndf: N, material: &str, law: Law, walk: &Detector<1>, wi: DVec3, seed: u64) -> Detector<1> {
    if material.contains("conductor") {
        reference(&ndf, &Conductor::<1> { fresnel: ConductorFresnel::None }, law, walk, wi, seed)
    } else if material.contains("diffuse") {
        reference(&ndf, &Lambertian::<1> { albedo: [0.9] }, law, walk, wi, seed)
    } else {
        reference(&ndf, &Dielectric { eta: 1.5 }, law, walk, wi, seed)
    }
}
