//! Prediction: each model's lobes in the run's bins (case, order slot, hemisphere, channel),
//! bin by bin, with a standard error for the Monte Carlo models (docs/theory.md §4.7, §7.1).
//! Closed-form models are integrated to a tolerance tied to the measured bin's standard error;
//! Monte Carlo models are walked into the run's own detector, so their slots fold as the run's.

use std::time::Instant;

use anyhow::Result;
use indicatif::ProgressBar;
use microsurface::wang::Shadowing;

use super::lobe::{channel_index, folded_slot, hemisphere_name};
use crate::analysis::albedo_table::AlbedoTable;
use crate::analysis::compensation::{AlbedoCache, Compensation, compensated_bins};
use crate::analysis::external::ExternalModel;
use crate::analysis::models::{HammonFitPart, LobeIntegrals, hammon_fit_lobe_bins, single_scattering_lobe};
use crate::analysis::vgroove::{lee2018_lobe_bins, slot_orders};
use crate::engine::detector::{Detector, Hemisphere};
use crate::engine::run::{CaseResult, ChainModel, Estimator, Shard};
use crate::engine::{RunOptions, Simulation};
use crate::io::output::hemispheres;
use crate::io::rundir::{BinValue, Lobes, RunDir};
use crate::setup::cases::Case;
use crate::setup::config::{Config, Model};

/// Outgoing directions per hit of the next-event estimator.
const NEE_DIRECTIONS: u32 = 4;

/// The quadrature tolerance of a bin of a closed-form model, as a fraction of the measured
/// bin's standard error (at least of one photon's energy, `1/N`, for an empty bin): a bias of
/// 0.05 standard errors moves a bin's expected chi-square by 0.0025, far below its spread.
pub(super) const QUADRATURE_FRACTION: f64 = 0.05;

/// One model's prediction of one lobe (case, order slot, hemisphere, channel), bin by bin.
pub(super) struct ModelLobe {
    pub(super) case: usize,
    pub(super) order: usize,
    pub(super) hemisphere: Hemisphere,
    pub(super) channel: usize,
    pub(super) energy: Vec<f64>,
    pub(super) stderr: Vec<f64>,
}

/// One model's lobes and what its quadrature (closed-form models) reports.
#[derive(Default)]
pub(super) struct Predictions {
    pub(super) lobes: Vec<ModelLobe>,
    /// Bin integrals stopped at the evaluation bound, and the largest error estimate there in
    /// units of the bin's tolerance.
    pub(super) capped: usize,
    pub(super) worst_capped: f64,
    /// Why the model was not compared, if it was not.
    pub(super) skipped: Option<String>,
}

/// The closed-form models' lobes: `single` (order 1), `hammon-fit` (order 1, folded into
/// all orders for a "1+" slot, and all orders) and `lee2018` (every slot of the run, §14), in every channel of the run with that
/// channel's material parameters, each bin integrated to a tolerance tied to the measured bin's
/// standard error ([`tolerances`]). The equal channels of a material with one value per
/// parameter in an RGB run are integrated once.
pub(super) fn closed_form(model: Model, run: &RunDir, measured: &Lobes, progress: &ProgressBar) -> Predictions {
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
            // Where the run's last slot is the folded "K+", the all-orders slot is the sum of the
            // others (added below), which saves its integration, the dearest of all.
            Model::Lee2018 => {
                let first = usize::from(sums_slots(run, case.index, folded));
                (first..run.slots[case.index]).map(|slot| (slot, Hemisphere::R)).collect()
            }
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
            Model::Lee2018 => lee2018_lobe_bins(case, &run.grid, slot_orders(slot, folded), shared[0], &tolerance),
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
    if model == Model::Lee2018 {
        let mut all: Vec<ModelLobe> = Vec::new();
        for lobe in out.lobes.iter().filter(|l| sums_slots(run, l.case, folded)) {
            match all.iter_mut().find(|a| (a.case, a.channel) == (lobe.case, lobe.channel)) {
                Some(a) => a.energy.iter_mut().zip(&lobe.energy).for_each(|(a, e)| *a += e),
                None => {
                    all.push(ModelLobe { order: 0, energy: lobe.energy.clone(), stderr: lobe.stderr.clone(), ..*lobe })
                }
            }
        }
        out.lobes.extend(all);
    }
    out
}

/// Whether case `case`'s order slots end with the run's folded slot `folded` ("K+"), so that
/// its all-orders slot is the sum of its other slots.
fn sums_slots(run: &RunDir, case: usize, folded: Option<usize>) -> bool {
    folded.is_some_and(|k| run.slots[case] == k + 1)
}

/// The note that a model skips some of the run's `cases`, with how many and why (`unavailable`
/// gives a case's reason, `None` where the model applies): "skips 2 of 4 cases: light from
/// inside", reasons in the order first met, each with its count when there are several; `None`
/// when it skips none.
pub(super) fn skipped_cases(cases: &[Case], unavailable: fn(&Case) -> Option<&'static str>) -> Option<String> {
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
pub(super) fn monte_carlo(
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
/// facets ([`Case::position_free_applies`]), Cui's released model only conductors
/// ([`Case::cui_released_applies`]), the others every case.
fn describes(model: Model, case: &Case) -> bool {
    match model {
        Model::ExactPositionFree => case.position_free_applies(),
        Model::CuiReleased => case.cui_released_applies(),
        _ => true,
    }
}

/// Why Cui et al.'s released model does not describe `case`, if it does not (for
/// [`skipped_cases`]): the released code is a rough-conductor BRDF (docs/theory.md §7.3).
pub(super) fn cui_released_unavailable(case: &Case) -> Option<&'static str> {
    (!case.cui_released_applies()).then_some("not a conductor with the true Smith Lambda and visible normals")
}

/// The seed of a Monte Carlo model's streams: the run's seed mixed with the model's name (FNV-1a),
/// so that a model gives the same numbers whichever other models are compared with it.
pub(super) fn model_seed(run_seed: u64, name: &str) -> u64 {
    let fnv = name.bytes().fold(0xcbf2_9ce4_8422_2325_u64, |h, b| (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3));
    run_seed ^ fnv
}

/// The chain model behind a Monte Carlo model, if it is one.
pub(super) fn chain_model(model: Model) -> Option<ChainModel> {
    match model {
        Model::WangCorrelated => Some(ChainModel::Wang(Shadowing::Correlated)),
        Model::WangUncorrelated => Some(ChainModel::Wang(Shadowing::Uncorrelated)),
        Model::ExactPositionFree => Some(ChainModel::PositionFree),
        Model::CuiReleased => Some(ChainModel::CuiReleased),
        _ => None,
    }
}

/// The lobes of the chain models among `models`, walked on one chain of directions (model `c`
/// in channel `c`, [`Estimator::JointChains`]) when three or more are asked for and the run is
/// mono (the first three in the canonical order; a fourth is walked alone); empty otherwise
/// (each is then walked alone). Two models would pay for the third
/// channel of the RGB detector and gain nothing: measured on the quickstart, the three take
/// 6.6 s together against 9.1 s alone, two about as long together as alone. Each model's
/// estimator is the one it has alone but for the random numbers, and Russian roulette plays on
/// the largest of the weights, so no model is noisier than alone.
pub(super) fn joint_chains(
    models: &[Model],
    config: &Config,
    threads: Option<usize>,
    progress: bool,
) -> Result<Vec<(Model, Predictions)>> {
    // Channels in the models' canonical order, so that the joint walk depends on which models
    // share it, not on the order they were asked for in.
    let chained: Vec<(Model, ChainModel)> = Model::ALL
        .iter()
        .filter(|m| models.contains(m))
        .filter_map(|&m| chain_model(m).map(|c| (m, c)))
        .take(3)
        .collect();
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
pub(super) fn compensation(
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
pub(super) fn external_lobes(external: Option<&ExternalModel>) -> Predictions {
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

/// CPU seconds used so far by every thread of this process.
pub(super) fn cpu_seconds() -> f64 {
    let t = rustix::time::clock_gettime(rustix::time::ClockId::ProcessCPUTime);
    t.tv_sec as f64 + 1e-9 * t.tv_nsec as f64
}
