//! smithwalk: a virtual gonioreflectometer for the Smith microsurface.
//!
//! Data flows one way: a [`config::Config`] expands into [`cases::Case`]s; each case is walked
//! by the [`microsurface`] crate in fixed chunks ([`run`]); escaping light is binned as it goes
//! by a [`detector::Detector`]; [`output`] writes the tables. [`models`], [`quadrature`] and
//! [`stats`] hold the analytic oracles and the statistics the measurements are tested with.

pub mod bench;
pub mod cases;
pub mod config;
pub mod detector;
pub mod models;
pub mod output;
pub mod quadrature;
pub mod run;
pub mod shard;
pub mod stats;

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressStyle};

pub use microsurface;

use crate::cases::Case;
use crate::config::Config;
use crate::run::{CaseResult, RunSettings, Shard, simulate_case};

/// The measurements of a whole run, in case order.
#[derive(Clone, Debug)]
pub struct Simulation {
    pub cases: Vec<Case>,
    pub results: Vec<CaseResult>,
    pub rgb: bool,
    pub threads: usize,
    pub wall_seconds: f64,
}

/// Simulates every case of `config` on `threads` threads (all cores if `None`).
pub fn simulate(config: &Config, threads: Option<usize>, show_progress: bool) -> Result<Simulation> {
    simulate_shard(config, Shard::WHOLE, threads, show_progress)
}

/// Simulates one shard of the work of `config` (see [`run::Shard`]).
pub fn simulate_shard(
    config: &Config,
    shard: Shard,
    threads: Option<usize>,
    show_progress: bool,
) -> Result<Simulation> {
    let cases = cases::expand(config);
    let settings = RunSettings { shard, ..RunSettings::from_config(config) };
    let rgb = config.is_rgb();
    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(n) = threads {
        builder = builder.num_threads(n);
    }
    let pool = builder.build().context("cannot start the worker threads")?;
    let total = settings.shard_paths() * cases.len() as u64;
    let progress = if show_progress { ProgressBar::new(total) } else { ProgressBar::hidden() };
    progress.set_style(
        ProgressStyle::with_template(
            "{elapsed_precise} [{bar:40}] {human_pos}/{human_len} paths ({per_sec}, eta {eta})",
        )
        .expect("static template")
        .progress_chars("=> "),
    );
    let start = Instant::now();
    let results = cases.iter().map(|case| simulate_case(case, &settings, rgb, &pool, &progress)).collect();
    progress.finish_and_clear();
    Ok(Simulation {
        cases,
        results,
        rgb,
        threads: pool.current_num_threads(),
        wall_seconds: start.elapsed().as_secs_f64(),
    })
}

/// Writes `lobes.csv`, `summary.csv` and `run.json` of a simulation into `dir`, atomically.
pub fn write_outputs(sim: &Simulation, config: &Config, dir: &Path) -> Result<Vec<PathBuf>> {
    let files = [
        ("lobes.csv", output::lobes_csv(sim)?),
        ("summary.csv", output::summary_csv(sim)?),
        ("run.json", output::run_json(sim, config)?),
    ];
    output::write_atomically(dir, &files)
}
