//! The engine: every case of a configuration walked in fixed chunks on a thread pool
//! ([`run`]), its escaping light binned by a [`detector::Detector`]; runs split into shards
//! ([`shard`]), resumed from checkpoints ([`checkpoint`]) or spread over MPI ranks (`ranks`).

pub mod bench;
pub mod checkpoint;
pub mod detector;
#[cfg(feature = "mpi")]
pub mod ranks;
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
    let options = RunOptions { shard, threads, show_progress, estimator: Estimator::Walk };
    simulate_from(config, &options, None, &mut |_, _, _| Ok(()))
}

/// The most worker threads a run may ask for. Outputs do not depend on the thread count, and
/// starting many more threads than cores only costs time (`--threads 100000` took minutes).
pub const MAX_THREADS: usize = 1024;

/// Order slots assumed by the memory estimate when `detector.max_order` leaves the number of
/// slots to the walk (slots are added as orders are seen).
pub const ESTIMATED_SLOTS: usize = 16;

/// Bytes per row of `lobes.csv` assumed by the memory estimate (rows of the shipped configs
/// take 110 to 150 bytes).
const CSV_ROW_BYTES: u64 = 160;

/// Checks, before any work, that a run of `config` on `threads` threads can finish: the thread
/// count is within [`MAX_THREADS`] and the estimated memory (detectors of every case and of
/// the threads' rounds, and the text of `lobes.csv`) fits in the memory available now. The
/// error names the fields to change.
pub fn check_resources(config: &Config, threads: Option<usize>) -> Result<()> {
    let threads = match threads {
        Some(0) => anyhow::bail!("`--threads` = 0 is not allowed: at least 1 thread"),
        Some(n) if n > MAX_THREADS => anyhow::bail!(
            "`--threads` = {n} is not allowed: at most {MAX_THREADS} (outputs do not depend on the thread count;              this machine has {} cores)",
            cores()
        ),
        Some(n) => n,
        None => cores(),
    };
    let estimate = memory_estimate(config, threads);
    if let Some(available) = available_memory()
        && estimate > available
    {
        let d = &config.detector;
        let slots =
            d.max_order.map_or(format!("{ESTIMATED_SLOTS} order slots assumed"), |k| format!("{} order slots", k + 1));
        anyhow::bail!(
            "the run needs about {:.1} GB but {:.1} GB of memory are available: {} cases x {} x {} bins              (detector.cos_theta_bins x detector.phi_bins) x {slots} (detector.max_order) x {} channels,              held for every case and {threads} threads (--threads), plus lobes.csv; reduce the bins, set or              lower detector.max_order, sweep fewer cases or split the sweep into several configs",
            estimate as f64 / 1e9,
            available as f64 / 1e9,
            config.cases(),
            d.cos_theta_bins,
            d.phi_bins,
            if config.is_rgb() { 3 } else { 1 }
        );
    }
    Ok(())
}

fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, usize::from)
}

/// Bytes a run of `config` on `threads` threads is estimated to hold at its peak (§9.2 tallies,
/// both hemispheres of every order slot; the text of lobes.csv once).
pub fn memory_estimate(config: &Config, threads: usize) -> u64 {
    let d = &config.detector;
    let (tally, channels) = if config.is_rgb() {
        (std::mem::size_of::<detector::Tally<3>>(), 3)
    } else {
        (std::mem::size_of::<detector::Tally<1>>(), 1)
    };
    let slots = d.max_order.map_or(ESTIMATED_SLOTS, |k| k as usize + 1) as u64;
    let bins = (d.cos_theta_bins * d.phi_bins) as u64;
    let cases = config.cases();
    let detector = slots * 2 * bins * tally as u64;
    // Every case's state, and per thread the part of a round it walks and one waiting round.
    let held = (cases + 2 * threads as u64).saturating_mul(detector);
    let rows = cases.saturating_mul(slots * 2 * bins * channels);
    held.saturating_add(rows.saturating_mul(CSV_ROW_BYTES))
}

/// `MemAvailable` of `/proc/meminfo` in bytes, where there is one.
fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
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
    check_resources(config, options.threads)?;
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
