//! Throughput of the walk on the reference cases (single thread, 100 000 photons per
//! iteration). Run with `cargo bench`; `walk` reports paths per second (per core: one
//! thread), `interactions` the same runs counted in facet interactions, whose inverse
//! throughput is the time per bounce. `smithwalk bench` prints the same cases, plus the
//! 1 -> 2 thread scaling.

use smithwalk::engine::bench::{CASES, case_config};

const PATHS: u64 = 100_000;

fn main() {
    divan::main();
}

/// Runs a reference case on 1 thread; returns its number of facet interactions (the same for
/// every run: the seed is fixed).
fn walk_case(config: &smithwalk::setup::config::Config) -> u64 {
    smithwalk::simulate(divan::black_box(config), Some(1), false).expect("runs").results[0].interactions()
}

#[divan::bench(args = 0..CASES.len(), sample_count = 10)]
fn walk(bencher: divan::Bencher, case: usize) {
    let config = case_config(case, PATHS).expect("the reference cases allow PATHS photons");
    bencher.counter(divan::counter::ItemsCount::new(PATHS)).bench(|| walk_case(&config));
}

#[divan::bench(args = 0..CASES.len(), sample_count = 10)]
fn interactions(bencher: divan::Bencher, case: usize) {
    let config = case_config(case, PATHS).expect("the reference cases allow PATHS photons");
    let bounces = walk_case(&config);
    bencher.counter(divan::counter::ItemsCount::new(bounces)).bench(|| walk_case(&config));
}

/// The tabulated NDF against the NDF its table was sampled from (issue 38 point 6: at most 2x
/// GGX per facet interaction): 100 000 photons on a conductor with F = 1 at 60 degrees, GGX
/// of roughness 0.5 and its table at the recommended 0.25 degree step, walked side by side on
/// one thread through the physics crate (the command line's cases cannot name a table).
/// Counted in facet interactions.
#[divan::bench(args = ["ggx", "table"], sample_count = 10)]
fn tabulated(bencher: divan::Bencher, ndf: &str) {
    use microsurface::facet::{Conductor, ConductorFresnel};
    use microsurface::ndf::{Ggx, Ndf, Roughness};
    use microsurface::normals::Normals;
    use microsurface::smith::Smith;
    use microsurface::tabulated::{RECOMMENDED_STEP_DEG, Tabulated};
    use microsurface::walk::{EnergyPolicy, Loss, Microsurface, Observer};
    use microsurface::{DVec3, facet::Side};

    /// Counts facet interactions.
    struct Count(u64);
    impl Observer<1> for Count {
        fn escape(&mut self, _: u32, _: Side, _: DVec3, _: &[f64; 1]) {}
        fn lose(&mut self, _: Loss, _: &[f64; 1]) {}
        fn end_photon(&mut self, interactions: u64) {
            self.0 += interactions;
        }
    }
    fn run<N: Ndf>(ndf: N) -> u64 {
        let surface = Microsurface { ndf, smith: Smith::Exact, normals: Normals::Visible };
        let facet = Conductor::<1> { fresnel: ConductorFresnel::Schlick { f0: [1.0] } };
        let policy = EnergyPolicy { split: false, threshold: 0.1 };
        let (s, c) = 60f64.to_radians().sin_cos();
        let mut count = Count(0);
        let mut rng = rand_pcg::Pcg64Mcg::new(1);
        surface.walk_side_by_side(&facet, &policy, DVec3::new(s, 0.0, c), PATHS, &mut rng, &mut count);
        count.0
    }

    let ggx = Ggx(Roughness::isotropic(0.5));
    let steps = (90.0 / RECOMMENDED_STEP_DEG) as usize;
    let theta: Vec<f64> = (0..=steps).map(|i| i as f64 * RECOMMENDED_STEP_DEG).collect();
    let d: Vec<f64> = theta
        .iter()
        .map(|t| {
            let (s, c) = t.to_radians().sin_cos();
            ggx.d(DVec3::new(s, 0.0, c))
        })
        .collect();
    let table = Tabulated::new(&theta, &d).expect("a GGX table");
    let interactions = if ndf == "ggx" { run(ggx) } else { run(table) };
    bencher
        .counter(divan::counter::ItemsCount::new(interactions))
        .bench(|| if ndf == "ggx" { run(divan::black_box(ggx)) } else { run(divan::black_box(table)) });
}
