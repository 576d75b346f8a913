//! Reading a run directory back: the resolved config in `run.json` and the tables
//! `lobes.csv`, `summary.csv` and (after `compare`) `models.csv`, for the commands that work
//! on finished runs (`compare`, `plot`, `merl`).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use serde::Deserialize;

use crate::engine::detector::Grid;
use crate::setup::cases::Case;
use crate::setup::config::Config;

/// The resolved, validated config of a finished run, from its `run.json`.
pub fn read_config(run_dir: &Path) -> Result<Config> {
    let run_json = run_dir.join("run.json");
    let text = std::fs::read_to_string(&run_json).with_context(|| format!("cannot read {}", run_json.display()))?;
    let json: serde_json::Value =
        serde_json::from_str(&text).with_context(|| format!("{} is not JSON", run_json.display()))?;
    let Some(config_json) = json.get("config") else { bail!("{}: no `config`", run_json.display()) };
    let config: Config = serde_json::from_value(config_json.clone()).context("the run's config")?;
    config.validate()?;
    Ok(config)
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

#[derive(Deserialize)]
struct BinRow {
    case: usize,
    #[serde(default)]
    model: Option<String>,
    order: usize,
    hemisphere: String,
    #[serde(default)]
    channel: Option<String>,
    cos_lo: f64,
    cos_hi: f64,
    phi_lo_deg: f64,
    energy: f64,
    energy_stderr: f64,
    bsdf: f64,
    #[serde(default)]
    bsdf_stderr: Option<f64>,
}

fn channel_index(channel: &Option<String>) -> usize {
    match channel.as_deref() {
        Some("g") => 1,
        Some("b") => 2,
        _ => 0,
    }
}

/// Reads a bin table (`lobes.csv` or `models.csv`) into lobes per model name (`""` for the
/// measurement).
fn read_bins(path: &Path, grid: Grid) -> Result<HashMap<String, Lobes>> {
    let mut reader = csv::Reader::from_path(path).with_context(|| format!("cannot read {}", path.display()))?;
    let mut out: HashMap<String, Lobes> = HashMap::new();
    for row in reader.deserialize() {
        let row: BinRow = row.with_context(|| format!("{}: bad row", path.display()))?;
        // |cos| of the bin's centre finds its cos index in either hemisphere.
        let ic = ((0.5 * (row.cos_lo + row.cos_hi)).abs() * grid.cos_bins as f64) as usize;
        let ip = (row.phi_lo_deg / 360.0 * grid.phi_bins as f64).round() as usize;
        if ic >= grid.cos_bins || ip >= grid.phi_bins {
            bail!("{}: a bin outside the run's {} x {} grid", path.display(), grid.cos_bins, grid.phi_bins);
        }
        let lobes = out.entry(row.model.clone().unwrap_or_default()).or_default();
        let bins = lobes
            .lobes
            .entry((row.case, row.order, row.hemisphere.clone(), channel_index(&row.channel)))
            .or_insert_with(|| vec![BinValue::default(); grid.bins()]);
        bins[ic * grid.phi_bins + ip] = BinValue {
            energy: row.energy,
            energy_stderr: row.energy_stderr,
            bsdf: row.bsdf,
            bsdf_stderr: row.bsdf_stderr.unwrap_or(0.0),
        };
    }
    Ok(out)
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
}

impl RunDir {
    pub fn open(path: &Path) -> Result<Self> {
        let config = read_config(path)?;
        let cases = crate::setup::cases::expand(&config);
        let grid = Grid { cos_bins: config.detector.cos_theta_bins, phi_bins: config.detector.phi_bins };
        Ok(Self { path: path.to_path_buf(), config, cases, grid })
    }

    /// The measured lobes of `lobes.csv`.
    pub fn measured(&self) -> Result<Lobes> {
        Ok(read_bins(&self.path.join("lobes.csv"), self.grid)?.remove("").unwrap_or_default())
    }

    /// The model lobes of `models.csv` per model name; empty if `compare` has not run.
    pub fn models(&self) -> Result<HashMap<String, Lobes>> {
        let path = self.path.join("models.csv");
        if !path.exists() {
            return Ok(HashMap::new());
        }
        read_bins(&path, self.grid)
    }

    /// The rows of `summary.csv`.
    pub fn summary(&self) -> Result<Vec<SummaryRow>> {
        let path = self.path.join("summary.csv");
        let mut reader = csv::Reader::from_path(&path).with_context(|| format!("cannot read {}", path.display()))?;
        reader.deserialize().map(|r| r.with_context(|| format!("{}: bad row", path.display()))).collect()
    }
}
