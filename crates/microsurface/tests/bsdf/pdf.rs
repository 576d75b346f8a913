//! `pdf`: normalised, positive where `eval` is, and unbiased in MIS.

use super::*;

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
