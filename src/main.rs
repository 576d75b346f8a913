//! The `smithwalk` command line: its arguments (clap), the call of each subcommand
//! ([`smithwalk::commands`] or the library function it names) and the exit status.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::parser::ValueSource;
use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};
use smithwalk::commands;
use smithwalk::commands::run::RunArgs;
use smithwalk::engine::run::Shard;
use smithwalk::setup::config::{EnergyConfig, Model};

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
        /// The most memory the run may plan to use, e.g. 8G or 512M (default: 80% of the memory
        /// available to the process: the machine's, its cgroup's or its Slurm allocation's,
        /// whichever is least). A run whose estimated peak exceeds it is refused before any work.
        #[arg(long, value_name = "SIZE", value_parser = smithwalk::engine::resources::parse_size)]
        max_memory: Option<u64>,
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
        /// wang-correlated, wang-uncorrelated, cui2023-released, kulla-conty, turquin, fdez-aguera, materialx, lee2018.
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
        /// Evaluate kulla-conty, turquin and fdez-aguera (not materialx, which has its own fit)
        /// from this table of E(mu, alpha) and E_avg(alpha) with F = 1 instead of exact
        /// quadrature: a `smithwalk lut` conductor directory, or its lut.csv (quantity R_1; E_avg
        /// from lut_avg.csv beside it), bilinear, clamped at the table's edges
        /// (docs/compensation.md).
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

fn main() -> ExitCode {
    let matches = Cli::command().get_matches();
    let cli = Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit());
    // `compare` without `--models` compares with the default list.
    let default_models =
        matches.subcommand_matches("compare").and_then(|m| m.value_source("models")) == Some(ValueSource::DefaultValue);
    let result = match cli.command {
        Command::Run { config, paths, seed, threads, out, shard, resume, checkpoint_seconds, max_memory } => {
            commands::run::run(RunArgs {
                config,
                paths,
                seed,
                threads,
                out,
                shard,
                resume,
                checkpoint_seconds,
                max_memory,
            })
        }
        Command::Merge { shards, out } => commands::merge::merge(&shards, &out),
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
        Command::Lut { config, paths, threads, out } => commands::lut::lut(&config, paths, threads, out),
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
            commands::bench::bench_precision(paths, &energy)
        }
        Command::Bench { paths, repeats, .. } => commands::bench::bench(paths, repeats),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
