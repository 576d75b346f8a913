//! The `smithwalk` command line.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use std::time::Duration;

use anyhow::{Context, Result, bail};
use clap::parser::ValueSource;
use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};
use smithwalk::atomic::{lock_dir, prepare_dir};
use smithwalk::engine::checkpoint::{self, Checkpointer};
use smithwalk::engine::run::{Estimator, Shard};
use smithwalk::engine::shard::write_shard;
use smithwalk::exports::lut::LutConfig;
use smithwalk::io::output;
use smithwalk::setup::config::Model;
use smithwalk::setup::config::{Config, EnergyConfig};
use smithwalk::{RunOptions, Simulation};

#[derive(Parser)]
#[command(version, about = "A virtual gonioreflectometer for the Smith microsurface")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Simulate every case of a TOML config, write lobes.csv, summary.csv and run.json, and
    /// print each case's energy balance (R, T, absorbed with its standard error, lost, the
    /// highest order), with a legend of its columns.
    Run {
        /// The run configuration (TOML).
        config: PathBuf,
        /// Photons per case (overrides `paths`).
        #[arg(long)]
        paths: Option<u64>,
        /// Random seed (overrides `seed`).
        #[arg(long)]
        seed: Option<u64>,
        /// Worker threads (default: all cores). Outputs do not depend on it.
        #[arg(long)]
        threads: Option<usize>,
        /// Output directory (default: out/<config name>).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Walk only share I of N (chunk c of every case goes to share c mod N) and write its
        /// raw accumulators (shard.bin) instead of the tables; combine with `smithwalk merge`.
        #[arg(long, value_name = "I/N", value_parser = Shard::parse)]
        shard: Option<Shard>,
        /// Continue from the checkpoint in the output directory, if there is one; the outputs
        /// are bit-identical to an uninterrupted run's.
        #[arg(long)]
        resume: bool,
        /// Seconds between checkpoints (written atomically to checkpoint.bin in the output
        /// directory, removed when the run finishes).
        #[arg(long, default_value_t = 10.0)]
        checkpoint_seconds: f64,
    },
    /// Combine the shard.bin files of all shards of a run into the run's tables, identical to
    /// those of the unsplit run.
    Merge {
        /// The shards' output directories.
        #[arg(required = true)]
        shards: Vec<PathBuf>,
        /// Output directory.
        #[arg(long)]
        out: PathBuf,
    },
    /// Compare a run's lobes with analytic models in the same bins; writes models.csv and
    /// compare.csv into the run directory and prints the worst lobes per model.
    Compare {
        /// The run's output directory (with run.json, lobes.csv and summary.csv).
        run_dir: PathBuf,
        /// Comma-separated models: single, hammon-fit, heitz-nee, exact-position-free,
        /// wang-correlated, wang-uncorrelated, kulla-conty, turquin, fdez-aguera.
        #[arg(
            long,
            value_delimiter = ',',
            value_parser = Model::parse,
            default_value = "single,hammon-fit,heitz-nee,exact-position-free,wang-correlated,wang-uncorrelated"
        )]
        models: Vec<Model>,
        /// Photons per case for the Monte Carlo models (default: the run's).
        #[arg(long)]
        paths: Option<u64>,
        /// Worker threads (default: all cores).
        #[arg(long)]
        threads: Option<usize>,
        /// Family-wise level of each model's verdict: its lobes are judged at the Sidak level
        /// that keeps the chance of any false rejection among them at this value.
        #[arg(long, default_value_t = smithwalk::analysis::compare::DEFAULT_FAMILY_LEVEL)]
        level: f64,
        /// Exit with status 3 when an exact oracle (single, heitz-nee, exact-position-free)
        /// rejects a lobe, to gate code on it in CI (exit status 1 is an error).
        #[arg(long)]
        fail_on_reject: bool,
        /// A user's own model in the run's bins, judged as `external` (CSV: case, order,
        /// hemisphere, [channel], cos_lo, cos_hi, phi_lo_deg, phi_hi_deg, energy,
        /// [energy_stderr]; docs/compensation.md).
        #[arg(long)]
        external: Option<PathBuf>,
        /// Evaluate kulla-conty, turquin and fdez-aguera from this table of E(mu, alpha) and
        /// E_avg(alpha) with F = 1 instead of exact quadrature: a `smithwalk lut` conductor
        /// directory, or its lut.csv (quantity R_1; E_avg from lut_avg.csv beside it), bilinear,
        /// clamped at the table's edges (docs/compensation.md).
        #[arg(long, value_name = "DIR_OR_FILE")]
        albedo_table: Option<PathBuf>,
    },
    /// Draw a run's lobes (plane of incidence per order with the models of models.csv, polar
    /// heat maps) and per-order albedos, with an index.html report, into the run directory.
    Plot {
        /// The run's output directory.
        run_dir: PathBuf,
        /// Figure format: png, or svg (vector; heat maps embedded as images).
        #[arg(long, default_value = "png", value_parser = ["png", "svg"])]
        format: String,
        /// Directory for the figures and index.html (default: RUN_DIR).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Channel drawn for RGB runs.
        #[arg(long, default_value = "r", value_parser = ["r", "g", "b"])]
        channel: String,
        /// Heat maps on a logarithmic colour scale (three decades below each panel's maximum).
        #[arg(long)]
        log: bool,
    },
    /// Export an isotropic reflective sweep (one surface and material, many theta_deg) as a
    /// MERL .binary BRDF file.
    Merl {
        /// The run's output directory.
        run_dir: PathBuf,
        /// The MERL file to write (default: RUN_DIR/brdf.binary).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Export an isotropic reflective sweep as an RGL material file (.bsdf, RGB), the format of
    /// the RGL material database that Mitsuba 3's `measured` plugin renders.
    Rgl {
        /// The run's output directory.
        run_dir: PathBuf,
        /// The .bsdf file to write (default: RUN_DIR/brdf.bsdf).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Grid points per axis of the half-vector square, per incident angle.
        #[arg(long, default_value_t = smithwalk::exports::rgl::DEFAULT_RESOLUTION)]
        resolution: usize,
    },
    /// Measure energy-compensation tables (directional albedo per order, its average) from a
    /// table config; writes lut.csv, lut_avg.csv, lut.exr, lut.h, lut.rs and lut.json.
    Lut {
        /// The table configuration (TOML; see configs/lut-*.toml).
        config: PathBuf,
        /// Photons per cell (overrides `paths`).
        #[arg(long)]
        paths: Option<u64>,
        /// Worker threads (default: all cores). Outputs do not depend on it.
        #[arg(long)]
        threads: Option<usize>,
        /// Output directory (default: out/<config name>).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Measure the walk's throughput on the reference cases (paths/s per core, ns per
    /// facet interaction, the 1 -> 2 thread scaling, two independent 1-thread runs at once as
    /// its ceiling on this machine, and the cores the 2-thread run keeps busy).
    Bench {
        /// Photons per case and thread count.
        #[arg(long, default_value_t = 4_000_000)]
        paths: u64,
        /// Measurements per case and thread count, alternating 1 thread, 2 threads and two
        /// 1-thread runs at once; the fastest of each is reported (a shared machine only ever
        /// slows a run down).
        #[arg(long, default_value_t = 3)]
        repeats: usize,
        /// Instead, the time to a 1% relative standard error on each per-order albedo (orders
        /// 1, 2, 3 and all, R and T) on 1 thread, and the speed-up over the Heitz et al. 2016
        /// reference code from its binomial variance and its measured rate (docs/performance.md).
        #[arg(long)]
        precision: bool,
        /// With `--precision`: follow both Fresnel branches (true) or choose one at random
        /// (false), as `[energy] split` of a config (default: the config's default, true).
        #[arg(long, requires = "precision")]
        split: Option<bool>,
        /// With `--precision`: the weight below which paths stop splitting and play Russian
        /// roulette, as `[energy] threshold` of a config (default: the config's default, 0.1).
        #[arg(long, requires = "precision")]
        threshold: Option<f64>,
    },
}

fn bench(paths: u64, repeats: usize) -> Result<()> {
    use smithwalk::engine::bench::{CASES, Throughput, measure, measure_pair};
    // The reference configurations with this photon count are checked before the table starts.
    smithwalk::engine::bench::case_config(0, paths)?;
    if repeats == 0 {
        bail!("`--repeats` = 0 is not allowed: at least 1 measurement per case");
    }
    let cores = std::thread::available_parallelism().map_or(1, usize::from);
    let mut out = std::io::stdout().lock();
    let legend = format!(
        "Per case, {paths} photons, the fastest of --repeats {repeats}: paths/s per core on 1 thread; ns per facet \
         interaction (bounce); facet interactions per path; the 2-thread over the 1-thread rate; two independent \
         1-thread runs at once over one alone (what this machine gives two workers, the ceiling of the scaling); \
         the cores the 2-thread run kept busy (docs/performance.md)."
    );
    if !print_line(&mut out, &legend)? {
        return Ok(());
    }
    let header = format!(
        "{:<36} {:>14} {:>12} {:>10} {:>14} {:>14} {:>12}",
        "case", "paths/s/core", "ns/bounce", "bounces", "scaling 1->2", "two 1-thread", "busy cores"
    );
    if !print_line(&mut out, &header)? {
        return Ok(());
    }
    for (i, (label, _, _)) in CASES.iter().enumerate() {
        let (mut one, mut two): (Option<Throughput>, Option<Throughput>) = (None, None);
        let mut pair: Option<f64> = None;
        for _ in 0..repeats {
            one = Some(measure(i, paths, 1)?.fastest(one));
            if cores >= 2 {
                two = Some(measure(i, paths, 2)?.fastest(two));
                pair = Some(measure_pair(i, paths)?.max(pair.unwrap_or(0.0)));
            }
        }
        let one = one.expect("at least one measurement");
        let factor = |rate: Option<f64>| {
            rate.map_or("n/a (1 core)".to_string(), |rate| format!("{:.2}x", rate / one.paths_per_second))
        };
        let (scaling, ceiling) = (factor(two.map(|t| t.paths_per_second)), factor(pair));
        let busy = two.map_or("n/a".to_string(), |t| format!("{:.3}", t.busy_cores));
        let row = format!(
            "{label:<36} {:>14.3e} {:>12.1} {:>10.3} {scaling:>14} {ceiling:>14} {busy:>12}",
            one.per_core(),
            one.ns_per_interaction(),
            one.interactions_per_path
        );
        if !print_line(&mut out, &row)? {
            return Ok(());
        }
    }
    Ok(())
}

/// The time-to-precision table of `smithwalk bench --precision`: per case, paths per
/// CPU-second on 1 thread, then per albedo (orders 1, 2, 3 and all, R then T) the CPU seconds to
/// a 1% relative standard error and, in brackets, the reference's time over it (`-`: no light
/// goes there; `exact`: no variance, as the all-orders reflection of a conductor with F = 1).
fn bench_precision(paths: u64, energy: &EnergyConfig) -> Result<()> {
    use smithwalk::engine::bench::{MIN_PRECISION_PATHS, precision_cases, precision_config, time_to_precision};
    if paths < MIN_PRECISION_PATHS {
        bail!(
            "`--paths` = {paths} is not allowed with `--precision`: at least {MIN_PRECISION_PATHS} photons per \
             case (the rarest albedos of the table carry about 5e-5 of the light: with fewer photons an order \
             no photon reached would read `-`, one without observed variance `exact`)"
        );
    }
    // Every case's configuration is made, and so checked, before the table starts.
    let cases = precision_cases();
    let configs =
        cases.iter().map(|case| precision_config(case, energy, paths)).collect::<Result<Vec<_>>>().with_context(
            || {
                format!(
                    "the options `--paths {paths} --split {} --threshold {}` (every case's `paths` and `[energy]`)",
                    energy.split, energy.threshold
                )
            },
        )?;
    let mut out = std::io::stdout().lock();
    let legend = format!(
        "[energy] split = {}, threshold = {}. Per albedo (orders 1, 2, 3 and all; R, T): the CPU seconds \
         on 1 thread that a 1% relative standard error needs, projected from this run's per-photon \
         variance and rate, and in brackets the Heitz 2016 reference's projected time over it (its \
         binomial variance at its rates per case, measured on the host of docs/performance.md, not \
         here: on another or a loaded machine the ratios differ); `exact`: no variance on either \
         side; `-`: no light.",
        energy.split, energy.threshold
    );
    if !print_line(&mut out, &legend)? {
        return Ok(());
    }
    let quantities = ["R1", "R2", "R3", "R", "T1", "T2", "T3", "T"];
    let mut header = format!("{:<28} {:>12}", "case (alpha, theta_i rad)", "paths/cpu-s");
    for q in quantities {
        header += &format!(" {q:>16}");
    }
    if !print_line(&mut out, &header)? {
        return Ok(());
    }
    for (case, config) in cases.iter().zip(&configs) {
        let (rate, albedos) = time_to_precision(case, config)?;
        let mut row = format!("{:<28} {rate:>12.3e}", format!("{} {} {}", case.material, case.alpha, case.theta));
        for a in albedos {
            let cell = match a {
                None => "-".to_string(),
                Some(a) if a.seconds == 0.0 => "exact".to_string(),
                Some(a) => format!("{:.2e}s ({:.1}x)", a.seconds, a.speedup),
            };
            row += &format!(" {cell:>16}");
        }
        if !print_line(&mut out, &row)? {
            return Ok(());
        }
    }
    Ok(())
}

/// Prints a line of a table; `false` if the reader has gone (a closed pipe, as with `| head`),
/// which ends the table without an error.
fn print_line(out: &mut impl std::io::Write, line: &str) -> Result<bool> {
    match writeln!(out, "{line}").and_then(|()| out.flush()) {
        Ok(()) => Ok(true),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(false),
        Err(e) => Err(e.into()),
    }
}

/// The options of `smithwalk run`.
#[derive(Clone)]
struct RunArgs {
    config: PathBuf,
    paths: Option<u64>,
    seed: Option<u64>,
    threads: Option<usize>,
    out: Option<PathBuf>,
    shard: Option<Shard>,
    resume: bool,
    checkpoint_seconds: f64,
}

fn run(args: RunArgs) -> Result<()> {
    let config = run_config(&args)?;
    let out = args.out.clone().unwrap_or_else(|| default_out(&args.config));
    #[cfg(feature = "mpi")]
    if let Some(ranks) = smithwalk::engine::ranks::Ranks::join()? {
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
        let written = write_shard(&sim, &config, shard, &out)?;
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
    let written = smithwalk::write_outputs(&sim, &config, &out)?;
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
    smithwalk::engine::check_resources(&config, args.threads)?;
    note_threads(args.threads);
    if !(args.checkpoint_seconds.is_finite() && args.checkpoint_seconds > 0.0) {
        bail!("`--checkpoint-seconds` = {} is not allowed: a positive number of seconds", args.checkpoint_seconds);
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
    let states = if args.resume { checkpoint::load(dir, config, shard)? } else { None };
    let mut checkpoints = Checkpointer::new(dir, Duration::from_secs_f64(args.checkpoint_seconds), config, shard)?;
    let options = RunOptions { shard, threads: args.threads, show_progress, estimator: Estimator::Walk };
    let sim = smithwalk::simulate_from(config, &options, states, &mut |done, current, later| {
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
    if let Some(c) = &config.compare {
        let models =
            c.models.iter().map(|m| Model::parse(m).map_err(anyhow::Error::msg)).collect::<Result<Vec<_>>>()?;
        print!("{}", smithwalk::analysis::compare::compare(out, &models, c.paths, threads)?);
    }
    Ok(())
}

/// A run under `mpirun` with several ranks: each walks its share, checkpointing into
/// `OUT/rank-R-of-N`; rank 0 merges every rank's accumulators and writes the outputs. The
/// checkpoints go only when the outputs are written.
#[cfg(feature = "mpi")]
fn run_ranks(args: &RunArgs, config: &Config, out: &Path, ranks: &smithwalk::engine::ranks::Ranks) -> Result<()> {
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
    if let Some(shards) = ranks.gather(smithwalk::engine::shard::encode(&sim, config, shard)?) {
        let (config, sim) = smithwalk::engine::shard::merge_bytes(&shards)?;
        let written = smithwalk::write_outputs(&sim, &config, out)?;
        finish_run(&sim, &config, out, &written, args.threads)?;
    }
    ranks.barrier();
    checkpoints.finish()?;
    // The directory is this rank's own; a kill during a checkpoint may have left a temporary file.
    std::fs::remove_dir_all(&dir).with_context(|| format!("cannot remove {}", dir.display()))
}

/// `--threads`, when given, must be at least 1.
fn check_threads(threads: Option<usize>) -> Result<()> {
    if threads == Some(0) {
        bail!("`--threads` = 0 is not allowed: at least 1 thread");
    }
    Ok(())
}

/// A note when `--threads` asks for many more threads than cores: allowed (outputs do not
/// depend on it), but it only adds overhead.
fn note_threads(threads: Option<usize>) {
    let cores = std::thread::available_parallelism().map_or(1, usize::from);
    if let Some(n) = threads
        && n > 8 * cores
    {
        eprintln!(
            "note: --threads {n} on {cores} cores: outputs are the same, more threads than cores only add overhead"
        );
    }
}

fn default_out(config_path: &Path) -> PathBuf {
    PathBuf::from("out").join(config_path.file_stem().map_or("run".into(), |s| s.to_string_lossy().into_owned()))
}

fn lut(config_path: &Path, paths: Option<u64>, threads: Option<usize>, out: Option<PathBuf>) -> Result<()> {
    let mut config = LutConfig::load(config_path)?;
    if let Some(p) = paths {
        // The file is valid (`load` checked it), so an error now is the option's.
        config.paths = p;
        config.validate().map_err(|e| e.from_option("--paths"))?;
    }
    check_threads(threads)?;
    let out = out.unwrap_or_else(|| default_out(config_path));
    prepare_dir(&out)?;
    let lut = smithwalk::exports::lut::build(&config, threads, true)?;
    let written = smithwalk::exports::lut::write(&lut, &out)?;
    let worst = lut.tables.iter().flat_map(|t| t.e_stderr.iter()).fold(0.0_f64, |a, &b| a.max(b));
    println!(
        "{} cells, {} photons in {:.2} s; largest standard error {worst:.2e}",
        lut.photons.len(),
        lut.photons.iter().sum::<u64>(),
        lut.wall_seconds
    );
    for path in written {
        println!("wrote {}", path.display());
    }
    Ok(())
}

fn merge(shards: &[PathBuf], out: &Path) -> Result<()> {
    let (config, sim) = smithwalk::engine::shard::merge(shards)?;
    prepare_dir(out)?;
    let _lock = lock_dir(out, true)?;
    let written = smithwalk::write_outputs(&sim, &config, out)?;
    report(&sim, &config, &written)
}

/// Prints the end summary; a closed pipe (`| head`) is not an error, the outputs are written.
fn report(sim: &Simulation, config: &Config, written: &[PathBuf]) -> Result<()> {
    if let Err(e) = print_summary(sim, config, written)
        && e.kind() != std::io::ErrorKind::BrokenPipe
    {
        return Err(e.into());
    }
    Ok(())
}

/// "1 thread", "2 threads".
fn threads_text(threads: usize) -> String {
    format!("{threads} thread{}", if threads == 1 { "" } else { "s" })
}

/// The end summary: throughput, then each case's energy balance with a legend of its columns.
fn print_summary(sim: &Simulation, config: &Config, written: &[PathBuf]) -> std::io::Result<()> {
    let mut out = std::io::stdout().lock();
    let total = config.paths as f64 * sim.cases.len() as f64;
    let rate = total / sim.wall_seconds;
    writeln!(
        out,
        "{} cases x {} paths in {:.2} s on {}: {rate:.3e} paths/s ({:.3e} per thread)",
        sim.cases.len(),
        config.paths,
        sim.wall_seconds,
        threads_text(sim.threads),
        rate / sim.threads as f64
    )?;
    write!(out, "{}{}", output::BALANCE_LEGEND, output::balance_table(sim))?;
    for path in written {
        writeln!(out, "wrote {}", path.display())?;
    }
    warn_losses(sim);
    warn_unreliable_errors(sim);
    Ok(())
}

/// One line on the console when some albedo's standard error is itself too uncertain to trust
/// (its VOV, `albedo_vov` in summary.csv, above [`output::VOV_THRESHOLD`]), naming the worst.
fn warn_unreliable_errors(sim: &Simulation) {
    let flagged = output::unreliable_albedos(sim);
    if flagged.is_empty() {
        return;
    }
    let worst: Vec<String> = flagged
        .iter()
        .take(5)
        .map(|&(case, slot, h, c, vov)| {
            let channel = if sim.rgb { format!(" {}", output::CHANNEL_NAMES[c]) } else { String::new() };
            format!("case {case} order {slot} {h:?}{channel} (VOV {vov:.2})")
        })
        .collect();
    eprintln!(
        "note: {} albedo standard errors are unreliable (variance of the variance above {}: rare large \
         weights dominate; run more photons): {}; all in summary.csv, column albedo_vov",
        flagged.len(),
        output::VOV_THRESHOLD,
        worst.join(", ")
    );
}

/// One line on the console when any case lost energy (trapped, NaN or runaway walks): the
/// tables hold only the energy that escaped or was absorbed, and run.json has the details.
fn warn_losses(sim: &Simulation) {
    let balances: Vec<output::EnergyBalance> = sim.results.iter().map(output::EnergyBalance::from_result).collect();
    let lossy = balances.iter().filter(|e| e.lost() > 0.0).count();
    let Some((case, worst)) = balances.iter().enumerate().max_by(|a, b| a.1.lost().total_cmp(&b.1.lost())) else {
        return;
    };
    if lossy > 0 {
        let sum = |v: &[f64]| v.iter().sum::<f64>();
        eprintln!(
            "warning: {lossy} of {} cases lost energy; the most case {case}: {:.3e} of the incident energy \
             (trapped {:.3e}, NaN {:.3e}, runaway {:.3e}); see cases[].energy in run.json",
            sim.cases.len(),
            worst.lost(),
            sum(&worst.lost_trapped),
            sum(&worst.lost_invalid),
            sum(&worst.lost_runaway)
        );
    }
}

fn main() -> ExitCode {
    let matches = Cli::command().get_matches();
    let cli = Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit());
    // `compare` without `--models` compares with the default list.
    let default_models =
        matches.subcommand_matches("compare").and_then(|m| m.value_source("models")) == Some(ValueSource::DefaultValue);
    let result = match cli.command {
        Command::Run { config, paths, seed, threads, out, shard, resume, checkpoint_seconds } => {
            run(RunArgs { config, paths, seed, threads, out, shard, resume, checkpoint_seconds })
        }
        Command::Merge { shards, out } => merge(&shards, &out),
        Command::Compare { run_dir, models, paths, threads, level, fail_on_reject, external, albedo_table } => {
            let options = smithwalk::analysis::compare::CompareOptions {
                family_level: level,
                external,
                albedo_table,
                default_models,
                ..smithwalk::analysis::compare::CompareOptions::new(models, paths, threads)
            };
            match smithwalk::analysis::compare::compare_with(&run_dir, &options) {
                Ok(outcome) => {
                    print!("{}", outcome.report);
                    if fail_on_reject && outcome.exact_oracle_rejected() {
                        return ExitCode::from(3);
                    }
                    Ok(())
                }
                Err(e) => Err(e),
            }
        }
        Command::Lut { config, paths, threads, out } => lut(&config, paths, threads, out),
        Command::Plot { run_dir, format, out, channel, log } => {
            use smithwalk::exports::plot::{Format, PlotOptions};
            let format = if format == "svg" { Format::Svg } else { Format::Png };
            let channel = ["r", "g", "b"].iter().position(|c| *c == channel).unwrap_or(0);
            let index = out.clone().unwrap_or_else(|| run_dir.clone()).join("index.html");
            smithwalk::exports::plot::plot(&run_dir, &PlotOptions { format, out, channel, log })
                .map(|written| println!("wrote {} files; open {}", written.len(), index.display()))
        }
        Command::Merl { run_dir, out } => {
            let out = out.unwrap_or_else(|| run_dir.join("brdf.binary"));
            smithwalk::exports::merl::export(&run_dir, &out).map(|p| println!("wrote {}", p.display()))
        }
        Command::Rgl { run_dir, out, resolution } => {
            let out = out.unwrap_or_else(|| run_dir.join("brdf.bsdf"));
            smithwalk::exports::rgl::export(&run_dir, &out, resolution).map(|p| println!("wrote {}", p.display()))
        }
        Command::Bench { paths, precision: true, split, threshold, .. } => {
            let default = EnergyConfig::default();
            let energy = EnergyConfig {
                split: split.unwrap_or(default.split),
                threshold: threshold.unwrap_or(default.threshold),
            };
            bench_precision(paths, &energy)
        }
        Command::Bench { paths, repeats, .. } => bench(paths, repeats),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
