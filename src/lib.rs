//! smithwalk: a virtual gonioreflectometer for the Smith microsurface.
//!
//! Data flows one way: a [`config::Config`] expands into [`cases::Case`]s; each case is walked
//! by the [`microsurface`] crate in fixed chunks ([`run`]); escaping light is binned as it goes
//! by a [`detector::Detector`]; [`output`] writes the tables. [`models`], [`quadrature`] and
//! [`stats`] hold the analytic oracles and the statistics the measurements are tested with.

pub mod bench;
pub mod cases;
pub mod checkpoint;
pub mod compare;
pub mod config;
pub mod detector;
pub mod lut;
pub mod merl;
pub mod models;
pub mod output;
pub mod plot;
pub mod quadrature;
#[cfg(feature = "mpi")]
pub mod ranks;
pub mod rgl;
pub mod run;
pub mod rundir;
pub mod shard;
pub mod stats;
pub mod sweep;

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressStyle};

pub use microsurface;

use crate::cases::Case;
use crate::config::Config;
use crate::run::{CaseResult, CaseState, Estimator, RunSettings, Shard, run_case, with_walker};

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
    let options = RunOptions { shard, threads, show_progress, estimator: Estimator::Walk };
    simulate_from(config, &options, None, &mut |_, _, _| Ok(()))
}

/// Called after every round with (finished cases, the current case, cases not started).
pub type RoundHook<'a> = dyn FnMut(&[CaseState], &CaseState, &[CaseState]) -> Result<()> + 'a;

/// How to run a simulation, beyond its config.
#[derive(Clone, Copy, Debug)]
pub struct RunOptions {
    pub estimator: Estimator,
    pub shard: Shard,
    pub threads: Option<usize>,
    pub show_progress: bool,
}

/// Runs a simulation from saved case states (a resumed checkpoint) or from scratch, calling
/// `after_round(finished cases, current case, cases not started)` after every round of chunks
/// (for checkpoints). Cases stop early when `config.precision` is met.
pub fn simulate_from(
    config: &Config,
    options: &RunOptions,
    states: Option<Vec<CaseState>>,
    after_round: &mut RoundHook<'_>,
) -> Result<Simulation> {
    let cases = cases::expand(config);
    let settings =
        RunSettings { shard: options.shard, estimator: options.estimator, ..RunSettings::from_config(config) };
    let rgb = config.is_rgb();
    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(n) = options.threads {
        builder = builder.num_threads(n);
    }
    let pool = builder.build().context("cannot start the worker threads")?;
    let mut states = match states {
        Some(s) => s,
        None => cases
            .iter()
            .map(|case| CaseState {
                result: with_walker(case, &settings, rgb, |w| w.empty()),
                rounds_done: 0,
                finished: false,
            })
            .collect(),
    };
    let total = settings.shard_paths() * cases.len() as u64;
    let progress = if options.show_progress { ProgressBar::new(total) } else { ProgressBar::hidden() };
    progress.set_style(
        ProgressStyle::with_template(
            "{elapsed_precise} [{bar:40}] {human_pos}/{human_len} paths ({per_sec}, eta {eta})",
        )
        .expect("static template")
        .progress_chars("=> "),
    );
    progress.inc(states.iter().map(|s| s.result.photons()).sum());
    let start = Instant::now();
    for (i, case) in cases.iter().enumerate() {
        let (done, rest) = states.split_at_mut(i);
        let (current, later) = rest.split_first_mut().expect("one state per case");
        let mut round = |state: &CaseState| -> Result<bool> {
            after_round(done, state, later)?;
            Ok(!config.precision.as_ref().is_some_and(|p| p.is_met(&state.result)))
        };
        with_walker(case, &settings, rgb, |w| run_case(w, &settings, current, &pool, &progress, &mut round))?;
    }
    progress.finish_and_clear();
    Ok(Simulation {
        cases,
        results: states.into_iter().map(|s| s.result).collect(),
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
