//! Every `sample` against `eval`: the lossless furnace and the order-by-order chi-square.

use super::*;

/// Every `sample` of a lossless facet has weight 1 (to rounding: a dielectric's random
/// branch choice divides `F` by the probability `F / (F + (1 - F))`): 20 000 photons per case,
/// GGX, Beckmann and Student-T (gamma 1.6 and 4), alpha from 0.2 to 3, conductor `F = 1` from
/// above, dielectric from both sides. Reflection stays above the horizon.
#[test]
fn lossless_facets_return_weight_one_from_every_sample() {
    let mut rng = stream(1, &[]);
    for alpha in [0.2, 0.6, 1.0, 3.0] {
        for ndf in [ggx(alpha), beckmann(alpha), student_t(alpha, 1.6), student_t(alpha, 4.0)] {
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

/// `sample` against `eval` order by order ([`assert_sample_matches_eval`]) on Student-T
/// surfaces (theory §1.6, §3.4): a Schlick conductor at gamma 2.5, Lambertian facets at gamma 4
/// and glass at gamma 3 (2 x 4 bins, 65 536 points, as for the dielectrics above). Below gamma =
/// 7/4 `eval`'s next-event estimates have infinite variance (theory §13.3), so no chi-square
/// of a finite sample is valid there; `sample`'s furnace above covers gamma 1.6.
#[test]
fn sample_matches_eval_order_by_order_for_student_t() {
    let schlick = Material::Conductor(Conductor { fresnel: ConductorFresnel::Schlick { f0: [0.8] } });
    let lambertian = Material::Lambertian(Lambertian { albedo: [0.8] });
    assert_sample_matches_eval(&[
        ("Schlick Student-T 2.5", bsdf(student_t(0.5, 2.5), schlick), dir(40.0, 10.0), FINE),
        ("Lambertian Student-T 4", bsdf(student_t(0.7, 4.0), lambertian), dir(50.0, 0.0), FINE),
        ("glass Student-T 3", bsdf(student_t(0.5, 3.0), glass()), dir(30.0, 0.0), (Grid { cos: 2, phi: 4 }, 65_536)),
    ]);
}
