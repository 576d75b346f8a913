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
