//! `smithwalk bench`: throughput of the walk on the reference cases of the throughput issue,
//! reported as paths per second per core and nanoseconds per facet interaction, plus the
//! scaling from 1 to 2 threads and, as its ceiling on this machine, the throughput of two
//! independent 1-thread runs at the same time, and how many cores a 2-thread run keeps busy.

use std::time::{Duration, Instant};

use anyhow::Result;
use rustix::time::{ClockId, clock_gettime};

use crate::engine::detector::Hemisphere;
use crate::engine::simulate;
use crate::setup::config::{Config, EnergyConfig, parse_toml};

/// The reference cases: (label, `[surface]` and `[material]` TOML, theta_i in degrees).
pub const CASES: [(&str, &str, f64); 7] = [
    ("ggx conductor F=1 a=0.5 60deg", "ndf = \"ggx\"\nalpha = 0.5\n[material]\nkind = \"conductor\"", 60.0),
    ("ggx conductor F=1 a=1 0deg", "ndf = \"ggx\"\nalpha = 1.0\n[material]\nkind = \"conductor\"", 0.0),
    (
        "ggx dielectric 1.5 a=0.5 60deg",
        "ndf = \"ggx\"\nalpha = 0.5\n[material]\nkind = \"dielectric\"\neta = 1.5",
        60.0,
    ),
    ("ggx diffuse a=1 0deg", "ndf = \"ggx\"\nalpha = 1.0\n[material]\nkind = \"diffuse\"", 0.0),
    ("beckmann conductor F=1 a=0.5 60deg", "ndf = \"beckmann\"\nalpha = 0.5\n[material]\nkind = \"conductor\"", 60.0),
    (
        "student-t 3 conductor F=1 a=0.5 60deg",
        "ndf = \"student-t\"\ngamma = 3\nalpha = 0.5\n[material]\nkind = \"conductor\"",
        60.0,
    ),
    (
        "student-t 1.6 conductor F=1 a=0.5 60deg",
        "ndf = \"student-t\"\ngamma = 1.6\nalpha = 0.5\n[material]\nkind = \"conductor\"",
        60.0,
    ),
];

/// The run configuration of a reference case with `paths` photons and the default detector;
/// an error naming `--paths` if the run configuration does not allow that many photons.
pub fn case_config(case: usize, paths: u64) -> Result<Config> {
    let (_, surface, theta) = CASES[case];
    let toml = format!("paths = {paths}\nseed = 1\n[surface]\n{surface}\n[incident]\ntheta_deg = {theta}\n");
    let config: Config = parse_toml(&toml)?;
    // The cases are valid, so an error is the photon count's, which `--paths` gave.
    config.validate().map_err(|e| e.from_option("--paths"))?;
    Ok(config)
}

/// One measurement: throughput on `threads` threads.
#[derive(Clone, Copy, Debug)]
pub struct Throughput {
    pub paths_per_second: f64,
    pub interactions_per_path: f64,
    pub threads: usize,
    /// CPU time of the process over wall time during the run (setup included): the cores it
    /// kept busy. Below the thread count by the time threads wait for work; how fast each
    /// busy core went is in `paths_per_second`. (Idle pool threads spin briefly before they
    /// sleep, which counts as busy; at the end of a run that is well below a chunk's time.)
    pub busy_cores: f64,
}

impl Throughput {
    /// The faster of this measurement and `other`.
    pub fn fastest(self, other: Option<Throughput>) -> Throughput {
        match other {
            Some(o) if o.paths_per_second > self.paths_per_second => o,
            _ => self,
        }
    }

    pub fn per_core(&self) -> f64 {
        self.paths_per_second / self.threads as f64
    }

    /// Wall nanoseconds per facet interaction, per core.
    pub fn ns_per_interaction(&self) -> f64 {
        1e9 / (self.per_core() * self.interactions_per_path)
    }
}

/// Runs a reference case on `threads` threads.
pub fn measure(case: usize, paths: u64, threads: usize) -> Result<Throughput> {
    let config = case_config(case, paths)?;
    let (cpu, wall) = (process_cpu_time(), Instant::now());
    let sim = simulate(&config, Some(threads), false)?;
    let busy_cores = (process_cpu_time() - cpu).as_secs_f64() / wall.elapsed().as_secs_f64();
    let interactions = sim.results[0].interactions();
    Ok(Throughput {
        paths_per_second: paths as f64 / sim.wall_seconds,
        interactions_per_path: interactions as f64 / paths as f64,
        threads: sim.threads,
        busy_cores,
    })
}

/// CPU time used so far by all threads of this process, the finished ones included.
fn process_cpu_time() -> Duration {
    let t = clock_gettime(ClockId::ProcessCPUTime);
    Duration::new(t.tv_sec.unsigned_abs(), t.tv_nsec.unsigned_abs() as u32)
}

/// Two runs of a reference case on 1 thread each, at the same time: paths per second of the
/// pair, counted up to the later one's end. Independent runs share nothing but the machine, so
/// this is what the machine gives two workers, the ceiling of the 1 -> 2 thread scaling (below
/// 2 where the two cores share a physical core, caches or memory bandwidth, or other tenants
/// take part of them).
pub fn measure_pair(case: usize, paths: u64) -> Result<f64> {
    let (a, b) = std::thread::scope(|scope| {
        let other = scope.spawn(|| measure(case, paths, 1));
        (measure(case, paths, 1), other.join().expect("a bench run panicked"))
    });
    // Both runs walk `paths`: the pair's rate is twice the slower one's.
    Ok(2.0 * a?.paths_per_second.min(b?.paths_per_second))
}

/// The fewest photons per case of a time-to-precision table, a guard: the rarest albedos of the
/// table carry down to about 5·10^-5 of the light (the dielectric's R3 at alpha 0.25, normal
/// incidence), so with fewer photons they get no escape to estimate a variance from, and their
/// cells would read `exact` or `-`. At this count their figures are still rough.
pub const MIN_PRECISION_PATHS: u64 = 100_000;

/// A case of the time-to-precision table: a GGX facet material at `(alpha, theta_i in radians)`
/// and the rate of the Heitz et al. 2016 reference code on it.
#[derive(Clone, Copy, Debug)]
pub struct PrecisionCase {
    /// `conductor`, `dielectric` or `lambertian`.
    pub material: &'static str,
    /// Its `[material]` table.
    pub toml: &'static str,
    pub alpha: f64,
    pub theta: f64,
    /// Paths per CPU-second of the reference code on this case (docs/performance.md).
    pub reference_rate: f64,
}

/// The incidences of the time-to-precision table, (alpha, theta_i in radians): the Heitz 2016
/// comparison (0.5, 1.0), and alpha 0.25 and 1.0 at normal and 1.5 rad incidence.
const PRECISION_ANGLES: [(f64, f64); 5] = [(0.5, 1.0), (0.25, 0.0), (0.25, 1.5), (1.0, 0.0), (1.0, 1.5)];

/// The materials of the time-to-precision table: GGX conductor (F = 1), dielectric (eta 1.5)
/// and Lambertian (albedo 1) facets, each with the paths per CPU-second of the Heitz et al.
/// 2016 reference code (its public release, `float`, GGX, uniform heights, built with `g++
/// -O2`) at each of [`PRECISION_ANGLES`], measured on the host of docs/performance.md (the
/// fastest of three runs of 2·10^6 paths each, alternated with smithwalk's bench).
const PRECISION_MATERIALS: [(&str, &str, [f64; 5]); 3] = [
    ("conductor", "kind = \"conductor\"", [3.00e6, 5.31e6, 3.86e6, 2.12e6, 3.62e6]),
    ("dielectric", "kind = \"dielectric\"\neta = 1.5", [3.25e6, 5.07e6, 3.02e6, 4.35e6, 1.44e6]),
    ("lambertian", "kind = \"diffuse\"\nalbedo = 1.0", [2.62e6, 4.34e6, 3.13e6, 2.11e6, 2.18e6]),
];

/// The 15 cases of the time-to-precision table, material by material.
pub fn precision_cases() -> Vec<PrecisionCase> {
    PRECISION_MATERIALS
        .iter()
        .flat_map(|&(material, toml, rates)| {
            PRECISION_ANGLES.iter().zip(rates).map(move |(&(alpha, theta), reference_rate)| PrecisionCase {
                material,
                toml,
                alpha,
                theta,
                reference_rate,
            })
        })
        .collect()
}

/// The run configuration of a time-to-precision case with `paths` photons under `energy`; an
/// error that names the field (`paths`, `energy.threshold`) if `energy` or `paths` is not
/// allowed.
pub fn precision_config(case: &PrecisionCase, energy: &EnergyConfig, paths: u64) -> Result<Config> {
    let PrecisionCase { toml, alpha, theta, .. } = case;
    // The policy is set as a field, not written into the text, so that a NaN is refused by name
    // like any other value instead of failing to parse as TOML; then everything is checked once.
    let mut config: Config = parse_toml(&format!(
        "paths = {paths}\nseed = 1\n[surface]\nalpha = {alpha}\n[material]\n{toml}\n[incident]\ntheta_rad = {theta}\n[detector]\nmax_order = 4\n"
    ))?;
    config.energy = energy.clone();
    config.validate()?;
    Ok(config)
}

/// One per-order albedo of a time-to-precision measurement.
#[derive(Clone, Copy, Debug)]
pub struct Precision {
    /// The albedo.
    pub albedo: f64,
    /// CPU seconds for smithwalk to reach a relative standard error of 1% on it.
    pub seconds: f64,
    /// The reference's CPU seconds for the same, over smithwalk's.
    pub speedup: f64,
}

/// Time to a relative standard error of 1% on the albedos of orders 1, 2, 3 and all, R then T,
/// of `case` walked on 1 thread with its run configuration `config` ([`precision_config`]):
/// smithwalk's per-photon variance (`stderr^2 N`) over its measured paths per CPU-second,
/// against the reference's binomial variance `p (1 - p)` (it walks unit-weight photons with
/// coin escapes) over its rate. `None` where no light goes.
pub fn time_to_precision(case: &PrecisionCase, config: &Config) -> Result<(f64, Vec<Option<Precision>>)> {
    let paths = config.paths;
    let cpu = process_cpu_time();
    let sim = simulate(config, Some(1), false)?;
    let rate = paths as f64 / (process_cpu_time() - cpu).as_secs_f64();
    let reference = case.reference_rate;
    let result = &sim.results[0];
    let mut out = Vec::new();
    for hemisphere in [Hemisphere::R, Hemisphere::T] {
        for slot in [1, 2, 3, 0] {
            let (p, se) = result.albedo(slot, hemisphere);
            // A quantity without variance (a conductor with F = 1 reflects everything) is
            // exact at once, for both codes: reported as 0 seconds and a speed-up of 1.
            out.push((p > 0.0).then(|| {
                if se == 0.0 {
                    return Precision { albedo: p, seconds: 0.0, speedup: 1.0 };
                }
                // Photons to a relative standard error of 1%: variance per photon / (0.01 p)^2.
                let photons = |variance: f64| variance / (0.01 * p).powi(2);
                let seconds = photons(se * se * paths as f64) / rate;
                let reference_seconds = photons(p * (1.0 - p)) / reference;
                Precision { albedo: p, seconds, speedup: reference_seconds / seconds }
            }));
        }
    }
    Ok((rate, out))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first case of `material` in the table: alpha 0.5 at 1 rad.
    fn case_of(material: &str) -> PrecisionCase {
        let case = precision_cases().into_iter().find(|c| c.material == material).unwrap();
        assert_eq!((case.alpha, case.theta), (0.5, 1.0));
        case
    }

    #[test]
    fn unit_weight_walks_gain_exactly_their_throughput_ratio() {
        // A conductor with F = 1 walks photons of weight 1 with one escape each, like the
        // reference: the per-order variances are binomial on both sides, so every speed-up is
        // the ratio of the rates (times (N - 1) / N: smithwalk's variance is the unbiased sample
        // variance), and the all-orders albedo (1, without variance) is exact.
        let n = 20_000;
        let case = case_of("conductor");
        let (rate, albedos) =
            time_to_precision(&case, &precision_config(&case, &EnergyConfig::default(), n).unwrap()).unwrap();
        let ratio = rate / case.reference_rate * (n - 1) as f64 / n as f64;
        for a in albedos[..3].iter().map(|a| a.expect("orders 1 to 3 reflect light")) {
            assert!((a.speedup / ratio - 1.0).abs() < 1e-9, "{} against {ratio}", a.speedup);
        }
        assert_eq!(albedos[3].map(|a| a.seconds), Some(0.0));
        assert!(albedos[4..].iter().all(Option::is_none), "a conductor transmits nothing");
    }

    #[test]
    fn the_policy_reaches_the_walk() {
        // Without splitting and without roulette a dielectric walks photons of weight 1 with one
        // escape each, like the reference: every albedo, R and T, per order and in all, gains
        // the ratio of the rates (times (N - 1) / N). With splitting (the default) photons carry
        // Fresnel weights and the gains differ from albedo to albedo.
        let (n, case) = (20_000, case_of("dielectric"));
        let unit = EnergyConfig { split: false, threshold: 0.0 };
        let (rate, albedos) = time_to_precision(&case, &precision_config(&case, &unit, n).unwrap()).unwrap();
        let ratio = rate / case.reference_rate * (n - 1) as f64 / n as f64;
        for a in albedos.iter().map(|a| a.expect("a dielectric reflects and transmits every order")) {
            assert!((a.speedup / ratio - 1.0).abs() < 1e-9, "{} against {ratio}", a.speedup);
        }
        let (rate, albedos) =
            time_to_precision(&case, &precision_config(&case, &EnergyConfig::default(), n).unwrap()).unwrap();
        let ratio = rate / case.reference_rate * (n - 1) as f64 / n as f64;
        let speedups: Vec<f64> = albedos.iter().map(|a| a.unwrap().speedup / ratio).collect();
        assert!(speedups.iter().any(|s| (s - 1.0).abs() > 0.1), "split photons gain like unit ones: {speedups:?}");
    }

    #[test]
    fn a_bad_policy_names_its_field() {
        for threshold in [0.0, 2.0, f64::NAN] {
            let bad = EnergyConfig { split: true, threshold };
            let err = precision_config(&case_of("conductor"), &bad, 100).unwrap_err().to_string();
            assert!(err.contains(&format!("`energy.threshold` = {threshold}")), "{err}");
        }
        let err = precision_config(&case_of("conductor"), &EnergyConfig::default(), 0).unwrap_err().to_string();
        assert!(err.contains("`paths` = 0"), "{err}");
    }
}
