//! Files written whole or not at all: every file goes to a temporary file in its directory,
//! and only when all are complete are they renamed into place. Directories in use are locked
//! ([`lock_dir`]), and the temporary files a killed process left are removed by the next one.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

/// Makes sure `dir` exists and is writable, before any simulation time is spent. Errors name
/// the directory, not the command-line option that gave it (the Python package calls this too).
pub fn prepare_dir(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create the output directory {}", dir.display()))?;
    temp_file(dir).with_context(|| format!("the output directory {} is not writable", dir.display()))?;
    Ok(())
}

/// Temporary files start with this prefix, so that leftovers of a killed run can be told apart.
pub const TEMP_PREFIX: &str = ".smithwalk-tmp-";

/// The advisory lock file of a directory in use.
pub const LOCK_FILE: &str = ".smithwalk.lock";

/// An advisory lock on a directory, held until dropped (or the process ends, however it ends).
#[derive(Debug)]
pub struct DirLock {
    _file: Option<std::fs::File>,
}

/// Locks `dir` (which must exist): exclusively for a process that writes a run into it, shared
/// for one that reads a finished run. A run then removes the temporary files a killed process
/// left there: while it holds the exclusive lock, no other smithwalk writes into `dir`.
/// A reader of a directory without a lock file (not written by `run`, or read-only) reads it
/// without a lock.
pub fn lock_dir(dir: &Path, exclusive: bool) -> Result<DirLock> {
    let path = dir.join(LOCK_FILE);
    // A reader writes nothing: without a lock file, no run has locked the directory.
    let file =
        match std::fs::OpenOptions::new().read(true).write(exclusive).create(exclusive).truncate(false).open(&path) {
            Ok(f) => f,
            Err(_) if !exclusive => return Ok(DirLock { _file: None }),
            Err(e) => return Err(e).with_context(|| format!("cannot create the lock file {}", path.display())),
        };
    let locked = if exclusive { file.try_lock() } else { file.try_lock_shared() };
    match locked {
        Ok(()) => {}
        Err(std::fs::TryLockError::WouldBlock) if exclusive => anyhow::bail!(
            "{} is in use by another smithwalk process (it holds {LOCK_FILE}); wait for it to finish or choose \
             another output directory",
            dir.display()
        ),
        Err(std::fs::TryLockError::WouldBlock) => {
            anyhow::bail!("{} is being written by a smithwalk run; wait for it to finish", dir.display())
        }
        Err(std::fs::TryLockError::Error(e)) => {
            return Err(e).with_context(|| format!("cannot lock {}", path.display()));
        }
    }
    if exclusive {
        remove_leftovers(dir)?;
    }
    Ok(DirLock { _file: Some(file) })
}

/// Removes the temporary files of killed processes from `dir`.
fn remove_leftovers(dir: &Path) -> Result<()> {
    let entries = std::fs::read_dir(dir).with_context(|| format!("cannot list {}", dir.display()))?;
    for entry in entries.flatten() {
        if entry.file_name().to_string_lossy().starts_with(TEMP_PREFIX) {
            let path = entry.path();
            std::fs::remove_file(&path).with_context(|| format!("cannot remove the leftover {}", path.display()))?;
        }
    }
    Ok(())
}

/// Writes one file at the path `out` (whose directory is created if need be) atomically.
pub fn write_file_atomically(out: &Path, bytes: Vec<u8>) -> Result<PathBuf> {
    let dir = match out.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let name = out
        .file_name()
        .and_then(|n| n.to_str())
        .with_context(|| format!("the output {} needs a file name", out.display()))?;
    // Checked before the directory is prepared, so that nothing is written beside a device.
    refuse_special(out)?;
    prepare_dir(dir)?;
    let written = write_atomically(dir, &[(name, bytes)])?;
    Ok(written.into_iter().next().expect("one file"))
}

/// Writes all files: every one goes to a temporary file first; only when all are complete are
/// they renamed into place, so a failure leaves no partial or corrupt output.
pub fn write_atomically(dir: &Path, files: &[(&str, Vec<u8>)]) -> Result<Vec<PathBuf>> {
    for (file, _) in files {
        refuse_special(&dir.join(file))?;
    }
    let mut staged = Vec::new();
    for (file, bytes) in files {
        let mut tmp = temp_file(dir).with_context(|| format!("cannot create a temporary file in {}", dir.display()))?;
        tmp.write_all(bytes).with_context(|| format!("cannot write {file}"))?;
        make_readable(tmp.as_file()).with_context(|| format!("cannot set the permissions of {file}"))?;
        tmp.as_file().sync_all().with_context(|| format!("cannot write {file}"))?;
        staged.push((tmp, dir.join(file)));
    }
    let mut written = Vec::new();
    for (tmp, path) in staged {
        // Checked again just before the rename, which would replace whatever is there.
        refuse_special(&path)?;
        tmp.persist(&path).with_context(|| format!("cannot rename into {}", path.display()))?;
        written.push(path);
    }
    Ok(written)
}

/// Refuses an output path that exists and is not a regular file (a device, FIFO, socket or
/// directory, followed through symbolic links): the rename would replace it with a regular
/// file (as root, `--out /dev/null` turned the host's `/dev/null` into one).
fn refuse_special(path: &Path) -> Result<()> {
    let Ok(meta) = std::fs::metadata(path) else { return Ok(()) };
    if meta.is_file() {
        return Ok(());
    }
    anyhow::bail!(
        "the output {} is {}, not a regular file; smithwalk writes only regular files: choose another path",
        path.display(),
        kind_of(&meta.file_type())
    )
}

/// The kind of a file that is not a regular file, in words.
#[cfg(unix)]
fn kind_of(t: &std::fs::FileType) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    if t.is_dir() {
        "a directory"
    } else if t.is_fifo() {
        "a FIFO"
    } else if t.is_socket() {
        "a socket"
    } else if t.is_block_device() || t.is_char_device() {
        "a device"
    } else {
        "a special file"
    }
}

#[cfg(not(unix))]
fn kind_of(t: &std::fs::FileType) -> &'static str {
    if t.is_dir() { "a directory" } else { "a special file" }
}

fn temp_file(dir: &Path) -> std::io::Result<tempfile::NamedTempFile> {
    tempfile::Builder::new().prefix(TEMP_PREFIX).tempfile_in(dir)
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

#[cfg(test)]
mod tests {
    /// An output directory that is an existing file is refused by its path, in words that fit
    /// the command line and the Python package alike (it named `--out` to Python users).
    #[test]
    fn an_output_directory_that_is_a_file_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("taken");
        std::fs::write(&file, "x").unwrap();
        let e = format!("{:#}", super::prepare_dir(&file).unwrap_err());
        assert!(e.starts_with(&format!("cannot create the output directory {}: ", file.display())), "{e}");
        assert!(!e.contains("--out"), "{e}");
    }

    /// Issue 36 item 1: an output path that is a FIFO or a directory is refused with one line
    /// naming it, and left as it was (the rename used to replace it by a regular file).
    #[cfg(unix)]
    #[test]
    fn an_output_that_is_not_a_regular_file_is_refused() {
        use std::os::unix::fs::FileTypeExt;
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("pipe");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status().unwrap();
        assert!(made.success());
        let e = format!("{:#}", super::write_file_atomically(&fifo, b"x".to_vec()).unwrap_err());
        assert!(e.contains("is a FIFO, not a regular file"), "{e}");
        assert!(std::fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo());

        let sub = dir.path().join("sub");
        std::fs::create_dir(&sub).unwrap();
        let e = format!("{:#}", super::write_atomically(dir.path(), &[("sub", b"x".to_vec())]).unwrap_err());
        assert!(e.contains("is a directory, not a regular file"), "{e}");
        assert!(sub.is_dir());
        // Nothing was staged: no temporary file is left behind.
        let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(names.len(), 2, "{names:?}");

        // A device is refused before anything is written, even into /dev.
        let e = format!("{:#}", super::write_file_atomically(std::path::Path::new("/dev/null"), vec![]).unwrap_err());
        assert!(e.contains("/dev/null is a device, not a regular file"), "{e}");
        assert!(std::fs::metadata("/dev/null").unwrap().file_type().is_char_device());
    }
}
