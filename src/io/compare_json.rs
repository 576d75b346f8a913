//! `compare.json`: the seal of the files `compare` derives from a run (docs/run-directory.md).
//!
//! `models.csv` and `compare.csv` are sealed like the run's own tables: `compare.json` records
//! their sizes and SHA-256 digests, the run they belong to (`run.json`'s `run_id`, and the
//! digests of the run's `lobes.csv` and `summary.csv`, which decide: a comparison holds for
//! any run with bit-identical tables, such as the Python package's save of the run it
//! compared) and the settings of the comparison, and ends with the digest of
//! itself. `compare` writes it last, after the two tables, so a comparison killed between the
//! renames leaves tables that the old record does not describe. A reader accepts the tables
//! only when the record matches them and the run beside them ([`verify`]); otherwise it gets
//! one error line, and a CSV reader that knows nothing of the record still reads plain CSV.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{Context, Result, bail};
use serde::{Deserialize, Serialize};

use crate::io::output::{self_digest, sha256_hex};
use crate::io::schema;

/// What `compare` was asked to do, as `compare.json` records it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Settings {
    /// The models, in the order compared (`models.csv` has their columns in this order).
    pub models: Vec<String>,
    /// Photons per case of the Monte Carlo models.
    pub paths: u64,
    /// The run's seed, from which each Monte Carlo model's seed is derived.
    pub seed: u64,
    /// The family-wise level of each model's verdict.
    pub family_level: f64,
    /// `--external`, as given.
    pub external: Option<String>,
    /// `--albedo-table`, as given.
    pub albedo_table: Option<String>,
}

/// A file of the comparison as `compare.json` records it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct FileRecord {
    bytes: u64,
    sha256: String,
}

/// The content of `compare.json` (its fields are declared in [`schema::COMPARE_JSON`]).
#[derive(Serialize, Deserialize)]
struct Record {
    format_version: u32,
    smithwalk_version: String,
    run_id: String,
    run_tables: BTreeMap<String, String>,
    settings: Settings,
    files: BTreeMap<String, FileRecord>,
    /// The SHA-256 of this file's text with these 64 hex digits written as zeros.
    self_sha256: String,
}

/// The run a comparison belongs to: `run.json`'s `run_id` (which names it) and the SHA-256
/// digests of its tables per file name (which decide).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RunIdentity {
    pub run_id: String,
    pub tables: BTreeMap<String, String>,
}

/// The text of `compare.json` for the tables `tables` (file name, bytes: `models.csv` and
/// `compare.csv`) that `compare` derived with `settings` from the run `run`.
pub fn text(run: &RunIdentity, settings: &Settings, tables: &[(&str, &[u8])]) -> Result<Vec<u8>> {
    let record = Record {
        format_version: schema::FORMAT_VERSION,
        smithwalk_version: env!("CARGO_PKG_VERSION").into(),
        run_id: run.run_id.clone(),
        run_tables: run.tables.clone(),
        settings: settings.clone(),
        files: tables
            .iter()
            .map(|(name, bytes)| {
                (name.to_string(), FileRecord { bytes: bytes.len() as u64, sha256: sha256_hex(bytes) })
            })
            .collect(),
        self_sha256: "0".repeat(64),
    };
    let mut text = serde_json::to_vec_pretty(&record)?;
    text.push(b'\n');
    let (range, digest) = self_digest(&text).expect("compare.json ends with its digest");
    text[range].copy_from_slice(digest.as_bytes());
    Ok(text)
}

/// The settings of the comparison in `dir`, once its files are checked to be one sealed set
/// that belongs to the run `run`: `compare.json` is intact (its own digest), of a format this
/// smithwalk reads, records this run, and `models.csv` and `compare.csv` are the files it
/// records. `None` when `dir` holds none of the three (no comparison); one error line
/// otherwise.
pub fn verify(dir: &Path, run: &RunIdentity) -> Result<Option<Settings>> {
    let path = dir.join(schema::COMPARE_JSON.file);
    let tables = [schema::MODELS.file, schema::COMPARE.file];
    let text = match crate::input::read(&path, crate::input::MAX_CONFIG_BYTES) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            let present: Vec<&str> = tables.into_iter().filter(|t| dir.join(t).exists()).collect();
            if present.is_empty() {
                return Ok(None);
            }
            bail!(
                "{}: {} without {} (left by a compare that was killed, or written by a smithwalk before analysis \
                 files were sealed); rerun `smithwalk compare {}`",
                dir.display(),
                present.join(" and "),
                schema::COMPARE_JSON.file,
                dir.display()
            );
        }
        Err(e) => return Err(e).with_context(|| format!("cannot read {}", path.display())),
    };
    let rerun = format!("rerun `smithwalk compare {}`", dir.display());
    match self_digest(&text) {
        Some((range, digest)) if text.get(range.clone()) == Some(digest.as_bytes()) => {}
        _ => bail!("{} is corrupt: its self_sha256 does not match its content; {rerun}", path.display()),
    }
    let record: Record = serde_json::from_slice(&text)
        .with_context(|| format!("{} is not the compare.json of a smithwalk comparison", path.display()))?;
    if record.format_version > schema::FORMAT_VERSION {
        bail!(
            "{}: format_version = {} is not allowed: this smithwalk reads format {} or older; open it with a newer \
             smithwalk",
            path.display(),
            record.format_version,
            schema::FORMAT_VERSION
        );
    }
    if record.run_tables != run.tables {
        bail!(
            "{} belongs to another run (run_id {}; this run is {}, with other tables): its models.csv and \
             compare.csv describe that run; {rerun}",
            path.display(),
            record.run_id,
            run.run_id
        );
    }
    for table in tables {
        let file = dir.join(table);
        let recorded = record.files.get(table).with_context(|| format!("{}: no digest of {table}", path.display()))?;
        let bytes = match crate::input::read(&file, crate::input::MAX_TABLE_BYTES) {
            Ok(bytes) => bytes,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                bail!("{} records {table}, which is missing; {rerun}", path.display())
            }
            Err(e) => return Err(e).with_context(|| format!("cannot read {}", file.display())),
        };
        if sha256_hex(&bytes) != recorded.sha256 {
            bail!(
                "{} is not the {table} that {} records (changed, damaged, copied from another run, or left by a \
                 compare that was killed); {rerun}",
                file.display(),
                path.display()
            );
        }
    }
    Ok(Some(record.settings))
}
