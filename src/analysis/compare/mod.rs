//! `smithwalk compare`: a run's measured lobes against models in the same bins, per case, order
//! and hemisphere, with a verdict per model (docs/theory.md §4.7, §9.5; docs/compare.md).
//!
//! Models: `single` (exact single scattering by quadrature, order 1, every facet material with
//! the true Smith Lambda and visible normals), `heitz-nee` (next-event estimation along the
//! walk, every order), `exact-position-free` (the walk with its depths integrated out, §7.1, for
//! one-sided facets), `cui2023-released` (Cui et al. 2023 as its released code computes it,
//! conductors, §7.3): these four are exact for the Smith walk, so a rejection says the
//! measurement (or the oracle) is wrong. `wang-correlated` and `wang-uncorrelated` (the Wang et
//! al. 2022 chains) and `hammon-fit` (Hammon 2017's closed-form fit of his facet, order 1 and all
//! orders) are approximations: their rejections measure how far they are from the walk.
//! `lee2018` (Lee et al. 2018's specular V-grooves, conductors, every order slot, §14) is an
//! approximation on another microsurface: its rejections measure how far V-grooves are from
//! the Smith walk, order by order. The Monte Carlo models run into the same detector with their
//! own standard errors.
//!
//! Like with like: the run's last order slot "K+" (`max_order = K`) holds every order from K
//! on; a Monte Carlo model is walked with the same `max_order`, so its slots are folded exactly
//! as the run's; `hammon-fit` folds its order-1 part into its all-orders part for a "1+" slot;
//! `lee2018` sums its orders from K on (up to its `MAX_ORDER`) for the "K+" slot;
//! `single`, order 1 alone, is never tested against a "1+" slot. With `max_order = 1` the "1+"
//! slot is the all-orders lobe, which is tested once, as order 0.
//!
//! This module drives; its children each do one job: `predict` (models to per-bin values),
//! `verdict` (the statistics), `report` (console and CSV text) and `lobe` (a lobe's key,
//! folding and which lobes are tested).

mod lobe;
mod predict;
mod report;
mod verdict;

use std::io::IsTerminal as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Result, bail};
use indicatif::{ProgressBar, ProgressFinish, ProgressStyle};

use self::lobe::{channel_index, folded_slot, hemisphere_name, is_tested};
use self::predict::{
    ModelLobe, Predictions, QUADRATURE_FRACTION, chain_model, closed_form, compensation, cpu_seconds,
    cui_released_unavailable, external_lobes, joint_chains, model_seed, monte_carlo, skipped_cases,
};
pub use self::report::p_value_text;
use self::report::{compare_table, models_table, report};
pub use self::verdict::{DEFAULT_FAMILY_LEVEL, Verdict, is_exact_oracle, is_monte_carlo};
use self::verdict::{LobeComparison, Value, compare_lobe, verdicts};
use crate::analysis::albedo_table::AlbedoTable;
use crate::analysis::compensation::{Compensation, applies, materialx_unavailable};
use crate::analysis::external::ExternalModel;
use crate::analysis::models::{
    MAX_BIN_EVALUATIONS, MAX_EXIT_BIN_EVALUATIONS, hammon_fit_unavailable, single_scattering_unavailable,
};
use crate::analysis::vgroove::lee2018_unavailable;
use crate::atomic::write_atomically;
use crate::io::compare_json::{self, Settings};
use crate::io::rundir::{BinValue, LobeId, RunDir};
use crate::io::schema;
use crate::setup::config::{MAX_PATHS, Model};

/// What `smithwalk compare` is asked to do.
#[derive(Clone, Debug)]
pub struct CompareOptions {
    pub models: Vec<Model>,
    /// Photons per case for the Monte Carlo models (default: the run's).
    pub paths: Option<u64>,
    pub threads: Option<usize>,
    /// The family-wise level of each model's verdict (Sidak over its lobes).
    pub family_level: f64,
    /// A user's own model in the run's bins (`--external`), judged as [`Model::External`].
    pub external: Option<PathBuf>,
    /// A table of `E` and `E_avg` with F = 1 that the compensation models read in place of the
    /// exact functions (`--albedo-table`, [`AlbedoTable`]).
    pub albedo_table: Option<PathBuf>,
    /// Whether `models` is the default list, not one the user named: a model of it that applies
    /// to no case of the run is then only named in one line of the report, with no section.
    pub default_models: bool,
}

impl CompareOptions {
    pub fn new(models: Vec<Model>, paths: Option<u64>, threads: Option<usize>) -> Self {
        Self {
            models,
            paths,
            threads,
            family_level: DEFAULT_FAMILY_LEVEL,
            external: None,
            albedo_table: None,
            default_models: false,
        }
    }

    fn validate(&self) -> Result<()> {
        if let Some(p) = self.paths
            && !(2..=MAX_PATHS).contains(&p)
        {
            bail!("`--paths` = {p} is not allowed: from 2 to 10^15 photons per case for the Monte Carlo models");
        }
        if self.threads == Some(0) {
            bail!("`--threads` = 0 is not allowed: at least 1 thread");
        }
        if !(self.family_level > 0.0 && self.family_level < 1.0) {
            bail!("`--level` = {} is not allowed: a family-wise level in (0, 1), such as 0.01", self.family_level);
        }
        Ok(())
    }
}

/// The outcome of `smithwalk compare`: the report to print and the verdicts.
#[derive(Clone, Debug)]
pub struct Outcome {
    pub report: String,
    pub verdicts: Vec<Verdict>,
}

impl Outcome {
    /// Whether an exact oracle rejected a lobe (`--fail-on-reject` turns this into exit status 3).
    pub fn exact_oracle_rejected(&self) -> bool {
        self.verdicts.iter().any(|v| is_exact_oracle(v.model) && v.rejected > 0)
    }
}

/// A progress bar on a terminal naming the model, hidden otherwise.
fn model_progress(model: Model, terminal: bool) -> ProgressBar {
    if !terminal {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(0);
    bar.set_style(
        ProgressStyle::with_template("{msg} {elapsed_precise} [{bar:40}] {pos}/{len} lobes")
            .expect("static template")
            .progress_chars("=> "),
    );
    bar.set_message(model.name());
    bar
}

/// A spinner on a terminal naming a step of `compare` outside the models (reading and checking a
/// run of many cases takes seconds, so does writing its tables), hidden otherwise.
fn step_progress(what: String, terminal: bool) -> ProgressBar {
    if !terminal {
        return ProgressBar::hidden();
    }
    // Cleared also when an error ends the step.
    let bar = ProgressBar::new_spinner().with_finish(ProgressFinish::AndClear);
    bar.set_style(ProgressStyle::with_template("{spinner} {msg} {elapsed_precise}").expect("static template"));
    bar.set_message(what);
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    bar
}

/// [`compare_with`] at the default family level: the report to print.
pub fn compare(run_dir: &Path, models: &[Model], paths: Option<u64>, threads: Option<usize>) -> Result<String> {
    compare_with(run_dir, &CompareOptions::new(models.to_vec(), paths, threads)).map(|outcome| outcome.report)
}

/// Runs the comparison of `run_dir` with the models of `options`, writes `models.csv`,
/// `compare.csv` and their seal `compare.json` into it, as one set, and returns the report and
/// the verdicts. Progress goes to stderr: on a terminal every step (reading the run, each model, writing the tables), otherwise one line
/// per model when it finishes.
pub fn compare_with(run_dir: &Path, options: &CompareOptions) -> Result<Outcome> {
    options.validate()?;
    let terminal = std::io::stderr().is_terminal();
    let reading = step_progress(format!("compare: reading {}", run_dir.display()), terminal);
    let run = RunDir::open(run_dir)?;
    if let Some(reason) = options.models.iter().find_map(|m| m.refuses_threshold(run.config.energy.threshold)) {
        bail!("`--models`: {reason}");
    }
    let external = options.external.as_deref().map(|path| crate::analysis::external::read(path, &run)).transpose()?;
    let models = [&options.models[..], if external.is_some() { &[Model::External][..] } else { &[] }].concat();
    let albedo_table = options.albedo_table.as_deref().map(AlbedoTable::read).transpose()?;
    if albedo_table.is_some() && !models.iter().any(|&m| Compensation::of(m).is_some_and(Compensation::reads_table)) {
        bail!(
            "`--albedo-table` is only read by the models kulla-conty, turquin and fdez-aguera; add one to `--models`"
        );
    }
    if let Some(table) = &albedo_table {
        for case in run.cases.iter().filter(|c| applies(c)) {
            table.check(case)?;
        }
    }
    let measured = run.measured()?;
    let summary = run.summary()?;
    reading.finish_and_clear();
    let measured_photons = run.config.paths;
    let mut config = run.config.clone();
    if let Some(p) = options.paths {
        config.paths = p;
    }
    config.precision = None;
    config.compare = None;
    let rgb = config.is_rgb();
    let folded = folded_slot(&config);
    let albedo = |lobe: &LobeId| {
        summary
            .iter()
            .find(|r| {
                (r.case, r.order, r.hemisphere.as_str(), channel_index(r.channel.as_deref()))
                    == (lobe.0, lobe.1, lobe.2.as_str(), lobe.3)
            })
            .map_or(Value::default(), |r| Value { energy: r.albedo, stderr: r.albedo_stderr })
    };
    let mut predicted: Vec<(Model, Vec<ModelLobe>)> = Vec::new();
    let mut comparisons = Vec::new();
    let mut notes: Vec<(Model, String)> = Vec::new();
    let mut skipped: Vec<(Model, String)> = Vec::new();
    let empty: Vec<BinValue> = vec![BinValue::default(); run.grid.bins()];
    let mut joint: Option<Vec<(Model, Predictions)>> = None;
    for (k, &model) in models.iter().enumerate() {
        // The joint walk is timed on its own line, before the first of its models.
        if chain_model(model).is_some() && joint.is_none() {
            joint = Some(joint_chains(&models, &config, options.threads, terminal)?);
        }
        let (start, cpu_start) = (Instant::now(), cpu_seconds());
        if terminal {
            eprintln!("compare: {} ({}/{})", model.name(), k + 1, models.len());
        }
        let seed = model_seed(config.seed, model.name());
        let predictions = match model {
            Model::Single | Model::HammonFit | Model::Lee2018 => {
                let bar = model_progress(model, terminal);
                let p = closed_form(model, &run, &measured, &bar);
                bar.finish_and_clear();
                let unavailable = match model {
                    Model::Single => single_scattering_unavailable,
                    Model::Lee2018 => lee2018_unavailable,
                    _ => hammon_fit_unavailable,
                };
                if let Some(note) = skipped_cases(&run.cases, unavailable) {
                    notes.push((model, note));
                }
                p
            }
            Model::KullaConty | Model::Turquin | Model::FdezAguera => {
                let bar = model_progress(model, terminal);
                let p = compensation(model, &run, &measured, albedo_table.as_ref(), &bar);
                bar.finish_and_clear();
                if let Some(table) = &albedo_table {
                    notes.push((model, table.describe()));
                }
                p
            }
            Model::MaterialX => {
                let bar = model_progress(model, terminal);
                let p = compensation(model, &run, &measured, None, &bar);
                bar.finish_and_clear();
                if let Some(note) = skipped_cases(&run.cases, materialx_unavailable) {
                    notes.push((model, note));
                }
                p
            }
            Model::External => external_lobes(external.as_ref()),
            _ => {
                if model == Model::CuiReleased
                    && let Some(note) = skipped_cases(&run.cases, cui_released_unavailable)
                {
                    notes.push((model, note));
                }
                match joint.as_mut().and_then(|j| j.iter().position(|(m, _)| *m == model).map(|i| j.swap_remove(i).1)) {
                    Some(p) => p,
                    None => monte_carlo(model, &config, seed, options.threads, terminal)?,
                }
            }
        };
        if let Some(reason) = predictions.skipped {
            skipped.push((model, reason));
        }
        if predictions.capped > 0 {
            notes.push((
                model,
                format!(
                    "the quadrature stopped at its evaluation bound ({MAX_BIN_EVALUATIONS} per bin, \
                     {MAX_EXIT_BIN_EVALUATIONS} for the diffuse exits of diffuse and Hammon facets) in {} bin integrals; largest error estimate there: {:.2} \
                     standard errors of the bin",
                    predictions.capped,
                    predictions.worst_capped * QUADRATURE_FRACTION
                ),
            ));
        }
        let model_photons = match model {
            Model::External => external.as_ref().map_or(0, ExternalModel::photons),
            _ if is_monte_carlo(model) => config.paths,
            _ => 0,
        };
        for lobe in &predictions.lobes {
            let h = hemisphere_name(lobe.hemisphere);
            let id: LobeId = (lobe.case, lobe.order, h.clone(), lobe.channel);
            let bins = measured.get(lobe.case, lobe.order, &h, lobe.channel).unwrap_or(&empty);
            if !is_tested(&config, &run.cases[lobe.case], model, lobe.order, lobe.channel) {
                continue;
            }
            let (test, rel_l1, rel_l2, albedo_model) = compare_lobe(bins, lobe, measured_photons, model_photons);
            comparisons.push(LobeComparison {
                albedo_measured: albedo(&id),
                lobe: id,
                model,
                test,
                rel_l1,
                rel_l2,
                albedo_model,
            });
        }
        predicted.push((model, predictions.lobes));
        let tested = comparisons.iter().filter(|c| c.model == model).count();
        eprintln!(
            "compare: {} done: {tested} lobes in {:.1} s ({:.1} CPU s)",
            model.name(),
            start.elapsed().as_secs_f64(),
            cpu_seconds() - cpu_start
        );
    }
    let writing = step_progress(
        format!("compare: writing {}, {} and {}", schema::MODELS.file, schema::COMPARE.file, schema::COMPARE_JSON.file),
        terminal,
    );
    let verdicts = verdicts(&models, &comparisons, &skipped, options.family_level);
    let compare_csv = compare_table(&comparisons, &run, &verdicts, options.family_level, rgb, folded)?;
    let models_csv = models_table(&run, &predicted, rgb, folded)?;
    let settings = Settings {
        models: models.iter().map(|m| m.name().to_string()).collect(),
        paths: config.paths,
        seed: config.seed,
        family_level: options.family_level,
        external: options.external.as_ref().map(|p| p.display().to_string()),
        albedo_table: options.albedo_table.as_ref().map(|p| p.display().to_string()),
    };
    let record = compare_json::text(
        &run.identity,
        &settings,
        &[(schema::MODELS.file, &models_csv), (schema::COMPARE.file, &compare_csv)],
    )?;
    // One set: compare.json last, so that a compare killed between the renames leaves tables
    // that the previous record does not describe, which readers refuse.
    write_atomically(
        run_dir,
        &[(schema::MODELS.file, models_csv), (schema::COMPARE.file, compare_csv), (schema::COMPARE_JSON.file, record)],
    )?;
    writing.finish_and_clear();
    let report = report(&comparisons, &verdicts, &notes, options.family_level, rgb, folded, options.default_models);
    Ok(Outcome { report, verdicts })
}
