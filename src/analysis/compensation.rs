//! Energy-compensation models of conductors as renderers ship them, evaluated exactly as
//! published in the detector's bins, to be judged against the walk's all-orders lobe:
//!
//! - Kulla & Conty 2017 ("Revisiting Physically Based Shading at Imageworks", SIGGRAPH course,
//!   the "energy compensation" slides): single scattering plus
//!   `f_ms = (1 - E(mu_o))(1 - E(mu_i)) / (pi (1 - E_avg))`, scaled for Fresnel by
//!   `F_avg^2 E_avg / (1 - F_avg (1 - E_avg))`, `F_avg = 2 ∫ F(mu) mu dmu`.
//! - Turquin 2019 ("Practical multiple scattering compensation for microfacet models", tech
//!   report): single scattering times `1 + F0 (1 - E(mu_v)) / E(mu_v)`.
//! - Fdez-Agüera 2019 ("A Multiple-Scattering Microfacet Model for Real-Time Image-based
//!   Lighting", JCGT 8(1)): single scattering plus a lobe constant in the light direction,
//!   `F_ms E_ms / pi`, `E_ms = 1 - E(mu_v)`, `F_ms = E_F(mu_v) F_avg / (1 - E_ms F_avg)`,
//!   `F_avg = F0 + (1 - F0) / 21`.
//!
//! `mu_v` is the cosine of the view direction of the engines, the direction the renderer's
//! camera ray arrives from: smithwalk's outgoing direction `wo` (towards the detector), not the
//! light's `wi`. `E(mu)` is the directional albedo of single scattering with F = 1 and
//! `E_F(mu)` the one with the facet's Fresnel (THEORY.md §9.4), both from quadrature of the exact
//! single-scattering lobe (§5), not from a noisy table; [`Albedo::from_table`] evaluates a
//! model from a table of the user's own instead, as engines ship them.

use std::f64::consts::PI;

use glam::DVec3;
use microsurface::fresnel;
use microsurface::ndf::{Beckmann, Ggx, Ndf, Roughness};
use microsurface::single;

use crate::analysis::models::{BinRule, integrate_bins};
use crate::analysis::quadrature::{gauss_legendre, integrate, integrate_2d};
use crate::engine::detector::{Grid, Hemisphere};
use crate::setup::cases::Case;
use crate::setup::config::{FresnelKind, IncidentSide, MaterialConfig, NdfKind, NormalsKind, SmithKind};

/// A published energy-compensation model.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Compensation {
    KullaConty,
    Turquin,
    FdezAguera,
}

/// The reflectance of a conductor facet in one colour channel, as a function of the cosine
/// between the light and the facet normal (§4.2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Fresnel {
    One,
    Schlick(f64),
    Conductor { eta: f64, k: f64 },
}

impl Fresnel {
    pub fn at(self, c: f64) -> f64 {
        match self {
            Fresnel::One => 1.0,
            Fresnel::Schlick(f0) => fresnel::schlick(f0, c),
            Fresnel::Conductor { eta, k } => fresnel::conductor(eta, k, c),
        }
    }

    /// `F0 = F(1)`, the reflectance at normal incidence that Turquin and Fdez-Agüera use.
    pub fn f0(self) -> f64 {
        self.at(1.0)
    }

    /// The channels of a conductor material (`C` = 1 or 3), or `None` for other materials.
    pub fn channels<const C: usize>(material: &MaterialConfig) -> Option<[Fresnel; C]> {
        let MaterialConfig::Conductor { fresnel: kind, f0, eta, k, .. } = material else { return None };
        Some(match kind {
            FresnelKind::None => [Fresnel::One; C],
            FresnelKind::Schlick => (*f0)?.to_array::<C>().map(Fresnel::Schlick),
            FresnelKind::Exact => {
                let (eta, k) = ((*eta)?.to_array::<C>(), (*k)?.to_array::<C>());
                std::array::from_fn(|c| Fresnel::Conductor { eta: eta[c], k: k[c] })
            }
        })
    }
}

/// The hemispherical average of a reflectance, `F_avg = 2 ∫_0^1 F(mu) mu dmu` (Kulla & Conty
/// 2017, the Fresnel slides), by adaptive quadrature.
pub fn fresnel_average(f: Fresnel) -> f64 {
    2.0 * integrate(|mu| f.at(mu) * mu, 0.0, 1.0, 1e-13).0
}

/// Fdez-Agüera 2019's closed form of `F_avg` (§3 of the paper): `F0 + (1 - F0) / 21`, exact
/// for Schlick's Fresnel (`2 ∫ (1 - mu)^5 mu dmu = 1/21`), an approximation otherwise.
pub fn fdez_aguera_fresnel_average(f0: f64) -> f64 {
    f0 + (1.0 - f0) / 21.0
}

/// Kulla & Conty 2017's multiple-scattering lobe with F = 1,
/// `f_ms = (1 - E(mu_o)) (1 - E(mu_i)) / (pi (1 - E_avg))` (a BSDF value, sr^-1): its
/// cosine-weighted integral over either direction is `1 - E` of the other, which is what
/// single scattering loses. 0 where nothing is lost (`E_avg = 1`).
pub fn kulla_conty_lobe(e_i: f64, e_o: f64, e_avg: f64) -> f64 {
    let lost = 1.0 - e_avg;
    if lost <= 0.0 { 0.0 } else { (1.0 - e_o) * (1.0 - e_i) / (PI * lost) }
}

/// Kulla & Conty 2017's Fresnel factor of the multiple-scattering lobe,
/// `F_avg^2 E_avg / (1 - F_avg (1 - E_avg))`: the geometric series of bounces that each
/// escape with probability `E_avg` and reflect `F_avg`, relative to `1 - E_avg` at F = 1.
pub fn kulla_conty_fresnel(f_avg: f64, e_avg: f64) -> f64 {
    f_avg * f_avg * e_avg / (1.0 - f_avg * (1.0 - e_avg))
}

/// Turquin 2019's scale of single scattering, `1 + F0 (1 - E(mu_v)) / E(mu_v)`, with `e_v`
/// the F = 1 albedo of the view direction: with F = 1 the compensated lobe integrates to 1
/// over the light directions.
pub fn turquin_scale(f0: f64, e_v: f64) -> f64 {
    if e_v > 0.0 { 1.0 + f0 * (1.0 - e_v) / e_v } else { 1.0 }
}

/// Fdez-Agüera 2019's multiple-scattering lobe (a BSDF value, sr^-1), constant in the light
/// direction: `F_ms E_ms / pi` with `E_ms = 1 - E(mu_v)` and
/// `F_ms = E_F(mu_v) F_avg / (1 - E_ms F_avg)`, where `e_fresnel_v = E_F(mu_v)` is the
/// single-scattering albedo with the facet's Fresnel (the paper's `F_ss E_ss`).
pub fn fdez_aguera_lobe(e_v: f64, e_fresnel_v: f64, f_avg: f64) -> f64 {
    let e_ms = 1.0 - e_v;
    e_fresnel_v * f_avg / (1.0 - e_ms * f_avg) * e_ms / PI
}

/// An isotropic NDF of a given roughness.
pub trait Isotropic: Ndf {
    fn with_alpha(alpha: f64) -> Self;
}

impl Isotropic for Ggx {
    fn with_alpha(alpha: f64) -> Self {
        Ggx(Roughness::isotropic(alpha))
    }
}

impl Isotropic for Beckmann {
    fn with_alpha(alpha: f64) -> Self {
        Beckmann(Roughness::isotropic(alpha))
    }
}

/// The directional albedo of exact single scattering (§5, §9.4) of an isotropic NDF for light at
/// `mu = cos theta_i` with the facet reflectance `f`: `E_F(mu) = ∫ f_1(wi, wo) cos theta_o dwo`
/// over the upper hemisphere, by nested adaptive Gauss–Kronrod to `abs_tol` in `cos theta_o`
/// (split at `mu`, where the specular peak is) and in the azimuth over `[0, pi]` (the lobe is
/// symmetric about the plane of incidence; the peak sits at the end `pi`). The cosine-weighted
/// lobe is smooth in `wo` above the horizon, so the rule converges fast.
pub fn directional_albedo<N: Ndf>(ndf: &N, mu: f64, f: Fresnel, abs_tol: f64) -> f64 {
    let wi = DVec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
    let lobe = |u: f64, phi: f64| {
        let s = (1.0 - u * u).max(0.0).sqrt();
        let (sp, cp) = phi.sin_cos();
        single::reflection(ndf, wi, DVec3::new(s * cp, s * sp, u), |c| f.at(c))
    };
    let half = 0.5 * abs_tol;
    let below = integrate_2d(lobe, (0.0, mu), (0.0, PI), half).0;
    let above = integrate_2d(lobe, (mu, 1.0), (0.0, PI), half).0;
    2.0 * (below + above)
}

/// Gauss–Legendre nodes per panel of an [`Albedo`].
const NODES: usize = 12;
/// Panel edges of an [`Albedo`] in mu: halving towards grazing, where E changes fastest at low
/// roughness, and four equal panels on [1/2, 1].
const EDGES: [f64; 16] = [
    0.0,
    1.0 / 4096.0,
    1.0 / 2048.0,
    1.0 / 1024.0,
    1.0 / 512.0,
    1.0 / 256.0,
    1.0 / 128.0,
    1.0 / 64.0,
    1.0 / 32.0,
    1.0 / 16.0,
    1.0 / 8.0,
    1.0 / 4.0,
    0.5,
    0.625,
    0.75,
    0.875,
];

/// One panel of a piecewise-polynomial E: values at Gauss–Legendre nodes with their
/// quadrature and barycentric weights.
#[derive(Clone, Debug)]
struct Panel {
    lo: f64,
    hi: f64,
    nodes: Vec<(f64, f64)>,
    values: Vec<f64>,
    barycentric: Vec<f64>,
}

impl Panel {
    /// Lagrange interpolation through the nodes (barycentric form).
    fn at(&self, mu: f64) -> f64 {
        let (mut num, mut den) = (0.0, 0.0);
        for ((&(x, _), &v), &b) in self.nodes.iter().zip(&self.values).zip(&self.barycentric) {
            if mu == x {
                return v;
            }
            let t = b / (mu - x);
            num += t * v;
            den += t;
        }
        num / den
    }
}

/// A directional albedo `E(mu)` on `[0, 1]` as a function: either the exact quadrature of single
/// scattering at Gauss–Legendre nodes of graded panels with polynomial interpolation between
/// them (the interpolant differs from direct quadrature by < 1e-8 for GGX and Beckmann at alpha
/// 0.01 to 3, tested in `tests/compensation.rs`), or a user's table interpolated linearly at its
/// own resolution. `average` is `E_avg = 2 ∫ E(mu) mu dmu` of the same function.
#[derive(Clone, Debug)]
pub struct Albedo {
    shape: Shape,
    average: f64,
}

#[derive(Clone, Debug)]
enum Shape {
    Panels(Vec<Panel>),
    /// `(mu, E)` knots in increasing mu, constant beyond the first and last.
    Table(Vec<(f64, f64)>),
}

impl Albedo {
    /// `E_F(mu)` of exact single scattering for an isotropic NDF and one channel's Fresnel.
    pub fn exact<N: Ndf>(ndf: &N, f: Fresnel) -> Self {
        use rayon::prelude::*;
        let mut edges = EDGES.to_vec();
        edges.push(1.0);
        let mut panels: Vec<Panel> = edges
            .windows(2)
            .map(|w| {
                let nodes = gauss_legendre(NODES, w[0], w[1]);
                let barycentric = (0..NODES)
                    .map(|j| {
                        let prod: f64 = (0..NODES)
                            .filter(|&k| k != j)
                            .map(|k| (nodes[j].0 - nodes[k].0) * 4.0 / (w[1] - w[0]))
                            .product();
                        1.0 / prod
                    })
                    .collect();
                Panel { lo: w[0], hi: w[1], nodes, values: Vec::new(), barycentric }
            })
            .collect();
        panels.par_iter_mut().for_each(|p| {
            p.values = p.nodes.iter().map(|&(mu, _)| directional_albedo(ndf, mu, f, 1e-10)).collect();
        });
        let average = 2.0
            * panels.iter().flat_map(|p| p.nodes.iter().zip(&p.values).map(|(&(mu, w), &e)| w * mu * e)).sum::<f64>();
        Albedo { shape: Shape::Panels(panels), average }
    }

    /// A user's table: `E` at knots `mu` (any order; linear interpolation between them, constant
    /// beyond) and the table's own `E_avg`, as an engine ships them.
    pub fn from_table(mut knots: Vec<(f64, f64)>, average: f64) -> Self {
        knots.sort_by(|a, b| a.0.total_cmp(&b.0));
        Albedo { shape: Shape::Table(knots), average }
    }

    /// `E(mu)` for `mu` in `[0, 1]`.
    pub fn at(&self, mu: f64) -> f64 {
        match &self.shape {
            Shape::Panels(panels) => {
                let p = panels.iter().find(|p| mu <= p.hi).unwrap_or(&panels[panels.len() - 1]);
                debug_assert!(mu >= p.lo || mu < 0.0);
                p.at(mu)
            }
            Shape::Table(knots) => {
                let i = knots.partition_point(|k| k.0 < mu);
                if i == 0 {
                    return knots[0].1;
                }
                if i == knots.len() {
                    return knots[i - 1].1;
                }
                let ((x0, y0), (x1, y1)) = (knots[i - 1], knots[i]);
                y0 + (y1 - y0) * (mu - x0) / (x1 - x0)
            }
        }
    }

    /// `E_avg = 2 ∫_0^1 E(mu) mu dmu`.
    pub fn average(&self) -> f64 {
        self.average
    }
}

/// One channel of a compensated conductor: its NDF, Fresnel and the albedo functions the
/// model reads.
pub struct Compensated<'a, N: Ndf> {
    model: Compensation,
    ndf: N,
    fresnel: Fresnel,
    /// `E(mu)` with F = 1.
    albedo: &'a Albedo,
    /// `E_F(mu)` with the channel's Fresnel (Fdez-Agüera's `F_ss E_ss`).
    albedo_fresnel: &'a Albedo,
    /// The model's `F_avg`: exact for Kulla & Conty, Fdez-Agüera's closed form for his.
    f_avg: f64,
}

impl<'a, N: Ndf> Compensated<'a, N> {
    /// `albedo` is `E(mu)` with F = 1; `albedo_fresnel` is `E_F(mu)` with `fresnel` (read by
    /// Fdez-Agüera's model only).
    pub fn new(model: Compensation, ndf: N, fresnel: Fresnel, albedo: &'a Albedo, albedo_fresnel: &'a Albedo) -> Self {
        let f_avg = match model {
            Compensation::KullaConty => fresnel_average(fresnel),
            Compensation::Turquin => fresnel.f0(),
            Compensation::FdezAguera => fdez_aguera_fresnel_average(fresnel.f0()),
        };
        Compensated { model, ndf, fresnel, albedo, albedo_fresnel, f_avg }
    }

    /// The single-scattering BSDF `F D G2 / (4 mu_i mu_o)` (§5): the order-1 part of every model.
    pub fn single(&self, wi: DVec3, wo: DVec3) -> f64 {
        if wo.z <= 0.0 {
            return 0.0;
        }
        single::reflection(&self.ndf, wi, wo, |c| self.fresnel.at(c)) / wo.z
    }

    /// What the model adds to single scattering (sr^-1), for `wi` towards the light and `wo`
    /// towards the viewer, both above the horizon.
    pub fn multiple(&self, wi: DVec3, wo: DVec3) -> f64 {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        let e_avg = self.albedo.average();
        match self.model {
            Compensation::KullaConty => {
                kulla_conty_lobe(self.albedo.at(wi.z), self.albedo.at(wo.z), e_avg)
                    * kulla_conty_fresnel(self.f_avg, e_avg)
            }
            Compensation::Turquin => {
                self.single(wi, wo) * (turquin_scale(self.fresnel.f0(), self.albedo.at(wo.z)) - 1.0)
            }
            Compensation::FdezAguera => {
                fdez_aguera_lobe(self.albedo.at(wo.z), self.albedo_fresnel.at(wo.z), self.f_avg)
            }
        }
    }

    /// The compensated BSDF, all orders (sr^-1).
    pub fn bsdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        self.single(wi, wo) + self.multiple(wi, wo)
    }
}

/// Albedo functions computed once per NDF, roughness and Fresnel, shared by every case and
/// model of a comparison.
#[derive(Default)]
pub struct AlbedoCache {
    entries: Vec<((NdfKind, f64, Fresnel), Albedo)>,
}

impl AlbedoCache {
    pub fn get(&mut self, ndf: NdfKind, alpha: f64, f: Fresnel) -> &Albedo {
        let key = (ndf, alpha, f);
        let index = match self.entries.iter().position(|(k, _)| *k == key) {
            Some(i) => i,
            None => {
                let albedo = match ndf {
                    NdfKind::Ggx => Albedo::exact(&Ggx::with_alpha(alpha), f),
                    NdfKind::Beckmann => Albedo::exact(&Beckmann::with_alpha(alpha), f),
                };
                self.entries.push((key, albedo));
                self.entries.len() - 1
            }
        };
        &self.entries[index].1
    }
}

/// Whether a case is one the compensation models describe: a conductor on an isotropic
/// surface with the true Smith Lambda and visible normals, lit from outside.
pub fn applies(case: &Case) -> bool {
    matches!(case.material, MaterialConfig::Conductor { .. })
        && case.alpha_x == case.alpha_y
        && case.smith == SmithKind::Exact
        && case.normals == NormalsKind::Vndf
        && case.side == IncidentSide::Outside
}

/// Expected all-orders reflected energy per photon of a compensation model in every reflection
/// bin of a case (index `cos * phi_bins + phi`), per channel (`C` = 1 or 3), integrated over each
/// bin by adaptive quadrature to `abs_tol`; `None` where the model does not apply.
pub fn compensated_bins<const C: usize>(
    model: Compensation,
    case: &Case,
    grid: &Grid,
    abs_tol: f64,
    cache: &mut AlbedoCache,
) -> Option<[Vec<f64>; C]> {
    if !applies(case) {
        return None;
    }
    let channels = Fresnel::channels::<C>(&case.material)?;
    let alpha = case.alpha_x;
    let albedo = cache.get(case.ndf, alpha, Fresnel::One).clone();
    let mut out: [Vec<f64>; C] = std::array::from_fn(|_| Vec::new());
    for (c, &f) in channels.iter().enumerate() {
        let albedo_fresnel = match model {
            Compensation::FdezAguera => cache.get(case.ndf, alpha, f).clone(),
            _ => albedo.clone(),
        };
        out[c] = match case.ndf {
            NdfKind::Ggx => {
                let lobe = Compensated::new(model, Ggx::with_alpha(alpha), f, &albedo, &albedo_fresnel);
                lobe_bins(&lobe, case, grid, abs_tol)
            }
            NdfKind::Beckmann => {
                let lobe = Compensated::new(model, Beckmann::with_alpha(alpha), f, &albedo, &albedo_fresnel);
                lobe_bins(&lobe, case, grid, abs_tol)
            }
        };
    }
    Some(out)
}

/// [`compensated_bins`] with the channel names of a run's tables: `""` for a mono run, `r`, `g`,
/// `b` for an RGB one. The tolerance is held at 1e-10 per bin or looser: the models' own
/// albedo functions are good to ~1e-9, and a bin's standard error at 10^8 photons is ~1e-6.
pub fn compensated_channels(
    model: Compensation,
    case: &Case,
    grid: &Grid,
    abs_tol: f64,
    rgb: bool,
    cache: &mut AlbedoCache,
) -> Option<Vec<(&'static str, Vec<f64>)>> {
    let abs_tol = abs_tol.max(1e-10);
    if rgb {
        let [r, g, b] = compensated_bins::<3>(model, case, grid, abs_tol, cache)?;
        Some(vec![("r", r), ("g", g), ("b", b)])
    } else {
        let [mono] = compensated_bins::<1>(model, case, grid, abs_tol, cache)?;
        Some(vec![("", mono)])
    }
}

/// The cosine-weighted compensated lobe of a case integrated over every reflection bin.
fn lobe_bins<N: Ndf>(lobe: &Compensated<'_, N>, case: &Case, grid: &Grid, abs_tol: f64) -> Vec<f64> {
    let wi = case.incident_direction();
    integrate_bins(case, grid, Hemisphere::R, BinRule::Adaptive(abs_tol), |wo| lobe.bsdf(wi, wo) * wo.z)
}
