//! `smithwalk compare`: a run's measured lobes against analytic models in the same bins, per
//! case, order and hemisphere (THEORY.md §4.7, §9.5).
//!
//! Models: `single` (exact single scattering by quadrature, order 1, every facet material with
//! the true Smith Lambda and visible normals), `heitz-nee` (next-event
//! estimation along the walk, every order), `wang-correlated` and `wang-uncorrelated` (the
//! Wang et al. 2022 chains), `exact-position-free` (the walk with its depths integrated out,
//! §7.1, for one-sided facets); the Monte Carlo models run into the same detector with their own
//! standard errors. `hammon-fit` is Hammon 2017's closed-form approximation for his facet
//! (order 1 and all orders), integrated over the bins by quadrature.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::Path;

use anyhow::Result;
use microsurface::wang::Shadowing;

use crate::analysis::compensation::{AlbedoCache, Compensation, compensated_channels};
use crate::analysis::external::ExternalModel;
use crate::analysis::models::{HammonFitPart, hammon_fit_bins, single_scattering_bins};
use crate::analysis::stats::{self, ChiSquare, WeightedBin};
use crate::atomic::write_atomically;
use crate::engine::detector::{Grid, Hemisphere};
use crate::engine::run::{Estimator, Shard};
use crate::engine::{RunOptions, Simulation};
use crate::io::output::case_fields;
use crate::io::rundir::{Table, read_config};
use crate::setup::config::{Config, Model};

/// Outgoing directions per hit of the next-event estimator.
const NEE_DIRECTIONS: u32 = 4;

/// A bin's value and standard error.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Value {
    energy: f64,
    stderr: f64,
}

/// Key of one bin row: case, order, hemisphere, channel, cos_lo, phi_lo (as written).
type BinKey = (String, String, String, String, String, String);
/// Key of one lobe: case, order, hemisphere, channel.
type LobeKey = (String, String, String, String);

/// The lobe key of every record: case, order, hemisphere, channel ("" for mono runs).
fn lobe_keys(table: &Table) -> Result<Vec<LobeKey>> {
    let (case, order, hemi) = (table.column("case")?, table.column("order")?, table.column("hemisphere")?);
    let channel = table.headers.iter().position(|h| h == "channel");
    Ok(table
        .records
        .iter()
        .map(|r| {
            let channel = channel.map_or(String::new(), |c| r[c].to_string());
            (r[case].to_string(), r[order].to_string(), r[hemi].to_string(), channel)
        })
        .collect())
}

/// The measured bins of a run directory's `lobes.csv`.
fn read_lobes(path: &Path) -> Result<HashMap<BinKey, Value>> {
    let table = Table::read(path)?;
    let (cos_lo, phi_lo) = (table.column("cos_lo")?, table.column("phi_lo_deg")?);
    let (energy, se) = (table.column("energy")?, table.column("energy_stderr")?);
    let mut out = HashMap::new();
    for ((case, order, hemi, channel), r) in lobe_keys(&table)?.into_iter().zip(&table.records) {
        let key = (case, order, hemi, channel, r[cos_lo].to_string(), r[phi_lo].to_string());
        out.insert(key, Value { energy: r[energy].parse()?, stderr: r[se].parse()? });
    }
    Ok(out)
}

/// The measured albedos of a run directory's `summary.csv`, per lobe.
fn read_summary(path: &Path) -> Result<HashMap<LobeKey, Value>> {
    let table = Table::read(path)?;
    let (albedo, se) = (table.column("albedo")?, table.column("albedo_stderr")?);
    let mut out = HashMap::new();
    for (key, r) in lobe_keys(&table)?.into_iter().zip(&table.records) {
        out.insert(key, Value { energy: r[albedo].parse()?, stderr: r[se].parse()? });
    }
    Ok(out)
}

/// One model's prediction of one bin.
struct Prediction {
    key: BinKey,
    fields: Vec<String>,
    value: Value,
    solid_angle: f64,
    bounds: [f64; 4],
}

/// The model's predictions for every bin of every case it applies to.
fn predict(
    model: Model,
    config: &Config,
    sim_photons: u64,
    seed: u64,
    threads: Option<usize>,
    external: Option<&ExternalModel>,
) -> Result<Vec<Prediction>> {
    let grid = Grid { cos_bins: config.detector.cos_theta_bins, phi_bins: config.detector.phi_bins };
    let cases = crate::setup::cases::expand(config);
    let mut out = Vec::new();
    let rows = |case: &crate::setup::cases::Case,
                order: usize,
                hemisphere: Hemisphere,
                channel: &str,
                values: &mut dyn FnMut(usize) -> Value,
                out: &mut Vec<Prediction>| {
        let sign = crate::io::output::hemisphere_sign(case.side, hemisphere);
        for ic in 0..grid.cos_bins {
            let (lo, hi) = grid.cos_edges(ic);
            let (cos_lo, cos_hi) = if sign > 0.0 { (lo, hi) } else { (-hi, -lo) };
            for ip in 0..grid.phi_bins {
                let (phi_lo, phi_hi) = grid.phi_edges_deg(ip);
                let key = (
                    case.index.to_string(),
                    order.to_string(),
                    format!("{hemisphere:?}"),
                    channel.to_string(),
                    cos_lo.to_string(),
                    phi_lo.to_string(),
                );
                out.push(Prediction {
                    key,
                    fields: case_fields(case),
                    value: values(ic * grid.phi_bins + ip),
                    solid_angle: grid.projected_solid_angle(ic),
                    bounds: [cos_lo, cos_hi, phi_lo, phi_hi],
                });
            }
        }
    };
    // Closed-form models: channel 0 of RGB runs, and a quadrature error far below the
    // statistical error of the measurement.
    let channel = if config.is_rgb() { "r" } else { "" };
    let tol = 1e-3 / (sim_photons as f64 * grid.bins() as f64);
    match model {
        Model::Single => {
            for case in &cases {
                for &h in crate::io::output::hemispheres(case) {
                    let Some(bins) = single_scattering_bins(case, &grid, h, tol) else { continue };
                    rows(case, 1, h, channel, &mut |i| Value { energy: bins[i], stderr: 0.0 }, &mut out);
                }
            }
        }
        Model::HammonFit => {
            for case in &cases {
                for (slot, part) in [(0, HammonFitPart::All), (1, HammonFitPart::Single)] {
                    let Some(bins) = hammon_fit_bins(case, &grid, part, tol) else { continue };
                    rows(case, slot, Hemisphere::R, channel, &mut |i| Value { energy: bins[i], stderr: 0.0 }, &mut out);
                }
            }
        }
        Model::KullaConty | Model::Turquin | Model::FdezAguera => {
            let compensation = match model {
                Model::KullaConty => Compensation::KullaConty,
                Model::Turquin => Compensation::Turquin,
                _ => Compensation::FdezAguera,
            };
            let mut cache = AlbedoCache::default();
            for case in &cases {
                let rgb = config.is_rgb();
                let Some(lobes) = compensated_channels(compensation, case, &grid, tol, rgb, &mut cache) else {
                    continue;
                };
                for (channel, bins) in lobes {
                    rows(case, 0, Hemisphere::R, channel, &mut |i| Value { energy: bins[i], stderr: 0.0 }, &mut out);
                }
            }
        }
        Model::External => {
            for lobe in external.map_or(&[][..], |e| &e.lobes[..]) {
                let value = &mut |i: usize| Value { energy: lobe.energy[i], stderr: lobe.stderr[i] };
                rows(&cases[lobe.case], lobe.order, lobe.hemisphere, &lobe.channel, value, &mut out);
            }
        }
        Model::HeitzNee | Model::WangCorrelated | Model::WangUncorrelated | Model::ExactPositionFree => {
            let estimator = match model {
                Model::WangCorrelated => Estimator::Wang(Shadowing::Correlated),
                Model::WangUncorrelated => Estimator::Wang(Shadowing::Uncorrelated),
                Model::ExactPositionFree => Estimator::PositionFree,
                _ => Estimator::HeitzNee(NEE_DIRECTIONS),
            };
            let model_config = Config { seed, ..config.clone() };
            let options = RunOptions { estimator, shard: Shard::WHOLE, threads, show_progress: true };
            let sim = crate::engine::simulate_from(&model_config, &options, None, &mut |_, _, _| Ok(()))?;
            for_each_lobe(&sim, &mut |case, order, hemisphere, channel, value| {
                if model != Model::ExactPositionFree || case.position_free_applies() {
                    rows(case, order, hemisphere, channel, value, &mut out)
                }
            });
        }
    }
    Ok(out)
}

type LobeVisitor<'a> =
    dyn FnMut(&crate::setup::cases::Case, usize, Hemisphere, &str, &mut dyn FnMut(usize) -> Value) + 'a;

/// Calls `f` for every lobe (case, order, hemisphere, channel) of a simulation with a function
/// giving each bin's value.
fn for_each_lobe(sim: &Simulation, f: &mut LobeVisitor<'_>) {
    fn visit<const C: usize>(
        case: &crate::setup::cases::Case,
        d: &crate::engine::detector::Detector<C>,
        f: &mut LobeVisitor<'_>,
    ) {
        let bins = d.grid.bins();
        let n = d.tallies.photons;
        for (slot, tallies) in d.tallies.orders.iter().enumerate() {
            for &h in crate::io::output::hemispheres(case) {
                for c in 0..C {
                    let channel = if C > 1 { ["r", "g", "b"][c] } else { "" };
                    let mut value = |i: usize| {
                        let (energy, stderr) = tallies.bins[h as usize * bins + i].mean_and_stderr(n, c);
                        Value { energy, stderr }
                    };
                    f(case, slot, h, channel, &mut value);
                }
            }
        }
    }
    for (case, result) in sim.cases.iter().zip(&sim.results) {
        match result {
            crate::engine::run::CaseResult::Mono(d) => visit(case, d, f),
            crate::engine::run::CaseResult::Rgb(d) => visit(case, d, f),
        }
    }
}

/// The agreement of one lobe with one model.
struct LobeComparison {
    key: LobeKey,
    fields: Vec<String>,
    model: Model,
    test: ChiSquare,
    rel_l1: f64,
    rel_l2: f64,
    albedo_measured: Value,
    albedo_model: Value,
}

impl LobeComparison {
    fn albedo_diff_se(&self) -> f64 {
        let (a, b) = (self.albedo_measured, self.albedo_model);
        (a.energy - b.energy) / (a.stderr * a.stderr + b.stderr * b.stderr).sqrt()
    }
}

/// A bin as per-photon moments: mean `e` and second moment `q = Q/N`, recovered from the
/// written energy and standard error (`se^2 = (q - e^2) / (N - 1)`).
fn moments(v: Value, photons: u64) -> WeightedBin {
    let n = photons as f64;
    WeightedBin { mean: v.energy, second_moment: v.stderr * v.stderr * (n - 1.0) + v.energy * v.energy }
}

/// Compares one lobe bin by bin with [`stats::two_sample_at_null`] (the model exact when
/// `model_photons = 0`), pooling bins in which less than 5 photons' worth of energy is
/// expected; also the relative L1 and L2 errors and the model's albedo.
fn compare_lobe(
    measured: &HashMap<BinKey, Value>,
    predictions: &[&Prediction],
    photons: u64,
    model_photons: u64,
) -> (ChiSquare, f64, f64, Value) {
    let (mut l1, mut l2, mut norm1, mut norm2) = (0.0, 0.0, 0.0, 0.0);
    let (mut albedo, mut albedo_var) = (0.0, 0.0);
    let (mut observed, mut model) = (Vec::new(), Vec::new());
    for p in predictions {
        let m = measured.get(&p.key).copied().unwrap_or_default();
        let (o, e) = (m.energy, p.value.energy);
        l1 += (o - e).abs();
        l2 += (o - e) * (o - e);
        norm1 += e.abs();
        norm2 += e * e;
        albedo += e;
        albedo_var += p.value.stderr * p.value.stderr;
        observed.push(moments(m, photons));
        model.push(moments(p.value, model_photons));
    }
    let test = stats::two_sample_at_null(&observed, photons, &model, model_photons, 5.0);
    let rel_l1 = if norm1 > 0.0 { l1 / norm1 } else { 0.0 };
    let rel_l2 = if norm2 > 0.0 { (l2 / norm2).sqrt() } else { 0.0 };
    (test, rel_l1, rel_l2, Value { energy: albedo, stderr: albedo_var.sqrt() })
}

/// Runs the comparison of `run_dir` with `models` and the user's model in `external`, if any,
/// and writes `models.csv` and `compare.csv` into it; returns the human-readable report.
pub fn compare(
    run_dir: &Path,
    models: &[Model],
    paths: Option<u64>,
    threads: Option<usize>,
    external: Option<&Path>,
) -> Result<String> {
    let mut config = read_config(run_dir)?;
    let external = external.map(|path| crate::analysis::external::read(path, &config)).transpose()?;
    let models = &[models, if external.is_some() { &[Model::External][..] } else { &[] }].concat();
    let measured_photons = config.paths;
    let measured = read_lobes(&run_dir.join("lobes.csv"))?;
    let summary = read_summary(&run_dir.join("summary.csv"))?;
    if let Some(p) = paths {
        config.paths = p;
    }
    config.precision = None;
    config.compare = None;
    let rgb = config.is_rgb();
    let mut model_rows = csv::Writer::from_writer(Vec::new());
    let mut header: Vec<&str> = crate::io::output::CASE_COLUMNS.to_vec();
    header.extend(["model", "order", "hemisphere"]);
    if rgb {
        header.push("channel");
    }
    header.extend(["cos_lo", "cos_hi", "phi_lo_deg", "phi_hi_deg", "energy", "energy_stderr", "bsdf"]);
    model_rows.write_record(&header)?;
    let mut comparisons = Vec::new();
    for (k, &model) in models.iter().enumerate() {
        let seed = config.seed.wrapping_add(0x9e37_79b9_7f4a_7c15_u64.wrapping_mul(k as u64 + 1));
        let predictions = predict(model, &config, measured_photons, seed, threads, external.as_ref())?;
        let mut lobes: Vec<(LobeKey, Vec<&Prediction>)> = Vec::new();
        for p in &predictions {
            let mut row = p.fields.clone();
            row.extend([model.name().to_string(), p.key.1.clone(), p.key.2.clone()]);
            if rgb {
                row.push(p.key.3.clone());
            }
            row.extend(p.bounds.map(|b| b.to_string()));
            row.extend([p.value.energy, p.value.stderr, p.value.energy / p.solid_angle].map(|v| v.to_string()));
            model_rows.write_record(&row)?;
            let lobe = (p.key.0.clone(), p.key.1.clone(), p.key.2.clone(), p.key.3.clone());
            match lobes.last_mut() {
                Some((key, bins)) if *key == lobe => bins.push(p),
                _ => lobes.push((lobe, vec![p])),
            }
        }
        for (key, bins) in lobes {
            let albedo_measured = summary.get(&key).copied().unwrap_or_default();
            let model_photons = match &external {
                Some(e) if model == Model::External => e.photons(),
                _ if model.is_exact() => 0,
                _ => config.paths,
            };
            let (test, rel_l1, rel_l2, albedo_model) = compare_lobe(&measured, &bins, measured_photons, model_photons);
            comparisons.push(LobeComparison {
                fields: bins[0].fields.clone(),
                key,
                model,
                test,
                rel_l1,
                rel_l2,
                albedo_measured,
                albedo_model,
            });
        }
    }
    let mut compare_rows = csv::Writer::from_writer(Vec::new());
    let mut header: Vec<&str> = crate::io::output::CASE_COLUMNS.to_vec();
    header.extend(["model", "order", "hemisphere"]);
    if rgb {
        header.push("channel");
    }
    header.extend([
        "chi2",
        "dof",
        "p_value",
        "rel_l1",
        "rel_l2",
        "albedo_measured",
        "albedo_measured_stderr",
        "albedo_model",
        "albedo_model_stderr",
        "albedo_diff_se",
    ]);
    compare_rows.write_record(&header)?;
    for c in &comparisons {
        let mut row = c.fields.clone();
        row.extend([c.model.name().to_string(), c.key.1.clone(), c.key.2.clone()]);
        if rgb {
            row.push(c.key.3.clone());
        }
        row.extend([c.test.statistic.to_string(), c.test.dof.to_string(), c.test.p_value.to_string()]);
        row.extend(
            [
                c.rel_l1,
                c.rel_l2,
                c.albedo_measured.energy,
                c.albedo_measured.stderr,
                c.albedo_model.energy,
                c.albedo_model.stderr,
                c.albedo_diff_se(),
            ]
            .map(|v| v.to_string()),
        );
        compare_rows.write_record(&row)?;
    }
    write_atomically(
        run_dir,
        &[("models.csv", model_rows.into_inner()?), ("compare.csv", compare_rows.into_inner()?)],
    )?;
    Ok(report(&comparisons, models))
}

/// The worst lobes per model: lowest p-values, with their lobe errors and albedo differences.
fn report(comparisons: &[LobeComparison], models: &[Model]) -> String {
    let mut out = String::new();
    for &model in models {
        let mut mine: Vec<&LobeComparison> = comparisons.iter().filter(|c| c.model == model).collect();
        if mine.is_empty() {
            let _ = writeln!(out, "{}: applies to no case of this run", model.name());
            continue;
        }
        mine.sort_by(|a, b| a.test.p_value.total_cmp(&b.test.p_value));
        let _ = writeln!(out, "{} ({} lobes), worst first:", model.name(), mine.len());
        let _ = writeln!(
            out,
            "  {:>5} {:>5} {:>4} {:>10} {:>6} {:>10} {:>8} {:>8} {:>11}",
            "case", "order", "hemi", "chi2", "dof", "p", "rel L1", "rel L2", "albedo diff"
        );
        for c in mine.iter().take(5) {
            let _ = writeln!(
                out,
                "  {:>5} {:>5} {:>4} {:>10.1} {:>6} {:>10.2e} {:>8.4} {:>8.4} {:>8.1} SE",
                c.key.0,
                c.key.1,
                c.key.2,
                c.test.statistic,
                c.test.dof,
                c.test.p_value,
                c.rel_l1,
                c.rel_l2,
                c.albedo_diff_se()
            );
        }
    }
    out
}
