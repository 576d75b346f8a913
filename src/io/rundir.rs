//! Reading a run directory back: the resolved config in `run.json` and the tables
//! `lobes.csv`, `summary.csv` and (after `compare`) `models.csv`, for the commands that work
//! on finished runs (`compare`, `plot`, `merl`, `rgl`).
//!
//! A run directory is validated before any of it is used ([`RunDir::open`]): the tables must be
//! the ones `run.json` records (SHA-256 digests: nothing changed them, and they belong to the
//! same run), complete (every case, order slot, hemisphere, channel and bin exactly once) and
//! finite, with non-negative energies. `models.csv` and `compare.csv`, when a command reads them,
//! must be the ones `compare.json` records for this run (`io::compare_json`), and `models.csv`
//! must hold the rows of `lobes.csv` in the same order (the same key columns), with finite non-negative values.
//! Otherwise the reader gets one error and writes nothing.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use serde::Deserialize;

use crate::atomic::{DirLock, lock_dir};
use crate::engine::detector::Grid;
use crate::input;
use crate::io::compare_json::{self, RunIdentity, Settings};
use crate::io::output::{TABLES, self_digest, sha256_hex};
use crate::io::schema::{self, Column};
use crate::setup::cases::Case;
use crate::setup::config::Config;

/// A CSV table of a run directory, read whole, with its columns found by name.
pub(crate) struct Table {
    pub path: PathBuf,
    pub headers: csv::StringRecord,
    pub records: Vec<csv::StringRecord>,
}

impl Table {
    /// Reads the table at `path`, refusing a file of more than `limit` bytes.
    pub fn read(path: &Path, limit: u64) -> Result<Self> {
        let cannot_read = || format!("cannot read {}", path.display());
        let mut reader = csv::Reader::from_reader(input::open(path, limit).with_context(cannot_read)?);
        let headers = reader.headers().with_context(cannot_read)?.clone();
        let records = reader.records().collect::<Result<Vec<_>, _>>().with_context(cannot_read)?;
        Ok(Self { path: path.to_path_buf(), headers, records })
    }

    /// The index of `column`, which the table must have.
    pub fn column(&self, column: Column) -> Result<usize> {
        self.optional(column).with_context(|| format!("{}: no column {}", self.path.display(), column.name))
    }

    /// The index of `column`, if the table has it.
    pub fn optional(&self, column: Column) -> Option<usize> {
        self.headers.iter().position(|h| h == column.name)
    }
}

/// The resolved, validated config of a finished run, from its `run.json`, once the whole run
/// directory is validated ([`RunDir::open`]).
pub fn read_config(run_dir: &Path) -> Result<Config> {
    Ok(RunDir::open(run_dir)?.config)
}

/// What `run.json` says of the run beyond its config.
#[derive(Deserialize)]
struct RunJson {
    /// Absent in run directories written before the format had a version (those are format 1).
    #[serde(default)]
    format_version: Option<u32>,
    config: Config,
    /// Absent in run directories written before runs had an identifier.
    #[serde(default)]
    run_id: String,
    #[serde(default)]
    files: Option<HashMap<String, FileRecord>>,
    cases: Vec<CaseJson>,
}

#[derive(Deserialize)]
struct FileRecord {
    /// The table's size, which bounds what is read of it ([`input::bins_table_limit`]).
    #[serde(default)]
    bytes: u64,
    sha256: String,
}

#[derive(Deserialize)]
struct CaseJson {
    energy: EnergyJson,
}

#[derive(Deserialize)]
struct EnergyJson {
    highest_order: usize,
}

/// The shape of a run's tables: which rows `lobes.csv` and `summary.csv` must hold.
struct Shape<'a> {
    cases: &'a [Case],
    /// Order slots per case.
    slots: Vec<usize>,
    channels: usize,
    grid: Grid,
    /// The most bytes read of one of the run's tables.
    table_limit: u64,
}

impl Shape<'_> {
    fn hemispheres(&self, case: usize) -> usize {
        if self.cases[case].material.transmits() { 2 } else { 1 }
    }

    /// The first row of each case in `table` when case `i` has `rows(hemispheres, slots)`
    /// rows, and a mark per row, once the table is checked to have them all.
    fn rows(&self, table: &Table, rows: impl Fn(usize, usize) -> usize) -> Result<(Vec<usize>, Vec<bool>)> {
        let mut offsets = Vec::with_capacity(self.slots.len());
        let mut total = 0usize;
        for (i, &slots) in self.slots.iter().enumerate() {
            offsets.push(total);
            // Saturating: a forged run.json may claim any number of slots.
            total = total.saturating_add(rows(self.hemispheres(i), slots));
        }
        if table.records.len() != total {
            bail!("{} has {} rows, but the run in run.json has {total}", table.path.display(), table.records.len());
        }
        Ok((offsets, vec![false; total]))
    }

    /// The case of a row and its number of order slots.
    fn case_of(&self, r: &csv::StringRecord, column: usize, at: &dyn Fn() -> String) -> Result<(usize, usize)> {
        let case = index(r, column, "case", at)?;
        let slots = self.slots.get(case).with_context(|| format!("{}: case {case} is not a case of the run", at()))?;
        Ok((case, *slots))
    }
}

/// `run.json` of `dir`, checked against the tables beside it, and the run's identity.
fn read_run_json(dir: &Path) -> Result<(RunJson, RunIdentity)> {
    let path = dir.join(schema::RUN_JSON);
    let text = input::read_to_string(&path, input::MAX_RUN_JSON_BYTES)
        .with_context(|| format!("cannot read {}", path.display()))?;
    match self_digest(text.as_bytes()) {
        Some((range, digest)) if text.get(range.clone()) == Some(digest.as_str()) => {}
        Some(_) => bail!("{} is corrupt: its self_sha256 does not match its content; rerun the config", path.display()),
        None => bail!(
            "{}: no self_sha256 (not written by this smithwalk, or written before run directories were sealed); \
             rerun the config",
            path.display()
        ),
    }
    let run: RunJson = serde_json::from_str(&text)
        .with_context(|| format!("{} is not the run.json of a finished smithwalk run", path.display()))?;
    if let Some(version) = run.format_version.filter(|&v| v > schema::FORMAT_VERSION) {
        bail!(
            "{}: format_version = {version} is not allowed: this smithwalk reads run directories of format {} or \
             older (docs/run-directory.md); open it with a newer smithwalk",
            path.display(),
            schema::FORMAT_VERSION
        );
    }
    run.config.validate().with_context(|| format!("{}: the run's config", path.display()))?;
    let Some(files) = &run.files else {
        bail!(
            "{}: no digests of the tables (written by a smithwalk before 0.1 with digests); rerun the config",
            path.display()
        )
    };
    for table in TABLES {
        let file = dir.join(table);
        let recorded = files.get(table).with_context(|| format!("{}: no digest of {table}", path.display()))?;
        let bytes = input::read(&file, input::bins_table_limit(recorded.bytes))
            .with_context(|| format!("cannot read {}", file.display()))?;
        if sha256_hex(&bytes) != recorded.sha256 {
            bail!(
                "{} is not the {table} that {} records (changed, damaged, or from an interrupted or other run); \
                 rerun the config into this directory",
                file.display(),
                path.display()
            );
        }
    }
    let tables = TABLES.iter().map(|t| (t.to_string(), files[*t].sha256.clone())).collect();
    let identity = RunIdentity { run_id: run.run_id.clone(), tables };
    Ok((run, identity))
}

/// The value of column `column` of a row as a number that must be finite (and >= 0 if
/// `non_negative`); `at` names the row in errors.
fn number(
    record: &csv::StringRecord,
    column: usize,
    name: &str,
    non_negative: bool,
    at: &dyn Fn() -> String,
) -> Result<f64> {
    let text = record.get(column).unwrap_or("");
    let v: f64 = text.trim().parse().map_err(|_| anyhow::anyhow!("{}: {name} = {text:?} is not a number", at()))?;
    if !v.is_finite() || (non_negative && v < 0.0) {
        let allowed = if non_negative { "a finite number >= 0" } else { "a finite number" };
        bail!("{}: {name} = {v} is not allowed: {allowed}", at());
    }
    Ok(v)
}

fn index(record: &csv::StringRecord, column: usize, name: &str, at: &dyn Fn() -> String) -> Result<usize> {
    let text = record.get(column).unwrap_or("");
    text.trim().parse().map_err(|_| anyhow::anyhow!("{}: {name} = {text:?} is not an index", at()))
}

/// Marks `key` (of `total`) as seen, refusing a duplicate.
fn mark(seen: &mut [bool], key: usize, at: &dyn Fn() -> String) -> Result<()> {
    let slot = seen.get_mut(key).with_context(|| format!("{}: not a row of this run", at()))?;
    if std::mem::replace(slot, true) {
        bail!("{}: the same row twice", at());
    }
    Ok(())
}

fn channel_of(
    record: &csv::StringRecord,
    column: Option<usize>,
    channels: usize,
    at: &dyn Fn() -> String,
) -> Result<usize> {
    match (column, channels) {
        (None, 1) => Ok(0),
        (Some(c), 3) => match record.get(c) {
            Some("r") => Ok(0),
            Some("g") => Ok(1),
            Some("b") => Ok(2),
            other => bail!("{}: channel = {other:?} is not r, g or b", at()),
        },
        _ => bail!("{}: the channel column does not fit a run with {channels} channel(s)", at()),
    }
}

fn hemisphere_of(text: Option<&str>, hemispheres: usize, at: &dyn Fn() -> String) -> Result<usize> {
    match (text, hemispheres) {
        (Some("R"), _) => Ok(0),
        (Some("T"), 2) => Ok(1),
        (other, _) => bail!("{}: hemisphere = {other:?} is not one of this case's", at()),
    }
}

/// Reports the first missing row of a table, if any.
fn complete(seen: &[bool], path: &Path, describe: impl Fn(usize) -> String) -> Result<()> {
    let missing = seen.iter().filter(|s| !**s).count();
    if let Some(first) = seen.iter().position(|s| !*s) {
        bail!(
            "{} is incomplete: {missing} of {} rows missing (the first: {})",
            path.display(),
            seen.len(),
            describe(first)
        );
    }
    Ok(())
}

/// The key columns of a table with one row per bin of the run (`lobes.csv`, `models.csv`),
/// found by name.
struct BinKeys {
    case: usize,
    order: usize,
    hemisphere: usize,
    channel: Option<usize>,
    cos_lo: usize,
    cos_hi: usize,
    phi_lo: usize,
}

/// Where a row of a bin table belongs: its position in the run's order (case, slot,
/// hemisphere, bin, channel: the order of `lobes.csv`), its lobe and its bin in the lobe.
struct BinKey {
    row: usize,
    lobe: LobeId,
    cos_index: usize,
    bin: usize,
}

impl BinKeys {
    fn of(table: &Table) -> Result<Self> {
        Ok(Self {
            case: table.column(schema::CASE)?,
            order: table.column(schema::ORDER)?,
            hemisphere: table.column(schema::HEMISPHERE)?,
            channel: table.optional(schema::CHANNEL),
            cos_lo: table.column(schema::COS_LO)?,
            cos_hi: table.column(schema::COS_HI)?,
            phi_lo: table.column(schema::PHI_LO_DEG)?,
        })
    }

    /// The key of row `r`, given the first row of each case (`offsets`); an error if it is
    /// not a bin of the run.
    fn key(&self, r: &csv::StringRecord, shape: &Shape, offsets: &[usize], at: &dyn Fn() -> String) -> Result<BinKey> {
        let (case, slots) = shape.case_of(r, self.case, at)?;
        let order = index(r, self.order, "order", at)?;
        if order >= slots {
            bail!("{}: order {order} is not a slot of case {case} ({slots} slots)", at());
        }
        let hemispheres = shape.hemispheres(case);
        let h = hemisphere_of(r.get(self.hemisphere), hemispheres, at)?;
        let (grid, channels) = (shape.grid, shape.channels);
        let c = channel_of(r, self.channel, channels, at)?;
        let (lo, hi, phi) = (
            number(r, self.cos_lo, "cos_lo", false, at)?,
            number(r, self.cos_hi, "cos_hi", false, at)?,
            number(r, self.phi_lo, "phi_lo_deg", false, at)?,
        );
        let (ic, ip) = bin_of(grid, lo, hi, phi).with_context(|| format!("{}: a bin outside the run's grid", at()))?;
        let bin = ic * grid.phi_bins + ip;
        Ok(BinKey {
            row: offsets[case] + ((order * hemispheres + h) * grid.bins() + bin) * channels + c,
            lobe: (case, order, ["R", "T"][h].to_string(), c),
            cos_index: ic,
            bin,
        })
    }
}

/// Rows of `lobes.csv` of a case with `hemispheres` hemispheres and `slots` order slots.
fn lobe_rows(shape: &Shape, hemispheres: usize, slots: usize) -> usize {
    slots.saturating_mul(hemispheres * shape.grid.bins() * shape.channels)
}

/// Reads the measured lobes of `lobes.csv` once it is checked to have every case, slot,
/// hemisphere, channel and bin exactly once, with finite non-negative energies and BSDF
/// values. Columns are found by name; others are allowed.
fn read_lobes(path: &Path, shape: &Shape) -> Result<Lobes> {
    let table = Table::read(path, shape.table_limit)?;
    let keys = BinKeys::of(&table)?;
    let [energy, energy_stderr, bsdf, bsdf_stderr] =
        [schema::ENERGY, schema::ENERGY_STDERR, schema::BSDF, schema::BSDF_STDERR]
            .map(|c| table.column(c).map(|i| (c, i)));
    let values = [energy?, energy_stderr?, bsdf?, bsdf_stderr?];
    let (offsets, mut seen) = shape.rows(&table, |hemispheres, slots| lobe_rows(shape, hemispheres, slots))?;
    let mut out = Lobes::default();
    for (line, r) in table.records.iter().enumerate() {
        let at = || format!("{} line {}", path.display(), line + 2);
        let key = keys.key(r, shape, &offsets, &at)?;
        let [energy, energy_stderr, bsdf, bsdf_stderr] = values.map(|(c, i)| number(r, i, c.name, true, &at));
        let bins = out.lobes.entry(key.lobe).or_insert_with(|| vec![BinValue::default(); shape.grid.bins()]);
        bins[key.bin] =
            BinValue { energy: energy?, energy_stderr: energy_stderr?, bsdf: bsdf?, bsdf_stderr: bsdf_stderr? };
        mark(&mut seen, key.row, &at)?;
    }
    complete(&seen, path, |k| format!("row {k} in the run's order"))?;
    Ok(out)
}

/// The models of `models.csv`: each column `<name>` with a column `<name>_stderr`
/// ([`schema::MODELS`]), as `(name, energy column, standard error column)` in the order of the
/// header.
fn model_columns(headers: &csv::StringRecord) -> Vec<(String, usize, usize)> {
    headers
        .iter()
        .enumerate()
        .filter_map(|(i, name)| {
            let stderr = format!("{name}{}", schema::STDERR_SUFFIX);
            headers.iter().position(|h| h == stderr).map(|j| (name.to_string(), i, j))
        })
        .collect()
}

/// Reads `models.csv` into lobes per model, once it is checked to have the columns of the
/// models `recorded` (in their order) and to hold the rows of `lobes.csv` in their order (by their key columns), each model's cells both empty (the model gives no
/// such lobe) or both finite and non-negative. A model's BSDF is its energy over the bin's
/// projected solid angle, as in `lobes.csv`.
fn read_models(path: &Path, shape: &Shape, recorded: &[String]) -> Result<HashMap<String, Lobes>> {
    let table = Table::read(path, shape.table_limit)?;
    let keys = BinKeys::of(&table)?;
    let models = model_columns(&table.headers);
    let names: Vec<&str> = models.iter().map(|(name, ..)| name.as_str()).collect();
    if names != recorded {
        bail!(
            "{}: its models ({}) are not the ones {} records ({}); rerun `smithwalk compare`",
            path.display(),
            names.join(", "),
            schema::COMPARE_JSON.file,
            recorded.join(", ")
        );
    }
    let (offsets, _) = shape.rows(&table, |hemispheres, slots| lobe_rows(shape, hemispheres, slots))?;
    let mut out: HashMap<String, Lobes> = HashMap::new();
    for (line, r) in table.records.iter().enumerate() {
        let at = || format!("{} line {}", path.display(), line + 2);
        let key = keys.key(r, shape, &offsets, &at)?;
        if key.row != line {
            bail!(
                "{}: not the bin of lobes.csv's line {} (models.csv has the rows of lobes.csv, in its order)",
                at(),
                line + 2
            );
        }
        let projected = shape.grid.projected_solid_angle(key.cos_index);
        for (name, energy_c, stderr_c) in &models {
            match (r.get(*energy_c), r.get(*stderr_c)) {
                (Some(""), Some("")) => continue,
                (Some(""), _) | (_, Some("")) => {
                    bail!("{}: {name} and {name}_stderr must be both empty (no lobe) or both numbers", at())
                }
                _ => {}
            }
            let energy = number(r, *energy_c, name, true, &at)?;
            let stderr = number(r, *stderr_c, &format!("{name}_stderr"), true, &at)?;
            let lobes = &mut out.entry(name.clone()).or_default().lobes;
            let bins = lobes.entry(key.lobe.clone()).or_insert_with(|| vec![BinValue::default(); shape.grid.bins()]);
            bins[key.bin] =
                BinValue { energy, energy_stderr: stderr, bsdf: energy / projected, bsdf_stderr: stderr / projected };
        }
    }
    Ok(out)
}

/// The bin `(cos index, phi index)` of a row, from the centre of its `|cos|` range and its
/// lower phi edge.
fn bin_of(grid: Grid, cos_lo: f64, cos_hi: f64, phi_lo_deg: f64) -> Option<(usize, usize)> {
    let c = (0.5 * (cos_lo + cos_hi)).abs() * grid.cos_bins as f64;
    let p = (phi_lo_deg / 360.0 * grid.phi_bins as f64).round();
    let ok = |x: f64, n: usize| (0.0..n as f64).contains(&x);
    (ok(c, grid.cos_bins) && ok(p, grid.phi_bins)).then_some((c as usize, p as usize))
}

/// Checks that `summary.csv` has every case's albedos (per slot, hemisphere and channel), its
/// absorbed and lost energy exactly once, finite, and non-negative except the absorbed energy
/// (an unbiased estimate of 1 - the escaped energy, which may dip below 0 by noise), with
/// finite non-negative standard errors and VOVs.
fn check_summary(path: &Path, shape: &Shape) -> Result<()> {
    let table = Table::read(path, shape.table_limit)?;
    let col = |c| table.column(c);
    let (case_c, order_c, hemi_c, paths_c) =
        (col(schema::CASE)?, col(schema::ORDER)?, col(schema::SUMMARY_ROW)?, col(schema::PATHS)?);
    let (albedo_c, stderr_c, vov_c) = (col(schema::ALBEDO)?, col(schema::ALBEDO_STDERR)?, col(schema::ALBEDO_VOV)?);
    let channel_c = table.optional(schema::CHANNEL);
    let channels = shape.channels;
    // Per case: slots x hemispheres albedo rows, then absorbed and lost, each per channel.
    let (offsets, mut seen) = shape.rows(&table, |hemispheres, slots| {
        slots.saturating_mul(hemispheres).saturating_add(2).saturating_mul(channels)
    })?;
    for (line, r) in table.records.iter().enumerate() {
        let at = || format!("{} line {}", path.display(), line + 2);
        let (case, slots) = shape.case_of(r, case_c, &at)?;
        let order = index(r, order_c, "order", &at)?;
        let paths = index(r, paths_c, "paths", &at)?;
        if paths < 2 {
            bail!("{}: paths = {paths} is not allowed: at least 2", at());
        }
        let hemispheres = shape.hemispheres(case);
        let c = channel_of(r, channel_c, channels, &at)?;
        let what = r.get(hemi_c);
        let row = match what {
            Some("absorbed" | "lost") if order != 0 => bail!("{}: order {order} for {what:?}", at()),
            Some("absorbed") => slots * hemispheres,
            Some("lost") => slots * hemispheres + 1,
            _ if order >= slots => bail!("{}: order {order} is not a slot of case {case} ({slots} slots)", at()),
            _ => order * hemispheres + hemisphere_of(what, hemispheres, &at)?,
        };
        number(r, albedo_c, "albedo", what != Some("absorbed"), &at)?;
        number(r, stderr_c, "albedo_stderr", true, &at)?;
        // The lost weight sums three tallies; its VOV is left empty unless nothing was lost.
        if !(what == Some("lost") && r.get(vov_c) == Some("")) {
            number(r, vov_c, "albedo_vov", true, &at)?;
        }
        mark(&mut seen, offsets[case] + row * channels + c, &at)?;
    }
    complete(&seen, path, |k| format!("row {k} in the run's order"))
}

/// One bin's value: energy per photon and BSDF (energy over projected solid angle), each
/// with its standard error (0 for closed-form models).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BinValue {
    pub energy: f64,
    pub energy_stderr: f64,
    pub bsdf: f64,
    pub bsdf_stderr: f64,
}

/// Which lobe: case, order slot (0 = all orders), hemisphere (`R`/`T`), channel (0 for mono).
pub type LobeId = (usize, usize, String, usize);

/// Lobes of one source (the measurement or one model), each as its bins in detector order
/// (`cos_index * phi_bins + phi_index`).
#[derive(Clone, Debug, Default)]
pub struct Lobes {
    pub lobes: HashMap<LobeId, Vec<BinValue>>,
}

impl Lobes {
    pub fn get(&self, case: usize, order: usize, hemisphere: &str, channel: usize) -> Option<&[BinValue]> {
        self.lobes.get(&(case, order, hemisphere.to_string(), channel)).map(Vec::as_slice)
    }
}

/// One row of `summary.csv`: an albedo (or the absorbed or lost energy).
#[derive(Clone, Debug, Deserialize)]
pub struct SummaryRow {
    pub case: usize,
    pub paths: u64,
    pub order: usize,
    /// `R`, `T`, `absorbed` or `lost`.
    pub hemisphere: String,
    #[serde(default)]
    pub channel: Option<String>,
    pub albedo: f64,
    pub albedo_stderr: f64,
    pub folded: bool,
}

/// A finished run: its config, cases and tables.
pub struct RunDir {
    pub path: PathBuf,
    pub config: Config,
    pub cases: Vec<Case>,
    pub grid: Grid,
    /// Order slots of each case (the highest order with light, plus slot 0 for all orders).
    pub slots: Vec<usize>,
    /// The most bytes read of one of its tables or of a table in its bins (`models.csv`,
    /// `compare.csv`, `--external`): [`input::bins_table_limit`] of its `lobes.csv`.
    pub table_limit: u64,
    /// Which run this is: what `compare.json` records of the run it belongs to.
    pub identity: RunIdentity,
    /// A shared lock: no run writes into the directory while it is read.
    _lock: DirLock,
}

impl RunDir {
    /// Opens the run in `path` once it is validated: `run.json` records the digests of the
    /// tables beside it, and the tables hold every row of its cases exactly once, finite, with
    /// non-negative energies (see the module doc). Otherwise one error names what is wrong.
    pub fn open(path: &Path) -> Result<Self> {
        let lock = lock_dir(path, false)?;
        let (run, identity) = read_run_json(path)?;
        let config = run.config;
        let cases = crate::setup::cases::expand(&config)?;
        if run.cases.len() != cases.len() {
            bail!(
                "{}: {} cases recorded, the config has {}",
                path.join(schema::RUN_JSON).display(),
                run.cases.len(),
                cases.len()
            );
        }
        let grid = Grid { cos_bins: config.detector.cos_theta_bins, phi_bins: config.detector.phi_bins };
        let slots: Vec<usize> = run.cases.iter().map(|c| c.energy.highest_order.saturating_add(1)).collect();
        if let (Some(max), Some(worst)) =
            (config.detector.max_order, run.cases.iter().map(|c| c.energy.highest_order).max())
            && worst > max as usize
        {
            bail!(
                "{}: a case reached order {worst}, beyond detector.max_order = {max} (a run written before max_order \
                 defaulted to {}); rerun the config",
                path.join(schema::RUN_JSON).display(),
                crate::setup::config::DEFAULT_MAX_ORDER
            );
        }
        let lobes_bytes = run.files.as_ref().and_then(|f| f.get(TABLES[0])).map_or(0, |f| f.bytes);
        let table_limit = input::bins_table_limit(lobes_bytes);
        let run = Self { path: path.to_path_buf(), config, cases, grid, slots, table_limit, identity, _lock: lock };
        let shape = run.shape();
        read_lobes(&path.join(TABLES[0]), &shape)?;
        check_summary(&path.join(TABLES[1]), &shape)?;
        Ok(run)
    }

    /// The measured lobes of `lobes.csv`.
    pub fn measured(&self) -> Result<Lobes> {
        read_lobes(&self.path.join(schema::LOBES.file), &self.shape())
    }

    /// The settings of the comparison beside the run, once `models.csv`, `compare.csv` and
    /// `compare.json` are checked to be one sealed set that belongs to this run
    /// ([`compare_json::verify`]); `None` if `compare` has not run.
    pub fn comparison(&self) -> Result<Option<Settings>> {
        compare_json::verify(&self.path, &self.identity)
    }

    /// The model lobes of `models.csv` per model name (its columns `<name>` with a
    /// `<name>_stderr`; a model without any lobe is absent), once the comparison is checked
    /// ([`RunDir::comparison`]) and the file too: its models the ones `compare.json` records,
    /// the rows of `lobes.csv` in its order, each model's two cells both empty or both finite
    /// numbers >= 0. Empty if `compare` has not run.
    pub fn models(&self) -> Result<HashMap<String, Lobes>> {
        let Some(settings) = self.comparison()? else { return Ok(HashMap::new()) };
        read_models(&self.path.join(schema::MODELS.file), &self.shape(), &settings.models)
    }

    fn shape(&self) -> Shape<'_> {
        let channels = if self.config.is_rgb() { 3 } else { 1 };
        Shape {
            cases: &self.cases,
            slots: self.slots.clone(),
            channels,
            grid: self.grid,
            table_limit: self.table_limit,
        }
    }

    /// For exports of reflection only: a one-line note of the transmission they drop (the
    /// largest transmitted albedo of the run's cases), or `None` if no case transmits.
    pub fn dropped_transmission(&self) -> Result<Option<String>> {
        let transmitted = self.summary()?.into_iter().filter(|r| r.hemisphere == "T" && r.order == 0);
        let Some(worst) = transmitted.max_by(|a, b| a.albedo.total_cmp(&b.albedo)) else { return Ok(None) };
        Ok(Some(format!(
            "note: the file holds reflection only; the run's transmission is dropped (up to {:.4} of the incident \
             energy, case {})",
            worst.albedo, worst.case
        )))
    }

    /// The rows of `summary.csv`.
    pub fn summary(&self) -> Result<Vec<SummaryRow>> {
        let path = self.path.join(schema::SUMMARY.file);
        let file = input::open(&path, self.table_limit).with_context(|| format!("cannot read {}", path.display()))?;
        let mut reader = csv::Reader::from_reader(file);
        reader.deserialize().map(|r| r.with_context(|| format!("{}: bad row", path.display()))).collect()
    }
}
