//! Checks and defaults of the options that several commands share.

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};

/// `--threads`, when given, must be at least 1.
pub fn check_threads(threads: Option<usize>) -> Result<()> {
    if threads == Some(0) {
        bail!("`--threads` = 0 is not allowed: at least 1 thread");
    }
    Ok(())
}

/// A note when `--threads` asks for many more threads than cores: allowed (outputs do not
/// depend on it), but it only adds overhead.
pub fn note_threads(threads: Option<usize>) {
    let cores = std::thread::available_parallelism().map_or(1, usize::from);
    if let Some(n) = threads
        && n > 8 * cores
    {
        eprintln!(
            "note: --threads {n} on {cores} cores: outputs are the same, more threads than cores only add overhead"
        );
    }
}

/// The output directory when `--out` is not given: `out/<config file stem>`.
pub fn default_out(config_path: &Path) -> PathBuf {
    PathBuf::from("out").join(config_path.file_stem().map_or("run".into(), |s| s.to_string_lossy().into_owned()))
}
