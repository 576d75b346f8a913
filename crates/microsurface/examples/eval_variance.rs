//! Variance of `Bsdf::eval` from one end and from both (`eval_bidirectional`), orders 2 and
//! up, at a few direction pairs (docs/theory.md §13.3): `cargo run --release -p
//! smithwalk-microsurface --example eval_variance`. Prints each end's mean and relative
//! standard deviation per call and the variance ratio of two forward calls to one
//! bidirectional call (the same cost): above 1, the bidirectional form wins.

use microsurface::DVec3;
use microsurface::bsdf::*;
use microsurface::facet::*;
use microsurface::material::Material;
use microsurface::ndf::*;
use microsurface::normals::Normals;
use microsurface::smith::Smith;
use microsurface::walk::Microsurface;
/// The unit direction at polar angle `t` and azimuth `p` (degrees).
fn dir(t: f64, p: f64) -> DVec3 {
    let (st, ct) = t.to_radians().sin_cos();
    let (sp, cp) = p.to_radians().sin_cos();
    DVec3::new(st * cp, st * sp, ct)
}
fn main() {
    let g = |a| AnyNdf::Ggx(Ggx(Roughness::isotropic(a)));
    let cases: Vec<(&str, AnyNdf, Material<1>, DVec3, DVec3)> = vec![
        (
            "conductor 0.5",
            g(0.5),
            Material::Conductor(Conductor { fresnel: ConductorFresnel::None }),
            dir(20.0, 0.0),
            dir(70.0, 120.0),
        ),
        (
            "conductor 1.0 grazing",
            g(1.0),
            Material::Conductor(Conductor { fresnel: ConductorFresnel::None }),
            dir(80.0, 0.0),
            dir(30.0, 90.0),
        ),
        (
            "beckmann 0.3 grazing",
            AnyNdf::Beckmann(Beckmann(Roughness::isotropic(0.3))),
            Material::Conductor(Conductor { fresnel: ConductorFresnel::None }),
            dir(80.0, 10.0),
            dir(50.0, 250.0),
        ),
        ("glass T 0.5", g(0.5), Material::Dielectric(Dielectric { eta: 1.5 }), dir(30.0, 0.0), dir(110.0, 20.0)),
        ("glass R 0.5", g(0.5), Material::Dielectric(Dielectric { eta: 1.5 }), dir(30.0, 0.0), dir(60.0, 150.0)),
        ("lambert 0.7", g(0.7), Material::Lambertian(Lambertian { albedo: [0.8] }), dir(60.0, 0.0), dir(40.0, 180.0)),
    ];
    let n = 200_000u64;
    for (name, ndf, m, wi, wo) in cases {
        let b: Bsdf<_, _, 1> = Bsdf::new(Microsurface { ndf, smith: Smith::Exact, normals: Normals::Visible }, m)
            .unwrap()
            .with_orders(Orders::at_least(2));
        let mut rng = stream(1, &[]);
        let stats = |v: &mut dyn FnMut() -> f64| {
            let (mut s, mut q) = (0.0, 0.0);
            for _ in 0..n {
                let x = v();
                s += x;
                q += x * x;
            }
            let m = s / n as f64;
            (m, q / n as f64 - m * m)
        };
        // f(wi->wo) estimated forward: eval(wi,wo)/|cos o|; backward by reciprocity: eval(wo,wi, Radiance)/|cos i|
        let (mf, vf) = stats(&mut || b.eval(wi, wo, Transport::Importance, &mut rng)[0] / wo.z.abs());
        let (mb, vb) = stats(&mut || b.eval(wo, wi, Transport::Radiance, &mut rng)[0] / wi.z.abs());
        let va = 0.25 * (vf + vb); // average of one of each, per pair of calls
        println!(
            "{name}: forward {mf:.4e} (rel sd {:.2}), backward {mb:.4e} (rel sd {:.2}), average rel sd per 2 calls {:.2}; variance ratio at equal cost {:.2}",
            vf.sqrt() / mf,
            vb.sqrt() / mb,
            va.sqrt() / mf,
            (vf / 2.0) / va
        );
    }
}
