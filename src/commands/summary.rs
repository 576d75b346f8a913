//! The console's end summary of a run: throughput, each case's energy balance with a legend of
//! its columns, the files written, and warnings about lost energy and unreliable standard errors.

use std::io::Write;
use std::path::PathBuf;

use anyhow::Result;

use crate::engine::Simulation;
use crate::io::output;
use crate::setup::config::Config;

/// Prints the end summary; a closed pipe (`| head`) is not an error, the outputs are written.
pub fn report(sim: &Simulation, config: &Config, written: &[PathBuf]) -> Result<()> {
    if let Err(e) = print_summary(sim, config, written)
        && e.kind() != std::io::ErrorKind::BrokenPipe
    {
        return Err(e.into());
    }
    Ok(())
}

/// "1 thread", "2 threads".
pub fn threads_text(threads: usize) -> String {
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
