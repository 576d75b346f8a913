//! Running cases: the work is cut into fixed chunks of photons, each with its own random
//! stream derived from (seed, case, chunk), and spread over a thread pool. Detectors are merged
//! with exact integer sums, so outputs are bit-identical for any thread count.

use std::collections::BTreeMap;
use std::collections::btree_map::Entry;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc;

use indicatif::ProgressBar;
use microsurface::chain::{self, Escapes, Visibility};
use microsurface::cui::ReleasedPath;
use microsurface::facet::Facet;
use microsurface::material::Material;
use microsurface::ndf::{AnyNdf, Beckmann, Ggx, Ndf};
use microsurface::nee::NextEvent;
use microsurface::position_free::DepthProfile;
use microsurface::student_t::StudentT;
use microsurface::walk::{EnergyPolicy, Microsurface, Observer};
use microsurface::wang::Shadowing;
use rand_pcg::Pcg64Mcg;
use serde::{Deserialize, Serialize};

use crate::engine::detector::{Detector, Grid, Hemisphere};
use crate::setup::cases::Case;
use crate::setup::config::{Config, PrecisionConfig};

/// Photons per chunk: the unit of work and of random streams. Part of the output's identity:
/// changing it changes which random numbers each photon uses.
pub const CHUNK: u64 = 1 << 14;

/// A share of a run's work: chunk `c` of every case belongs to shard `c % count`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    pub index: u64,
    pub count: u64,
}

impl Shard {
    /// The whole run.
    pub const WHOLE: Shard = Shard { index: 0, count: 1 };

    /// Parses `I/N` with `0 <= I < N`.
    pub fn parse(text: &str) -> Result<Self, String> {
        let bad = || format!("`--shard` = {text:?} is not allowed: expected I/N with 0 <= I < N, e.g. 0/4");
        let (i, n) = text.split_once('/').ok_or_else(bad)?;
        let (index, count) = (i.trim().parse::<u64>().map_err(|_| bad())?, n.trim().parse::<u64>().map_err(|_| bad())?);
        if count == 0 || index >= count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }
}

/// What produces the escaping light: the random walk (the measurement) or an analytic model's
/// path chain evaluated by Monte Carlo into the same detector.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Estimator {
    /// The random walk on the Smith microsurface (§4).
    Walk,
    /// The Wang et al. 2022 chain with the given shadowing model (§6.5).
    Wang(Shadowing),
    /// Next-event estimation along the walk (Heitz et al. 2016 `eval`, §4.7), with this many
    /// outgoing directions per hit.
    HeitzNee(u32),
    /// The exact position-free chain (§7.1). Cases it does not describe
    /// ([`Case::position_free_applies`]) are skipped: their photons deposit nothing.
    PositionFree,
    /// The chain of Cui et al.'s released code (§7.3). Cases it does not describe
    /// ([`Case::cui_released_applies`]) are skipped: their photons deposit nothing.
    CuiReleased,
    /// Up to three chain models on one chain of directions, model `c` in channel `c` of an
    /// RGB detector (mono cases only; see [`chain::trace`]). Where the position-free chain
    /// or Cui's does not apply, its channel follows the first model and means nothing.
    JointChains([ChainModel; 3]),
}

/// A height-free chain model (§6.5, §7.1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ChainModel {
    Wang(Shadowing),
    PositionFree,
    CuiReleased,
}

impl ChainModel {
    /// The estimator that walks this model alone.
    pub fn estimator(self) -> Estimator {
        match self {
            ChainModel::Wang(s) => Estimator::Wang(s),
            ChainModel::PositionFree => Estimator::PositionFree,
            ChainModel::CuiReleased => Estimator::CuiReleased,
        }
    }
}

/// The visibility of a [`ChainModel`] for one photon.
#[derive(Clone, Debug)]
enum ChainVisibility {
    Wang(Shadowing),
    PositionFree(DepthProfile),
    CuiReleased(ReleasedPath),
}

impl ChainVisibility {
    fn of(model: ChainModel, case: &Case, fallback: ChainModel) -> Self {
        match model {
            ChainModel::Wang(s) => ChainVisibility::Wang(s),
            ChainModel::PositionFree if case.position_free_applies() => {
                ChainVisibility::PositionFree(DepthProfile::default())
            }
            ChainModel::PositionFree => Self::of(fallback, case, ChainModel::Wang(Shadowing::Correlated)),
            ChainModel::CuiReleased if case.cui_released_applies() => {
                ChainVisibility::CuiReleased(ReleasedPath::default())
            }
            ChainModel::CuiReleased => Self::of(fallback, case, ChainModel::Wang(Shadowing::Correlated)),
        }
    }
}

impl Visibility for ChainVisibility {
    fn enter(&mut self, rate: f64) {
        match self {
            ChainVisibility::Wang(s) => s.enter(rate),
            ChainVisibility::PositionFree(p) => p.enter(rate),
            ChainVisibility::CuiReleased(c) => c.enter(rate),
        }
    }

    fn leave(&mut self, rate_in: f64, rate_out: f64, up: bool, refracted: bool) -> f64 {
        match self {
            ChainVisibility::Wang(s) => s.leave(rate_in, rate_out, up, refracted),
            ChainVisibility::PositionFree(p) => p.leave(rate_in, rate_out, up, refracted),
            ChainVisibility::CuiReleased(c) => c.leave(rate_in, rate_out, up, refracted),
        }
    }

    fn carried(&self, escaped: f64) -> f64 {
        match self {
            ChainVisibility::Wang(s) => s.carried(escaped),
            ChainVisibility::PositionFree(p) => p.carried(escaped),
            ChainVisibility::CuiReleased(c) => c.carried(escaped),
        }
    }
}

/// One visibility per channel of the chain's weight.
struct PerChannel<const C: usize>([ChainVisibility; C]);

impl<const C: usize> Escapes<C> for PerChannel<C> {
    fn start(&mut self, rate: f64) {
        self.0.iter_mut().for_each(|v| v.enter(rate));
    }

    fn escaping(&mut self, rate_in: f64, rate_out: f64, up: bool, refracted: bool) -> [f64; C] {
        std::array::from_fn(|c| self.0[c].leave(rate_in, rate_out, up, refracted))
    }

    fn carrying(&self, escaped: &[f64; C]) -> [f64; C] {
        std::array::from_fn(|c| self.0[c].carried(escaped[c]))
    }
}

/// What every case of a run shares.
#[derive(Clone, Copy, Debug)]
pub struct RunSettings {
    pub estimator: Estimator,
    pub paths: u64,
    pub seed: u64,
    pub grid: Grid,
    pub max_order: Option<u32>,
    pub policy: EnergyPolicy,
    pub shard: Shard,
}

impl RunSettings {
    pub fn from_config(config: &Config) -> Self {
        Self {
            estimator: Estimator::Walk,
            paths: config.paths,
            seed: config.seed,
            grid: Grid { cos_bins: config.detector.cos_theta_bins, phi_bins: config.detector.phi_bins },
            max_order: config.detector.max_order,
            policy: EnergyPolicy { split: config.energy.split, threshold: config.energy.threshold },
            shard: Shard::WHOLE,
        }
    }

    fn chunks(&self) -> u64 {
        self.paths.div_ceil(CHUNK)
    }

    /// Photons of one case that this shard walks: whole chunks, and the short last chunk of
    /// the case if it is this shard's (closed form: the photon count may be huge).
    pub fn shard_paths(&self) -> u64 {
        let chunks = self.shard_chunks();
        let last = self.chunks().saturating_sub(1);
        match chunks {
            0 => 0,
            _ if last % self.shard.count == self.shard.index => (chunks - 1) * CHUNK + self.chunk_photons(last),
            _ => chunks * CHUNK,
        }
    }

    fn chunk_photons(&self, chunk: u64) -> u64 {
        CHUNK.min(self.paths - chunk * CHUNK)
    }
}

/// SplitMix64 finalizer: a bijective mixer of 64-bit words.
fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce5_e4b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Seed offset of the next-event estimator's own streams (directions, stochastic phases), so
/// that the walk underneath uses exactly the measurement's streams.
const NEE_STREAMS: u64 = 0x6e65_655f_7374_7265;

/// The random stream of one chunk of one case, derived from (seed, case, chunk) only.
pub fn chunk_rng(seed: u64, case: usize, chunk: u64) -> Pcg64Mcg {
    let a = mix(seed ^ mix(case as u64 ^ mix(chunk)));
    let b = mix(a ^ 0x5851_f42d_4c95_7f2d);
    Pcg64Mcg::new(((a as u128) << 64) | b as u128)
}

/// The result of one case: its detector, in one or three channels.
#[derive(Clone, Debug)]
pub enum CaseResult {
    Mono(Box<Detector<1>>),
    Rgb(Box<Detector<3>>),
}

impl CaseResult {
    /// Adds the photons of another result of the same case.
    pub fn merge(&mut self, other: &CaseResult) {
        match (self, other) {
            (CaseResult::Mono(a), CaseResult::Mono(b)) => a.merge(b),
            (CaseResult::Rgb(a), CaseResult::Rgb(b)) => a.merge(b),
            _ => unreachable!("results of one case have one channel count"),
        }
    }

    pub fn photons(&self) -> u64 {
        match self {
            CaseResult::Mono(d) => d.tallies.photons,
            CaseResult::Rgb(d) => d.tallies.photons,
        }
    }

    /// The facet interactions of all its photons' rays.
    pub fn interactions(&self) -> u64 {
        match self {
            CaseResult::Mono(d) => d.tallies.interactions,
            CaseResult::Rgb(d) => d.tallies.interactions,
        }
    }

    /// The albedo of order slot `slot` into `hemisphere` (channel 0) and its standard error;
    /// zero for slots no light reached.
    pub fn albedo(&self, slot: usize, hemisphere: Hemisphere) -> (f64, f64) {
        fn of<const C: usize>(d: &Detector<C>, slot: usize, hemisphere: Hemisphere) -> (f64, f64) {
            d.tallies
                .orders
                .get(slot)
                .map_or((0.0, 0.0), |o| o.albedo[hemisphere as usize].mean_and_stderr(d.tallies.photons, 0))
        }
        match self {
            CaseResult::Mono(d) => of(d, slot, hemisphere),
            CaseResult::Rgb(d) => of(d, slot, hemisphere),
        }
    }

    /// Whether this measurement meets a precision target: every nonzero albedo of the target's
    /// order slots has at most the target's absolute and relative standard errors.
    pub fn meets(&self, target: &PrecisionConfig) -> bool {
        self.albedo_stderrs(target.orders).iter().all(|&(mean, se)| {
            target.target_stderr.is_none_or(|t| se <= t) && target.target_rel_stderr.is_none_or(|t| se <= t * mean)
        })
    }

    /// The albedos and standard errors of order slots `0..=slots` in both hemispheres
    /// (channel 0), leaving out those with no light.
    pub fn albedo_stderrs(&self, slots: usize) -> Vec<(f64, f64)> {
        fn of<const C: usize>(d: &Detector<C>, slots: usize) -> Vec<(f64, f64)> {
            let n = d.tallies.photons;
            d.tallies
                .orders
                .iter()
                .take(slots + 1)
                .flat_map(|o| o.albedo.iter())
                .map(|t| t.mean_and_stderr(n, 0))
                .filter(|(mean, _)| *mean > 0.0)
                .collect()
        }
        match self {
            CaseResult::Mono(d) => of(d, slots),
            CaseResult::Rgb(d) => of(d, slots),
        }
    }
}

/// A detector type that a [`CaseResult`] can hold.
pub trait DetectorResult: Sized {
    fn into_result(self) -> CaseResult;
    fn of_result(result: &mut CaseResult) -> &mut Self;
}

impl DetectorResult for Detector<1> {
    fn into_result(self) -> CaseResult {
        CaseResult::Mono(Box::new(self))
    }
    fn of_result(result: &mut CaseResult) -> &mut Self {
        match result {
            CaseResult::Mono(d) => d,
            CaseResult::Rgb(_) => unreachable!("a mono walker fills mono results"),
        }
    }
}

impl DetectorResult for Detector<3> {
    fn into_result(self) -> CaseResult {
        CaseResult::Rgb(Box::new(self))
    }
    fn of_result(result: &mut CaseResult) -> &mut Self {
        match result {
            CaseResult::Rgb(d) => d,
            CaseResult::Mono(_) => unreachable!("an RGB walker fills RGB results"),
        }
    }
}

/// Walks the photons of one case, chunk by chunk, into detectors.
pub trait CaseWalker: Sync {
    /// An empty detector for this case.
    fn empty(&self) -> CaseResult;
    /// Walks every photon of `chunk` into `into`.
    fn walk_chunk(&self, chunk: u64, into: &mut CaseResult);
}

/// The walker of one case: a microsurface, a facet material, the incident direction.
struct Walker<'a, N, F> {
    surface: Microsurface<N>,
    facet: F,
    case: &'a Case,
    settings: &'a RunSettings,
}

impl<N, F, const C: usize> CaseWalker for (Walker<'_, N, F>, [(); C])
where
    N: Ndf,
    F: Facet<C>,
    Detector<C>: DetectorResult,
{
    fn empty(&self) -> CaseResult {
        let w = &self.0;
        Detector::<C>::new(w.settings.grid, w.case.wi, w.settings.max_order).into_result()
    }

    fn walk_chunk(&self, chunk: u64, into: &mut CaseResult) {
        let w = &self.0;
        let detector = Detector::<C>::of_result(into);
        let wi = w.case.wi;
        let mut rng = chunk_rng(w.settings.seed, w.case.index, chunk);
        let policy = &w.settings.policy;
        let photons = w.settings.chunk_photons(chunk);
        // Paths that never split are measured side by side. Which walk runs is part of the
        // output's identity, like CHUNK: the two draw random numbers in different orders.
        if w.settings.estimator == Estimator::Walk && policy.never_splits(&w.facet) {
            w.surface.walk_side_by_side(&w.facet, policy, wi, photons, &mut rng, detector);
            detector.end_chunk();
            return;
        }
        let mut stack = Vec::new();
        let mut nee_rng = chunk_rng(w.settings.seed ^ NEE_STREAMS, w.case.index, chunk);
        let mut profile = DepthProfile::default();
        let mut released = ReleasedPath::default();
        let mut joint = match w.settings.estimator {
            Estimator::JointChains(models) => {
                Some(PerChannel(std::array::from_fn(|c| ChainVisibility::of(models[c], w.case, models[0]))))
            }
            _ => None,
        };
        for _ in 0..photons {
            let interactions = match w.settings.estimator {
                Estimator::Walk => w.surface.trace(&w.facet, policy, wi, &mut rng, &mut stack, detector),
                Estimator::Wang(mut shadowing) => {
                    chain::trace(&mut shadowing, &w.surface.ndf, &w.facet, policy, wi, &mut rng, detector)
                }
                Estimator::PositionFree if !w.case.position_free_applies() => 0,
                Estimator::PositionFree => {
                    chain::trace(&mut profile, &w.surface.ndf, &w.facet, policy, wi, &mut rng, detector)
                }
                Estimator::CuiReleased if !w.case.cui_released_applies() => 0,
                Estimator::CuiReleased => {
                    chain::trace(&mut released, &w.surface.ndf, &w.facet, policy, wi, &mut rng, detector)
                }
                Estimator::JointChains(_) => {
                    let joint = joint.as_mut().expect("built above for joint chains");
                    chain::trace(joint, &w.surface.ndf, &w.facet, policy, wi, &mut rng, detector)
                }
                Estimator::HeitzNee(samples) => {
                    let (ndf, normals, facet, sink) = (&w.surface.ndf, w.surface.normals, &w.facet, &mut *detector);
                    let mut nee = NextEvent { ndf, normals, facet, sink, rng: &mut nee_rng, samples };
                    w.surface.trace(&w.facet, policy, wi, &mut rng, &mut stack, &mut nee)
                }
            };
            detector.end_photon(interactions);
        }
        detector.end_chunk();
    }
}

/// Builds the walker of a case and hands it to `f`. The case's height distribution does not
/// enter: the walk runs in optical depth, where every height law gives the same walk
/// (docs/theory.md §2.1, §2.4).
pub fn with_walker<T>(case: &Case, settings: &RunSettings, rgb: bool, f: impl FnOnce(&dyn CaseWalker) -> T) -> T {
    if rgb { with_ndf::<3, T>(case, settings, f) } else { with_ndf::<1, T>(case, settings, f) }
}

fn with_ndf<const C: usize, T>(case: &Case, settings: &RunSettings, f: impl FnOnce(&dyn CaseWalker) -> T) -> T
where
    Detector<C>: DetectorResult,
{
    // Each NDF and facet is compiled into a walker of its own: the walk's hot loop then
    // calls them without a dispatch.
    let Microsurface { ndf, smith, normals } = case.surface;
    match ndf {
        AnyNdf::Ggx(ndf) => with_material::<Ggx, C, T>(Microsurface { ndf, smith, normals }, case, settings, f),
        AnyNdf::Beckmann(ndf) => {
            with_material::<Beckmann, C, T>(Microsurface { ndf, smith, normals }, case, settings, f)
        }
        AnyNdf::StudentT(ndf) => {
            with_material::<StudentT, C, T>(Microsurface { ndf, smith, normals }, case, settings, f)
        }
    }
}

fn with_material<N: Ndf, const C: usize, T>(
    surface: Microsurface<N>,
    case: &Case,
    settings: &RunSettings,
    f: impl FnOnce(&dyn CaseWalker) -> T,
) -> T
where
    Detector<C>: DetectorResult,
{
    let channels = [(); C];
    match case.material.channels::<C>() {
        Material::Conductor(facet) => f(&(Walker { surface, facet, case, settings }, channels)),
        Material::Dielectric(facet) => f(&(Walker { surface, facet, case, settings }, channels)),
        Material::Lambertian(facet) => f(&(Walker { surface, facet, case, settings }, channels)),
        Material::Hammon(facet) => f(&(Walker { surface, facet, case, settings }, channels)),
    }
}

/// Chunks per round: the unit at which runs checkpoint and check precision targets. Rounds
/// are fixed stretches of a shard's chunk sequence, so where a run stops does not depend on
/// threads.
pub const ROUND_CHUNKS: u64 = 32;

/// How far one case has got: its detector and how many rounds of its chunks are in it.
#[derive(Clone, Debug)]
pub struct CaseState {
    pub result: CaseResult,
    pub rounds_done: u64,
    pub finished: bool,
}

impl RunSettings {
    /// Chunks of this shard.
    fn shard_chunks(&self) -> u64 {
        self.chunks().saturating_sub(self.shard.index).div_ceil(self.shard.count)
    }

    /// The `k`-th chunk of this shard, if it has that many.
    fn shard_chunk(&self, k: u64) -> Option<u64> {
        (k < self.shard_chunks()).then(|| self.shard.index + k * self.shard.count)
    }

    /// Rounds of this shard.
    pub(crate) fn rounds(&self) -> u64 {
        self.shard_chunks().div_ceil(ROUND_CHUNKS)
    }

    /// Chunks of this shard in round `round`.
    fn round_len(&self, round: u64) -> u64 {
        self.shard_chunks().saturating_sub(round * ROUND_CHUNKS).min(ROUND_CHUNKS)
    }
}

/// What one thread walked of one round: `chunks` of its chunks, in `result`.
struct RoundPart {
    round: u64,
    chunks: u64,
    result: CaseResult,
}

/// Continues one case from `state` round by round until its chunks are done or `after_round`
/// returns false (it is called after every round, in order, e.g. to checkpoint or check
/// precision).
///
/// There is no barrier between rounds, so that every thread stays busy at round ends and
/// however many threads there are per round. The pool's threads take this shard's chunks in
/// sequence, each walking into its own part of the round of its chunk and handing the part
/// over when it moves on to the next round. The calling thread adds the parts up and passes
/// each round to `state` once all its chunks are in, rounds in order; when the case stops,
/// chunks already walked in later rounds are dropped. So `state` always holds whole rounds
/// and ends as the rounds walked one after the other would leave it.
pub fn run_case(
    walker: &dyn CaseWalker,
    settings: &RunSettings,
    state: &mut CaseState,
    pool: &rayon::ThreadPool,
    progress: &ProgressBar,
    after_round: &mut dyn FnMut(&CaseState) -> anyhow::Result<bool>,
) -> anyhow::Result<()> {
    if state.rounds_done >= settings.rounds() {
        // A shard without chunks (more shards than chunks) has no rounds.
        state.finished = true;
    }
    if state.finished {
        return Ok(());
    }
    let next = &AtomicU64::new(state.rounds_done * ROUND_CHUNKS);
    let stop = &AtomicBool::new(false);
    let (sender, parts) = mpsc::channel();
    std::thread::scope(|scope| {
        scope.spawn(move || {
            pool.broadcast(|_| walk_parts(walker, settings, next, stop, progress, &sender));
        });
        let mut waiting: BTreeMap<u64, RoundPart> = BTreeMap::new();
        for part in parts {
            if state.finished {
                continue;
            }
            match waiting.entry(part.round) {
                Entry::Vacant(v) => {
                    v.insert(part);
                }
                Entry::Occupied(mut o) => {
                    let whole = o.get_mut();
                    whole.result.merge(&part.result);
                    whole.chunks += part.chunks;
                }
            }
            while waiting.get(&state.rounds_done).is_some_and(|p| p.chunks == settings.round_len(p.round)) {
                let done = waiting.remove(&state.rounds_done).expect("the round is complete");
                state.result.merge(&done.result);
                state.rounds_done += 1;
                state.finished = state.rounds_done >= settings.rounds();
                let go_on = after_round(state);
                if !matches!(go_on, Ok(true)) {
                    state.finished = true;
                }
                if state.finished {
                    stop.store(true, Ordering::Relaxed);
                    go_on?;
                    break;
                }
            }
        }
        Ok(())
    })
}

/// One pool thread's share of [`run_case`]: takes the shard's next chunk until there is none
/// or the case stops, and sends each round's part when it moves past it.
fn walk_parts(
    walker: &dyn CaseWalker,
    settings: &RunSettings,
    next: &AtomicU64,
    stop: &AtomicBool,
    progress: &ProgressBar,
    sender: &mpsc::Sender<RoundPart>,
) {
    let mut part: Option<RoundPart> = None;
    while !stop.load(Ordering::Relaxed) {
        let k = next.fetch_add(1, Ordering::Relaxed);
        let Some(chunk) = settings.shard_chunk(k) else { break };
        let round = k / ROUND_CHUNKS;
        if let Some(done) = part.take_if(|p| p.round != round) {
            // The receiver is gone only when the calling thread stopped on an error or a
            // panic, and then no part is wanted.
            let _ = sender.send(done);
        }
        let p = part.get_or_insert_with(|| RoundPart { round, chunks: 0, result: walker.empty() });
        walker.walk_chunk(chunk, &mut p.result);
        p.chunks += 1;
        progress.inc(settings.chunk_photons(chunk));
    }
    if let Some(done) = part {
        let _ = sender.send(done);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed form of `shard_paths` against the sum over the shard's chunks.
    #[test]
    fn shard_paths_is_the_sum_over_the_shards_chunks() {
        let config = crate::setup::config::Config::parse(
            "paths = 2\n[surface]\nalpha = 0.5\n[material]\nkind = \"conductor\"\n[incident]\ntheta_deg = 0\n",
        )
        .unwrap();
        for paths in [2, CHUNK - 1, CHUNK, CHUNK + 1, 5 * CHUNK + 7, 9 * CHUNK] {
            for count in 1..=11 {
                for index in 0..count {
                    let s = RunSettings { paths, shard: Shard { index, count }, ..RunSettings::from_config(&config) };
                    let sum: u64 = (index..s.chunks()).step_by(count as usize).map(|c| s.chunk_photons(c)).sum();
                    assert_eq!(s.shard_paths(), sum, "paths {paths}, shard {index}/{count}");
                }
            }
        }
        // 10^19 photons: once a loop over 6 x 10^14 chunks.
        let s = RunSettings { paths: 10_000_000_000_000_000_000, ..RunSettings::from_config(&config) };
        assert_eq!(s.shard_paths(), 10_000_000_000_000_000_000);
    }
}
