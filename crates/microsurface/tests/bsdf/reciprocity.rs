//! Reciprocity of `eval`, its bidirectional form, and the transport modes.

use super::*;

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
