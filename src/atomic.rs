//! Files written whole or not at all: every file goes to a temporary file in its directory,
//! and only when all are complete are they renamed into place.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

/// Makes sure `dir` exists and is writable, before any simulation time is spent.
pub fn prepare_dir(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir)
        .with_context(|| format!("--out {}: cannot create the output directory", dir.display()))?;
    tempfile::NamedTempFile::new_in(dir)
        .with_context(|| format!("--out {}: the output directory is not writable", dir.display()))?;
    Ok(())
}

/// Writes one file at the path `out` (whose directory is created if need be) atomically.
pub fn write_file_atomically(out: &Path, bytes: Vec<u8>) -> Result<PathBuf> {
    let dir = match out.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let name = out.file_name().and_then(|n| n.to_str()).context("--out needs a file name")?;
    prepare_dir(dir)?;
    let written = write_atomically(dir, &[(name, bytes)])?;
    Ok(written.into_iter().next().expect("one file"))
}

/// Writes all files: every one goes to a temporary file first; only when all are complete are
/// they renamed into place, so a failure leaves no partial or corrupt output.
pub fn write_atomically(dir: &Path, files: &[(&str, Vec<u8>)]) -> Result<Vec<PathBuf>> {
    let mut staged = Vec::new();
    for (file, bytes) in files {
        let mut tmp = tempfile::NamedTempFile::new_in(dir)
            .with_context(|| format!("cannot create a temporary file in {}", dir.display()))?;
        tmp.write_all(bytes).with_context(|| format!("cannot write {file}"))?;
        make_readable(tmp.as_file()).with_context(|| format!("cannot set the permissions of {file}"))?;
        tmp.as_file().sync_all().with_context(|| format!("cannot write {file}"))?;
        staged.push((tmp, dir.join(file)));
    }
    let mut written = Vec::new();
    for (tmp, path) in staged {
        tmp.persist(&path).with_context(|| format!("cannot rename into {}", path.display()))?;
        written.push(path);
    }
    Ok(written)
}

/// Output files are ordinary readable files (temporary files start private).
#[cfg(unix)]
fn make_readable(file: &std::fs::File) -> std::io::Result<()> {
    use std::os::unix::fs::PermissionsExt;
    file.set_permissions(std::fs::Permissions::from_mode(0o644))
}

#[cfg(not(unix))]
fn make_readable(_file: &std::fs::File) -> std::io::Result<()> {
    Ok(())
}
