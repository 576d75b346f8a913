//! `smithwalk merge`: the shards of a run combined into the run's tables.

use std::path::{Path, PathBuf};

use anyhow::Result;

use crate::atomic::{lock_dir, prepare_dir};
use crate::commands::summary::report;

/// `smithwalk merge`: merges the shard.bin files of `shards`, writes the run's outputs into
/// `out` and prints its summary.
pub fn merge(shards: &[PathBuf], out: &Path) -> Result<()> {
    let (config, sim) = crate::engine::shard::merge(shards)?;
    prepare_dir(out)?;
    let _lock = lock_dir(out, true)?;
    let written = crate::io::output::write_outputs(&sim, &config, out)?;
    report(&sim, &config, &written)
}
