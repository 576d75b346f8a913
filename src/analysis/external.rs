//! A user's own model of a run (`smithwalk compare RUN_DIR --external FILE.csv`): the energy it
//! predicts in the run's bins, read from a CSV file with the columns of `models.csv` and
//! validated against the run (its cases, detector bins and channels), so that compare judges
//! it like a built-in model.
//!
//! Columns (any order; other columns, such as those that name the case, are ignored): `case`
//! (the run's case index), `order` (0 for all orders, k for bounce order k), `hemisphere` (`R`
//! or `T`), `channel` (`r`, `g`, `b`, for RGB runs only), `cos_lo`, `cos_hi`, `phi_lo_deg`,
//! `phi_hi_deg` (a bin of the run, as `lobes.csv` writes it: cosines negative in the
//! transmission hemisphere), `energy` (expected energy per incident photon in the bin, i.e.
//! `∫_bin f(wi, wo) |cos theta_o| dwo`) and, optionally, `energy_stderr` (the model's own
//! standard error if it is a Monte Carlo estimate; without it the model is exact). Every bin of
//! a lobe (case, order, hemisphere, channel) must be given exactly once. The run's folded slot
//! "K+" (`max_order = K`, every order from K on) is compared only with a model that folds at
//! the same order: one whose optional `folded` column is `true` in that slot (as `models.csv`
//! writes it), or the `lobes.csv` of another run directory (its `run.json` beside it, validated
//! like the run's) with the same `detector.max_order`. A per-order model is never compared with
//! a folded slot, nor a folded model's slot with a per-order one.

use std::collections::HashMap;
use std::path::Path;

use anyhow::{Context, Result, bail};

use crate::engine::detector::{Grid, Hemisphere};
use crate::input;
use crate::io::output::hemisphere_sign;
use crate::io::rundir::RunDir;
use crate::io::schema::{self, Column};
use crate::setup::cases::Case;

/// The columns an external model's CSV must have (in any order; others are ignored).
const REQUIRED: [Column; 8] = [
    schema::CASE,
    schema::ORDER,
    schema::HEMISPHERE,
    schema::COS_LO,
    schema::COS_HI,
    schema::PHI_LO_DEG,
    schema::PHI_HI_DEG,
    schema::ENERGY,
];

/// A nominal photon count for a model with standard errors: large enough that the two-sample
/// test's variance of the model is its `energy_stderr^2` (the count itself drops out).
const NOMINAL_PHOTONS: u64 = 1_000_000_000_000;

/// One lobe of the user's model: energy and standard error per bin (index `cos * phi_bins +
/// phi`, as the detector's).
#[derive(Clone, Debug, PartialEq)]
pub struct ExternalLobe {
    pub case: usize,
    pub order: usize,
    pub hemisphere: Hemisphere,
    /// `""` for mono runs, `r`, `g` or `b` for RGB runs.
    pub channel: String,
    pub energy: Vec<f64>,
    pub stderr: Vec<f64>,
}

/// A user's model, validated against a run.
#[derive(Clone, Debug, PartialEq)]
pub struct ExternalModel {
    pub lobes: Vec<ExternalLobe>,
    /// Whether the file gave `energy_stderr` (a Monte Carlo model).
    pub has_stderr: bool,
}

impl ExternalModel {
    /// The photon count of the model for the two-sample test: 0 (exact) without standard
    /// errors, else `NOMINAL_PHOTONS`.
    pub fn photons(&self) -> u64 {
        if self.has_stderr { NOMINAL_PHOTONS } else { 0 }
    }
}

/// The order from which the model at `path` folds every order into one slot, when `path` is the
/// `lobes.csv` of another run directory (its `run.json` beside it, the directory validated as
/// [`RunDir::open`] validates the run): that run's `detector.max_order`. `None` for any other
/// file.
fn other_run_folding(path: &Path) -> Result<Option<usize>> {
    let Some(dir) = path.parent().filter(|_| path.file_name() == Some(schema::LOBES.file.as_ref())) else {
        return Ok(None);
    };
    let dir = if dir.as_os_str().is_empty() { Path::new(".") } else { dir };
    if !dir.join(schema::RUN_JSON).exists() {
        return Ok(None);
    }
    let other =
        RunDir::open(dir).with_context(|| format!("the run directory of the external model {}", path.display()))?;
    Ok(other.config.detector.max_order.map(|k| k as usize))
}

/// Reads and validates `path` against `run`; errors name the file, the line, the column, the
/// value and what is allowed.
pub fn read(path: &Path, run: &RunDir) -> Result<ExternalModel> {
    let (config, cases, grid) = (&run.config, &run.cases, run.grid);
    let file = path.display();
    let input = input::open(path, run.table_limit).with_context(|| format!("cannot read external model {file}"))?;
    let mut reader = csv::Reader::from_reader(input);
    let headers = reader.headers().with_context(|| format!("{file}: cannot read the header line"))?.clone();
    let column = |c: Column| headers.iter().position(|h| h.trim() == c.name);
    let required = |c: Column| {
        column(c).with_context(|| {
            let needed: Vec<&str> = REQUIRED.iter().map(|c| c.name).collect();
            format!("{file}: no column `{}` (needed: {})", c.name, needed.join(", "))
        })
    };
    let (case_col, order_col, hemi_col) =
        (required(schema::CASE)?, required(schema::ORDER)?, required(schema::HEMISPHERE)?);
    let bounds = [
        required(schema::COS_LO)?,
        required(schema::COS_HI)?,
        required(schema::PHI_LO_DEG)?,
        required(schema::PHI_HI_DEG)?,
    ];
    let energy_col = required(schema::ENERGY)?;
    let folded_col = column(schema::FOLDED);
    let other_run_folds = other_run_folding(path)?;
    let stderr_col = column(schema::ENERGY_STDERR);
    let rgb = config.is_rgb();
    let channel_col = column(schema::CHANNEL);
    if rgb && channel_col.is_none() {
        bail!("{file}: no column `channel`, and the run is RGB (give r, g and b rows)");
    }
    let mut lobes: Vec<ExternalLobe> = Vec::new();
    let mut index: HashMap<(usize, usize, usize, String), usize> = HashMap::new();
    let mut given: Vec<Vec<bool>> = Vec::new();
    for record in reader.records() {
        let record = record.with_context(|| format!("{file}: not a valid CSV row"))?;
        let line = record.position().map_or(0, |p| p.line());
        let field = |col: usize| record.get(col).unwrap_or("").trim();
        let at = |col: usize| format!("{file}, line {line}, column `{}`", headers.get(col).unwrap_or("?"));
        let number = |col: usize| -> Result<f64> {
            let v: f64 =
                field(col).parse().map_err(|_| anyhow::anyhow!("{}: {:?} is not a number", at(col), field(col)))?;
            if !v.is_finite() {
                bail!("{}: {v} is not allowed: a finite number", at(col));
            }
            Ok(v)
        };
        let case: usize = field(case_col).parse().map_err(|_| {
            anyhow::anyhow!("{}: {:?} is not a case index (0 to {})", at(case_col), field(case_col), cases.len() - 1)
        })?;
        let Some(c) = cases.get(case) else {
            bail!("{}: case {case} is not in the run (cases 0 to {})", at(case_col), cases.len() - 1)
        };
        let order: usize = field(order_col).parse().map_err(|_| {
            anyhow::anyhow!(
                "{}: {:?} is not an order (0 for all orders, k >= 1 for order k)",
                at(order_col),
                field(order_col)
            )
        })?;
        let run_folds = config.detector.max_order.map(|k| k as usize);
        let model_folds_here = match folded_col {
            Some(col) => match field(col) {
                "true" => true,
                "false" | "" => false,
                other => {
                    bail!("{}: {other:?} is not allowed: true (the slot K+ of a model folded at K) or false", at(col))
                }
            },
            None => other_run_folds == Some(order),
        };
        if order > 0 && model_folds_here && run_folds != Some(order) {
            let run_slot = match run_folds {
                Some(k) if order > k => format!("the run has no slot {order} (it folds every order from {k} on)"),
                _ => format!("the run's slot {order} is order {order} alone"),
            };
            bail!(
                "{}: order {order} is not allowed: the model's slot {order} is \"{order}+\" (every order from {order} \
                 on), and {run_slot}; compare runs whose detector.max_order is the same",
                at(order_col)
            );
        }
        if let Some(max) = run_folds
            && order >= max
            && order > 0
            && !model_folds_here
        {
            bail!(
                "{}: order {order} is not allowed: the run's slot {max} is \"{max}+\" (every order from {max} on), \
                 which a per-order model is never compared with; give order 0 (all orders) or an order below {max} \
                 (a model folded at {max} too says so: a `folded` column, or another run's lobes.csv with its run.json \
                 beside it)",
                at(order_col)
            );
        }
        let hemisphere = match field(hemi_col) {
            "R" => Hemisphere::R,
            "T" if c.material.transmits() => Hemisphere::T,
            other => {
                let allowed = if c.material.transmits() { "R or T" } else { "R (case {case} does not transmit)" };
                bail!("{}: {other:?} is not allowed: {}", at(hemi_col), allowed.replace("{case}", &case.to_string()))
            }
        };
        let channel = match channel_col {
            Some(col) if rgb => match field(col) {
                ch @ ("r" | "g" | "b") => ch.to_string(),
                other => bail!("{}: {other:?} is not allowed: r, g or b", at(col)),
            },
            Some(col) if !field(col).is_empty() => {
                bail!("{}: {:?} is not allowed: the run is mono (leave it empty)", at(col), field(col))
            }
            _ => String::new(),
        };
        let bin = bin_index(c, &grid, hemisphere, [0, 1, 2, 3].map(|i| number(bounds[i])).map(|r| r.ok()))
            .with_context(|| {
                format!(
                    "{file}, line {line}: cos [{}, {}], phi [{}, {}] deg is not a bin of the run ({} cos x {} phi bins)",
                    field(bounds[0]),
                    field(bounds[1]),
                    field(bounds[2]),
                    field(bounds[3]),
                    grid.cos_bins,
                    grid.phi_bins
                )
            })?;
        let energy = number(energy_col)?;
        let stderr = match stderr_col {
            Some(col) => {
                let s = number(col)?;
                if s < 0.0 {
                    bail!("{}: {s} is not allowed: a standard error >= 0", at(col));
                }
                s
            }
            None => 0.0,
        };
        let key = (case, order, hemisphere as usize, channel.clone());
        let k = *index.entry(key).or_insert_with(|| {
            lobes.push(ExternalLobe {
                case,
                order,
                hemisphere,
                channel,
                energy: vec![0.0; grid.bins()],
                stderr: vec![0.0; grid.bins()],
            });
            given.push(vec![false; grid.bins()]);
            lobes.len() - 1
        });
        if given[k][bin] {
            bail!("{file}, line {line}: this bin of case {case}, order {order}, {hemisphere:?} is given twice");
        }
        given[k][bin] = true;
        lobes[k].energy[bin] = energy;
        lobes[k].stderr[bin] = stderr;
    }
    if lobes.is_empty() {
        bail!("{file}: no rows");
    }
    for (lobe, given) in lobes.iter().zip(&given) {
        let missing = given.iter().filter(|g| !**g).count();
        if missing > 0 {
            bail!(
                "{file}: case {}, order {}, {:?}{}: {missing} of its {} bins are missing (give every bin of a lobe)",
                lobe.case,
                lobe.order,
                lobe.hemisphere,
                if lobe.channel.is_empty() { String::new() } else { format!(", channel {}", lobe.channel) },
                grid.bins()
            );
        }
    }
    lobes.sort_by_key(|l| (l.case, l.order, l.hemisphere as usize, l.channel.clone()));
    Ok(ExternalModel { lobes, has_stderr: stderr_col.is_some() })
}

/// The detector index of the bin with written bounds `[cos_lo, cos_hi, phi_lo_deg,
/// phi_hi_deg]` (cosines negative in the hemisphere below the surface), if it is one of the
/// grid's (to 1e-9).
fn bin_index(case: &Case, grid: &Grid, hemisphere: Hemisphere, bounds: [Option<f64>; 4]) -> Option<usize> {
    let [cos_lo, cos_hi, phi_lo, phi_hi] = bounds.map(|b| b.unwrap_or(f64::NAN));
    let (lo, hi) = if hemisphere_sign(case.side, hemisphere) > 0.0 { (cos_lo, cos_hi) } else { (-cos_hi, -cos_lo) };
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-9;
    let ic = (lo * grid.cos_bins as f64).round();
    let ip = (phi_lo / 360.0 * grid.phi_bins as f64).round();
    if !(ic >= 0.0 && ic < grid.cos_bins as f64 && ip >= 0.0 && ip < grid.phi_bins as f64) {
        return None;
    }
    let (ic, ip) = (ic as usize, ip as usize);
    let (clo, chi) = grid.cos_edges(ic);
    let (plo, phi) = grid.phi_edges_deg(ip);
    (close(lo, clo) && close(hi, chi) && close(phi_lo, plo) && close(phi_hi, phi)).then_some(ic * grid.phi_bins + ip)
}
