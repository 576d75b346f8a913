//! `smithwalk lut`: energy-compensation tables measured from a table config.

use std::path::{Path, PathBuf};

use anyhow::Result;

use crate::atomic::prepare_dir;
use crate::commands::options::{check_threads, default_out};
use crate::exports::lut::LutConfig;

/// `smithwalk lut`: builds the tables of the config at `config_path` (with the command line's
/// overrides), writes them into `out` and prints what it wrote.
pub fn lut(config_path: &Path, paths: Option<u64>, threads: Option<usize>, out: Option<PathBuf>) -> Result<()> {
    let mut config = LutConfig::load(config_path)?;
    if let Some(p) = paths {
        // The file is valid (`load` checked it), so an error now is the option's.
        config.table.paths = p;
        config.validate().map_err(|e| e.from_option("--paths"))?;
    }
    check_threads(threads)?;
    let out = out.unwrap_or_else(|| default_out(config_path));
    prepare_dir(&out)?;
    let lut = crate::exports::lut::build(&config, threads, true)?;
    let written = crate::exports::lut::write(&lut, &out)?;
    let worst = lut.tables.iter().flat_map(|t| t.e_stderr.iter()).fold(0.0_f64, |a, &b| a.max(b));
    println!(
        "{} cells, {} photons in {:.2} s; largest standard error {worst:.2e}",
        lut.photons.len(),
        lut.photons.iter().sum::<u64>(),
        lut.wall_seconds
    );
    for path in written {
        println!("wrote {}", path.display());
    }
    Ok(())
}
