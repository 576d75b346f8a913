//! Checkpoints of long runs: every few seconds a run saves its raw accumulators and how far
//! each case has got, atomically; `run --resume` continues from the last checkpoint. The
//! accumulators are integers and every chunk has its own random stream, so a resumed run's
//! outputs are bit-identical to an uninterrupted run's, wherever it was killed.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, ensure};
use serde::{Deserialize, Serialize};

use crate::atomic::write_atomically;
use crate::engine::run::{CaseState, RunSettings, Shard};
use crate::engine::sealed::{Kind, seal, unseal};
use crate::engine::shard::CaseTallies;
use crate::setup::cases::expand;
use crate::setup::config::Config;

/// The file a run keeps its checkpoint in, inside its output directory.
pub const CHECKPOINT_FILE: &str = "checkpoint.bin";

#[derive(Serialize, Deserialize)]
struct SavedState {
    tallies: CaseTallies,
    rounds_done: u64,
    finished: bool,
}

#[derive(Serialize, Deserialize)]
struct CheckpointFile {
    version: String,
    config_toml: String,
    shard: Shard,
    states: Vec<SavedState>,
}

/// Writes checkpoints of a run at most every `every`.
pub struct Checkpointer {
    dir: PathBuf,
    every: Duration,
    last: Instant,
    config_toml: String,
    shard: Shard,
}

impl Checkpointer {
    pub fn new(dir: &Path, every: Duration, config: &Config, shard: Shard) -> Result<Self> {
        Ok(Self {
            dir: dir.to_path_buf(),
            every,
            last: Instant::now(),
            config_toml: toml::to_string(config).context("cannot serialize the config")?,
            shard,
        })
    }

    /// Saves the state of every case if the last checkpoint is older than the interval.
    pub fn after_round(&mut self, done: &[CaseState], current: &CaseState, later: &[CaseState]) -> Result<()> {
        if self.last.elapsed() < self.every {
            return Ok(());
        }
        let states = done
            .iter()
            .chain(std::iter::once(current))
            .chain(later)
            .map(|s| SavedState {
                tallies: CaseTallies::of(&s.result),
                rounds_done: s.rounds_done,
                finished: s.finished,
            })
            .collect();
        let file = CheckpointFile {
            version: env!("CARGO_PKG_VERSION").into(),
            config_toml: self.config_toml.clone(),
            shard: self.shard,
            states,
        };
        let bytes = seal(Kind::Checkpoint, &postcard::to_stdvec(&file).context("cannot encode the checkpoint")?);
        write_atomically(&self.dir, &[(CHECKPOINT_FILE, bytes)])?;
        self.last = Instant::now();
        Ok(())
    }

    /// Removes the checkpoint once the run's outputs are written.
    pub fn finish(&self) -> Result<()> {
        match std::fs::remove_file(self.dir.join(CHECKPOINT_FILE)) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(e).context("cannot remove the checkpoint"),
            _ => Ok(()),
        }
    }
}

/// The case states saved in `dir` for this config and shard, or `None` if there is no
/// checkpoint. A checkpoint of another config, shard or version is an error.
pub fn load(dir: &Path, config: &Config, shard: Shard) -> Result<Option<Vec<CaseState>>> {
    let path = dir.join(CHECKPOINT_FILE);
    let bytes = match std::fs::read(&path) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(e).with_context(|| format!("cannot read {}", path.display())),
    };
    let origin = path.display().to_string();
    let file: CheckpointFile = postcard::from_bytes(unseal(Kind::Checkpoint, &bytes, &origin)?)
        .with_context(|| format!("{origin} is not a smithwalk checkpoint"))?;
    ensure!(file.version == env!("CARGO_PKG_VERSION"), "{}: written by another smithwalk version", path.display());
    ensure!(
        file.config_toml == toml::to_string(config)? && file.shard == shard,
        "{}: the checkpoint belongs to another config, seed, path count or shard; remove it or run without --resume",
        path.display()
    );
    let cases = expand(config)?;
    ensure!(file.states.len() == cases.len(), "{}: case count differs", path.display());
    let rounds = RunSettings { shard, ..RunSettings::from_config(config) }.rounds();
    for (i, s) in file.states.iter().enumerate() {
        s.tallies.check(config, i).with_context(|| origin.clone())?;
        ensure!(s.rounds_done <= rounds, "{origin}: case {i} has {} rounds done of {rounds}", s.rounds_done);
    }
    Ok(Some(
        file.states
            .into_iter()
            .zip(&cases)
            .map(|(s, case)| CaseState {
                result: s.tallies.into_result(case, config),
                rounds_done: s.rounds_done,
                finished: s.finished,
            })
            .collect(),
    ))
}
