//! Runs split across machines: a shard walks every `N`-th chunk of every case and saves its
//! raw accumulators; merging the shards reproduces the unsplit run's `lobes.csv` and
//! `summary.csv` to the bit (the accumulators are integers, §4.6 determinism).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail, ensure};
use serde::{Deserialize, Serialize};

use crate::Simulation;
use crate::cases::{Case, expand};
use crate::config::Config;
use crate::detector::{Detector, Grid, Tallies};
use crate::output::write_atomically;
use crate::run::{CaseResult, Shard};

/// The file a shard writes into its output directory.
pub const SHARD_FILE: &str = "shard.bin";
const FORMAT: &str = "smithwalk-shard-1";

/// The raw accumulators of one case, as saved in shard and checkpoint files.
#[derive(Serialize, Deserialize)]
pub(crate) enum CaseTallies {
    Mono(Box<Tallies<1>>),
    Rgb(Box<Tallies<3>>),
}

impl CaseTallies {
    pub(crate) fn of(result: &CaseResult) -> Self {
        match result {
            CaseResult::Mono(d) => CaseTallies::Mono(Box::new(d.tallies.clone())),
            CaseResult::Rgb(d) => CaseTallies::Rgb(Box::new(d.tallies.clone())),
        }
    }

    /// The result of `case` holding these tallies.
    pub(crate) fn into_result(self, case: &Case, config: &Config) -> CaseResult {
        let grid = Grid { cos_bins: config.detector.cos_theta_bins, phi_bins: config.detector.phi_bins };
        let wi = case.incident_direction();
        let max_order = config.detector.max_order;
        match self {
            CaseTallies::Mono(t) => {
                let mut d = Detector::<1>::new(grid, wi, max_order);
                d.tallies = *t;
                CaseResult::Mono(Box::new(d))
            }
            CaseTallies::Rgb(t) => {
                let mut d = Detector::<3>::new(grid, wi, max_order);
                d.tallies = *t;
                CaseResult::Rgb(Box::new(d))
            }
        }
    }

    fn mono(&self) -> Option<&Tallies<1>> {
        if let CaseTallies::Mono(t) = self { Some(t) } else { None }
    }

    fn rgb(&self) -> Option<&Tallies<3>> {
        if let CaseTallies::Rgb(t) = self { Some(t) } else { None }
    }
}

/// The detector of case `i` with the tallies of every shard added.
fn merged<const C: usize>(
    grid: Grid,
    wi: glam::DVec3,
    max_order: Option<u32>,
    files: &[ShardFile],
    i: usize,
    channels: fn(&CaseTallies) -> Option<&Tallies<C>>,
) -> Result<Detector<C>> {
    let mut detector = Detector::<C>::new(grid, wi, max_order);
    for file in files {
        let tallies = file.tallies.get(i).and_then(channels).with_context(|| format!("case {i}: shards differ"))?;
        detector.tallies.merge(tallies);
    }
    Ok(detector)
}

/// What a shard saves: the resolved config (as TOML), which share it walked, and the raw
/// accumulators of every case.
#[derive(Serialize, Deserialize)]
struct ShardFile {
    format: String,
    version: String,
    config_toml: String,
    shard: Shard,
    threads: usize,
    wall_seconds: f64,
    tallies: Vec<CaseTallies>,
}

/// Writes the accumulators of a shard's simulation into `dir/shard.bin`, atomically.
pub fn write_shard(sim: &Simulation, config: &Config, shard: Shard, dir: &Path) -> Result<PathBuf> {
    let file = ShardFile {
        format: FORMAT.into(),
        version: env!("CARGO_PKG_VERSION").into(),
        config_toml: toml::to_string(config).context("cannot serialize the config")?,
        shard,
        threads: sim.threads,
        wall_seconds: sim.wall_seconds,
        tallies: sim.results.iter().map(CaseTallies::of).collect(),
    };
    let bytes = postcard::to_stdvec(&file).context("cannot encode the shard")?;
    let written = write_atomically(dir, &[(SHARD_FILE, bytes)])?;
    Ok(written.into_iter().next().expect("one file"))
}

fn read_shard(dir: &Path) -> Result<ShardFile> {
    let path = dir.join(SHARD_FILE);
    let bytes = std::fs::read(&path).with_context(|| format!("cannot read {}", path.display()))?;
    let file: ShardFile =
        postcard::from_bytes(&bytes).with_context(|| format!("{} is not a smithwalk shard file", path.display()))?;
    ensure!(file.format == FORMAT, "{}: format {:?}, expected {FORMAT:?}", path.display(), file.format);
    Ok(file)
}

/// Merges the shards saved in `dirs` into the simulation of the whole run, checking that they
/// come from one config and together cover every share exactly once.
pub fn merge(dirs: &[PathBuf]) -> Result<(Config, Simulation)> {
    ensure!(!dirs.is_empty(), "merge needs at least one shard directory");
    let files = dirs.iter().map(|d| read_shard(d)).collect::<Result<Vec<_>>>()?;
    let first = &files[0];
    let count = first.shard.count;
    let mut seen = vec![false; count as usize];
    for (file, dir) in files.iter().zip(dirs) {
        if file.config_toml != first.config_toml || file.version != first.version {
            bail!("{}: shard of a different config or smithwalk version than {}", dir.display(), dirs[0].display());
        }
        if file.shard.count != count {
            bail!("{}: shard {}/{} does not match {} shards", dir.display(), file.shard.index, file.shard.count, count);
        }
        let slot = &mut seen[file.shard.index as usize];
        ensure!(!*slot, "{}: shard {}/{count} given twice", dir.display(), file.shard.index);
        *slot = true;
    }
    let missing: Vec<String> =
        seen.iter().enumerate().filter(|(_, s)| !**s).map(|(i, _)| format!("{i}/{count}")).collect();
    ensure!(missing.is_empty(), "missing shards: {}", missing.join(", "));
    let config = Config::parse(&first.config_toml).context("the shards' config")?;
    let cases = expand(&config);
    let grid = Grid { cos_bins: config.detector.cos_theta_bins, phi_bins: config.detector.phi_bins };
    let max_order = config.detector.max_order;
    let mut results = Vec::with_capacity(cases.len());
    for (i, case) in cases.iter().enumerate() {
        let wi = case.incident_direction();
        let result = match &first.tallies[i] {
            CaseTallies::Mono(_) => {
                CaseResult::Mono(Box::new(merged(grid, wi, max_order, &files, i, CaseTallies::mono)?))
            }
            CaseTallies::Rgb(_) => CaseResult::Rgb(Box::new(merged(grid, wi, max_order, &files, i, CaseTallies::rgb)?)),
        };
        results.push(result);
    }
    let sim = Simulation {
        cases,
        results,
        rgb: config.is_rgb(),
        threads: files.iter().map(|f| f.threads).sum(),
        wall_seconds: files.iter().map(|f| f.wall_seconds).fold(0.0, f64::max),
    };
    Ok((config, sim))
}
