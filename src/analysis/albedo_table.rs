//! A table of single-scattering albedos that the compensation models read in place of the exact
//! functions (`smithwalk compare --albedo-table`), as engines ship them: `E(mu, alpha)` of a
//! conductor with F = 1 at the nodes of a grid and `E_avg(alpha)` at its own alpha nodes, in the
//! CSV format `smithwalk lut` writes (`lut.csv`, `lut_avg.csv`; docs/exports.md).
//!
//! Between nodes the table is interpolated as a GPU samples a texture with bilinear filtering
//! and clamp-to-edge addressing: `E` bilinearly in `(alpha, mu)`, `E_avg` linearly in `alpha`,
//! and outside the nodes' range each coordinate is clamped to its first or last node (the
//! table's edge values are held; nothing is extrapolated).
//!
//! A table `smithwalk lut` made carries its record (`lut.json` beside `lut.csv`: the NDF, the
//! facet, the alpha range); a run is refused the table of another NDF, facet or range
//! ([`AlbedoTable::check`]). A table of your own without a record is taken on trust.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};

use crate::input;
use crate::io::table_record::{TableKind, TableRecord};
use crate::setup::cases::Case;
use crate::setup::config::values::name;

/// The quantity of `lut.csv` that the compensation models need: reflection, order 1 (single
/// scattering) of the F = 1 conductor table.
const QUANTITY: &str = "R_1";

/// `E(mu, alpha)` and `E_avg(alpha)` read from a table.
#[derive(Clone, Debug, PartialEq)]
pub struct AlbedoTable {
    /// The file `E` was read from (for the report).
    pub path: PathBuf,
    /// Increasing alpha nodes of `E`.
    pub alpha: Vec<f64>,
    /// Increasing mu nodes of `E`.
    pub mu: Vec<f64>,
    /// `E` at `(alpha[i], mu[j])`, index `i * mu.len() + j`.
    e: Vec<f64>,
    /// Increasing alpha nodes of `E_avg`.
    avg_alpha: Vec<f64>,
    e_avg: Vec<f64>,
    /// What the table is, from the `.json` beside the `E` file (`lut.json`), if there is one.
    pub record: Option<TableRecord>,
}

/// `values` (at increasing `nodes`, at least 2) interpolated linearly at `x`, clamped to the
/// first and last node outside their range.
pub fn linear(nodes: &[f64], values: &[f64], x: f64) -> f64 {
    let last = nodes.len() - 1;
    let x = x.clamp(nodes[0], nodes[last]);
    let i = nodes.partition_point(|&n| n <= x).clamp(1, last);
    let t = (x - nodes[i - 1]) / (nodes[i] - nodes[i - 1]);
    values[i - 1] + t * (values[i] - values[i - 1])
}

/// The rows of one quantity of a `smithwalk lut` CSV file: the values of the columns `names`
/// per row, each a finite number in `allowed.0 ..= allowed.1` of the matching column, with the
/// row's line. Without a `quantity` column every row counts.
fn rows(path: &Path, names: &[&str], allowed: &[(f64, f64, &str)]) -> Result<Vec<Vec<f64>>> {
    let file = path.display();
    let input =
        input::open(path, input::MAX_TABLE_BYTES).with_context(|| format!("cannot read albedo table {file}"))?;
    let mut reader = csv::Reader::from_reader(input);
    let headers = reader.headers().with_context(|| format!("{file}: cannot read the header line"))?.clone();
    let column = |name: &str| headers.iter().position(|h| h.trim() == name);
    let cols: Vec<usize> = names
        .iter()
        .map(|n| column(n).with_context(|| format!("{file}: no column `{n}` (needed: {})", names.join(", "))))
        .collect::<Result<_>>()?;
    let quantity = column("quantity");
    let (mut out, mut found) = (Vec::new(), Vec::<String>::new());
    for record in reader.records() {
        let record = record.with_context(|| format!("{file}: not a valid CSV row"))?;
        let line = record.position().map_or(0, |p| p.line());
        if let Some(q) = quantity.map(|col| record.get(col).unwrap_or("").trim())
            && q != QUANTITY
        {
            if !found.iter().any(|f| f == q) {
                found.push(q.to_string());
            }
            continue;
        }
        let row = cols
            .iter()
            .zip(names)
            .zip(allowed)
            .map(|((&col, name), &(lo, hi, what))| {
                let text = record.get(col).unwrap_or("").trim();
                match text.parse::<f64>() {
                    Ok(v) if v >= lo && v <= hi => Ok(v),
                    _ => bail!("{file}, line {line}, column `{name}`: {text:?} is not allowed: {what}"),
                }
            })
            .collect::<Result<Vec<f64>>>()?;
        out.push(row);
    }
    if out.is_empty() {
        let seen = if found.is_empty() { "none".to_string() } else { found.join(", ") };
        bail!(
            "{file}: no rows of quantity `{QUANTITY}` (found: {seen}); the compensation models need single-scattering \
             reflection with F = 1, which `smithwalk lut configs/lut-conductor.toml` writes as `{QUANTITY}`"
        );
    }
    Ok(out)
}

/// The sorted distinct values of `values`, at least 2 of them, else an error naming `what`.
fn nodes(file: &Path, values: impl Iterator<Item = f64>, what: &str) -> Result<Vec<f64>> {
    let mut nodes: Vec<f64> = values.collect();
    nodes.sort_by(f64::total_cmp);
    nodes.dedup();
    if nodes.len() < 2 {
        bail!("{}: {} {what} node(s) is not allowed: at least 2 for the interpolation", file.display(), nodes.len());
    }
    Ok(nodes)
}

impl AlbedoTable {
    /// Reads `E` from `path` (a directory: its `lut.csv`; a file: that file) and `E_avg` from the
    /// `_avg` file beside it (`lut_avg.csv` for `lut.csv`). Rows of quantity `R_1` are read when
    /// there is a `quantity` column, every row otherwise; `E` must be given at every node of a
    /// grid of at least 2 x 2 `(alpha, mu)` nodes exactly once. Errors name the file, the line,
    /// the column, the value and what is allowed.
    pub fn read(path: &Path) -> Result<Self> {
        let e_path = if path.is_dir() { path.join("lut.csv") } else { path.to_path_buf() };
        let stem = e_path.file_stem().and_then(|s| s.to_str()).unwrap_or("lut");
        let avg_path = e_path.with_file_name(format!("{stem}_avg.csv"));
        let positive = (0.0, f64::MAX, "a finite alpha >= 0");
        let albedo = (0.0, 1.0, "a directional albedo in [0, 1]");
        let rows_e = rows(&e_path, &["alpha", "mu", "E"], &[positive, (0.0, 1.0, "a cosine in [0, 1]"), albedo])?;
        let alpha = nodes(&e_path, rows_e.iter().map(|r| r[0]), "alpha")?;
        let mu = nodes(&e_path, rows_e.iter().map(|r| r[1]), "mu")?;
        let mut e = vec![f64::NAN; alpha.len() * mu.len()];
        for r in &rows_e {
            let k = alpha.partition_point(|&a| a < r[0]) * mu.len() + mu.partition_point(|&m| m < r[1]);
            if !e[k].is_nan() {
                bail!("{}: E at alpha {}, mu {} is given twice", e_path.display(), r[0], r[1]);
            }
            e[k] = r[2];
        }
        if let Some(k) = e.iter().position(|v| v.is_nan()) {
            bail!(
                "{}: no E at alpha {}, mu {} ({} of the {} x {} grid's nodes are missing; give E at every (alpha, mu) node)",
                e_path.display(),
                alpha[k / mu.len()],
                mu[k % mu.len()],
                e.iter().filter(|v| v.is_nan()).count(),
                alpha.len(),
                mu.len()
            );
        }
        let mut rows_avg =
            rows(&avg_path, &["alpha", "E_avg"], &[positive, (0.0, 1.0, "an average albedo in [0, 1]")])?;
        rows_avg.sort_by(|a, b| a[0].total_cmp(&b[0]));
        let avg_alpha = nodes(&avg_path, rows_avg.iter().map(|r| r[0]), "alpha")?;
        if avg_alpha.len() != rows_avg.len() {
            bail!("{}: an alpha is given twice", avg_path.display());
        }
        let e_avg = rows_avg.iter().map(|r| r[1]).collect();
        let record_path = e_path.with_extension("json");
        let record = record_path.exists().then(|| TableRecord::read(&record_path)).transpose()?;
        Ok(AlbedoTable { path: e_path, alpha, mu, e, avg_alpha, e_avg, record })
    }

    /// Refuses the table for `case` (one the compensation models apply to: a conductor on an
    /// isotropic surface with the true Smith Lambda and visible normals) when its record says
    /// it was made for another facet than the conductor with F = 1, another NDF or Smith
    /// variant, or a range of alpha without the case's: one line naming both.
    pub fn check(&self, case: &Case) -> Result<()> {
        let Some(r) = &self.record else { return Ok(()) };
        let alpha = case.roughness().x;
        let [lo, hi] = r.alpha_range;
        let ndf = case.surface.ndf.name();
        let smith = name(&r.smith);
        let matches =
            r.table == TableKind::Conductor && name(&r.ndf) == ndf && smith == "exact" && (lo..=hi).contains(&alpha);
        if matches {
            return Ok(());
        }
        bail!(
            "--albedo-table {}: the table is for {} {} facets ({} Smith), alpha in [{lo}, {hi}] (its lut.json), but case {} \
             of the run is {ndf}, alpha {alpha}: the compensation models read the F = 1 conductor table of the run's NDF \
             over a range with its alpha (`smithwalk lut`, docs/compensation.md)",
            self.path.display(),
            name(&r.ndf),
            name(&r.table),
            smith,
            case.index
        )
    }

    /// `E` at the `mu` nodes and `E_avg`, at roughness `alpha`: the rows of `E` interpolated
    /// linearly in alpha (clamped), so that the result, linear in mu between the mu nodes
    /// (clamped), is the table's bilinear interpolation; `E_avg` linear in alpha (clamped).
    pub fn at_alpha(&self, alpha: f64) -> (Vec<f64>, f64) {
        let n = self.mu.len();
        let row: Vec<f64> = (0..n)
            .map(|j| {
                let column: Vec<f64> = (0..self.alpha.len()).map(|i| self.e[i * n + j]).collect();
                linear(&self.alpha, &column, alpha)
            })
            .collect();
        (row, linear(&self.avg_alpha, &self.e_avg, alpha))
    }

    /// A one-line description for the report.
    pub fn describe(&self) -> String {
        let made = match &self.record {
            Some(r) => format!("{} {}", name(&r.ndf), name(&r.table)),
            None => "without a lut.json: NDF and facet unchecked".to_string(),
        };
        format!(
            "E(mu) and E_avg from the table {} ({made}; {} alpha x {} mu nodes, bilinear, clamped to alpha [{}, {}], mu [{}, {}])",
            self.path.display(),
            self.alpha.len(),
            self.mu.len(),
            self.alpha[0],
            self.alpha[self.alpha.len() - 1],
            self.mu[0],
            self.mu[self.mu.len() - 1]
        )
    }
}
