//! Running cases: the work is cut into fixed chunks of photons, each with its own random
//! stream derived from (seed, case, chunk), and spread over a thread pool. Detectors are merged
//! with exact integer sums, so outputs are bit-identical for any thread count.

use std::sync::atomic::{AtomicU64, Ordering};

use indicatif::ProgressBar;
use microsurface::facet::{Conductor, ConductorFresnel, Dielectric, Facet, Hammon, Lambertian};
use microsurface::ndf::{Beckmann, Ggx, Ndf, Roughness};
use microsurface::normals::Normals;
use microsurface::smith::Smith;
use microsurface::walk::{EnergyPolicy, Microsurface};
use rand_pcg::Pcg64Mcg;
use serde::{Deserialize, Serialize};

use crate::cases::Case;
use crate::config::{Config, FresnelKind, MaterialConfig, NdfKind, NormalsKind, SmithKind};
use crate::detector::{Detector, Grid};

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

/// What every case of a run shares.
#[derive(Clone, Copy, Debug)]
pub struct RunSettings {
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

    /// Photons of one case that this shard walks.
    pub fn shard_paths(&self) -> u64 {
        (self.shard.index..self.chunks()).step_by(self.shard.count as usize).map(|c| self.chunk_photons(c)).sum()
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

/// Simulates one case over `threads` worker threads of `pool`.
pub fn simulate_case(
    case: &Case,
    settings: &RunSettings,
    rgb: bool,
    pool: &rayon::ThreadPool,
    progress: &ProgressBar,
) -> CaseResult {
    if rgb {
        CaseResult::Rgb(Box::new(with_ndf::<3>(case, settings, pool, progress)))
    } else {
        CaseResult::Mono(Box::new(with_ndf::<1>(case, settings, pool, progress)))
    }
}

fn with_ndf<const C: usize>(
    case: &Case,
    settings: &RunSettings,
    pool: &rayon::ThreadPool,
    progress: &ProgressBar,
) -> Detector<C> {
    let roughness = Roughness { x: case.alpha_x, y: case.alpha_y };
    match case.ndf {
        NdfKind::Ggx => with_surface::<Ggx, C>(Ggx(roughness), case, settings, pool, progress),
        NdfKind::Beckmann => with_surface::<Beckmann, C>(Beckmann(roughness), case, settings, pool, progress),
    }
}

/// Builds the microsurface of a case. The case's height distribution does not enter: the walk
/// runs in optical depth, where every height law gives the same walk (THEORY.md §2.1, §2.4).
fn with_surface<N: Ndf, const C: usize>(
    ndf: N,
    case: &Case,
    settings: &RunSettings,
    pool: &rayon::ThreadPool,
    progress: &ProgressBar,
) -> Detector<C> {
    let smith = match case.smith {
        SmithKind::Exact => Smith::Exact,
        SmithKind::Symmetric => Smith::Symmetric,
    };
    let normals = match case.normals {
        NormalsKind::Vndf => Normals::Visible,
        NormalsKind::HammonRejection => Normals::HammonRejection,
    };
    with_material(&Microsurface { ndf, smith, normals }, case, settings, pool, progress)
}

fn with_material<N: Ndf, const C: usize>(
    surface: &Microsurface<N>,
    case: &Case,
    settings: &RunSettings,
    pool: &rayon::ThreadPool,
    progress: &ProgressBar,
) -> Detector<C> {
    match &case.material {
        MaterialConfig::Conductor { fresnel, f0, eta, k, .. } => {
            let fresnel = match fresnel {
                FresnelKind::None => ConductorFresnel::None,
                FresnelKind::Schlick => ConductorFresnel::Schlick { f0: channels(f0) },
                FresnelKind::Exact => ConductorFresnel::Exact { eta: channels(eta), k: channels(k) },
            };
            run_chunks(surface, &Conductor { fresnel }, case, settings, pool, progress)
        }
        MaterialConfig::Dielectric { eta, .. } => {
            run_chunks(surface, &Dielectric { eta: *eta }, case, settings, pool, progress)
        }
        MaterialConfig::Diffuse { albedo, .. } => {
            run_chunks(surface, &Lambertian { albedo: albedo.to_array() }, case, settings, pool, progress)
        }
        MaterialConfig::Hammon { f0, albedo, .. } => {
            let facet = Hammon { f0: f0.to_array(), albedo: albedo.to_array() };
            run_chunks(surface, &facet, case, settings, pool, progress)
        }
    }
}

fn channels<const C: usize>(c: &Option<crate::config::Channels>) -> [f64; C] {
    c.expect("validated: the Fresnel mode's parameters are present").to_array()
}

/// Runs every chunk of a case on the pool: each worker takes the next chunk index from a
/// shared counter and accumulates into its own detector; the detectors are merged at the end.
fn run_chunks<N, F, const C: usize>(
    surface: &Microsurface<N>,
    facet: &F,
    case: &Case,
    settings: &RunSettings,
    pool: &rayon::ThreadPool,
    progress: &ProgressBar,
) -> Detector<C>
where
    N: Ndf,
    F: Facet<C>,
{
    let wi = case.incident_direction();
    let next = AtomicU64::new(0);
    let chunks = settings.chunks();
    let partials = pool.broadcast(|_| {
        let mut detector = Detector::<C>::new(settings.grid, wi, settings.max_order);
        let mut stack = Vec::new();
        loop {
            let chunk = settings.shard.index + next.fetch_add(1, Ordering::Relaxed) * settings.shard.count;
            if chunk >= chunks {
                break detector;
            }
            let photons = settings.chunk_photons(chunk);
            let mut rng = chunk_rng(settings.seed, case.index, chunk);
            for _ in 0..photons {
                let interactions = surface.trace(facet, &settings.policy, wi, &mut rng, &mut stack, &mut detector);
                detector.end_photon(interactions);
            }
            progress.inc(photons);
        }
    });
    let mut partials = partials.into_iter();
    let mut total = partials.next().unwrap_or_else(|| Detector::new(settings.grid, wi, settings.max_order));
    for p in partials {
        total.merge(&p);
    }
    total
}
