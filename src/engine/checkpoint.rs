//! Checkpoints of long runs: every few seconds a run saves its raw accumulators and how far
//! each case has got, atomically; `run --resume` continues from the last checkpoint. The
//! accumulators are integers and every chunk has its own random stream, so a resumed run's
//! outputs are bit-identical to an uninterrupted run's, wherever it was killed.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, anyhow, ensure};
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

/// Writes files into a directory as one atomic set: [`write_atomically`], or in tests a
/// stand-in that fails as a full disk does.
type WriteFiles = fn(&Path, &[(&str, Vec<u8>)]) -> Result<Vec<PathBuf>>;

/// Writes checkpoints of a run at most every `every`.
pub struct Checkpointer {
    dir: PathBuf,
    every: Duration,
    last: Instant,
    config_toml: String,
    shard: Shard,
    write: WriteFiles,
}

impl Checkpointer {
    pub fn new(dir: &Path, every: Duration, config: &Config, shard: Shard) -> Result<Self> {
        Ok(Self {
            dir: dir.to_path_buf(),
            every,
            last: Instant::now(),
            config_toml: toml::to_string(config).context("cannot serialize the config")?,
            shard,
            write: write_atomically,
        })
    }

    /// The one-line error of a run that could not write `what` into its directory (a full
    /// disk, most often): the cause, and that the last checkpoint is intact and how to continue
    /// from it. A checkpoint is replaced only by a complete one ([`write_atomically`]), so the
    /// last one is the one a failed write leaves.
    pub fn stopped(&self, what: &str, error: &anyhow::Error) -> anyhow::Error {
        let saved = self.dir.join(CHECKPOINT_FILE);
        let fix = if is_disk_full(error) { "free space" } else { "fix that" };
        let resume = if saved.is_file() {
            format!(
                "the last checkpoint, {}, is intact: {fix} and run the same command with --resume to continue from it",
                saved.display()
            )
        } else {
            format!("no checkpoint was written yet: {fix} and run the command again")
        };
        anyhow!("the run stopped: cannot write {what} into {}: {error:#}; {resume}", self.dir.display())
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
        (self.write)(&self.dir, &[(CHECKPOINT_FILE, bytes)]).map_err(|e| self.stopped("a checkpoint", &e))?;
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

/// Whether `error` comes from a full volume or an exhausted quota.
fn is_disk_full(error: &anyhow::Error) -> bool {
    use std::io::ErrorKind::{QuotaExceeded, StorageFull};
    error
        .chain()
        .any(|e| e.downcast_ref::<std::io::Error>().is_some_and(|e| matches!(e.kind(), StorageFull | QuotaExceeded)))
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::resources::DiskEstimate;
    use crate::engine::run::Estimator;
    use crate::engine::{RunOptions, simulate_from};

    /// A full disk: the write fails as `write_atomically` fails on `ENOSPC`, before any rename.
    fn full_disk(_dir: &Path, files: &[(&str, Vec<u8>)]) -> Result<Vec<PathBuf>> {
        let e = std::io::Error::from(std::io::ErrorKind::StorageFull);
        Err(anyhow::Error::new(e).context(format!("cannot write {}", files[0].0)))
    }

    /// Issue 36 item 16: a disk that fills while a run checkpoints leaves the last checkpoint
    /// as it was (it still resumes the run) and stops the run with one line that says so and
    /// how to continue; without a checkpoint yet, the line says that instead. The disk
    /// estimate bounds the checkpoint (and, in `io::output`'s tests, the tables).
    #[test]
    fn a_full_disk_leaves_the_last_checkpoint_intact_and_says_how_to_resume() {
        let config = Config::parse(
            "paths = 40000\nseed = 5\n[surface]\nalpha = 0.5\n[material]\nkind = \"conductor\"\n[incident]\n\
             theta_deg = [20, 70]\n[detector]\ncos_theta_bins = 4\nphi_bins = 8\nmax_order = 3\n",
        )
        .unwrap();
        let dir = tempfile::tempdir().unwrap();
        let options = RunOptions {
            estimator: Estimator::Walk,
            shard: Shard::WHOLE,
            threads: Some(1),
            show_progress: false,
            max_memory: None,
        };
        let run = |checkpoints: &mut Checkpointer| {
            simulate_from(&config, &options, None, &mut |done, current, later| {
                checkpoints.after_round(done, current, later)
            })
        };
        // Without a checkpoint yet.
        let mut failing = Checkpointer {
            write: full_disk,
            ..Checkpointer::new(dir.path(), Duration::ZERO, &config, Shard::WHOLE).unwrap()
        };
        let Err(e) = run(&mut failing) else { panic!("the full disk did not stop the run") };
        let e = format!("{e:#}");
        assert!(!e.contains('\n') && e.contains("no checkpoint was written yet"), "{e}");

        // A checkpoint of every round, then a full disk.
        let mut saving = Checkpointer::new(dir.path(), Duration::ZERO, &config, Shard::WHOLE).unwrap();
        run(&mut saving).unwrap();
        let path = dir.path().join(CHECKPOINT_FILE);
        let last = std::fs::read(&path).unwrap();
        // The disk estimate bounds what the run wrote: the checkpoint, and the tables.
        let estimate = DiskEstimate::of(&config);
        assert!(last.len() as u64 <= estimate.checkpoint_bytes, "{} > {estimate:?}", last.len());
        let Err(e) = run(&mut failing) else { panic!("the full disk did not stop the run") };
        let e = format!("{e:#}");
        assert!(!e.contains('\n'), "{e}");
        for words in ["cannot write a checkpoint into", "is intact: free space", "--resume", "checkpoint.bin"] {
            assert!(e.contains(words), "{words:?} not in: {e}");
        }
        assert_eq!(std::fs::read(&path).unwrap(), last, "the last checkpoint changed");
        assert!(load(dir.path(), &config, Shard::WHOLE).unwrap().is_some(), "the last checkpoint does not resume");
    }
}
