//! Throughput of the walk on the reference cases (single thread, 100 000 photons per
//! iteration). Run with `cargo bench`; `smithwalk bench` prints the same cases as paths/s per
//! core and ns per facet interaction.

use smithwalk::bench::{CASES, case_config};

const PATHS: u64 = 100_000;

fn main() {
    divan::main();
}

#[divan::bench(args = 0..CASES.len(), sample_count = 10)]
fn walk(bencher: divan::Bencher, case: usize) {
    let config = case_config(case, PATHS).expect("the reference cases allow PATHS photons");
    bencher
        .counter(divan::counter::ItemsCount::new(PATHS))
        .bench(|| smithwalk::simulate(divan::black_box(&config), Some(1), false).expect("runs"));
}
