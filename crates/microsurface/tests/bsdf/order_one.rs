//! Order 1 of `eval` against exact single scattering, and `eval`'s albedo against the walk's.

use super::*;

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
