//! Output files of a run: `lobes.csv`, `summary.csv` and `run.json`, each written atomically
//! (temporary file in the output directory, then rename), and only after every case finished.

use std::path::{Path, PathBuf};

use anyhow::Result;
use serde::Serialize;

use crate::atomic::write_atomically;
use crate::engine::Simulation;
use crate::engine::detector::{Detector, Grid, Hemisphere, Moments, Tally};
use crate::engine::run::CaseResult;
use crate::io::schema;
use crate::setup::cases::Case;
use microsurface::ndf::Roughness;
use microsurface::normals::Normals;
use microsurface::smith::Smith;

use crate::setup::config::values::name;
use crate::setup::config::{Config, HeightKind, IncidentSide, MaterialConfig};

pub const CHANNEL_NAMES: [&str; 3] = ["r", "g", "b"];

/// The values of a case's leading columns ([`schema::CASE_COLUMNS`]).
pub(crate) fn case_fields(case: &Case) -> Vec<String> {
    vec![
        case.index.to_string(),
        case.surface.ndf.name().to_string(),
        case.roughness().x.to_string(),
        case.roughness().y.to_string(),
        case.gamma().map_or(String::new(), |g| g.to_string()),
        name(&case.height),
        case.surface.smith.name().to_string(),
        case.surface.normals.name().to_string(),
        case.material_label(),
        case.theta_i_deg.to_string(),
        case.phi_i_deg.to_string(),
        name(&case.side),
    ]
}

/// Sign of cos(theta) of the directions in a hemisphere: reflection goes back to the light's
/// side, transmission to the other one.
pub(crate) fn hemisphere_sign(side: IncidentSide, hemisphere: Hemisphere) -> f64 {
    match (side, hemisphere) {
        (IncidentSide::Outside, Hemisphere::R) | (IncidentSide::Inside, Hemisphere::T) => 1.0,
        _ => -1.0,
    }
}

pub(crate) fn hemispheres(case: &Case) -> &'static [Hemisphere] {
    if case.material.transmits() { &[Hemisphere::R, Hemisphere::T] } else { &[Hemisphere::R] }
}

/// Energy accounting of one case, per channel (§9.2).
#[derive(Clone, Debug, Serialize)]
pub struct EnergyBalance {
    pub reflected: Vec<f64>,
    pub transmitted: Vec<f64>,
    pub absorbed: Vec<f64>,
    pub absorbed_stderr: Vec<f64>,
    pub lost_trapped: Vec<f64>,
    pub lost_invalid: Vec<f64>,
    pub lost_runaway: Vec<f64>,
    /// Energy in the folded "K+" order (`detector.max_order`), or 0.
    pub folded: Vec<f64>,
    /// Highest order slot with light in it.
    pub highest_order: usize,
    /// Mean number of facet interactions per photon (all its rays).
    pub interactions_per_path: f64,
}

fn per_channel<const C: usize>(f: impl Fn(usize) -> f64) -> Vec<f64> {
    (0..C).map(f).collect()
}

impl EnergyBalance {
    fn of<const C: usize>(d: &Detector<C>) -> Self {
        let n = d.tallies.photons;
        let mean = |t: &Tally<C>, c| t.mean_and_stderr(n, c).0;
        let moment_mean = |t: &Moments<C>, c| t.mean_and_stderr(n, c).0;
        let all = &d.tallies.orders[0];
        let last = d.highest_slot();
        Self {
            reflected: per_channel::<C>(|c| moment_mean(&all.albedo[0], c)),
            transmitted: per_channel::<C>(|c| moment_mean(&all.albedo[1], c)),
            absorbed: per_channel::<C>(|c| 1.0 - moment_mean(&d.tallies.accounted, c)),
            absorbed_stderr: per_channel::<C>(|c| d.tallies.accounted.mean_and_stderr(n, c).1),
            lost_trapped: per_channel::<C>(|c| mean(&d.tallies.lost[0], c)),
            lost_invalid: per_channel::<C>(|c| mean(&d.tallies.lost[1], c)),
            lost_runaway: per_channel::<C>(|c| mean(&d.tallies.lost[2], c)),
            folded: per_channel::<C>(|c| {
                if d.is_folded(last) {
                    moment_mean(&d.tallies.orders[last].albedo[0], c)
                        + moment_mean(&d.tallies.orders[last].albedo[1], c)
                } else {
                    0.0
                }
            }),
            highest_order: last,
            interactions_per_path: d.tallies.interactions as f64 / n as f64,
        }
    }

    pub fn from_result(r: &CaseResult) -> Self {
        match r {
            CaseResult::Mono(d) => Self::of(d),
            CaseResult::Rgb(d) => Self::of(d),
        }
    }

    pub fn lost(&self) -> f64 {
        self.lost_trapped.iter().chain(&self.lost_invalid).chain(&self.lost_runaway).sum()
    }
}

/// The variance of the variance above which a standard error is not to be trusted (MCNP's
/// criterion for tallies, docs/theory.md §9.5): the variance is then uncertain by a third or
/// more, the standard error by a sixth.
pub const VOV_THRESHOLD: f64 = 0.1;

/// The albedos of `summary.csv` whose VOV is above [`VOV_THRESHOLD`], as `(case, order slot,
/// hemisphere, channel, VOV)`, largest VOV first.
pub fn unreliable_albedos(sim: &Simulation) -> Vec<(usize, usize, Hemisphere, usize, f64)> {
    fn of<const C: usize>(case: &Case, d: &Detector<C>, out: &mut Vec<(usize, usize, Hemisphere, usize, f64)>) {
        for (slot, order) in d.tallies.orders.iter().enumerate() {
            for &h in hemispheres(case) {
                for c in 0..C {
                    let vov = order.albedo[h as usize].vov(d.tallies.photons, c);
                    if vov > VOV_THRESHOLD {
                        out.push((case.index, slot, h, c, vov));
                    }
                }
            }
        }
    }
    let mut out = Vec::new();
    for (case, result) in sim.cases.iter().zip(&sim.results) {
        match result {
            CaseResult::Mono(d) => of(case, d, &mut out),
            CaseResult::Rgb(d) => of(case, d, &mut out),
        }
    }
    out.sort_by(|a, b| b.4.total_cmp(&a.4));
    out
}

/// What the columns of [`balance_table`] mean, printed once above it.
pub const BALANCE_LEGEND: &str = "\
Energy balance per case, in fractions of the incident energy (per order: summary.csv):
  R, T       reflected and transmitted, all bounce orders
  absorbed   1 - R - T - lost, ± its standard error (a material that absorbs nothing
             shows 0 within the error: the noise of Russian roulette)
  lost       trapped at infinite depth, NaN or beyond 2^20 interactions (by reason: run.json)
  orders     highest bounce order that received light; K+ when detector.max_order = K folds
             the orders >= K into one\n";

/// The energy balance of every case as a text table (§9.2): the surface and material as the
/// config spells them, one row per case and channel (RGB runs get a `channel` column), the
/// absorbed fraction with its standard error. Columns `smith`, `normals` and `side` appear
/// only when some case departs from their defaults.
pub fn balance_table(sim: &Simulation) -> String {
    let cases = &sim.cases;
    let smith = cases.iter().any(|c| c.surface.smith != Smith::Exact);
    let normals = cases.iter().any(|c| c.surface.normals != Normals::Visible);
    let side = cases.iter().any(|c| c.side != IncidentSide::Outside);
    let mut header = vec!["case", "ndf", "alpha"];
    header.extend(smith.then_some("smith"));
    header.extend(normals.then_some("normals"));
    header.push("material");
    header.extend(side.then_some("side"));
    header.extend(sim.rgb.then_some("channel"));
    // Names align left, numbers right.
    let names = 1..header.len();
    header.extend(["theta_i_deg", "R", "T", "absorbed", "lost", "orders"]);
    let mut rows: Vec<Vec<String>> = vec![header.iter().map(|h| h.to_string()).collect()];
    for (case, result) in cases.iter().zip(&sim.results) {
        let e = EnergyBalance::from_result(result);
        let Roughness { x, y } = case.roughness();
        let alpha = if x == y { x.to_string() } else { format!("[{x}, {y}]") };
        let folded = match result {
            CaseResult::Mono(d) => d.is_folded(e.highest_order),
            CaseResult::Rgb(d) => d.is_folded(e.highest_order),
        };
        let orders = format!("{}{}", e.highest_order, if folded { "+" } else { "" });
        for (c, channel) in CHANNEL_NAMES.iter().enumerate().take(e.reflected.len()) {
            let mut row = vec![case.index.to_string(), case.surface.ndf.name().to_string(), alpha.clone()];
            row.extend(smith.then(|| case.surface.smith.name().to_string()));
            row.extend(normals.then(|| case.surface.normals.name().to_string()));
            row.push(case.material_label());
            row.extend(side.then(|| name(&case.side)));
            row.extend(sim.rgb.then(|| channel.to_string()));
            row.push(format!("{:.2}", case.theta_i_deg));
            let lost = e.lost_trapped[c] + e.lost_invalid[c] + e.lost_runaway[c];
            row.extend([
                format!("{:.6}", e.reflected[c]),
                format!("{:.6}", e.transmitted[c]),
                format!("{:.6} ± {:.6}", e.absorbed[c], e.absorbed_stderr[c]),
                format!("{lost:.6}"),
                orders.clone(),
            ]);
            rows.push(row);
        }
    }
    let widths: Vec<usize> =
        (0..rows[0].len()).map(|i| rows.iter().map(|r| r[i].chars().count()).max().unwrap_or(0)).collect();
    let mut text = String::new();
    for row in &rows {
        let cells: Vec<String> = row
            .iter()
            .zip(&widths)
            .enumerate()
            .map(|(i, (cell, &w))| if names.contains(&i) { format!("{cell:<w$}") } else { format!("{cell:>w$}") })
            .collect();
        text.push_str(cells.join("  ").trim_end());
        text.push('\n');
    }
    text
}

/// The bins of a lobe in the order of `lobes.csv` (and `models.csv`): cos index, then phi
/// index, each as `(cos index, bin index, [cos_lo, cos_hi, phi_lo_deg, phi_hi_deg])` with the
/// cos edges signed by the hemisphere's `sign` ([`hemisphere_sign`]).
pub(crate) fn bin_edges(grid: Grid, sign: f64) -> impl Iterator<Item = (usize, usize, [f64; 4])> {
    (0..grid.cos_bins).flat_map(move |ic| {
        let (lo, hi) = grid.cos_edges(ic);
        // `0.0 - lo`, not `-lo`: the horizon's edge of a transmission bin is written `0`, not `-0`.
        let (cos_lo, cos_hi) = if sign > 0.0 { (lo, hi) } else { (-hi, 0.0 - lo) };
        (0..grid.phi_bins).map(move |ip| {
            let (phi_lo, phi_hi) = grid.phi_edges_deg(ip);
            (ic, ic * grid.phi_bins + ip, [cos_lo, cos_hi, phi_lo, phi_hi])
        })
    })
}

fn lobe_rows<const C: usize>(w: &mut csv::Writer<Vec<u8>>, case: &Case, d: &Detector<C>) -> Result<()> {
    let fields = case_fields(case);
    let grid = d.grid;
    let n = d.tallies.photons;
    for (slot, tallies) in d.tallies.orders.iter().enumerate() {
        for &hemisphere in hemispheres(case) {
            for (ic, bin, edges) in bin_edges(grid, hemisphere_sign(case.side, hemisphere)) {
                let [cos_lo, cos_hi, phi_lo, phi_hi] = edges;
                let (lo, hi) = grid.cos_edges(ic);
                let projected = grid.projected_solid_angle(ic);
                // The bin's centre: the mid-point in cos theta (it halves the bin's solid angle)
                // and in phi; the solid angle is delta phi times delta cos (§4.7).
                let theta_deg = (0.5 * (cos_lo + cos_hi)).acos().to_degrees();
                let solid_angle = (hi - lo) * std::f64::consts::TAU / grid.phi_bins as f64;
                let tally = &tallies.bins[hemisphere as usize * grid.bins() + bin];
                for (c, channel) in CHANNEL_NAMES.iter().enumerate().take(C) {
                    let (energy, se) = tally.mean_and_stderr(n, c);
                    let mut row = fields.clone();
                    row.push(slot.to_string());
                    row.push(format!("{hemisphere:?}"));
                    if C > 1 {
                        row.push(channel.to_string());
                    }
                    row.extend([cos_lo, cos_hi, phi_lo, phi_hi, energy, se].map(|v| v.to_string()));
                    row.push(tally.count.to_string());
                    row.push((energy / projected).to_string());
                    row.push((se / projected).to_string());
                    row.extend([theta_deg, 0.5 * (phi_lo + phi_hi), solid_angle].map(|v| v.to_string()));
                    w.write_record(&row)?;
                }
            }
        }
    }
    Ok(())
}

fn summary_rows<const C: usize>(w: &mut csv::Writer<Vec<u8>>, case: &Case, d: &Detector<C>) -> Result<()> {
    let fields = case_fields(case);
    let n = d.tallies.photons;
    // The VOV cell is empty where it is not estimated: the lost weight sums three tallies.
    let mut write = |order: usize, what: &str, c: usize, value: f64, se: f64, vov: Option<f64>, folded: bool| {
        let mut row = fields.clone();
        row.push(n.to_string());
        row.push(order.to_string());
        row.push(what.to_string());
        if C > 1 {
            row.push(CHANNEL_NAMES[c].to_string());
        }
        row.extend([
            value.to_string(),
            se.to_string(),
            vov.map_or(String::new(), |v| v.to_string()),
            folded.to_string(),
        ]);
        w.write_record(&row)
    };
    for (slot, tallies) in d.tallies.orders.iter().enumerate() {
        for &hemisphere in hemispheres(case) {
            for c in 0..C {
                let tally = &tallies.albedo[hemisphere as usize];
                let (albedo, se) = tally.mean_and_stderr(n, c);
                write(slot, &format!("{hemisphere:?}"), c, albedo, se, Some(tally.vov(n, c)), d.is_folded(slot))?;
            }
        }
    }
    for c in 0..C {
        let (accounted, se) = d.tallies.accounted.mean_and_stderr(n, c);
        write(0, "absorbed", c, 1.0 - accounted, se, Some(d.tallies.accounted.vov(n, c)), false)?;
        let lost: f64 = d.tallies.lost.iter().map(|t| t.mean_and_stderr(n, c).0).sum();
        let lost_se = d.tallies.lost.iter().map(|t| t.mean_and_stderr(n, c).1.powi(2)).sum::<f64>().sqrt();
        write(0, "lost", c, lost, lost_se, (lost == 0.0).then_some(0.0), false)?;
    }
    Ok(())
}

/// The CSV text of `lobes.csv`: one row per case, order slot (0 = all orders, then 1 up to the
/// highest order that received light, or the folded `max_order` slot), hemisphere (`R`, and `T`
/// for materials that transmit), bin (every bin, empty ones too) and channel (RGB runs).
pub fn lobes_csv(sim: &Simulation) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let header = schema::LOBES.header(sim.rgb, &[]);
    w.write_record(&header)?;
    for (case, result) in sim.cases.iter().zip(&sim.results) {
        match result {
            CaseResult::Mono(d) => lobe_rows(&mut w, case, d)?,
            CaseResult::Rgb(d) => lobe_rows(&mut w, case, d)?,
        }
    }
    Ok(w.into_inner()?)
}

/// The CSV text of `summary.csv` (albedo per case, order, hemisphere; absorbed; lost).
pub fn summary_csv(sim: &Simulation) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let header = schema::SUMMARY.header(sim.rgb, &[]);
    w.write_record(&header)?;
    for (case, result) in sim.cases.iter().zip(&sim.results) {
        match result {
            CaseResult::Mono(d) => summary_rows(&mut w, case, d)?,
            CaseResult::Rgb(d) => summary_rows(&mut w, case, d)?,
        }
    }
    Ok(w.into_inner()?)
}

/// A case in `run.json`: its parameters as the configuration spells them, and its energy.
#[derive(Serialize)]
struct CaseReport<'a> {
    index: usize,
    ndf: &'static str,
    alpha_x: f64,
    alpha_y: f64,
    /// The Student-T shape; absent for the other NDFs.
    #[serde(skip_serializing_if = "Option::is_none")]
    gamma: Option<f64>,
    height: HeightKind,
    smith: &'static str,
    normals: &'static str,
    material: &'a MaterialConfig,
    theta_i_deg: f64,
    phi_i_deg: f64,
    side: IncidentSide,
    energy: EnergyBalance,
}

impl<'a> CaseReport<'a> {
    fn new(case: &'a Case, energy: EnergyBalance) -> Self {
        let Roughness { x, y } = case.roughness();
        CaseReport {
            index: case.index,
            ndf: case.surface.ndf.name(),
            alpha_x: x,
            alpha_y: y,
            gamma: case.gamma(),
            height: case.height,
            smith: case.surface.smith.name(),
            normals: case.surface.normals.name(),
            material: &case.material_spec,
            theta_i_deg: case.theta_i_deg,
            phi_i_deg: case.phi_i_deg,
            side: case.side,
            energy,
        }
    }
}

/// A file of the run as `run.json` records it, so that readers can tell it is the one this run
/// wrote (`sha256sum FILE` shows the same digest).
#[derive(Serialize)]
struct FileRecord {
    bytes: u64,
    sha256: String,
}

/// The SHA-256 digest of `bytes` in hex.
pub(crate) fn sha256_hex(bytes: &[u8]) -> String {
    use sha2::Digest;
    sha2::Sha256::digest(bytes).iter().map(|b| format!("{b:02x}")).collect()
}

/// The tables of a run, named as in its directory; `run.json` records their digests.
pub const TABLES: [&str; 2] = [schema::LOBES.file, schema::SUMMARY.file];

#[derive(Serialize)]
struct RunReport<'a> {
    smithwalk_version: &'static str,
    /// The run directory's format ([`schema::FORMAT_VERSION`]).
    format_version: u32,
    /// Identifies this run: the digest of its tables and the time it finished.
    run_id: String,
    /// `lobes.csv` and `summary.csv` as written, with their digests.
    files: std::collections::BTreeMap<&'static str, FileRecord>,
    config: &'a Config,
    seed: u64,
    paths: u64,
    threads: usize,
    chunk_photons: u64,
    wall_seconds: f64,
    paths_per_second: f64,
    cases: Vec<CaseReport<'a>>,
    /// The SHA-256 of this file's text with these 64 hex digits written as zeros
    /// ([`SELF_DIGEST`]), so that a reader can tell any change to `run.json` itself.
    self_sha256: String,
}

/// The key of `run.json`'s digest of itself, its last field.
pub const SELF_DIGEST: &str = "\"self_sha256\": \"";

/// The digest `run.json` text must carry: that of the text with its own digest as zeros.
pub(crate) fn self_digest(text: &[u8]) -> Option<(std::ops::Range<usize>, String)> {
    let key = SELF_DIGEST.as_bytes();
    let start = text.windows(key.len()).rposition(|w| w == key)? + key.len();
    let range = start..start + 64;
    let mut zeroed = text.get(..range.end)?.to_vec();
    zeroed[range.clone()].fill(b'0');
    zeroed.extend_from_slice(&text[range.end..]);
    Some((range, sha256_hex(&zeroed)))
}

/// The JSON text of `run.json`: resolved config, version, seed, paths, timing, energy balance,
/// and the digests of the run's tables `tables` (the contents of [`TABLES`], in order).
pub fn run_json(sim: &Simulation, config: &Config, tables: [&[u8]; 2]) -> Result<Vec<u8>> {
    let total = config.paths as f64 * sim.cases.len() as f64;
    let files: std::collections::BTreeMap<_, _> = TABLES
        .into_iter()
        .zip(tables)
        .map(|(name, bytes)| (name, FileRecord { bytes: bytes.len() as u64, sha256: sha256_hex(bytes) }))
        .collect();
    let now = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap_or_default();
    let stamp =
        format!("{} {} {} {}", files[TABLES[0]].sha256, files[TABLES[1]].sha256, now.as_nanos(), std::process::id());
    let report = RunReport {
        smithwalk_version: env!("CARGO_PKG_VERSION"),
        format_version: schema::FORMAT_VERSION,
        run_id: sha256_hex(stamp.as_bytes())[..32].to_string(),
        files,
        config,
        seed: config.seed,
        paths: config.paths,
        threads: sim.threads,
        chunk_photons: crate::engine::run::CHUNK,
        wall_seconds: sim.wall_seconds,
        paths_per_second: total / sim.wall_seconds.max(1e-9),
        cases: sim
            .cases
            .iter()
            .zip(&sim.results)
            .map(|(case, r)| CaseReport::new(case, EnergyBalance::from_result(r)))
            .collect(),
        self_sha256: "0".repeat(64),
    };
    let mut text = serde_json::to_vec_pretty(&report)?;
    text.push(b'\n');
    let (range, digest) = self_digest(&text).expect("run.json ends with its digest");
    text[range].copy_from_slice(digest.as_bytes());
    Ok(text)
}

/// Writes `lobes.csv`, `summary.csv` and `run.json` of a simulation into `dir`, atomically,
/// `run.json` last: it records the digests of the tables, so a run killed between the renames
/// leaves tables that readers refuse ([`crate::io::rundir::RunDir::open`]) rather than a mix.
/// The previous run's `models.csv` and `compare.csv` are removed first: they describe it.
pub fn write_outputs(sim: &Simulation, config: &Config, dir: &Path) -> Result<Vec<PathBuf>> {
    let (lobes, summary) = (lobes_csv(sim)?, summary_csv(sim)?);
    let run = run_json(sim, config, [&lobes, &summary])?;
    for stale in schema::COMPARE_FILES {
        match std::fs::remove_file(dir.join(stale)) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                return Err(anyhow::Error::new(e).context(format!("cannot remove the previous run's {stale}")));
            }
            _ => {}
        }
    }
    write_atomically(dir, &[(TABLES[0], lobes), (TABLES[1], summary), (schema::RUN_JSON, run)])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The disk estimate a run prints before it walks (issue 36 item 16) bounds the tables it
    /// writes: `lobes.csv`, `summary.csv` and `run.json` of a run with every slot reached.
    #[test]
    fn the_disk_estimate_bounds_the_tables_written() {
        let config = crate::setup::config::Config::parse(
            "paths = 40000\nseed = 5\n[surface]\nalpha = 0.5\n[material]\nkind = \"conductor\"\n[incident]\n\
             theta_deg = [20, 70]\n[detector]\ncos_theta_bins = 4\nphi_bins = 8\nmax_order = 3\n",
        )
        .unwrap();
        let sim = crate::engine::simulate(&config, Some(1), false).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let written: u64 =
            write_outputs(&sim, &config, dir.path()).unwrap().iter().map(|f| std::fs::metadata(f).unwrap().len()).sum();
        let estimate = crate::engine::resources::DiskEstimate::of(&config);
        assert!(written > 0 && written <= estimate.table_bytes, "{written} > {estimate:?}");
    }

    #[test]
    fn bin_edges_are_signed_by_hemisphere_without_negative_zero() {
        let grid = Grid { cos_bins: 4, phi_bins: 3 };
        for sign in [1.0, -1.0] {
            let edges: Vec<_> = bin_edges(grid, sign).collect();
            assert_eq!(edges.len(), 12);
            for (ic, _, [lo, hi, _, _]) in edges {
                assert!(lo < hi, "{lo} {hi}");
                let (a, b) = grid.cos_edges(ic);
                assert_eq!((lo.abs().min(hi.abs()), lo.abs().max(hi.abs())), (a, b));
                assert!(lo * sign >= 0.0 && hi * sign >= 0.0, "{lo} {hi} in hemisphere {sign}");
                // `-0` would be written to lobes.csv as "-0".
                assert!(lo.to_string() != "-0" && hi.to_string() != "-0", "{lo} {hi}");
            }
        }
    }
}
