//! `smithwalk run`: a run from its config to its run directory, whole, as one shard
//! (`--shard`), resumed from a checkpoint (`--resume`) or spread over MPI ranks.

use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{Result, bail};

use crate::atomic::{lock_dir, prepare_dir};
use crate::commands::options::{default_out, note_threads};
use crate::commands::summary::{report, threads_text};
use crate::engine::checkpoint::{self, Checkpointer};
use crate::engine::resources::{check_disk, check_resources, gigabytes, peak_memory};
use crate::engine::run::{Estimator, Shard};
use crate::engine::shard::write_shard;
use crate::engine::{RunOptions, Simulation};
use crate::setup::config::{Config, Model};

/// The longest `--checkpoint-seconds`: 10^6 s (11.6 days). A longer interval is no checkpoint at
/// all for any run, and `Duration` cannot hold one above about 1.8e19 s.
pub const MAX_CHECKPOINT_SECONDS: f64 = 1e6;

/// The options of `smithwalk run`.
#[derive(Clone)]
pub struct RunArgs {
    pub config: PathBuf,
    pub paths: Option<u64>,
    pub seed: Option<u64>,
    pub threads: Option<usize>,
    pub out: Option<PathBuf>,
    pub shard: Option<Shard>,
    pub resume: bool,
    pub checkpoint_seconds: f64,
    /// `--max-memory`, in bytes.
    pub max_memory: Option<u64>,
}

/// `smithwalk run`: walks the run (or its shard, or this MPI rank's share), writes its outputs
/// and prints its summary.
pub fn run(args: RunArgs) -> Result<()> {
    let config = run_config(&args)?;
    let out = args.out.clone().unwrap_or_else(|| default_out(&args.config));
    #[cfg(feature = "mpi")]
    if let Some(ranks) = crate::engine::ranks::Ranks::join()? {
        let result = run_ranks(&args, &config, &out, &ranks);
        ranks.abort_on_error(result);
        return Ok(());
    }
    let shard = args.shard.unwrap_or(Shard::WHOLE);
    if shard.count > 1 && config.precision.is_some() {
        bail!(
            "`--shard` = {}/{} is not allowed with a `[precision]` target: shards would stop independently",
            shard.index,
            shard.count
        );
    }
    prepare_dir(&out)?;
    let lock = lock_dir(&out, true)?;
    let (sim, checkpoints) = walk(&args, &config, shard, &out, true)?;
    if shard != Shard::WHOLE {
        let written = write_shard(&sim, &config, shard, &out).map_err(|e| checkpoints.stopped("the shard", &e))?;
        checkpoints.finish()?;
        println!(
            "shard {}/{} of {} cases in {:.2} s on {}: wrote {}",
            shard.index,
            shard.count,
            sim.cases.len(),
            sim.wall_seconds,
            threads_text(sim.threads),
            written.display()
        );
        return Ok(());
    }
    let written =
        crate::io::output::write_outputs(&sim, &config, &out).map_err(|e| checkpoints.stopped("the tables", &e))?;
    checkpoints.finish()?;
    // The run is complete: its comparison reads it like any reader, under a shared lock.
    drop(lock);
    finish_run(&sim, &config, &out, &written, args.threads)
}

/// The config of a run with the command line's overrides, validated with the command line.
fn run_config(args: &RunArgs) -> Result<Config> {
    let mut config = Config::load(&args.config)?;
    if let Some(p) = args.paths {
        // The file is valid (`load` checked it), so an error now is the option's.
        config.paths = p;
        config.validate().map_err(|e| e.from_option("--paths"))?;
    }
    if let Some(s) = args.seed {
        config.seed = s;
    }
    let (estimate, limit) = check_resources(&config, args.threads, args.max_memory)?;
    let allowed = limit.map_or(String::new(), |l| format!(" of {} allowed ({})", gigabytes(l.bytes), l.source));
    println!("memory: about {} at the peak{allowed}", gigabytes(estimate.bytes()));
    note_threads(args.threads);
    if !(args.checkpoint_seconds > 0.0 && args.checkpoint_seconds <= MAX_CHECKPOINT_SECONDS) {
        bail!(
            "`--checkpoint-seconds` = {} is not allowed: a positive number of seconds, at most {MAX_CHECKPOINT_SECONDS:e} \
             (11.6 days)",
            args.checkpoint_seconds
        );
    }
    Ok(config)
}

/// Walks `shard` of the run, checkpointing into `dir` (and resuming from there with
/// `--resume`). Returns the simulation and the checkpointer, to remove the checkpoint once the
/// run's results are safe.
fn walk(
    args: &RunArgs,
    config: &Config,
    shard: Shard,
    dir: &Path,
    show_progress: bool,
) -> Result<(Simulation, Checkpointer)> {
    let (disk, free) = check_disk(config, dir)?;
    if show_progress {
        let free = free.map_or(String::new(), |f| format!(", where {} are free", gigabytes(f)));
        println!("disk: up to {} written into {}{free}", gigabytes(disk.bytes()), dir.display());
    }
    let states = if args.resume { checkpoint::load(dir, config, shard)? } else { None };
    let mut checkpoints = Checkpointer::new(dir, Duration::from_secs_f64(args.checkpoint_seconds), config, shard)?;
    let options = RunOptions {
        shard,
        threads: args.threads,
        show_progress,
        estimator: Estimator::Walk,
        max_memory: args.max_memory,
    };
    let sim = crate::engine::simulate_from(config, &options, states, &mut |done, current, later| {
        checkpoints.after_round(done, current, later)
    })?;
    Ok((sim, checkpoints))
}

/// After a run's outputs are written: the summary, and the comparison the config asks for.
fn finish_run(
    sim: &Simulation,
    config: &Config,
    out: &Path,
    written: &[PathBuf],
    threads: Option<usize>,
) -> Result<()> {
    report(sim, config, written)?;
    if let Some(peak) = peak_memory() {
        println!("peak memory: {}", gigabytes(peak));
    }
    if let Some(c) = &config.compare {
        let models =
            c.models.iter().map(|m| Model::parse(m).map_err(anyhow::Error::msg)).collect::<Result<Vec<_>>>()?;
        print!("{}", crate::analysis::compare::compare(out, &models, c.paths, threads)?);
    }
    Ok(())
}

/// A run under `mpirun` with several ranks: each walks its share, checkpointing into
/// `OUT/rank-R-of-N`; rank 0 merges every rank's accumulators and writes the outputs. The
/// checkpoints go only when the outputs are written.
#[cfg(feature = "mpi")]
fn run_ranks(args: &RunArgs, config: &Config, out: &Path, ranks: &crate::engine::ranks::Ranks) -> Result<()> {
    use anyhow::Context as _;
    if let Some(s) = args.shard {
        bail!("`--shard` = {}/{} is not allowed under mpirun: the ranks share the work", s.index, s.count);
    }
    if config.precision.is_some() {
        bail!("a `[precision]` target is not allowed under mpirun: the ranks would stop independently");
    }
    let shard = ranks.shard();
    let dir = out.join(format!("rank-{}-of-{}", shard.index, shard.count));
    prepare_dir(&dir)?;
    let threads = args.threads.unwrap_or_else(|| ranks.default_threads());
    let args = &RunArgs { threads: Some(threads), ..args.clone() };
    let (sim, checkpoints) = walk(args, config, shard, &dir, ranks.is_root())?;
    if let Some(shards) = ranks.gather(crate::engine::shard::encode(&sim, config, shard)?) {
        let (config, sim) = crate::engine::shard::merge_bytes(&shards)?;
        let written = crate::io::output::write_outputs(&sim, &config, out)?;
        finish_run(&sim, &config, out, &written, args.threads)?;
    }
    ranks.barrier();
    checkpoints.finish()?;
    // The directory is this rank's own; a kill during a checkpoint may have left a temporary file.
    std::fs::remove_dir_all(&dir).with_context(|| format!("cannot remove {}", dir.display()))
}
