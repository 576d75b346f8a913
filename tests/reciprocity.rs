//! Reciprocity of the walk (THEORY.md §2.6, §9.3), by next-event point estimates of the
//! per-order lobe at fixed direction pairs: `f_k(wi, wo) = f_k(wo, wi)` for mirror, Lambertian
//! and Hammon facets, and the power-form transmission identity
//! `f_t(wi, wo) / eta_o^2 = f_t(wo, wi) / eta_i^2` for the dielectric. Each estimate uses
//! 4*10^5 photons; per order the two directions are compared by a z test with per-photon
//! variances, at the Sidak level keeping the family (all pairs and orders) at 0.01.

mod common;

use common::dir;
use microsurface::DVec3;
use microsurface::facet::{Conductor, ConductorFresnel, Dielectric, Facet, Hammon, Lambertian, Side};
use microsurface::ndf::{Ggx, Ndf, Roughness};
use microsurface::nee::contribution;
use microsurface::normals::Normals;
use microsurface::smith::Smith;
use microsurface::walk::{EnergyPolicy, Loss, Microsurface, Observer};
use rand_pcg::Pcg64Mcg;
use smithwalk::stats::sidak;
use statrs::distribution::{ContinuousCDF, Normal};

const PHOTONS: u64 = 400_000;
const ORDERS: usize = 3;

/// Accumulates, per order, the next-event estimate of `f_k(wi, wo) |cos theta_o|` towards a
/// fixed `wo`.
struct Point<'a, N, F> {
    ndf: &'a N,
    facet: &'a F,
    wo: DVec3,
    rng: Pcg64Mcg,
    photon: [f64; ORDERS],
    sum: [f64; ORDERS],
    sum_sq: [f64; ORDERS],
}

impl<N: Ndf, F: Facet<1>> Observer<1> for Point<'_, N, F> {
    fn escape(&mut self, _: u32, _: Side, _: DVec3, _: &[f64; 1]) {}
    fn lose(&mut self, loss: Loss, _: &[f64; 1]) {
        panic!("lost weight: {loss:?}");
    }
    fn hit(&mut self, order: u32, tau: f64, side: Side, d: DVec3, weight: &[f64; 1]) {
        let k = order as usize - 1;
        if k < ORDERS {
            let (value, _) = contribution(self.ndf, self.facet, tau, side, d, self.wo, &mut self.rng);
            self.photon[k] += weight[0] * value[0];
        }
    }
}

/// Per-order mean and standard error of `f_k(wi, wo)` (the lobe divided by `|cos theta_o|`).
fn lobe<N: Ndf, F: Facet<1>>(ndf: N, facet: &F, wi: DVec3, wo: DVec3, seed: u128) -> [(f64, f64); ORDERS] {
    let surface = Microsurface { ndf, smith: Smith::Exact, normals: Normals::Visible };
    let policy = EnergyPolicy { split: true, threshold: 0.1 };
    let mut point = Point {
        ndf: &ndf,
        facet,
        wo,
        rng: Pcg64Mcg::new(seed ^ 0xabcdef),
        photon: [0.0; ORDERS],
        sum: [0.0; ORDERS],
        sum_sq: [0.0; ORDERS],
    };
    let mut rng = Pcg64Mcg::new(seed);
    let mut stack = Vec::new();
    for _ in 0..PHOTONS {
        surface.trace(facet, &policy, wi, &mut rng, &mut stack, &mut point);
        for k in 0..ORDERS {
            point.sum[k] += point.photon[k];
            point.sum_sq[k] += point.photon[k] * point.photon[k];
            point.photon[k] = 0.0;
        }
    }
    let n = PHOTONS as f64;
    std::array::from_fn(|k| {
        let mean = point.sum[k] / n;
        let se = ((point.sum_sq[k] / n - mean * mean) / (n - 1.0)).sqrt();
        (mean / wo.z.abs(), se / wo.z.abs())
    })
}

type Pairs = [((f64, f64), (f64, f64)); 3];
/// Direction pairs (theta, phi) of light and detector, both above the surface.
const PAIRS: Pairs = [((20.0, 0.0), (55.0, 150.0)), ((70.0, 30.0), (35.0, 250.0)), ((50.0, 90.0), (80.0, 200.0))];
/// Pairs for transmission (the detector below, within reach of refraction into eta = 1.5).
const TRANSMISSION_PAIRS: Pairs =
    [((20.0, 0.0), (30.0, 150.0)), ((60.0, 30.0), (25.0, 250.0)), ((45.0, 90.0), (38.0, 200.0))];

fn check<F: Facet<1>>(facet: &F, name: &str, level: f64, transmission_scale: Option<f64>) {
    let z_limit = Normal::standard().inverse_cdf(1.0 - level / 2.0);
    let ndf = Ggx(Roughness { x: 0.7, y: 0.4 });
    let pairs = if transmission_scale.is_some() { TRANSMISSION_PAIRS } else { PAIRS };
    for (p, (a, b)) in pairs.into_iter().enumerate() {
        let wi = dir(a.0, a.1);
        let mut wo = dir(b.0, b.1);
        if transmission_scale.is_some() {
            wo.z = -wo.z;
        }
        let forward = lobe(ndf, facet, wi, wo, 10 + p as u128);
        let backward = lobe(ndf, facet, wo, wi, 20 + p as u128);
        // Power form: f(wi -> wo) / eta_o^2 = f(wo -> wi) / eta_i^2, with eta_o / eta_i = eta.
        let scale = transmission_scale.map_or(1.0, |eta| 1.0 / (eta * eta));
        for k in 0..ORDERS {
            let (f, b) = ((forward[k].0 * scale, forward[k].1 * scale), backward[k]);
            let z = (f.0 - b.0) / (f.1 * f.1 + b.1 * b.1).sqrt();
            assert!(f.0 > 0.0 && b.0 > 0.0, "{name} pair {p} order {}: no light ({f:?}, {b:?})", k + 1);
            assert!(z.abs() < z_limit, "{name} pair {p} order {}: {f:?} vs reversed {b:?}, z = {z:.2}", k + 1);
        }
    }
}

#[test]
fn the_walk_is_reciprocal_order_by_order() {
    let level = sidak(0.01, 5 * PAIRS.len() * ORDERS);
    check(&Conductor::<1> { fresnel: ConductorFresnel::None }, "conductor F=1", level, None);
    check(&Conductor::<1> { fresnel: ConductorFresnel::Exact { eta: [0.2], k: [3.0] } }, "conductor", level, None);
    check(&Lambertian::<1> { albedo: [0.9] }, "lambertian", level, None);
    check(&Hammon::<1> { f0: [0.04], albedo: [0.8] }, "hammon", level, None);
    check(&Dielectric { eta: 1.5 }, "dielectric T", level, Some(1.5));
}

#[test]
fn the_test_detects_a_broken_symmetry() {
    // Without the eta^2 of the power form, transmission is not symmetric: the z test above
    // must see that (eta = 1.5: a factor 2.25).
    let ndf = Ggx(Roughness { x: 0.7, y: 0.4 });
    let facet = Dielectric { eta: 1.5 };
    let (wi, mut wo) = (dir(20.0, 0.0), dir(30.0, 150.0));
    wo.z = -wo.z;
    let (f, b) = (lobe(ndf, &facet, wi, wo, 31)[0], lobe(ndf, &facet, wo, wi, 32)[0]);
    let z = (f.0 - b.0) / (f.1 * f.1 + b.1 * b.1).sqrt();
    assert!(z.abs() > 10.0, "z = {z}");
}
