//! `smithwalk bench`: the throughput table of the reference cases and the time-to-precision
//! table (`--precision`), printed from the measurements of [`crate::engine::bench`].

use anyhow::{Context, Result, bail};

use crate::setup::config::EnergyConfig;

/// The throughput table of `smithwalk bench`: per reference case, the fastest of `repeats`
/// measurements on 1 thread, on 2 threads and of two 1-thread runs at once.
pub fn bench(paths: u64, repeats: usize) -> Result<()> {
    use crate::engine::bench::{CASES, Throughput, measure, measure_pair};
    // The reference configurations with this photon count are checked before the table starts.
    crate::engine::bench::case_config(0, paths)?;
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
pub fn bench_precision(paths: u64, energy: &EnergyConfig) -> Result<()> {
    use crate::engine::bench::{MIN_PRECISION_PATHS, precision_cases, precision_config, time_to_precision};
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
