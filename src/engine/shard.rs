//! Runs split across machines: a shard walks every `N`-th chunk of every case and saves its
//! raw accumulators; merging the shards reproduces the unsplit run's `lobes.csv` and
//! `summary.csv` to the bit (the accumulators are integers, §4.6 determinism).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail, ensure};
use serde::{Deserialize, Serialize};

use crate::atomic::write_atomically;
use crate::engine::Simulation;
use crate::engine::detector::{Detector, Grid, Tallies};
use crate::engine::run::{CaseResult, Shard};
use crate::engine::sealed::{Kind, seal, unseal};
use crate::setup::cases::{Case, expand};
use crate::setup::config::Config;

/// The file a shard writes into its output directory.
pub const SHARD_FILE: &str = "shard.bin";

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
        let wi = case.wi;
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

    /// Checks that these tallies fit case `case` of `config` (channels, bins, order slots), so
    /// that a file of another build or a crafted one cannot index out of bounds.
    pub(crate) fn check(&self, config: &Config, case: usize) -> Result<()> {
        fn shape<const C: usize>(t: &Tallies<C>) -> (usize, Vec<usize>) {
            (C, t.orders.iter().map(|o| o.bins.len()).collect())
        }
        let (channels, bins) = match self {
            CaseTallies::Mono(t) => shape(t),
            CaseTallies::Rgb(t) => shape(t),
        };
        let want_channels = if config.is_rgb() { 3 } else { 1 };
        let want_bins = 2 * config.detector.cos_theta_bins * config.detector.phi_bins;
        let max_slots = config.detector.max_order.map_or(usize::MAX, |k| k as usize + 1);
        ensure!(
            channels == want_channels
                && !bins.is_empty()
                && bins.len() <= max_slots
                && bins.iter().all(|&b| b == want_bins),
            "case {case}: the saved tallies do not fit the config ({channels} channels, {} order slots)",
            bins.len()
        );
        Ok(())
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
    version: String,
    config_toml: String,
    shard: Shard,
    threads: usize,
    wall_seconds: f64,
    tallies: Vec<CaseTallies>,
}

/// The bytes of a shard: the accumulators of a shard's simulation with the config and share.
pub fn encode(sim: &Simulation, config: &Config, shard: Shard) -> Result<Vec<u8>> {
    let file = ShardFile {
        version: env!("CARGO_PKG_VERSION").into(),
        config_toml: toml::to_string(config).context("cannot serialize the config")?,
        shard,
        threads: sim.threads,
        wall_seconds: sim.wall_seconds,
        tallies: sim.results.iter().map(CaseTallies::of).collect(),
    };
    Ok(seal(Kind::Shard, &postcard::to_stdvec(&file).context("cannot encode the shard")?))
}

/// Writes the accumulators of a shard's simulation into `dir/shard.bin`, atomically.
pub fn write_shard(sim: &Simulation, config: &Config, shard: Shard, dir: &Path) -> Result<PathBuf> {
    let written = write_atomically(dir, &[(SHARD_FILE, encode(sim, config, shard)?)])?;
    Ok(written.into_iter().next().expect("one file"))
}

/// A shard from its bytes; `origin` names where they came from in errors.
fn decode(bytes: &[u8], origin: &str) -> Result<ShardFile> {
    let payload = unseal(Kind::Shard, bytes, origin)?;
    postcard::from_bytes(payload).with_context(|| format!("{origin} is not a smithwalk shard file"))
}

fn read_shard(dir: &Path) -> Result<ShardFile> {
    let path = dir.join(SHARD_FILE);
    let bytes = std::fs::read(&path).with_context(|| format!("cannot read {}", path.display()))?;
    decode(&bytes, &path.display().to_string())
}

/// Merges the shards saved in `dirs` into the simulation of the whole run, checking that they
/// come from one config and together cover every share exactly once.
pub fn merge(dirs: &[PathBuf]) -> Result<(Config, Simulation)> {
    ensure!(!dirs.is_empty(), "merge needs at least one shard directory");
    let files = dirs.iter().map(|d| read_shard(d)).collect::<Result<Vec<_>>>()?;
    merge_files(&files, &dirs.iter().map(|d| d.display().to_string()).collect::<Vec<_>>())
}

/// Merges the shards given as bytes (with names for errors) into the simulation of the whole
/// run, as [`merge`] does with shard directories.
#[cfg(feature = "mpi")]
pub fn merge_bytes(shards: &[(String, Vec<u8>)]) -> Result<(Config, Simulation)> {
    ensure!(!shards.is_empty(), "merging needs at least one shard");
    let files = shards.iter().map(|(origin, bytes)| decode(bytes, origin)).collect::<Result<Vec<_>>>()?;
    merge_files(&files, &shards.iter().map(|(origin, _)| origin.clone()).collect::<Vec<_>>())
}

/// Merges shards (named `origins` in errors), checking that they come from one config and
/// together cover every share exactly once.
fn merge_files(files: &[ShardFile], origins: &[String]) -> Result<(Config, Simulation)> {
    let first = &files[0];
    let count = first.shard.count;
    // Indexed by the shards given, not by the count a file claims, which may be huge.
    let mut seen = std::collections::BTreeSet::new();
    for (file, origin) in files.iter().zip(origins) {
        if file.config_toml != first.config_toml || file.version != first.version {
            bail!("{origin}: shard of a different config or smithwalk version than {}", origins[0]);
        }
        if file.shard.count != count || file.shard.index >= count {
            bail!("{origin}: shard {}/{} does not match {} shards", file.shard.index, file.shard.count, count);
        }
        ensure!(seen.insert(file.shard.index), "{origin}: shard {}/{count} given twice", file.shard.index);
    }
    if seen.len() as u64 != count {
        let missing: Vec<String> =
            (0..count).filter(|i| !seen.contains(i)).take(8).map(|i| format!("{i}/{count}")).collect();
        let more = if count - seen.len() as u64 > 8 { ", ..." } else { "" };
        bail!("missing shards: {}{more} ({} of {count})", missing.join(", "), count - seen.len() as u64);
    }
    let config = Config::parse(&first.config_toml).context("the shards' config")?;
    let cases = expand(&config)?;
    for (file, origin) in files.iter().zip(origins) {
        ensure!(
            file.tallies.len() == cases.len(),
            "{origin}: {} cases saved, the config has {}",
            file.tallies.len(),
            cases.len()
        );
        for (i, t) in file.tallies.iter().enumerate() {
            t.check(&config, i).with_context(|| origin.clone())?;
        }
    }
    let grid = Grid { cos_bins: config.detector.cos_theta_bins, phi_bins: config.detector.phi_bins };
    let max_order = config.detector.max_order;
    let mut results = Vec::with_capacity(cases.len());
    for (i, case) in cases.iter().enumerate() {
        let wi = case.wi;
        let result = match &first.tallies[i] {
            CaseTallies::Mono(_) => {
                CaseResult::Mono(Box::new(merged(grid, wi, max_order, files, i, CaseTallies::mono)?))
            }
            CaseTallies::Rgb(_) => CaseResult::Rgb(Box::new(merged(grid, wi, max_order, files, i, CaseTallies::rgb)?)),
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
