//! Verdict: the statistics that judge a model's lobes against the measured ones (docs/theory.md
//! §9.5): a two-sample chi-square per lobe with sparse bins pooled, and per model a family of
//! lobes judged at a Sidak per-lobe level.

use super::predict::ModelLobe;
use crate::analysis::stats::{self, ChiSquare, WeightedBin};
use crate::io::rundir::{BinValue, LobeId};
use crate::setup::config::Model;

/// The family-wise level at which each model's lobes are judged unless `--level` says otherwise.
pub const DEFAULT_FAMILY_LEVEL: f64 = 0.01;

/// Bins of a lobe with less than this many photons' worth of energy are pooled (§9.5).
pub(super) const MIN_COUNT: f64 = 5.0;

/// Whether a model is exact for the Smith walk, so that its rejection is a failure (of the
/// measurement or of the model's code) rather than a measure of an approximation.
pub fn is_exact_oracle(model: Model) -> bool {
    // Cui et al.'s released term equals the exact depth factor on every path a conductor's
    // chain produces (one down-to-up turn: a reflection keeps an upward direction upward,
    // docs/theory.md §7.3).
    matches!(model, Model::Single | Model::HeitzNee | Model::ExactPositionFree | Model::CuiReleased)
}

/// What kind of model the report calls `model`: an exact oracle of the Smith walk, an
/// approximation of it, or an approximation on another microsurface (Lee et al.'s V-grooves,
/// docs/theory.md §14), whose distance from the walk is what its rejections measure.
pub fn kind(model: Model) -> &'static str {
    if is_exact_oracle(model) {
        "exact oracle"
    } else if model == Model::Lee2018 {
        "approximation: V-groove microsurface, not Smith's"
    } else {
        "approximation"
    }
}

/// Whether a model is estimated by a Monte Carlo walk (with its own standard errors), not
/// integrated in closed form.
pub fn is_monte_carlo(model: Model) -> bool {
    matches!(
        model,
        Model::HeitzNee
            | Model::ExactPositionFree
            | Model::WangCorrelated
            | Model::WangUncorrelated
            | Model::CuiReleased
    )
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

/// The agreement of one lobe with one model.
pub(super) struct LobeComparison {
    pub(super) lobe: LobeId,
    pub(super) model: Model,
    pub(super) test: ChiSquare,
    pub(super) rel_l1: f64,
    pub(super) rel_l2: f64,
    pub(super) albedo_measured: Value,
    pub(super) albedo_model: Value,
}

/// An energy with its standard error.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct Value {
    pub(super) energy: f64,
    pub(super) stderr: f64,
}

impl LobeComparison {
    pub(super) fn albedo_diff_se(&self) -> f64 {
        let (a, b) = (self.albedo_measured, self.albedo_model);
        let se = (a.stderr * a.stderr + b.stderr * b.stderr).sqrt();
        if se > 0.0 { (a.energy - b.energy) / se } else { 0.0 }
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
pub(super) fn compare_lobe(
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

/// Each model's verdict: its tested lobes (the family) and those whose p-value is below the
/// Sidak per-lobe level of `family_level`, or why it was `skipped`.
pub(super) fn verdicts(
    models: &[Model],
    comparisons: &[LobeComparison],
    skipped: &[(Model, String)],
    family_level: f64,
) -> Vec<Verdict> {
    models
        .iter()
        .map(|&model| {
            let mine: Vec<&LobeComparison> = comparisons.iter().filter(|c| c.model == model).collect();
            let level = stats::sidak(family_level, mine.len().max(1));
            Verdict {
                model,
                lobes: mine.len(),
                rejected: mine.iter().filter(|c| c.test.p_value < level).count(),
                skipped: skipped.iter().find(|s| s.0 == model).map(|s| s.1.clone()),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_oracles_are_the_models_exact_for_the_smith_walk() {
        let exact: Vec<&str> = Model::ALL.into_iter().filter(|&m| is_exact_oracle(m)).map(Model::name).collect();
        assert_eq!(exact, ["single", "heitz-nee", "exact-position-free", "cui2023-released"]);
    }
}
