//! The renderer's BSDF (`microsurface::bsdf`, docs/theory.md §13) against oracles that do not
//! share its code path:
//!
//! * **White furnace**: a lossless facet (conductor with `F = 1`, dielectric from either side)
//!   returns weight 1 from every `sample`, exactly (no splitting, no roulette).
//! * **`sample` against `eval`, order by order**: a two-sample chi-square of `sample`'s weighted
//!   histogram against `eval` integrated over the same bins by Monte Carlo (uniform points in
//!   each bin), for orders 1, 2 and 3 and up alone, for every facet and both NDFs, once
//!   anisotropic, once with three channels (each channel its own test); cells with fewer
//!   than 30 photons pooled.
//! * **Order 1 of `eval`** equals exact single scattering (`single`, §5) to rounding for
//!   conductor and dielectric facets (both sides), and for Lambertian facets matches the
//!   quadrature of the visible-normal integral (§5, [HD15]) in mean.
//! * **Albedo**: `eval` integrated over the sphere by Monte Carlo equals `sample`'s mean weight.
//! * **Reciprocity** (§9.3): `f(wi -> wo) = f(wo -> wi)` for reflection, and for transmission
//!   `f(wi -> wo) / n_o^2 = f(wo -> wi) / n_i^2`, i.e. `eval` in radiance mode from one end
//!   equals `eval` in importance mode from the other.
//! * **`pdf`**: positive wherever `eval` is, integrates to 1 over the sphere (quadrature), and
//!   MIS with it stays unbiased.
//! * **Robustness**: grazing and below-horizon directions, extreme roughness and `eta` near 1
//!   give finite, non-negative values; out-of-range parameters give errors naming the field.
//!
//! Statistics: every test states its level; the tests of one function share a family level of
//! 0.01 by Sidak's correction. Fixed seeds throughout.

mod common;

use std::f64::consts::{PI, TAU};

use common::{dir, two_sided_z};
use microsurface::DVec3;
use microsurface::bsdf::{Bsdf, BsdfError, Orders, Transport, stream};
use microsurface::facet::{Conductor, ConductorFresnel, Dielectric, Facet, Hammon, Lambertian};
use microsurface::fresnel;
use microsurface::material::Material;
use microsurface::ndf::{AnyNdf, Beckmann, Ggx, Ndf, Roughness};
use microsurface::normals::Normals;
use microsurface::single;
use microsurface::smith::Smith;
use microsurface::walk::Microsurface;
use numerics::stats::{WeightedBin, sidak, two_sample};
use rand::{Rng, RngExt};

fn surface<N: Ndf>(ndf: N) -> Microsurface<N> {
    Microsurface { ndf, smith: Smith::Exact, normals: Normals::Visible }
}

fn ggx(alpha: f64) -> AnyNdf {
    AnyNdf::Ggx(Ggx(Roughness::isotropic(alpha)))
}

fn beckmann(alpha: f64) -> AnyNdf {
    AnyNdf::Beckmann(Beckmann(Roughness::isotropic(alpha)))
}

/// The BSDFs under test: run-time NDF and material, as a renderer builds them.
type TestBsdf<const C: usize> = Bsdf<AnyNdf, Material<C>, C>;

fn bsdf<const C: usize>(ndf: AnyNdf, material: Material<C>) -> TestBsdf<C> {
    Bsdf::new(surface(ndf), material).expect("valid parameters")
}

fn mirror() -> Material<1> {
    Material::Conductor(Conductor { fresnel: ConductorFresnel::None })
}

fn glass() -> Material<1> {
    Material::Dielectric(Dielectric { eta: 1.5 })
}

/// Every `sample` of a lossless facet has weight 1 (to rounding: a dielectric's random
/// branch choice divides `F` by the probability `F / (F + (1 - F))`): 20 000 photons per case,
/// GGX and Beckmann, alpha from 0.2 to 3, conductor `F = 1` from above, dielectric from both
/// sides. Reflection stays above the horizon.
#[test]
fn lossless_facets_return_weight_one_from_every_sample() {
    let mut rng = stream(1, &[]);
    for alpha in [0.2, 0.6, 1.0, 3.0] {
        for ndf in [ggx(alpha), beckmann(alpha)] {
            let cases = [(mirror(), dir(50.0, 20.0)), (glass(), dir(30.0, 0.0)), (glass(), dir(140.0, 70.0))];
            for (material, wi) in cases {
                let b = bsdf(ndf, material);
                for _ in 0..20_000 {
                    let s = b.sample(wi, Transport::Importance, &mut rng);
                    assert!((s.weight[0] - 1.0).abs() < 1e-12 && s.order >= 1, "{ndf:?} {material:?} {wi}: {s:?}");
                    assert!(material.transmits() || s.wo.z > 0.0, "{s:?}");
                }
            }
        }
    }
}

/// Bins uniform in `|cos theta|` and in absolute azimuth on each hemisphere (`cos x phi` each,
/// upper first), all of solid angle `2 pi / (cos phi)`.
#[derive(Clone, Copy)]
struct Grid {
    cos: usize,
    phi: usize,
}

impl Grid {
    fn hemisphere_bins(self) -> usize {
        self.cos * self.phi
    }

    fn solid_angle(self) -> f64 {
        TAU / self.hemisphere_bins() as f64
    }

    fn bin_of(self, d: DVec3) -> usize {
        let c = ((d.z.abs() * self.cos as f64) as usize).min(self.cos - 1);
        let phi = d.y.atan2(d.x).rem_euclid(TAU);
        let p = ((phi / TAU * self.phi as f64) as usize).min(self.phi - 1);
        usize::from(d.z < 0.0) * self.hemisphere_bins() + c * self.phi + p
    }

    /// A uniform direction in bin `bin`.
    fn point_in<R: Rng>(self, bin: usize, rng: &mut R) -> DVec3 {
        let (hemisphere, rest) = (bin / self.hemisphere_bins(), bin % self.hemisphere_bins());
        let (c, p) = (rest / self.phi, rest % self.phi);
        let z = (c as f64 + rng.random::<f64>()) / self.cos as f64;
        let phi = (p as f64 + rng.random::<f64>()) / self.phi as f64 * TAU;
        let s = (1.0 - z * z).max(0.0).sqrt();
        DVec3::new(s * phi.cos(), s * phi.sin(), if hemisphere == 0 { z } else { -z })
    }
}

/// A uniform direction on the sphere (density `1 / 4 pi`).
fn uniform_on_sphere<R: Rng>(rng: &mut R) -> DVec3 {
    let z: f64 = 2.0 * rng.random::<f64>() - 1.0;
    let phi = TAU * rng.random::<f64>();
    let r = (1.0 - z * z).max(0.0).sqrt();
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// `sample`'s histogram of `photons` photons (per-photon moments per bin and channel, and the
/// photon counts per bin), and `eval` integrated over each bin from `points` uniform points,
/// both over the two hemispheres; then one two-sample chi-square per channel (cells with fewer
/// than 30 photons pooled).
fn sample_against_eval<N: Ndf, F: Facet<C>, const C: usize>(
    b: &Bsdf<N, F, C>,
    wi: DVec3,
    grid: Grid,
    (photons, points): (u64, u64),
    seed: u64,
) -> Vec<numerics::stats::ChiSquare> {
    let mut rng = stream(seed, &[]);
    let bins = 2 * grid.hemisphere_bins();
    let zero = WeightedBin { mean: 0.0, second_moment: 0.0 };
    let (mut sampled, mut counts) = (vec![[zero; C]; bins], vec![0u64; bins]);
    for _ in 0..photons {
        let s = b.sample(wi, Transport::Importance, &mut rng);
        if s.weight.iter().all(|&w| w == 0.0) {
            continue;
        }
        let bin = grid.bin_of(s.wo);
        counts[bin] += 1;
        for (acc, w) in sampled[bin].iter_mut().zip(s.weight) {
            acc.mean += w / photons as f64;
            acc.second_moment += w * w / photons as f64;
        }
    }
    let mut integrated = vec![[zero; C]; bins];
    for (bin, acc) in integrated.iter_mut().enumerate() {
        for _ in 0..points {
            let value = b.eval(wi, grid.point_in(bin, &mut rng), Transport::Importance, &mut rng);
            for (a, v) in acc.iter_mut().zip(value) {
                let v = v * grid.solid_angle();
                a.mean += v / points as f64;
                a.second_moment += v * v / points as f64;
            }
        }
    }
    (0..C)
        .map(|c| {
            let a: Vec<_> = sampled.iter().map(|s| s[c]).collect();
            let e: Vec<_> = integrated.iter().map(|s| s[c]).collect();
            two_sample(&a, photons, &e, points, &counts, 30)
        })
        .collect()
}

/// The order sets tested one by one: 1, 2 and 3 and up.
fn order_sets() -> [(Orders, &'static str); 3] {
    [(Orders::only(1).unwrap(), "1"), (Orders::only(2).unwrap(), "2"), (Orders::at_least(3), "3+")]
}

/// `eval` integrated over 4 x 8 bins per hemisphere with 4096 points each.
const FINE: (Grid, u64) = (Grid { cos: 4, phi: 8 }, 4096);

/// Runs [`sample_against_eval`] with 200 000 photons for every order set of every case and
/// asserts each channel's chi-square at the Sidak level keeping all of them at 0.01.
fn assert_sample_matches_eval<const C: usize>(cases: &[(&str, TestBsdf<C>, DVec3, (Grid, u64))]) {
    let level = sidak(0.01, cases.len() * order_sets().len() * C);
    for (seed, &(name, b, wi, (grid, points))) in cases.iter().enumerate() {
        for (order, order_name) in order_sets() {
            let tests = sample_against_eval(&b.with_orders(order), wi, grid, (200_000, points), seed as u64);
            for (c, test) in tests.iter().enumerate() {
                let label = format!("{name}, order {order_name}, channel {c}");
                eprintln!("{label}: chi2 {:.1} / {} dof, p {:.3}", test.statistic, test.dof, test.p_value);
                assert!(test.dof > 2, "{label}: too few cells");
                assert!(test.p_value > level, "{label}: p = {:e}\n{}", test.p_value, test.worst_cells(5));
            }
        }
    }
}

/// `sample` against `eval` order by order ([`assert_sample_matches_eval`]) for conductors:
/// Schlick and exact Fresnel, GGX and Beckmann, once anisotropic.
#[test]
fn sample_matches_eval_order_by_order_for_conductors() {
    let schlick = Material::Conductor(Conductor { fresnel: ConductorFresnel::Schlick { f0: [0.8] } });
    let exact = Material::Conductor(Conductor { fresnel: ConductorFresnel::Exact { eta: [0.2], k: [3.0] } });
    let anisotropic = AnyNdf::Ggx(Ggx(Roughness { x: 0.2, y: 0.8 }));
    assert_sample_matches_eval(&[
        ("Schlick GGX", bsdf(ggx(0.5), schlick), dir(40.0, 10.0), FINE),
        ("exact Beckmann", bsdf(beckmann(0.8), exact), dir(70.0, 200.0), FINE),
        ("anisotropic GGX", bsdf(anisotropic, mirror()), dir(50.0, 30.0), FINE),
    ]);
}

/// `sample` against `eval` order by order ([`assert_sample_matches_eval`]) for the dielectric
/// from outside and from inside, both hemispheres. `eval` is integrated over 2 x 4 bins with
/// 65 536 points each: its next-event estimate of a refraction after a grazing reflection
/// evaluates a peaked phase function at a fixed direction, rarely and with values thousands
/// of times its mean, and each bin's sum must hold enough of them for the normal
/// approximation (theory §13.3).
#[test]
fn sample_matches_eval_order_by_order_for_dielectrics() {
    let coarse = (Grid { cos: 2, phi: 4 }, 65_536);
    assert_sample_matches_eval(&[
        ("GGX outside", bsdf(ggx(0.5), glass()), dir(30.0, 0.0), coarse),
        ("Beckmann inside", bsdf(beckmann(0.9), glass()), dir(130.0, 45.0), coarse),
    ]);
}

/// `sample` against `eval` order by order ([`assert_sample_matches_eval`]) for diffuse exits:
/// Lambertian facets, and Hammon's facets with three different channels (each its own test).
#[test]
fn sample_matches_eval_order_by_order_for_diffuse_facets() {
    let lambertian = Material::Lambertian(Lambertian { albedo: [0.8] });
    assert_sample_matches_eval(&[("Lambertian GGX", bsdf(ggx(0.7), lambertian), dir(50.0, 0.0), FINE)]);
    let hammon = Material::Hammon(Hammon { f0: [0.04, 0.2, 0.9], albedo: [0.9, 0.5, 1.0] });
    assert_sample_matches_eval(&[("Hammon RGB GGX", bsdf(ggx(0.5), hammon), dir(60.0, 100.0), FINE)]);
}

/// `eval` restricted to order 1 is `single::reflection` / `single::transmission` (§5) to
/// rounding (relative 1e-9) for conductor and dielectric facets, on a grid of directions on
/// both hemispheres, the dielectric lit from outside and from inside (where §5 holds in the
/// flipped frame with the relative index `1 / eta`). These facets draw no random numbers at
/// order 1, so the comparison is deterministic.
#[test]
fn order_one_of_eval_is_exact_single_scattering() {
    let schlick = Material::Conductor(Conductor { fresnel: ConductorFresnel::Schlick { f0: [0.7] } });
    let mut rng = stream(3, &[]);
    for ndf in [ggx(0.4), beckmann(0.9), AnyNdf::Ggx(Ggx(Roughness { x: 0.3, y: 1.2 }))] {
        for theta_i in [0.0, 30.0, 60.0, 85.0] {
            for theta_o in [5.0, 40.0, 75.0, 105.0, 140.0, 175.0] {
                for phi_o in [0.0, 90.0, 200.0] {
                    let (wi, wo) = (dir(theta_i, 30.0), dir(theta_o, phi_o));
                    let mut order_one = |m: Material<1>, wi: DVec3| {
                        bsdf(ndf, m).with_orders(Orders::only(1).unwrap()).eval(wi, wo, Transport::Importance, &mut rng)
                            [0]
                    };
                    let close = |a: f64, b: f64, what: &str| {
                        assert!((a - b).abs() <= 1e-9 * b.abs().max(1e-300), "{what} {wi} {wo}: {a} vs {b}")
                    };
                    let f_schlick = |c: f64| fresnel::schlick(0.7, c);
                    close(order_one(schlick, wi), single::reflection(&ndf, wi, wo, f_schlick), "conductor");
                    let outside = |c: f64| fresnel::dielectric(1.5, c);
                    let expected = if wo.z > 0.0 {
                        single::reflection(&ndf, wi, wo, outside)
                    } else {
                        single::transmission(&ndf, wi, wo, 1.5, outside)
                    };
                    close(order_one(glass(), wi), expected, "dielectric outside");
                    // From inside: wi below, the flipped frame (d -> -d) with eta -> 1 / eta.
                    let inside = |c: f64| fresnel::dielectric(1.0 / 1.5, c);
                    let expected = if wo.z < 0.0 {
                        single::reflection(&ndf, wi, -wo, inside)
                    } else {
                        single::transmission(&ndf, wi, -wo, 1.0 / 1.5, inside)
                    };
                    close(order_one(glass(), -wi), expected, "dielectric inside");
                }
            }
        }
    }
}

/// Lambertian facets at order 1: the mean of 100 000 `eval`s equals
/// `G2 / G1(wi) rho ∫ D_wi(m) <wo·m> / pi dm` (§5, [HD15]) by a midpoint quadrature over the
/// facet normal (600 x 600 in `(theta_m, phi_m)`, relative error far below the test's
/// resolution), z test per direction pair at the Sidak level for 6 pairs in a family of 0.01.
#[test]
fn order_one_of_eval_for_diffuse_facets_matches_quadrature() {
    let ndf = ggx(0.7);
    let b = bsdf(ndf, Material::Lambertian(Lambertian { albedo: [0.8] })).with_orders(Orders::only(1).unwrap());
    let pairs = [(0.0, 30.0), (45.0, 45.0), (70.0, 10.0), (30.0, 80.0), (60.0, 60.0), (85.0, 40.0)];
    let z_max = two_sided_z(sidak(0.01, pairs.len()));
    for (theta_i, theta_o) in pairs {
        let mut rng = stream(4, &[theta_i, theta_o]);
        let (wi, wo) = (dir(theta_i, 0.0), dir(theta_o, 135.0));
        let n = 600;
        let mut integral = 0.0;
        for i in 0..n {
            let theta = (i as f64 + 0.5) / n as f64 * PI / 2.0;
            for j in 0..n {
                let phi = (j as f64 + 0.5) / n as f64 * TAU;
                let m = DVec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos());
                let visible = wi.dot(m).max(0.0) * ndf.d(m) / ndf.projected_area(wi);
                integral += visible * wo.dot(m).max(0.0) / PI * theta.sin();
            }
        }
        integral *= (PI / 2.0 / n as f64) * (TAU / n as f64);
        let g1 = 1.0 / (1.0 + ndf.lambda(wi));
        let expected = single::g2_reflection(&ndf, wi, wo) / g1 * 0.8 * integral;
        let samples = 100_000;
        let (mut s, mut q) = (0.0, 0.0);
        for _ in 0..samples {
            let v = b.eval(wi, wo, Transport::Importance, &mut rng)[0];
            s += v;
            q += v * v;
        }
        let mean = s / samples as f64;
        let se = ((q / samples as f64 - mean * mean) / (samples - 1) as f64).sqrt();
        let z = (mean - expected) / se;
        assert!(z.abs() < z_max, "{wi} {wo}: {mean} ± {se} vs {expected} (z {z})");
    }
}

/// The all-order albedo two ways: `eval` integrated over the sphere by Monte Carlo (10^6
/// uniform directions) against `sample`'s mean weight (10^6 photons), z test at the Sidak
/// level for 4 cases in a family of 0.01.
#[test]
fn eval_integrates_to_the_walks_albedo() {
    let cases: [(TestBsdf<1>, DVec3); 4] = [
        (
            bsdf(
                beckmann(0.6),
                Material::Conductor(Conductor { fresnel: ConductorFresnel::Exact { eta: [1.1], k: [2.0] } }),
            ),
            dir(20.0, 0.0),
        ),
        (bsdf(ggx(1.0), glass()), dir(160.0, 0.0)),
        (bsdf(ggx(0.5), glass()), dir(70.0, 0.0)),
        (bsdf(ggx(0.8), Material::Hammon(Hammon { f0: [0.04], albedo: [0.7] })), dir(10.0, 0.0)),
    ];
    let z_max = two_sided_z(sidak(0.01, cases.len()));
    let n = 1_000_000;
    for (k, (b, wi)) in cases.iter().enumerate() {
        let mut rng = stream(10 + k as u64, &[]);
        let (mut s1, mut q1, mut s2, mut q2) = (0.0, 0.0, 0.0, 0.0);
        for _ in 0..n {
            let w = b.sample(*wi, Transport::Importance, &mut rng).weight[0];
            s1 += w;
            q1 += w * w;
            let wo = uniform_on_sphere(&mut rng);
            let v = b.eval(*wi, wo, Transport::Importance, &mut rng)[0] * 4.0 * PI;
            s2 += v;
            q2 += v * v;
        }
        let nf = n as f64;
        let (m1, m2) = (s1 / nf, s2 / nf);
        let var = (q1 / nf - m1 * m1) / nf + (q2 / nf - m2 * m2) / nf;
        let z = (m1 - m2) / var.sqrt();
        eprintln!("case {k}: sample {m1:.5}, eval {m2:.5}, z {z:.2}");
        assert!(z.abs() < z_max, "case {k}: sample {m1} vs eval {m2} (z {z})");
    }
}

/// Reciprocity (§9.3), by a chi-square over direction pairs: `eval(wi, wo)` in radiance mode
/// over `|cos theta_o|` (which is `f(wo -> wi)`) against `eval(wo, wi)` in importance mode over
/// `|cos theta_i|` (also `f(wo -> wi)`). For reflection the two modes agree, so this is
/// `f(wi, wo) = f(wo, wi)`; for transmission it is `f(wi -> wo) / n_o^2 = f(wo -> wi) / n_i^2`.
/// 20 000 evaluations each way per pair; the sum of squared z over the pairs is chi-square
/// with as many degrees of freedom, tested at the Sidak level for 5 cases in a family of 0.01.
#[test]
fn eval_is_reciprocal() {
    type Pairs = Vec<(DVec3, DVec3)>;
    let anisotropic = AnyNdf::Ggx(Ggx(Roughness { x: 0.3, y: 0.9 }));
    let cases: [(&str, TestBsdf<1>, Pairs); 5] = [
        (
            "conductor",
            bsdf(anisotropic, mirror()),
            vec![(dir(20.0, 0.0), dir(70.0, 120.0)), (dir(80.0, 10.0), dir(50.0, 250.0))],
        ),
        (
            "conductor Beckmann",
            bsdf(beckmann(0.7), mirror()),
            vec![(dir(20.0, 0.0), dir(70.0, 120.0)), (dir(60.0, 10.0), dir(50.0, 250.0))],
        ),
        (
            "Lambertian",
            bsdf(ggx(0.6), Material::Lambertian(Lambertian { albedo: [0.9] })),
            vec![(dir(10.0, 0.0), dir(75.0, 90.0)), (dir(60.0, 0.0), dir(40.0, 180.0))],
        ),
        (
            "dielectric reflection",
            bsdf(ggx(0.7), glass()),
            vec![(dir(30.0, 0.0), dir(60.0, 150.0)), (dir(120.0, 0.0), dir(170.0, 40.0))],
        ),
        (
            "dielectric transmission",
            bsdf(ggx(0.5), glass()),
            vec![
                (dir(30.0, 0.0), dir(160.0, 180.0)),
                (dir(70.0, 20.0), dir(120.0, 250.0)),
                (dir(45.0, 0.0), dir(100.0, 30.0)),
            ],
        ),
    ];
    let level = sidak(0.01, cases.len());
    let n = 20_000;
    let mut rng = stream(5, &[]);
    let mut mean_and_variance = |b: &TestBsdf<1>, wi: DVec3, wo: DVec3, transport| {
        let (mut s, mut q) = (0.0, 0.0);
        for _ in 0..n {
            let v = b.eval(wi, wo, transport, &mut rng)[0] / wo.z.abs();
            s += v;
            q += v * v;
        }
        let m = s / n as f64;
        (m, (q / n as f64 - m * m) / (n - 1) as f64)
    };
    for (name, b, pairs) in cases {
        let mut chi2 = 0.0;
        for &(wi, wo) in &pairs {
            let (a, va) = mean_and_variance(&b, wi, wo, Transport::Radiance);
            let (c, vc) = mean_and_variance(&b, wo, wi, Transport::Importance);
            eprintln!("{name} {wi} {wo}: {a:.5} vs {c:.5}");
            assert!(a > 0.0, "{name}: the pair must carry light to test anything");
            chi2 += (a - c) * (a - c) / (va + vc);
        }
        let p = statrs::distribution::ContinuousCDF::sf(
            &statrs::distribution::ChiSquared::new(pairs.len() as f64).unwrap(),
            chi2,
        );
        assert!(p > level, "{name}: chi2 {chi2}, p {p}");
    }
}

/// `eval_bidirectional` has the expectation of `eval`: 100 000 calls of each at pairs that
/// reflect and transmit (both modes, both sides), two-sample z test at the Sidak level for 4
/// pairs in a family of 0.01.
#[test]
fn bidirectional_eval_has_the_mean_of_eval() {
    let b = bsdf(ggx(0.6), glass());
    let pairs = [
        (dir(30.0, 0.0), dir(110.0, 20.0), Transport::Importance),
        (dir(30.0, 0.0), dir(110.0, 20.0), Transport::Radiance),
        (dir(140.0, 0.0), dir(60.0, 200.0), Transport::Radiance),
        (dir(50.0, 0.0), dir(20.0, 120.0), Transport::Importance),
    ];
    let z_max = two_sided_z(sidak(0.01, pairs.len()));
    let n = 100_000;
    for (k, (wi, wo, transport)) in pairs.into_iter().enumerate() {
        let mut rng = stream(30 + k as u64, &[]);
        let (mut s1, mut q1, mut s2, mut q2) = (0.0, 0.0, 0.0, 0.0);
        for _ in 0..n {
            let (x, y) = (b.eval(wi, wo, transport, &mut rng)[0], b.eval_bidirectional(wi, wo, transport, &mut rng)[0]);
            (s1, q1, s2, q2) = (s1 + x, q1 + x * x, s2 + y, q2 + y * y);
        }
        let nf = n as f64;
        let (m1, m2) = (s1 / nf, s2 / nf);
        let z = (m1 - m2) / ((q1 / nf - m1 * m1) / nf + (q2 / nf - m2 * m2) / nf).sqrt();
        eprintln!("{wi} {wo} {transport:?}: eval {m1:.5}, bidirectional {m2:.5}, z {z:.2}");
        assert!(m1 > 0.0 && z.abs() < z_max, "{wi} {wo} {transport:?}: {m1} vs {m2} (z {z})");
    }
}

/// A transmission in radiance mode is the importance-mode value times `(n_i / n_o)^2`: the
/// same walk (same seed) scaled, for `sample` and `eval`, from both sides.
#[test]
fn radiance_mode_scales_transmission_by_the_index_ratio() {
    let b = bsdf(ggx(0.5), glass());
    for (wi, wo, factor) in [(dir(30.0, 0.0), dir(150.0, 200.0), 1.0 / 2.25), (dir(150.0, 0.0), dir(20.0, 180.0), 2.25)]
    {
        let run = |transport| b.eval(wi, wo, transport, &mut stream(6, &[]))[0];
        let (importance, radiance) = (run(Transport::Importance), run(Transport::Radiance));
        assert!(importance > 0.0 && (radiance - factor * importance).abs() <= 1e-12 * radiance, "{wi} {wo}");
        for k in 0..200 {
            let sample = |transport| b.sample(wi, transport, &mut stream(k, &[]));
            let (a, r) = (sample(Transport::Importance), sample(Transport::Radiance));
            let crossed = (a.wo.z < 0.0) != (wi.z < 0.0);
            assert_eq!(a.wo, r.wo);
            assert_eq!(r.weight[0], if crossed { a.weight[0] * factor } else { a.weight[0] });
        }
    }
}

/// `pdf` integrates to 1 over the sphere: midpoint rule on 800 x 800 cells in
/// `(cos theta, phi)` per hemisphere, tolerance 2e-3 (the peaks at alpha >= 0.3 are resolved
/// to better than that).
#[test]
fn pdf_integrates_to_one() {
    let hammon = Material::Hammon(Hammon { f0: [0.04], albedo: [0.9] });
    let anisotropic = AnyNdf::Ggx(Ggx(Roughness { x: 0.3, y: 0.7 }));
    let cases: [(TestBsdf<1>, DVec3); 6] = [
        (bsdf(ggx(0.3), mirror()), dir(40.0, 0.0)),
        (bsdf(anisotropic, mirror()), dir(75.0, 30.0)),
        (bsdf(beckmann(1.0), glass()), dir(30.0, 0.0)),
        (bsdf(ggx(0.4), glass()), dir(160.0, 0.0)),
        (bsdf(ggx(0.5), Material::Lambertian(Lambertian { albedo: [0.5] })), dir(60.0, 0.0)),
        (bsdf(ggx(0.5), hammon), dir(20.0, 0.0)),
    ];
    let n = 800;
    for (b, wi) in cases {
        let mut total = 0.0;
        for hemisphere in [1.0, -1.0] {
            for i in 0..n {
                let z = (i as f64 + 0.5) / n as f64;
                let r = (1.0 - z * z).sqrt();
                for j in 0..n {
                    let phi = (j as f64 + 0.5) / n as f64 * TAU;
                    total += b.pdf(wi, DVec3::new(r * phi.cos(), r * phi.sin(), hemisphere * z));
                }
            }
        }
        total *= TAU / (n * n) as f64;
        assert!((total - 1.0).abs() < 2e-3, "{:?} {wi}: {total}", b.facet());
    }
}

/// Wherever one `eval` is positive, so is `pdf` (a grid of 12 x 12 x 12 direction pairs over
/// both hemispheres per material, alpha from 1e-3 to 2).
#[test]
fn pdf_is_positive_wherever_eval_is() {
    let mut rng = stream(7, &[]);
    let materials = [mirror(), glass(), Material::Lambertian(Lambertian { albedo: [0.9] })];
    for alpha in [1e-3, 0.1, 0.5, 2.0] {
        for material in materials {
            let b = bsdf(ggx(alpha), material);
            for i in 0..12 {
                let wi = dir(7.5 + 15.0 * i as f64, 0.0);
                for j in 0..12 {
                    for k in 0..12 {
                        let wo = dir(3.0 + 15.0 * j as f64, 30.0 * k as f64);
                        let f = b.eval(wi, wo, Transport::Importance, &mut rng)[0];
                        assert!(f == 0.0 || b.pdf(wi, wo) > 0.0, "{material:?} alpha {alpha}: {wi} {wo} f {f}");
                    }
                }
            }
        }
    }
}

/// A smooth environment `g(w) = 1 + w_x + 0.5 w_z^2`, positive on the sphere.
fn environment(w: DVec3) -> f64 {
    1.0 + w.x + 0.5 * w.z * w.z
}

/// MIS with `pdf` stays unbiased: an estimator of `∫ f |cos theta_o| g dwo` for the environment
/// `g` that takes one `sample` (weight `pdf / (pdf + p_light)`) and one uniform "light"
/// direction (`eval g / (pdf + p_light)`, `p_light = 1 / 4 pi`) per pair, against the plain
/// `sample` estimate `E[weight g(wo)]` from an independent stream: 300 000 pairs and 300 000
/// photons, two-sample z test at the Sidak level for 4 cases in a family of 0.01.
#[test]
fn mis_with_pdf_is_unbiased() {
    let cases: [(TestBsdf<1>, DVec3); 4] = [
        (bsdf(ggx(0.6), mirror()), dir(50.0, 0.0)),
        (bsdf(ggx(0.4), glass()), dir(35.0, 60.0)),
        (bsdf(beckmann(0.8), glass()), dir(150.0, 0.0)),
        (bsdf(ggx(1.0), Material::Hammon(Hammon { f0: [0.04], albedo: [0.8] })), dir(70.0, 0.0)),
    ];
    let z_max = two_sided_z(sidak(0.01, cases.len()));
    let n = 300_000;
    let p_light = 1.0 / (4.0 * PI);
    for (k, (b, wi)) in cases.iter().enumerate() {
        let (mut mis, mut plain) = (stream(20 + k as u64, &[]), stream(40 + k as u64, &[]));
        let (mut s1, mut q1, mut s2, mut q2) = (0.0, 0.0, 0.0, 0.0);
        for _ in 0..n {
            let s = b.sample(*wi, Transport::Importance, &mut mis);
            let from_sample = if s.weight[0] > 0.0 {
                let p = b.pdf(*wi, s.wo);
                s.weight[0] * environment(s.wo) * p / (p + p_light)
            } else {
                0.0
            };
            let wo = uniform_on_sphere(&mut mis);
            let from_light =
                b.eval(*wi, wo, Transport::Importance, &mut mis)[0] * environment(wo) / (b.pdf(*wi, wo) + p_light);
            let x = from_sample + from_light;
            s1 += x;
            q1 += x * x;
            let t = b.sample(*wi, Transport::Importance, &mut plain);
            let y = t.weight[0] * environment(t.wo);
            s2 += y;
            q2 += y * y;
        }
        let nf = n as f64;
        let (m1, m2) = (s1 / nf, s2 / nf);
        let (v1, v2) = ((q1 / nf - m1 * m1) / nf, (q2 / nf - m2 * m2) / nf);
        let z = (m1 - m2) / (v1 + v2).sqrt();
        eprintln!("case {k}: MIS {m1:.5} ± {:.5}, sample {m2:.5} ± {:.5}, z {z:.2}", v1.sqrt(), v2.sqrt());
        assert!(z.abs() < z_max, "case {k}: MIS {m1} vs sample {m2} (z {z})");
    }
}

/// Grazing and below-horizon directions (theta 89.99 degrees, `wo_z = ±1e-12`, exactly 0,
/// straight down), alpha 1e-4 and 3, `eta` 1.0001: `sample`, `eval` and `pdf` are finite and
/// non-negative; below the horizon of a surface that does not transmit, `eval`, `pdf` and
/// `sample`'s weight are 0.
#[test]
fn extreme_directions_and_parameters_give_finite_non_negative_values() {
    let grazing = 89.99_f64.to_radians();
    let directions = [
        DVec3::new(grazing.sin(), 0.0, grazing.cos()),
        DVec3::new(grazing.sin(), 0.0, -grazing.cos()),
        DVec3::new(1.0, 0.0, 1e-12).normalize(),
        DVec3::new(0.0, 1.0, -1e-12).normalize(),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::Z,
        -DVec3::Z,
        dir(45.0, 30.0),
        dir(135.0, 30.0),
    ];
    let materials = [
        mirror(),
        Material::Dielectric(Dielectric { eta: 1.0001 }),
        glass(),
        Material::Lambertian(Lambertian { albedo: [1.0] }),
        Material::Hammon(Hammon { f0: [0.04], albedo: [1.0] }),
    ];
    let mut rng = stream(8, &[]);
    let valid = |x: f64| x.is_finite() && x >= 0.0;
    for alpha in [1e-4, 0.5, 3.0] {
        for ndf in [ggx(alpha), beckmann(alpha), AnyNdf::Ggx(Ggx(Roughness { x: alpha, y: 1e-4 }))] {
            for material in materials {
                let b = bsdf(ndf, material);
                for wi in directions {
                    for _ in 0..20 {
                        let s = b.sample(wi, Transport::Radiance, &mut rng);
                        assert!(valid(s.weight[0]) && s.wo.is_finite(), "{ndf:?} {material:?} {wi}: {s:?}");
                        assert!(material.transmits() || s.weight[0] == 0.0 || s.wo.z > 0.0, "{s:?}");
                    }
                    for wo in directions {
                        for transport in [Transport::Importance, Transport::Radiance] {
                            let f = b.eval(wi, wo, transport, &mut rng)[0];
                            let p = b.pdf(wi, wo);
                            assert!(valid(f) && valid(p), "{ndf:?} {material:?} {wi} {wo}: f {f}, pdf {p}");
                            if !material.transmits() && (wi.z <= 0.0 || wo.z <= 0.0) {
                                assert!(f == 0.0 && p == 0.0, "{material:?} {wi} {wo}: f {f}, pdf {p}");
                            }
                        }
                    }
                }
            }
        }
    }
}

/// Out-of-range parameters: an error naming the field and its value.
#[test]
fn out_of_range_parameters_are_errors_naming_the_field() {
    let message = |r: Result<TestBsdf<1>, BsdfError>| r.expect_err("must be refused").to_string();
    let glass_at = |eta: f64| Material::Dielectric(Dielectric { eta });
    for (ndf, material, expected) in [
        (ggx(0.0), mirror(), "alpha_x = 0"),
        (ggx(-1.0), mirror(), "alpha_x = -1"),
        (AnyNdf::Ggx(Ggx(Roughness { x: 0.5, y: f64::NAN })), mirror(), "alpha_y = NaN"),
        (ggx(f64::INFINITY), mirror(), "alpha_x = inf"),
        (ggx(0.5), glass_at(0.0), "eta = 0"),
        (ggx(0.5), glass_at(f64::NAN), "eta = NaN"),
        (ggx(0.5), Material::Conductor(Conductor { fresnel: ConductorFresnel::Schlick { f0: [1.5] } }), "f0 = 1.5"),
        (
            ggx(0.5),
            Material::Conductor(Conductor { fresnel: ConductorFresnel::Exact { eta: [1.0], k: [-1.0] } }),
            "k = -1",
        ),
        (ggx(0.5), Material::Lambertian(Lambertian { albedo: [2.0] }), "albedo = 2"),
        (ggx(0.5), Material::Hammon(Hammon { f0: [0.04], albedo: [-0.1] }), "albedo = -0.1"),
    ] {
        let text = message(Bsdf::new(surface(ndf), material));
        assert!(text.starts_with(expected), "{text}");
    }
    let symmetric = Microsurface { ndf: ggx(0.5), smith: Smith::Symmetric, normals: Normals::Visible };
    assert!(message(Bsdf::new(symmetric, mirror())).starts_with("smith"));
    let hammon_normals = Microsurface { ndf: ggx(0.5), smith: Smith::Exact, normals: Normals::HammonRejection };
    assert!(message(Bsdf::new(hammon_normals, mirror())).starts_with("normals"));
}

/// The same key and numbers give the same stream, hence the same results; any other key or
/// number another stream.
#[test]
fn streams_are_determined_by_key_and_numbers() {
    let b = bsdf(ggx(0.5), glass());
    let wi = dir(40.0, 0.0);
    let draw = |key, numbers: &[f64]| b.sample(wi, Transport::Radiance, &mut stream(key, numbers));
    assert_eq!(draw(7, &[0.1, 0.2, 0.3]), draw(7, &[0.1, 0.2, 0.3]));
    let first = stream(7, &[0.1, 0.2, 0.3]).next_u64();
    for mut other in [stream(8, &[0.1, 0.2, 0.3]), stream(7, &[0.1, 0.2, 0.30000000000000004]), stream(7, &[])] {
        assert_ne!(first, other.next_u64());
    }
}

/// Order sets: membership of `only`, `at_least`, `union` and `ALL`.
#[test]
fn order_sets_hold_what_they_say() {
    let two = Orders::only(2).unwrap();
    let tail = Orders::at_least(5);
    let both = two.union(tail);
    for k in 0..200 {
        assert_eq!(two.contains(k), k == 2);
        assert_eq!(tail.contains(k), k >= 5);
        assert_eq!(both.contains(k), k == 2 || k >= 5);
        assert_eq!(Orders::ALL.contains(k), k >= 1);
    }
    assert_eq!(Orders::only(64).map(|o| o.contains(64)), Some(true));
    assert_eq!(Orders::only(0), None);
    assert_eq!(Orders::only(65), None);
}
