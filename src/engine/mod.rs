//! The engine: every case of a configuration walked in fixed chunks on a thread pool
//! ([`run`]), its escaping light binned by a [`detector::Detector`]; runs split into shards
//! ([`shard`]), resumed from checkpoints ([`checkpoint`]) or spread over MPI ranks (`ranks`).

pub mod bench;
pub mod checkpoint;
pub mod detector;
#[cfg(feature = "mpi")]
pub mod ranks;
pub mod resources;
pub mod run;
pub mod sealed;
pub mod shard;

use std::time::Instant;

use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressStyle};

use crate::engine::run::{CaseResult, CaseState, Estimator, RunSettings, Shard, run_case, with_walker};
use crate::setup::cases::Case;
use crate::setup::config::Config;

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
    let options = RunOptions { shard, threads, show_progress, estimator: Estimator::Walk, max_memory: None };
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
    /// The memory the run may plan to use (`--max-memory`); `None`: a share of what the
    /// process may use ([`resources::MemoryLimit::of`]).
    pub max_memory: Option<u64>,
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
    resources::check_resources(config, options.threads, options.max_memory)?;
    let cases = crate::setup::cases::expand(config)?;
    let settings =
        RunSettings { shard: options.shard, estimator: options.estimator, ..RunSettings::from_config(config) };
    // Joint chains carry one model per channel of an RGB detector.
    let rgb = config.is_rgb() || matches!(options.estimator, Estimator::JointChains(_));
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
    let total = settings.shard_paths().saturating_mul(cases.len() as u64);
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
            Ok(!config.precision.as_ref().is_some_and(|p| state.result.meets(p)))
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
