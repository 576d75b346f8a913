//! Robustness: extreme directions and parameters, errors, streams and order sets.

use super::*;

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
