//! Reciprocity of the walk (docs/theory.md §2.6, §9.3), by next-event point estimates of the
//! per-order lobe at fixed direction pairs: `f_k(wi, wo) = f_k(wo, wi)` for mirror, Lambertian
//! and Hammon facets (orders 1 to 4), and the power-form transmission identity
//! `f_t(wi, wo) / eta_o^2 = f_t(wo, wi) / eta_i^2` for the dielectric. Each estimate uses
//! 4*10^5 photons; per order the two directions are compared by a z test with per-photon
//! variances, at the Sidak level keeping the family (all pairs and orders) at 0.01.

use crate::common;

use common::dir;
use microsurface::DVec3;
use microsurface::facet::{Conductor, ConductorFresnel, Dielectric, Facet, Hammon, Lambertian, Side};
use microsurface::ndf::{Ggx, Ndf, Roughness};
use microsurface::nee::contribution;
use microsurface::normals::Normals;
use microsurface::smith::Smith;
use microsurface::walk::{EnergyPolicy, Loss, Microsurface, Observer};
use numerics::stats::sidak;
use rand_pcg::Pcg64Mcg;
use statrs::distribution::{ContinuousCDF, Normal};

const PHOTONS: u64 = 400_000;
const ORDERS: usize = 4;

/// Accumulates, per order, the next-event estimate of `f_k(wi, wo) |cos theta_o|` towards a
/// fixed `wo`.
struct Point<'a, N, F> {
    ndf: &'a N,
    facet: &'a F,
    normals: Normals,
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
            self.photon[k] += weight[0] * value[0] * self.normal_law_factor(-d);
        }
    }
}

impl<N: Ndf, F> Point<'_, N, F> {
    /// The phase functions assume visible normals, `D_w(h) = D(h) (w·h) / A(w)`. Hammon's
    /// sampler draws `D(h) h_z 1[w·h > 0] / N(w)` instead (§3.3), so a mirror facet's phase
    /// function is scaled by `h_z A(w) / (N(w) (w·h))`, with, for GGX, `N(w) = (1 + w'_z) / 2`
    /// (`w'` the stretched direction: the cosine-weighted measure of the lune `w'·m > 0`,
    /// Lambert's formula of §8.1). Only for mirror facets seen from outside.
    fn normal_law_factor(&self, w: DVec3) -> f64 {
        match self.normals {
            Normals::Visible => 1.0,
            Normals::HammonRejection => {
                let h = (w + self.wo).normalize();
                let n = 0.5 * (1.0 + self.ndf.roughness().stretch(w).z);
                h.z * self.ndf.projected_area(w) / (n * w.dot(h))
            }
        }
    }
}

/// Per-order mean and standard error of `f_k(wi, wo)` (the lobe divided by `|cos theta_o|`).
fn lobe<N: Ndf, F: Facet<1>>(ndf: N, facet: &F, wi: DVec3, wo: DVec3, seed: u128) -> [(f64, f64); ORDERS] {
    lobe_with(ndf, Smith::Exact, Normals::Visible, facet, wi, wo, seed)
}

fn lobe_with<N: Ndf, F: Facet<1>>(
    ndf: N,
    smith: Smith,
    normals: Normals,
    facet: &F,
    wi: DVec3,
    wo: DVec3,
    seed: u128,
) -> [(f64, f64); ORDERS] {
    let surface = Microsurface { ndf, smith, normals };
    let policy = EnergyPolicy { split: true, threshold: 0.1 };
    let mut point = Point {
        ndf: &ndf,
        facet,
        normals,
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

#[test]
fn hammons_variants_are_not_reciprocal() {
    // Order 1, conductor F = 1, isotropic GGX 0.5, light at 20 deg and detector at 70 deg.
    // The measured ratio f_1(wi, wo) / f_1(wo, wi) must match the closed forms:
    // * symmetric Lambda (§2.7): first-hit depth ~ Exp(Lambda_i), so
    //   f_1 ∝ Lambda_i / ((1 + Lambda_i)(Lambda_i + Lambda_o)) and the ratio is
    //   Lambda_i (1 + Lambda_o) / (Lambda_o (1 + Lambda_i));
    // * Hammon's normals (§3.3 item 1): f_1^H = f_1 h_z A(wi) / (N(wi) (wi·h)), so the ratio is
    //   A(wi) N(wo) / (N(wi) A(wo)) with N(w) = (1 + w'_z) / 2.
    // Tolerance: 5 standard errors of the measured ratio (first-order error propagation).
    let ndf = Ggx(Roughness::isotropic(0.5));
    let facet = Conductor::<1> { fresnel: ConductorFresnel::None };
    let (wi, wo) = (dir(20.0, 0.0), dir(70.0, 150.0));
    let (li, lo) = (ndf.lambda(wi), ndf.lambda(wo));
    let n = |w: DVec3| 0.5 * (1.0 + ndf.roughness().stretch(w).z);
    let cases = [
        ("symmetric Lambda", Smith::Symmetric, Normals::Visible, li * (1.0 + lo) / (lo * (1.0 + li))),
        (
            "Hammon normals",
            Smith::Exact,
            Normals::HammonRejection,
            ndf.projected_area(wi) * n(wo) / (n(wi) * ndf.projected_area(wo)),
        ),
    ];
    for (i, (name, smith, normals, expected)) in cases.into_iter().enumerate() {
        let forward = lobe_with(ndf, smith, normals, &facet, wi, wo, 40 + i as u128)[0];
        let backward = lobe_with(ndf, smith, normals, &facet, wo, wi, 50 + i as u128)[0];
        let ratio = forward.0 / backward.0;
        let se = ratio * ((forward.1 / forward.0).powi(2) + (backward.1 / backward.0).powi(2)).sqrt();
        println!("{name}: f1(wi,wo)/f1(wo,wi) = {ratio:.4} +- {se:.4}, closed form {expected:.4}");
        assert!((ratio - 1.0).abs() > 10.0 * se, "{name}: no asymmetry measured ({ratio} +- {se})");
        assert!((ratio - expected).abs() < 5.0 * se, "{name}: ratio {ratio} +- {se}, expected {expected}");
    }
}
