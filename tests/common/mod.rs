//! Shared helpers for the integration tests.
#![allow(dead_code)]

use smithwalk::Simulation;
use smithwalk::config::Config;
use smithwalk::detector::{Detector, Hemisphere, OrderTallies};
use smithwalk::microsurface::DVec3;
use smithwalk::run::CaseResult;
use smithwalk::stats::WeightedBin;

/// Parses a TOML config and runs it on `threads` threads without a progress bar.
pub fn simulate(toml: &str, threads: usize) -> Simulation {
    let config = Config::parse(toml).expect("test config is valid");
    smithwalk::simulate(&config, Some(threads), false).expect("simulation runs")
}

/// Parses a TOML config and runs it with `estimator` (the walk or a model) on 2 threads.
pub fn simulate_with(toml: &str, estimator: smithwalk::run::Estimator) -> Simulation {
    let config = Config::parse(toml).expect("test config is valid");
    let options = smithwalk::RunOptions {
        estimator,
        shard: smithwalk::run::Shard::WHOLE,
        threads: Some(2),
        show_progress: false,
    };
    smithwalk::simulate_from(&config, &options, None, &mut |_, _, _| Ok(())).expect("simulation runs")
}

/// The single-channel detector of case `i`.
pub fn mono(sim: &Simulation, i: usize) -> &Detector<1> {
    match &sim.results[i] {
        CaseResult::Mono(d) => d,
        CaseResult::Rgb(_) => panic!("expected a mono case"),
    }
}

/// The per-photon moments of every bin of one order slot and hemisphere.
pub fn weighted_bins(d: &Detector<1>, slot: usize, hemisphere: Hemisphere) -> Vec<WeightedBin> {
    let n = d.tallies.photons as f64;
    let bins = d.grid.bins();
    let empty = OrderTallies { bins: vec![Default::default(); 2 * bins], albedo: Default::default() };
    let tallies = d.tallies.orders.get(slot).unwrap_or(&empty);
    tallies.bins[hemisphere as usize * bins..(hemisphere as usize + 1) * bins]
        .iter()
        .map(|t| WeightedBin { mean: t.sum[0].to_f64() / n, second_moment: t.sum_sq[0].to_f64() / n })
        .collect()
}

/// Photon counts of every bin of one order slot and hemisphere.
pub fn bin_counts(d: &Detector<1>, slot: usize, hemisphere: Hemisphere) -> Vec<u64> {
    let bins = d.grid.bins();
    d.tallies.orders.get(slot).map_or(vec![0; bins], |t| {
        t.bins[hemisphere as usize * bins..(hemisphere as usize + 1) * bins].iter().map(|b| b.count).collect()
    })
}

/// Albedo and standard error of one order slot and hemisphere.
pub fn albedo(d: &Detector<1>, slot: usize, hemisphere: Hemisphere) -> (f64, f64) {
    d.tallies
        .orders
        .get(slot)
        .map_or((0.0, 0.0), |t| t.albedo[hemisphere as usize].mean_and_stderr(d.tallies.photons, 0))
}

/// The unit direction at polar angle `theta_deg` and azimuth `phi_deg` (degrees).
pub fn dir(theta_deg: f64, phi_deg: f64) -> DVec3 {
    let (st, ct) = theta_deg.to_radians().sin_cos();
    let (sp, cp) = phi_deg.to_radians().sin_cos();
    DVec3::new(st * cp, st * sp, ct)
}
