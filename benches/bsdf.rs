//! Cost per call of the renderer's BSDF (`microsurface::bsdf`): `sample`, `eval` (all orders
//! and order 1 alone) and `pdf`, single thread, on four reference cases built as a renderer
//! builds them (run-time NDF and material). Each iteration makes `CALLS` calls from one seeded
//! stream; divan reports the time per call (`ItemsCount`). Run with `cargo bench --bench bsdf`.

use microsurface::DVec3;
use microsurface::bsdf::{Bsdf, Orders, Transport, stream};
use microsurface::facet::{Conductor, ConductorFresnel, Dielectric, Lambertian};
use microsurface::material::Material;
use microsurface::ndf::{AnyNdf, Ggx, Roughness};
use microsurface::normals::Normals;
use microsurface::smith::Smith;
use microsurface::walk::Microsurface;

const CALLS: u64 = 10_000;

fn main() {
    divan::main();
}

/// The cases: name, BSDF and the incident direction (theta 45 degrees; 135 from inside).
const CASES: [&str; 4] = ["conductor-0.3", "conductor-1.0", "dielectric-0.5-outside", "lambertian-0.5"];

fn case(index: usize) -> (Bsdf<AnyNdf, Material<3>, 3>, DVec3) {
    let ggx = |alpha| AnyNdf::Ggx(Ggx(Roughness::isotropic(alpha)));
    let gold = Material::Conductor(Conductor {
        fresnel: ConductorFresnel::Exact { eta: [0.18, 0.42, 1.37], k: [3.42, 2.35, 1.77] },
    });
    let (ndf, material) = match index {
        0 => (ggx(0.3), gold),
        1 => (ggx(1.0), gold),
        2 => (ggx(0.5), Material::Dielectric(Dielectric { eta: 1.5 })),
        _ => (ggx(0.5), Material::Lambertian(Lambertian { albedo: [0.8, 0.6, 0.4] })),
    };
    let surface = Microsurface { ndf, smith: Smith::Exact, normals: Normals::Visible };
    let wi = DVec3::new(0.5f64.sqrt(), 0.0, 0.5f64.sqrt());
    (Bsdf::new(surface, material).expect("valid parameters"), wi)
}

/// A fixed outgoing direction on the reflection side.
fn outgoing() -> DVec3 {
    DVec3::new(-0.3, 0.2, 0.9).normalize()
}

#[divan::bench(args = 0..CASES.len(), sample_count = 20)]
fn sample(bencher: divan::Bencher, index: usize) {
    let (bsdf, wi) = case(index);
    let mut rng = stream(1, &[]);
    bencher.counter(divan::counter::ItemsCount::new(CALLS)).bench_local(|| {
        for _ in 0..CALLS {
            divan::black_box(bsdf.sample(divan::black_box(wi), Transport::Radiance, &mut rng));
        }
    });
}

#[divan::bench(args = 0..CASES.len(), sample_count = 20)]
fn eval(bencher: divan::Bencher, index: usize) {
    bench_eval(bencher, index, Orders::ALL);
}

#[divan::bench(args = 0..CASES.len(), sample_count = 20)]
fn eval_order_one(bencher: divan::Bencher, index: usize) {
    bench_eval(bencher, index, Orders::only(1).expect("order 1 exists"));
}

/// `CALLS` evaluations of case `index` restricted to `orders`, towards [`outgoing`].
fn bench_eval(bencher: divan::Bencher, index: usize, orders: Orders) {
    let (bsdf, wi) = case(index);
    let bsdf = bsdf.with_orders(orders);
    let mut rng = stream(2, &[]);
    bencher.counter(divan::counter::ItemsCount::new(CALLS)).bench_local(|| {
        for _ in 0..CALLS {
            divan::black_box(bsdf.eval(divan::black_box(wi), outgoing(), Transport::Radiance, &mut rng));
        }
    });
}

#[divan::bench(args = 0..CASES.len(), sample_count = 20)]
fn pdf(bencher: divan::Bencher, index: usize) {
    let (bsdf, wi) = case(index);
    bencher.counter(divan::counter::ItemsCount::new(CALLS)).bench_local(|| {
        for _ in 0..CALLS {
            divan::black_box(bsdf.pdf(divan::black_box(wi), outgoing()));
        }
    });
}

#[divan::bench(sample_count = 20)]
fn seed_stream(bencher: divan::Bencher) {
    bencher.counter(divan::counter::ItemsCount::new(CALLS)).bench_local(|| {
        for k in 0..CALLS {
            divan::black_box(stream(divan::black_box(k), &[0.1, 0.2, 0.3]));
        }
    });
}
