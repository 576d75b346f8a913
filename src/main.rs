//! The `smithwalk` command line.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Result;
use clap::{Parser, Subcommand};
use smithwalk::Simulation;
use smithwalk::config::Config;
use smithwalk::output::{EnergyBalance, prepare_dir};

#[derive(Parser)]
#[command(version, about = "A virtual gonioreflectometer for the Smith microsurface")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Simulate every case of a TOML config and write lobes.csv, summary.csv and run.json.
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
    },
}

fn run(
    config_path: PathBuf,
    paths: Option<u64>,
    seed: Option<u64>,
    threads: Option<usize>,
    out: Option<PathBuf>,
) -> Result<()> {
    let mut config = Config::load(&config_path)?;
    if let Some(p) = paths {
        config.paths = p;
    }
    if let Some(s) = seed {
        config.seed = s;
    }
    config.validate()?;
    if threads == Some(0) {
        anyhow::bail!("`--threads` = 0 is not allowed: at least 1 thread");
    }
    let out = out.unwrap_or_else(|| {
        PathBuf::from("out").join(config_path.file_stem().map_or("run".into(), |s| s.to_string_lossy().into_owned()))
    });
    prepare_dir(&out)?;
    let sim = smithwalk::simulate(&config, threads, true)?;
    let written = smithwalk::write_outputs(&sim, &config, &out)?;
    if let Err(e) = print_summary(&sim, &config, &written) {
        // A closed pipe (`| head`) is not an error of the run: the outputs are written.
        if e.kind() != std::io::ErrorKind::BrokenPipe {
            return Err(e.into());
        }
    }
    Ok(())
}

/// The end summary: throughput and each case's energy balance (channel 0 for RGB runs).
fn print_summary(sim: &Simulation, config: &Config, written: &[PathBuf]) -> std::io::Result<()> {
    let mut out = std::io::stdout().lock();
    let total = config.paths * sim.cases.len() as u64;
    let rate = total as f64 / sim.wall_seconds;
    writeln!(
        out,
        "{} cases x {} paths in {:.2} s on {} threads: {rate:.3e} paths/s ({:.3e} per thread)",
        sim.cases.len(),
        config.paths,
        sim.wall_seconds,
        sim.threads,
        rate / sim.threads as f64
    )?;
    writeln!(
        out,
        "{:>5}  {:<48} {:>9} {:>9} {:>9} {:>9} {:>6}",
        "case", "surface / material / incidence", "R", "T", "absorbed", "lost", "orders"
    )?;
    for (case, result) in sim.cases.iter().zip(&sim.results) {
        let e = EnergyBalance::from_result(result);
        let label = format!(
            "{:?} a=({},{}) {} th={:.2}",
            case.ndf,
            case.alpha_x,
            case.alpha_y,
            case.material.label(),
            case.theta_i_deg
        );
        writeln!(
            out,
            "{:>5}  {label:<48} {:>9.6} {:>9.6} {:>9.6} {:>9.2e} {:>6}",
            case.index,
            e.reflected[0],
            e.transmitted[0],
            e.absorbed[0],
            e.lost(),
            e.highest_order
        )?;
    }
    for path in written {
        writeln!(out, "wrote {}", path.display())?;
    }
    Ok(())
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Run { config, paths, seed, threads, out } => run(config, paths, seed, threads, out),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
