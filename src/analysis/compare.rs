//! `smithwalk compare`: a run's measured lobes against models in the same bins, per case, order
//! and hemisphere, with a verdict per model (docs/theory.md §4.7, §9.5; docs/compare.md).
//!
//! Models: `single` (exact single scattering by quadrature, order 1, every facet material with
//! the true Smith Lambda and visible normals), `heitz-nee` (next-event estimation along the
//! walk, every order), `exact-position-free` (the walk with its depths integrated out, §7.1, for
//! one-sided facets): these three are exact for the Smith walk, so a rejection says the
//! measurement (or the oracle) is wrong. `wang-correlated` and `wang-uncorrelated` (the Wang et
//! al. 2022 chains) and `hammon-fit` (Hammon 2017's closed-form fit of his facet, order 1 and all
//! orders) are approximations: their rejections measure how far they are from the walk. The
//! Monte Carlo models run into the same detector with their own standard errors.
//!
//! Like with like: the run's last order slot "K+" (`max_order = K`) holds every order from K
//! on; a Monte Carlo model is walked with the same `max_order`, so its slots are folded exactly
//! as the run's; `hammon-fit` folds its order-1 part into its all-orders part for a "1+" slot;
//! `single`, order 1 alone, is never tested against a "1+" slot. With `max_order = 1` the "1+"
//! slot is the all-orders lobe, which is tested once, as order 0.

use std::fmt::Write as _;
use std::io::IsTerminal as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Result, bail};
use indicatif::{ProgressBar, ProgressStyle};
use microsurface::wang::Shadowing;

use crate::analysis::albedo_table::AlbedoTable;
use crate::analysis::compensation::{AlbedoCache, Compensation, compensated_bins};
use crate::analysis::external::ExternalModel;
use crate::analysis::models::{
    HammonFitPart, LobeIntegrals, MAX_BIN_EVALUATIONS, MAX_EXIT_BIN_EVALUATIONS, hammon_fit_lobe_bins,
    hammon_fit_unavailable, single_scattering_lobe, single_scattering_unavailable,
};
use crate::analysis::stats::{self, ChiSquare, WeightedBin};
use crate::atomic::write_atomically;
use crate::engine::detector::{Detector, Hemisphere};
use crate::engine::run::{CaseResult, ChainModel, Estimator, Shard};
use crate::engine::{RunOptions, Simulation};
use crate::io::output::{bin_edges, case_fields, hemisphere_sign, hemispheres};
use crate::io::rundir::{BinValue, LobeId, Lobes, RunDir};
use crate::io::schema;
use crate::setup::cases::Case;
use crate::setup::config::{Config, Model};

/// Outgoing directions per hit of the next-event estimator.
const NEE_DIRECTIONS: u32 = 4;

/// The family-wise level at which each model's lobes are judged unless `--level` says otherwise.
pub const DEFAULT_FAMILY_LEVEL: f64 = 0.01;

/// The quadrature tolerance of a bin of a closed-form model, as a fraction of the measured
/// bin's standard error (at least of one photon's energy, `1/N`, for an empty bin): a bias of
/// 0.05 standard errors moves a bin's expected chi-square by 0.0025, far below its spread.
const QUADRATURE_FRACTION: f64 = 0.05;

/// Bins of a lobe with less than this many photons' worth of energy are pooled (§9.5).
const MIN_COUNT: f64 = 5.0;

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
            && p < 2
        {
            bail!("`--paths` = {p} is not allowed: at least 2 photons per case for the Monte Carlo models");
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

/// Whether a model is exact for the Smith walk, so that its rejection is a failure (of the
/// measurement or of the model's code) rather than a measure of an approximation.
pub fn is_exact_oracle(model: Model) -> bool {
    matches!(model, Model::Single | Model::HeitzNee | Model::ExactPositionFree)
}

/// Whether a model is estimated by a Monte Carlo walk (with its own standard errors), not
/// integrated in closed form.
pub fn is_monte_carlo(model: Model) -> bool {
    matches!(model, Model::HeitzNee | Model::ExactPositionFree | Model::WangCorrelated | Model::WangUncorrelated)
}

/// One model's verdict on a run.
#[derive(Clone, Debug, PartialEq)]
pub struct Verdict {
    pub model: Model,
    /// Lobes tested (the family).
    pub lobes: usize,
    /// Lobes whose p-value is below the Sidak per-lobe level.
    pub rejected: usize,
    /// Why the model was not compared at all, if it was not.
    pub skipped: Option<String>,
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

/// One model's prediction of one lobe (case, order slot, hemisphere, channel), bin by bin.
struct ModelLobe {
    case: usize,
    order: usize,
    hemisphere: Hemisphere,
    channel: usize,
    energy: Vec<f64>,
    stderr: Vec<f64>,
}

/// One model's lobes and what its quadrature (closed-form models) reports.
#[derive(Default)]
struct Predictions {
    lobes: Vec<ModelLobe>,
    /// Bin integrals stopped at the evaluation bound, and the largest error estimate there in
    /// units of the bin's tolerance.
    capped: usize,
    worst_capped: f64,
    /// Why the model was not compared, if it was not.
    skipped: Option<String>,
}

/// The agreement of one lobe with one model.
struct LobeComparison {
    lobe: LobeId,
    model: Model,
    test: ChiSquare,
    rel_l1: f64,
    rel_l2: f64,
    albedo_measured: Value,
    albedo_model: Value,
}

/// An energy with its standard error.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Value {
    energy: f64,
    stderr: f64,
}

impl LobeComparison {
    fn albedo_diff_se(&self) -> f64 {
        let (a, b) = (self.albedo_measured, self.albedo_model);
        let se = (a.stderr * a.stderr + b.stderr * b.stderr).sqrt();
        if se > 0.0 { (a.energy - b.energy) / se } else { 0.0 }
    }
}

fn hemisphere_name(h: Hemisphere) -> String {
    format!("{h:?}")
}

fn channel_name(rgb: bool, channel: usize) -> &'static str {
    if rgb { ["r", "g", "b"][channel] } else { "" }
}

/// The run's folded slot `K` ("K+") when `max_order = K`.
fn folded_slot(config: &Config) -> Option<usize> {
    config.detector.max_order.map(|k| k as usize)
}

/// Whether `model`'s lobe (of `case`, order slot `order`, channel `channel`) is tested, so that
/// no lobe is tested twice: with `max_order = 1` the "1+" slot is the all-orders lobe (slot 0)
/// again; in an RGB run, a material with one value per parameter has the same walk weights in
/// every channel, and so has every built-in model of it, so its three channels are one lobe,
/// tested once as channel `r` (a material given per channel is tested per channel). A user's
/// `--external` model may differ between channels whatever the material: all are tested.
fn is_tested(config: &Config, case: &Case, model: Model, order: usize, channel: usize) -> bool {
    let channel_of_its_own = channel == 0 || case.material_spec.is_rgb() || model == Model::External;
    !(folded_slot(config) == Some(1) && order == 1) && channel_of_its_own
}

/// The closed-form models' lobes: `single` (order 1) and `hammon-fit` (order 1, folded into
/// all orders for a "1+" slot, and all orders), in every channel of the run with that
/// channel's material parameters, each bin integrated to a tolerance tied to the measured bin's
/// standard error ([`tolerances`]). The equal channels of a material with one value per
/// parameter in an RGB run are integrated once.
fn closed_form(model: Model, run: &RunDir, measured: &Lobes, progress: &ProgressBar) -> Predictions {
    let folded = folded_slot(&run.config);
    if model == Model::Single && folded == Some(1) {
        return Predictions {
            skipped: Some(
                "not compared: `max_order = 1` folds every order into the \"1+\" slot, and single scattering \
                 is order 1 alone (run with max_order >= 2 to test it)"
                    .to_string(),
            ),
            ..Predictions::default()
        };
    }
    let channels = if run.config.is_rgb() { 3 } else { 1 };
    // (case, slot, hemisphere, channels) of every lobe the model integrates: the channels of
    // an RGB material one by one, those of a material with one value per parameter together.
    let mut wanted: Vec<(&Case, usize, Hemisphere, Vec<usize>)> = Vec::new();
    for case in &run.cases {
        let lobes: Vec<(usize, Hemisphere)> = match model {
            Model::Single => hemispheres(case).iter().map(|&h| (1, h)).collect(),
            _ => vec![(0, Hemisphere::R), (1, Hemisphere::R)],
        };
        let shared: Vec<Vec<usize>> = if case.material_spec.is_rgb() {
            (0..channels).map(|c| vec![c]).collect()
        } else {
            vec![(0..channels).collect()]
        };
        for (slot, h) in lobes {
            wanted.extend(shared.iter().map(|cs| (case, slot, h, cs.clone())));
        }
    }
    progress.set_length(wanted.len() as u64);
    let mut out = Predictions::default();
    for (case, slot, h, shared) in wanted {
        let tolerances = tolerances(run, measured, (case.index, slot, h), &shared);
        let tolerance = |bin: usize| tolerances[bin];
        let integrals = match model {
            Model::Single => single_scattering_lobe(case, &run.grid, h, shared[0], &tolerance),
            _ => {
                let part = if slot == 1 && folded != Some(1) { HammonFitPart::Single } else { HammonFitPart::All };
                hammon_fit_lobe_bins(case, &run.grid, part, shared[0], &tolerance)
            }
        };
        progress.inc(1);
        let Some(integrals) = integrals else { continue };
        out.capped += integrals.capped;
        if integrals.capped > 0 {
            for (error, tol) in integrals.error.iter().zip(&tolerances) {
                out.worst_capped = out.worst_capped.max(error / tol);
            }
        }
        out.lobes.extend(shared.into_iter().map(|channel| ModelLobe {
            case: case.index,
            order: slot,
            hemisphere: h,
            channel,
            energy: integrals.energy.clone(),
            stderr: vec![0.0; run.grid.bins()],
        }));
    }
    out
}

/// The note that a model skips some of the run's `cases`, with how many and why (`unavailable`
/// gives a case's reason, `None` where the model applies): "skips 2 of 4 cases: light from
/// inside", reasons in the order first met, each with its count when there are several; `None`
/// when it skips none.
fn skipped_cases(cases: &[Case], unavailable: fn(&Case) -> Option<&'static str>) -> Option<String> {
    let mut reasons: Vec<(&str, usize)> = Vec::new();
    for reason in cases.iter().filter_map(unavailable) {
        match reasons.iter_mut().find(|r| r.0 == reason) {
            Some(r) => r.1 += 1,
            None => reasons.push((reason, 1)),
        }
    }
    let skipped: usize = reasons.iter().map(|r| r.1).sum();
    let why: Vec<String> = match &reasons[..] {
        [] => return None,
        [(reason, _)] => vec![(*reason).to_string()],
        _ => reasons.iter().map(|(reason, n)| format!("{reason} ({n})")).collect(),
    };
    Some(format!("skips {skipped} of {} cases: {}", cases.len(), why.join(", ")))
}

/// The quadrature tolerance of every bin of a closed-form model's lobe (case, slot,
/// hemisphere) that stands for the run's `channels`: [`QUADRATURE_FRACTION`] of the smallest
/// standard error of the measured bin over those channels, at least of one photon's energy.
fn tolerances(
    run: &RunDir,
    measured: &Lobes,
    (case, slot, h): (usize, usize, Hemisphere),
    channels: &[usize],
) -> Vec<f64> {
    let photons = run.config.paths as f64;
    let empty: Vec<BinValue> = vec![BinValue::default(); run.grid.bins()];
    let lobes: Vec<&[BinValue]> =
        channels.iter().map(|&c| measured.get(case, slot, &hemisphere_name(h), c).map_or(&empty[..], |b| b)).collect();
    (0..run.grid.bins())
        .map(|bin| {
            let se = lobes.iter().map(|l| l[bin].energy_stderr).fold(f64::INFINITY, f64::min);
            QUADRATURE_FRACTION * se.max(1.0 / photons)
        })
        .collect()
}

/// The Monte Carlo models' lobes: the model's estimator walked with the run's config (the same
/// detector, `max_order` included, so the same folding) and `photons` per case.
fn monte_carlo(
    model: Model,
    config: &Config,
    seed: u64,
    threads: Option<usize>,
    progress: bool,
) -> Result<Predictions> {
    let estimator = chain_model(model).map_or(Estimator::HeitzNee(NEE_DIRECTIONS), ChainModel::estimator);
    let sim = simulate_model(config, seed, estimator, threads, progress)?;
    let mut out = Predictions::default();
    for_each_lobe(&sim, &mut |case, lobe| {
        if describes(model, case) {
            out.lobes.push(lobe);
        }
    });
    Ok(out)
}

/// A Monte Carlo model's simulation: `estimator` walked with the run's config and `seed`.
fn simulate_model(
    config: &Config,
    seed: u64,
    estimator: Estimator,
    threads: Option<usize>,
    progress: bool,
) -> Result<Simulation> {
    let model_config = Config { seed, ..config.clone() };
    let options = RunOptions { estimator, shard: Shard::WHOLE, threads, show_progress: progress, max_memory: None };
    crate::engine::simulate_from(&model_config, &options, None, &mut |_, _, _| Ok(()))
}

/// Whether a Monte Carlo model describes `case`: the exact position-free chain only one-sided
/// facets ([`Case::position_free_applies`]), the others every case.
fn describes(model: Model, case: &Case) -> bool {
    model != Model::ExactPositionFree || case.position_free_applies()
}

/// The seed of a Monte Carlo model's streams: the run's seed mixed with the model's name (FNV-1a),
/// so that a model gives the same numbers whichever other models are compared with it.
fn model_seed(run_seed: u64, name: &str) -> u64 {
    let fnv = name.bytes().fold(0xcbf2_9ce4_8422_2325_u64, |h, b| (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3));
    run_seed ^ fnv
}

/// The chain model behind a Monte Carlo model, if it is one.
fn chain_model(model: Model) -> Option<ChainModel> {
    match model {
        Model::WangCorrelated => Some(ChainModel::Wang(Shadowing::Correlated)),
        Model::WangUncorrelated => Some(ChainModel::Wang(Shadowing::Uncorrelated)),
        Model::ExactPositionFree => Some(ChainModel::PositionFree),
        _ => None,
    }
}

/// The lobes of the chain models among `models`, walked on one chain of directions (model `c`
/// in channel `c`, [`Estimator::JointChains`]) when all three are asked for and the run is
/// mono; empty otherwise (each is then walked alone). Two models would pay for the third
/// channel of the RGB detector and gain nothing: measured on the quickstart, the three take
/// 6.6 s together against 9.1 s alone, two about as long together as alone. Each model's
/// estimator is the one it has alone but for the random numbers, and Russian roulette plays on
/// the largest of the weights, so no model is noisier than alone.
fn joint_chains(
    models: &[Model],
    config: &Config,
    threads: Option<usize>,
    progress: bool,
) -> Result<Vec<(Model, Predictions)>> {
    // Channels in the models' canonical order, so that the joint walk depends on which models
    // share it, not on the order they were asked for in.
    let chained: Vec<(Model, ChainModel)> =
        Model::ALL.iter().filter(|m| models.contains(m)).filter_map(|&m| chain_model(m).map(|c| (m, c))).collect();
    if config.is_rgb() || chained.len() < 3 {
        return Ok(Vec::new());
    }
    let names: Vec<&str> = chained.iter().map(|(m, _)| m.name()).collect();
    let seed = model_seed(config.seed, &names.join(","));
    let (start, cpu_start) = (Instant::now(), cpu_seconds());
    let kinds = std::array::from_fn(|c| chained[c].1);
    let sim = simulate_model(config, seed, Estimator::JointChains(kinds), threads, progress)?;
    let mut out: Vec<(Model, Predictions)> = chained.iter().map(|&(m, _)| (m, Predictions::default())).collect();
    for_each_lobe(&sim, &mut |case, lobe| {
        if let Some((model, predictions)) = out.get_mut(lobe.channel)
            && describes(*model, case)
        {
            predictions.lobes.push(ModelLobe { channel: 0, ..lobe });
        }
    });
    eprintln!(
        "compare: {} walked on one chain of directions in {:.1} s ({:.1} CPU s)",
        names.join(", "),
        start.elapsed().as_secs_f64(),
        cpu_seconds() - cpu_start
    );
    Ok(out)
}

/// The compensation models' lobes (`analysis::compensation`): the all-orders reflection slot 0
/// of every case they apply to, per channel, each bin integrated to a tolerance tied to the
/// smallest standard error of the measured bin over the channels.
fn compensation(
    model: Model,
    run: &RunDir,
    measured: &Lobes,
    table: Option<&AlbedoTable>,
    progress: &ProgressBar,
) -> Predictions {
    let Some(compensation) = Compensation::of(model) else { return Predictions::default() };
    let channels = if run.config.is_rgb() { 3 } else { 1 };
    let mut cache = table.cloned().map_or_else(AlbedoCache::default, AlbedoCache::with_table);
    let mut out = Predictions::default();
    progress.set_length(run.cases.len() as u64);
    for case in &run.cases {
        let tolerances = tolerances(run, measured, (case.index, 0, Hemisphere::R), &Vec::from_iter(0..channels));
        let tolerance = |bin: usize| tolerances[bin];
        let lobes: Vec<LobeIntegrals> = if channels == 3 {
            compensated_bins::<3>(compensation, case, &run.grid, &tolerance, &mut cache).map(Vec::from)
        } else {
            compensated_bins::<1>(compensation, case, &run.grid, &tolerance, &mut cache).map(Vec::from)
        }
        .unwrap_or_default();
        for (channel, integrals) in lobes.into_iter().enumerate() {
            out.capped += integrals.capped;
            if integrals.capped > 0 {
                for (error, tol) in integrals.error.iter().zip(&tolerances) {
                    out.worst_capped = out.worst_capped.max(error / tol);
                }
            }
            let stderr = vec![0.0; run.grid.bins()];
            let energy = integrals.energy;
            out.lobes.push(ModelLobe {
                case: case.index,
                order: 0,
                hemisphere: Hemisphere::R,
                channel,
                energy,
                stderr,
            });
        }
        progress.inc(1);
    }
    out
}

/// The lobes of a user's model (`--external`), as read and validated against the run.
fn external_lobes(external: Option<&ExternalModel>) -> Predictions {
    let lobes = external.map_or(&[][..], |e| &e.lobes[..]);
    let lobes = lobes
        .iter()
        .map(|l| ModelLobe {
            case: l.case,
            order: l.order,
            hemisphere: l.hemisphere,
            channel: channel_index(Some(&l.channel)),
            energy: l.energy.clone(),
            stderr: l.stderr.clone(),
        })
        .collect();
    Predictions { lobes, ..Predictions::default() }
}

/// Calls `f` for every lobe (case, order, hemisphere, channel) of a simulation.
fn for_each_lobe(sim: &Simulation, f: &mut dyn FnMut(&Case, ModelLobe)) {
    fn visit<const C: usize>(case: &Case, d: &Detector<C>, f: &mut dyn FnMut(&Case, ModelLobe)) {
        let bins = d.grid.bins();
        let n = d.tallies.photons;
        for (slot, tallies) in d.tallies.orders.iter().enumerate() {
            for &h in hemispheres(case) {
                for c in 0..C {
                    let values: Vec<(f64, f64)> = tallies.bins[h as usize * bins..(h as usize + 1) * bins]
                        .iter()
                        .map(|t| t.mean_and_stderr(n, c))
                        .collect();
                    f(
                        case,
                        ModelLobe {
                            case: case.index,
                            order: slot,
                            hemisphere: h,
                            channel: c,
                            energy: values.iter().map(|v| v.0).collect(),
                            stderr: values.iter().map(|v| v.1).collect(),
                        },
                    );
                }
            }
        }
    }
    for (case, result) in sim.cases.iter().zip(&sim.results) {
        match result {
            CaseResult::Mono(d) => visit(case, d, f),
            CaseResult::Rgb(d) => visit(case, d, f),
        }
    }
}

/// A bin as per-photon moments: mean `e` and second moment `q = Q/N`, recovered from the
/// written energy and standard error (`se^2 = (q - e^2) / (N - 1)`).
fn moments(energy: f64, stderr: f64, photons: u64) -> WeightedBin {
    let n = photons as f64;
    WeightedBin { mean: energy, second_moment: stderr * stderr * (n - 1.0) + energy * energy }
}

/// Compares one lobe bin by bin with [`stats::two_sample_at_null`] (the model exact when
/// `model_photons = 0`), pooling bins in which less than [`MIN_COUNT`] photons' worth of energy
/// is expected; also the relative L1 and L2 errors and the model's albedo (the sum of its bins).
fn compare_lobe(
    measured: &[BinValue],
    model: &ModelLobe,
    photons: u64,
    model_photons: u64,
) -> (ChiSquare, f64, f64, Value) {
    let (mut l1, mut l2, mut norm1, mut norm2) = (0.0, 0.0, 0.0, 0.0);
    let (mut albedo, mut albedo_var) = (0.0, 0.0);
    let (mut observed, mut expected) = (Vec::new(), Vec::new());
    for ((m, &e), &se) in measured.iter().zip(&model.energy).zip(&model.stderr) {
        let o = m.energy;
        l1 += (o - e).abs();
        l2 += (o - e) * (o - e);
        norm1 += e.abs();
        norm2 += e * e;
        albedo += e;
        albedo_var += se * se;
        observed.push(moments(m.energy, m.energy_stderr, photons));
        expected.push(moments(e, se, model_photons));
    }
    let test = stats::two_sample_at_null(&observed, photons, &expected, model_photons, MIN_COUNT);
    let rel_l1 = if norm1 > 0.0 { l1 / norm1 } else { 0.0 };
    let rel_l2 = if norm2 > 0.0 { (l2 / norm2).sqrt() } else { 0.0 };
    (test, rel_l1, rel_l2, Value { energy: albedo, stderr: albedo_var.sqrt() })
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

/// CPU seconds used so far by every thread of this process.
fn cpu_seconds() -> f64 {
    let t = rustix::time::clock_gettime(rustix::time::ClockId::ProcessCPUTime);
    t.tv_sec as f64 + 1e-9 * t.tv_nsec as f64
}

/// A p-value for the console, to three digits; one too small for f64 (which a lobe far from its
/// model gives) as the bound it is, not as `0.00e0`.
pub fn p_value_text(p: f64) -> String {
    if p > 0.0 { format!("{p:.2e}") } else { "<1e-300".to_string() }
}

/// A difference in standard errors for the console, to one decimal; one that rounds to zero is
/// `0.0`, without the sign of a small negative difference.
fn standard_errors_text(se: f64) -> String {
    let text = format!("{se:.1}");
    if text == "-0.0" { "0.0".to_string() } else { text }
}

/// A number of `models.csv` to `digits` significant digits, and a zero as `0`: six for an
/// energy (a closed-form model's bins are accurate to 0.05 of the measured standard error, a
/// Monte Carlo model's to its own), three for a standard error (an error bar).
fn significant(v: f64, digits: usize) -> String {
    if v == 0.0 { "0".to_string() } else { format!("{v:.*e}", digits - 1) }
}

/// [`compare_with`] at the default family level: the report to print.
pub fn compare(run_dir: &Path, models: &[Model], paths: Option<u64>, threads: Option<usize>) -> Result<String> {
    compare_with(run_dir, &CompareOptions::new(models.to_vec(), paths, threads)).map(|outcome| outcome.report)
}

/// Runs the comparison of `run_dir` with the models of `options`, writes `models.csv` and
/// `compare.csv` into it and returns the report and the verdicts. Progress goes to stderr: on a
/// terminal the model being evaluated, otherwise one line per model when it finishes.
pub fn compare_with(run_dir: &Path, options: &CompareOptions) -> Result<Outcome> {
    options.validate()?;
    let run = RunDir::open(run_dir)?;
    let external = options.external.as_deref().map(|path| crate::analysis::external::read(path, &run)).transpose()?;
    let models = [&options.models[..], if external.is_some() { &[Model::External][..] } else { &[] }].concat();
    let albedo_table = options.albedo_table.as_deref().map(AlbedoTable::read).transpose()?;
    if albedo_table.is_some() && !models.iter().any(|&m| Compensation::of(m).is_some()) {
        bail!(
            "`--albedo-table` is only read by the models kulla-conty, turquin and fdez-aguera; add one to `--models`"
        );
    }
    let measured = run.measured()?;
    let summary = run.summary()?;
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
    let terminal = std::io::stderr().is_terminal();
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
            Model::Single | Model::HammonFit => {
                let bar = model_progress(model, terminal);
                let p = closed_form(model, &run, &measured, &bar);
                bar.finish_and_clear();
                let unavailable = match model {
                    Model::Single => single_scattering_unavailable,
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
            Model::External => external_lobes(external.as_ref()),
            _ => {
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
    let verdicts: Vec<Verdict> = models
        .iter()
        .map(|&model| {
            let mine: Vec<&LobeComparison> = comparisons.iter().filter(|c| c.model == model).collect();
            let level = stats::sidak(options.family_level, mine.len().max(1));
            Verdict {
                model,
                lobes: mine.len(),
                rejected: mine.iter().filter(|c| c.test.p_value < level).count(),
                skipped: skipped.iter().find(|s| s.0 == model).map(|s| s.1.clone()),
            }
        })
        .collect();
    let compare_csv = compare_table(&comparisons, &run, &verdicts, options.family_level, rgb, folded)?;
    let models_csv = models_table(&run, &predicted, rgb, folded)?;
    write_atomically(run_dir, &[(schema::MODELS.file, models_csv), (schema::COMPARE.file, compare_csv)])?;
    let report = report(&comparisons, &verdicts, &notes, options.family_level, rgb, folded, options.default_models);
    Ok(Outcome { report, verdicts })
}

fn channel_index(channel: Option<&str>) -> usize {
    match channel {
        Some("g") => 1,
        Some("b") => 2,
        _ => 0,
    }
}

/// The text of `models.csv`, row for row aligned with `lobes.csv`: its rows (every case,
/// order slot, hemisphere, bin and channel of the run, in its order) with their key columns and
/// `folded`, then per model compared, in that order, its energy (six significant digits) and
/// standard error (three: an error bar), both empty where the model gives no lobe
/// ([`model_lobe`]). A model's lobe for a slot the run does not have (no light reached that
/// order) is not written.
fn models_table(
    run: &RunDir,
    predicted: &[(Model, Vec<ModelLobe>)],
    rgb: bool,
    folded: Option<usize>,
) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let names: Vec<&str> = predicted.iter().map(|(model, _)| model.name()).collect();
    let header = schema::MODELS.header(rgb, &names);
    w.write_record(&header)?;
    let channels = if rgb { 3 } else { 1 };
    let zeros = vec![0.0; run.grid.bins()];
    let mut row: Vec<String> = Vec::with_capacity(header.len());
    for case in &run.cases {
        for order in 0..run.slots[case.index] {
            for &h in hemispheres(case) {
                // Per channel, each model's energies and standard errors, if it gives the lobe.
                let lobes: Vec<Vec<LobeCells>> = (0..channels)
                    .map(|c| predicted.iter().map(|p| model_lobe(p, (case.index, order, h, c), &zeros)).collect())
                    .collect();
                for (_, bin, edges) in bin_edges(run.grid, hemisphere_sign(case.side, h)) {
                    for (c, models) in lobes.iter().enumerate() {
                        row.clear();
                        row.extend([case.index.to_string(), order.to_string(), hemisphere_name(h)]);
                        if rgb {
                            row.push(channel_name(rgb, c).to_string());
                        }
                        row.extend(edges.map(|e| e.to_string()));
                        row.push((folded == Some(order)).to_string());
                        for lobe in models {
                            match lobe {
                                Some((e, se)) => row.extend([significant(e[bin], 6), significant(se[bin], 3)]),
                                None => row.extend([String::new(), String::new()]),
                            }
                        }
                        w.write_record(&row)?;
                    }
                }
            }
        }
    }
    Ok(w.into_inner()?)
}

/// A model's energies and standard errors of one lobe, bin by bin, if it gives the lobe.
type LobeCells<'a> = Option<(&'a [f64], &'a [f64])>;

/// A model's energies and standard errors of a lobe (case, order slot, hemisphere, channel),
/// or `None` if it does not give it; zero for a Monte Carlo model whose walk reached no light at
/// that order of a case it applies to.
fn model_lobe<'a>(
    (model, lobes): &'a (Model, Vec<ModelLobe>),
    lobe: (usize, usize, Hemisphere, usize),
    zeros: &'a [f64],
) -> LobeCells<'a> {
    let (case, _, _, channel) = lobe;
    match lobes.iter().find(|l| (l.case, l.order, l.hemisphere, l.channel) == lobe) {
        Some(l) => Some((&l.energy, &l.stderr)),
        None if is_monte_carlo(*model) && lobes.iter().any(|l| (l.case, l.channel) == (case, channel)) => {
            Some((zeros, zeros))
        }
        None => None,
    }
}

/// The text of `compare.csv`: one row per tested lobe and model.
fn compare_table(
    comparisons: &[LobeComparison],
    run: &RunDir,
    verdicts: &[Verdict],
    family_level: f64,
    rgb: bool,
    folded: Option<usize>,
) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let header = schema::COMPARE.header(rgb, &[]);
    w.write_record(&header)?;
    for c in comparisons {
        let lobes = verdicts.iter().find(|v| v.model == c.model).map_or(1, |v| v.lobes);
        let lobe_level = stats::sidak(family_level, lobes.max(1));
        let mut row = case_fields(&run.cases[c.lobe.0]);
        row.extend([c.model.name().to_string(), c.lobe.1.to_string(), c.lobe.2.clone()]);
        if rgb {
            row.push(channel_name(rgb, c.lobe.3).to_string());
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
        row.extend([
            (folded == Some(c.lobe.1)).to_string(),
            family_level.to_string(),
            lobe_level.to_string(),
            (c.test.p_value < lobe_level).to_string(),
        ]);
        w.write_record(&row)?;
    }
    Ok(w.into_inner()?)
}

/// What the columns of the worst-lobes table mean (docs/compare.md), printed after the first.
const WORST_LOBES_LEGEND: [&str; 3] = [
    "order 0: all orders; ch: channel (- in a one-channel run); rel L1, rel L2: the lobe's difference",
    "from the model in the L1 and L2 norms, over the model's norm; albedo diff: measured minus model",
    "albedo in units of sqrt(SE_measured^2 + SE_model^2) (positive: the walk measured more light)",
];

/// The report: per model its family, level, rejections and worst lobes (the first table with
/// [`WORST_LOBES_LEGEND`] under it), then the verdict. A model that applies to no case of the
/// run says so in its section when the user named it; models of the default list
/// (`default_models`) that apply to no case share one line instead.
fn report(
    comparisons: &[LobeComparison],
    verdicts: &[Verdict],
    notes: &[(Model, String)],
    family_level: f64,
    rgb: bool,
    folded: Option<usize>,
    default_models: bool,
) -> String {
    let mut out = String::new();
    let mut legend = Some(WORST_LOBES_LEGEND);
    let mut not_applicable: Vec<&str> = Vec::new();
    for v in verdicts {
        let kind = if is_exact_oracle(v.model) { "exact oracle" } else { "approximation" };
        if let Some(reason) = &v.skipped {
            let _ = writeln!(out, "{} ({kind}): {reason}", v.model.name());
            continue;
        }
        if v.lobes == 0 && default_models {
            not_applicable.push(v.model.name());
            continue;
        }
        if v.lobes == 0 {
            let _ = writeln!(out, "{} ({kind}): applies to no case of this run", v.model.name());
            continue;
        }
        let level = stats::sidak(family_level, v.lobes);
        let _ = writeln!(
            out,
            "{} ({kind}): {} lobes at family level {family_level} (Sidak: each lobe at {level:.2e}): {} rejected",
            v.model.name(),
            v.lobes,
            v.rejected
        );
        for (model, note) in notes.iter().filter(|n| n.0 == v.model) {
            let _ = writeln!(out, "  {}: {note}", model.name());
        }
        let mut mine: Vec<&LobeComparison> = comparisons.iter().filter(|c| c.model == v.model).collect();
        mine.sort_by(|a, b| a.test.p_value.total_cmp(&b.test.p_value));
        let _ = writeln!(out, "  its {} lobes with the lowest p, worst first:", mine.len().min(5));
        let _ = writeln!(
            out,
            "  {:>5} {:>5} {:>4} {:>3} {:>10} {:>6} {:>10} {:>8} {:>8} {:>11}  verdict",
            "case", "order", "hemi", "ch", "chi2", "dof", "p", "rel L1", "rel L2", "albedo diff"
        );
        for c in mine.iter().take(5) {
            let order = if folded == Some(c.lobe.1) { format!("{}+", c.lobe.1) } else { c.lobe.1.to_string() };
            let channel = if rgb { channel_name(rgb, c.lobe.3) } else { "-" };
            let _ = writeln!(
                out,
                "  {:>5} {order:>5} {:>4} {channel:>3} {:>10.1} {:>6} {:>10} {:>8.4} {:>8.4} {:>8} SE{}",
                c.lobe.0,
                c.lobe.2,
                c.test.statistic,
                c.test.dof,
                p_value_text(c.test.p_value),
                c.rel_l1,
                c.rel_l2,
                standard_errors_text(c.albedo_diff_se()),
                if c.test.p_value < level { "  rejected" } else { "" }
            );
        }
        for line in legend.take().into_iter().flatten() {
            let _ = writeln!(out, "  {line}");
        }
    }
    if !not_applicable.is_empty() {
        let _ = writeln!(out, "not applicable to any case of this run: {}", not_applicable.join(", "));
    }
    if folded == Some(1) {
        let _ = writeln!(out, "(max_order = 1: the \"1+\" slot is the all-orders lobe, tested once as order 0)");
    }
    let failed: Vec<String> = verdicts
        .iter()
        .filter(|v| is_exact_oracle(v.model) && v.rejected > 0)
        .map(|v| format!("{} ({} of {} lobes)", v.model.name(), v.rejected, v.lobes))
        .collect();
    let approximations: Vec<&str> =
        verdicts.iter().filter(|v| !is_exact_oracle(v.model) && v.rejected > 0).map(|v| v.model.name()).collect();
    if failed.is_empty() {
        let _ = writeln!(out, "verdict: no exact oracle rejects the run at family level {family_level}");
    } else {
        let _ = writeln!(
            out,
            "verdict: REJECTED by exact oracles: {}: the measurement or the oracle is wrong",
            failed.join(", ")
        );
    }
    if !approximations.is_empty() {
        let _ = writeln!(
            out,
            "({} {} the walk: rejections measure the approximation, not a fault)",
            approximations.join(", "),
            if approximations.len() == 1 { "approximates" } else { "approximate" }
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_p_value_below_f64s_range_is_printed_as_a_bound() {
        assert_eq!(p_value_text(0.0), "<1e-300");
        assert_eq!(p_value_text(5.25e-110), "5.25e-110");
        assert_eq!(p_value_text(0.5), "5.00e-1");
    }

    /// A comparison of lobe (case 0, order 1, R, channel 0) with `model`: p-value `p`, the
    /// measured albedo `measured` and the model's 0.5, both with standard error 0.1.
    fn comparison(model: Model, p: f64, measured: f64) -> LobeComparison {
        LobeComparison {
            lobe: (0, 1, "R".to_string(), 0),
            model,
            test: ChiSquare { statistic: 1.0, dof: 1, p_value: p, cells: Vec::new() },
            rel_l1: 0.0,
            rel_l2: 0.0,
            albedo_measured: Value { energy: measured, stderr: 0.1 },
            albedo_model: Value { energy: 0.5, stderr: 0.1 },
        }
    }

    #[test]
    fn an_albedo_difference_that_rounds_to_zero_is_printed_without_a_sign() {
        // Measured minus model is -0.004 in units of sqrt(0.1^2 + 0.1^2): -0.0 to one decimal.
        let comparisons = [comparison(Model::Single, 0.5, 0.5 - 0.004 * 0.02_f64.sqrt())];
        let verdicts = [Verdict { model: Model::Single, lobes: 1, rejected: 0, skipped: None }];
        let text = report(&comparisons, &verdicts, &[], 0.01, false, None, false);
        let row = text.lines().find(|l| l.trim_start().starts_with("0 ")).expect(&text);
        assert!(row.ends_with(" 0.0 SE") && !text.contains("-0.0"), "{text}");
        assert_eq!((standard_errors_text(-0.06), standard_errors_text(-0.0)), ("-0.1".into(), "0.0".into()));
    }

    #[test]
    fn the_worst_lobes_columns_are_explained_once_after_the_first_table() {
        let comparisons = [comparison(Model::Single, 0.5, 0.6), comparison(Model::HeitzNee, 0.5, 0.6)];
        let verdicts =
            [Model::Single, Model::HeitzNee].map(|model| Verdict { model, lobes: 1, rejected: 0, skipped: None });
        let text = report(&comparisons, &verdicts, &[], 0.01, false, None, false);
        let lines: Vec<&str> = text.lines().collect();
        // The line after the first table's row starts the legend; the second table has none.
        let row = lines.iter().position(|l| l.trim_start().starts_with("0 ")).expect(&text);
        assert!(
            lines[row + 1].starts_with("  order 0: all orders") && lines[row + 3].starts_with("  albedo in"),
            "{text}"
        );
        for term in [
            "order 0: all orders",
            "ch: channel (- in a one-channel run)",
            "rel L1, rel L2:",
            "albedo diff: measured minus model",
        ] {
            assert_eq!(text.matches(term).count(), 1, "{term}: {text}");
        }
    }

    #[test]
    fn single_scattering_is_never_tested_against_a_slot_that_holds_other_orders() {
        let mut config: Config = toml::from_str(
            "paths = 1000\n[surface]\nalpha = 0.5\n[material]\nkind = \"conductor\"\n[incident]\ntheta_deg = 0\n\
             [detector]\ncos_theta_bins = 2\nphi_bins = 2\nmax_order = 1\n",
        )
        .unwrap();
        let case = &crate::setup::cases::expand(&config).unwrap()[0];
        // max_order = 1: slot 1 is "1+" = slot 0, tested once, and `single` is skipped.
        let single = Model::Single;
        assert!(is_tested(&config, case, single, 0, 0) && !is_tested(&config, case, single, 1, 0));
        config.detector.max_order = Some(2);
        assert!(is_tested(&config, case, single, 1, 0) && is_tested(&config, case, single, 2, 0));
    }

    #[test]
    fn the_equal_channels_of_a_one_valued_material_are_tested_once() {
        let config: Config = toml::from_str(
            "paths = 1000\n[surface]\nalpha = 0.5\n[[material]]\nkind = \"conductor\"\n\
             [[material]]\nkind = \"conductor\"\nfresnel = \"schlick\"\nf0 = [0.2, 0.6, 1.0]\n\
             [incident]\ntheta_deg = 0\n[detector]\ncos_theta_bins = 2\nphi_bins = 2\n",
        )
        .unwrap();
        let cases = crate::setup::cases::expand(&config).unwrap();
        let tested = |case: &Case, model| (0..3).filter(|&c| is_tested(&config, case, model, 1, c)).count();
        assert_eq!((tested(&cases[0], Model::Single), tested(&cases[1], Model::Single)), (1, 3));
        assert_eq!((tested(&cases[0], Model::HeitzNee), tested(&cases[1], Model::KullaConty)), (1, 3));
        // A user's model may differ between channels where the walk does not.
        assert_eq!((tested(&cases[0], Model::External), tested(&cases[1], Model::External)), (3, 3));
    }

    #[test]
    fn exact_oracles_are_the_models_exact_for_the_smith_walk() {
        let exact: Vec<&str> = Model::ALL.into_iter().filter(|&m| is_exact_oracle(m)).map(Model::name).collect();
        assert_eq!(exact, ["single", "heitz-nee", "exact-position-free"]);
    }
}
