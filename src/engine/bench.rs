//! `smithwalk bench`: throughput of the walk on the reference cases of the throughput issue,
//! reported as paths per second per core and nanoseconds per facet interaction, plus the
//! scaling from 1 to 2 threads and, as its ceiling on this machine, the throughput of two
//! independent 1-thread runs at the same time, and how many cores a 2-thread run keeps busy.

use std::time::{Duration, Instant};

use anyhow::Result;
use rustix::time::{ClockId, clock_gettime};

use crate::engine::simulate;
use crate::setup::config::Config;

/// The reference cases: (label, `[surface]` and `[material]` TOML, theta_i in degrees).
pub const CASES: [(&str, &str, f64); 5] = [
    ("ggx conductor F=1 a=0.5 60deg", "ndf = \"ggx\"\nalpha = 0.5\n[material]\nkind = \"conductor\"", 60.0),
    ("ggx conductor F=1 a=1 0deg", "ndf = \"ggx\"\nalpha = 1.0\n[material]\nkind = \"conductor\"", 0.0),
    (
        "ggx dielectric 1.5 a=0.5 60deg",
        "ndf = \"ggx\"\nalpha = 0.5\n[material]\nkind = \"dielectric\"\neta = 1.5",
        60.0,
    ),
    ("ggx diffuse a=1 0deg", "ndf = \"ggx\"\nalpha = 1.0\n[material]\nkind = \"diffuse\"", 0.0),
    ("beckmann conductor F=1 a=0.5 60deg", "ndf = \"beckmann\"\nalpha = 0.5\n[material]\nkind = \"conductor\"", 60.0),
];

/// The run configuration of a reference case with `paths` photons and the default detector;
/// an error if the run configuration does not allow that many photons.
pub fn case_config(case: usize, paths: u64) -> Result<Config> {
    let (_, surface, theta) = CASES[case];
    let toml = format!("paths = {paths}\nseed = 1\n[surface]\n{surface}\n[incident]\ntheta_deg = {theta}\n");
    Ok(Config::parse(&toml)?)
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
