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
//! - MaterialX's GGX energy compensation (`mx_ggx_energy_compensation` in
//!   `libraries/pbrlib/genglsl/lib/mx_microfacet_specular.glsl`, read at AcademySoftwareFoundation/MaterialX
//!   commit 4177b2cbd48b579ca1e8f7d9901584d811c63b68): Turquin's scale with
//!   `F_ss = F0 + (F90 - F0) / 21` (F90 = 1 for a conductor) in place of `F0`, and `E(mu_v)` from
//!   MaterialX's rational fit `mx_ggx_dir_albedo_analytic` ([`materialx_albedo`]) in place of
//!   the exact albedo.
//!
//! `mu_v` is the cosine of the view direction of the engines, the direction the renderer's
//! camera ray arrives from: smithwalk's outgoing direction `wo` (towards the detector), not the
//! light's `wi`. `E(mu)` is the directional albedo of single scattering with F = 1 and
//! `E_F(mu)` the one with the facet's Fresnel (docs/theory.md §9.4), both from quadrature of the exact
//! single-scattering lobe (§5), not from a noisy table: each model is exactly itself. On request
//! (`--albedo-table`, [`AlbedoTable`]) `E` and `E_avg` come from a user's table instead, as
//! engines ship them.

use std::f64::consts::PI;

use glam::DVec3;
use microsurface::facet::{Conductor, ConductorFresnel};
use microsurface::fresnel;
use microsurface::material::Material;
use microsurface::ndf::{AnyNdf, Beckmann, Ggx, Ndf, Roughness, slope_to_normal};
use microsurface::normals::Normals;
use microsurface::single;
use microsurface::smith::Smith;

use crate::analysis::albedo_table::{AlbedoTable, linear};
use crate::analysis::models::{LobeIntegrals, MAX_BIN_EVALUATIONS, integrate_bins, specular_peak};
use crate::analysis::quadrature::{gauss_legendre, integrate};
use crate::engine::detector::{Grid, Hemisphere};
use crate::setup::cases::Case;
use crate::setup::config::{IncidentSide, Model};

/// A published energy-compensation model.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Compensation {
    KullaConty,
    Turquin,
    FdezAguera,
    MaterialX,
}

impl Compensation {
    /// The compensation model that `model` names, if it names one.
    pub fn of(model: Model) -> Option<Self> {
        match model {
            Model::KullaConty => Some(Compensation::KullaConty),
            Model::Turquin => Some(Compensation::Turquin),
            Model::FdezAguera => Some(Compensation::FdezAguera),
            Model::MaterialX => Some(Compensation::MaterialX),
            _ => None,
        }
    }

    /// Whether the model's `E` with F = 1 is the one a user's table (`--albedo-table`) replaces:
    /// MaterialX ships its own fit of `E`, which is the thing its model is judged on.
    pub fn reads_table(self) -> bool {
        self != Compensation::MaterialX
    }
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
    pub fn channels<const C: usize>(material: &Material<3>) -> Option<[Fresnel; C]> {
        let Material::Conductor(Conductor { fresnel }) = material.channels::<C>() else { return None };
        Some(match fresnel {
            ConductorFresnel::None => [Fresnel::One; C],
            ConductorFresnel::Schlick { f0 } => f0.map(Fresnel::Schlick),
            ConductorFresnel::Exact { eta, k } => std::array::from_fn(|c| Fresnel::Conductor { eta: eta[c], k: k[c] }),
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
/// over the light directions. MaterialX passes its `F_ss` as `f0`.
pub fn turquin_scale(f0: f64, e_v: f64) -> f64 {
    if e_v > 0.0 { 1.0 + f0 * (1.0 - e_v) / e_v } else { 1.0 }
}

/// MaterialX's rational fit of the GGX directional albedo with F = 1,
/// `mx_ggx_dir_albedo_analytic(NdotV, alpha, 1, 1) = A + B` (see the module's commit), each of
/// `A` and `B` a ratio of two polynomials of degree 2 in `mu` and in `alpha`, clamped to
/// `[0, 1]` as the shader clamps them. MaterialX's `alpha` is the GGX slope width of its NDF
/// and Smith terms (`mx_ggx_NDF`, `mx_ggx_smith_G1`; its roughness input is squared by
/// `mx_roughness_anisotropy` before it gets there), the same parameter as smithwalk's `alpha`,
/// so it goes in unchanged. The fit was made for `alpha` in `[0, 1]`, where MaterialX clamps it;
/// the caller keeps it there ([`materialx_unavailable`]).
pub fn materialx_albedo(mu: f64, alpha: f64) -> f64 {
    let (x, y) = (mu, alpha);
    let terms = [1.0, x, y, x * y, x * x, y * y, x * x * y, x * y * y, x * x * y * y];
    // Rows: the numerator and denominator of A, then of B; columns: the terms above.
    const C: [[f64; 9]; 4] = [
        [0.1003, -0.6303, 9.748, -2.038, 29.34, -8.245, -26.44, 19.99, -5.448],
        [1.0, -1.765, 8.263, 11.53, 28.96, -7.507, -36.11, 15.86, 33.37],
        [0.9345, -2.323, 2.229, -3.748, 1.424, -0.7684, 1.436, 0.2913, 0.6286],
        [1.0, 0.2281, 15.94, -55.83, 13.08, 41.26, 54.9, 300.2, -285.1],
    ];
    let poly = |row: &[f64; 9]| row.iter().zip(&terms).map(|(c, t)| c * t).sum::<f64>();
    let a = (poly(&C[0]) / poly(&C[1])).clamp(0.0, 1.0);
    let b = (poly(&C[2]) / poly(&C[3])).clamp(0.0, 1.0);
    a + b
}

/// The MaterialX shader's floor of `NdotV` (`clamp(dot(N, V), M_FLOAT_EPS, 1.0)`, `M_FLOAT_EPS`
/// = 1e-8 in `stdlib/genglsl/lib/mx_math.glsl`): the fit is read at it for views closer to the
/// horizon, as the shader reads it.
const MATERIALX_MU_MIN: f64 = 1e-8;

/// Fdez-Agüera 2019's multiple-scattering lobe (a BSDF value, sr^-1), constant in the light
/// direction: `F_ms E_ms / pi` with `E_ms = 1 - E(mu_v)` and
/// `F_ms = E_F(mu_v) F_avg / (1 - E_ms F_avg)`, where `e_fresnel_v = E_F(mu_v)` is the
/// single-scattering albedo with the facet's Fresnel (the paper's `F_ss E_ss`).
pub fn fdez_aguera_lobe(e_v: f64, e_fresnel_v: f64, f_avg: f64) -> f64 {
    let e_ms = 1.0 - e_v;
    e_fresnel_v * f_avg / (1.0 - e_ms * f_avg) * e_ms / PI
}

/// An isotropic NDF of a given roughness, with a chart of its slope plane (roughness 1, §1.1)
/// in which the slope density is bounded: `P22(x, y) dx dy = outer(t) inner(s) dt ds / pi`
/// with `x = x_of(t)`, `y = y_of(x, s)`.
pub trait Isotropic: Ndf {
    fn with_alpha(alpha: f64) -> Self;
    fn x_of(t: f64) -> f64;
    /// The chart coordinate of slope `x` (clamped where the chart is truncated).
    fn t_of(x: f64) -> f64;
    fn outer(t: f64) -> f64;
    fn y_of(x: f64, s: f64) -> f64;
    /// The chart coordinate of slope `y >= 0` at `x` (clamped where the chart is truncated).
    fn s_of(x: f64, y: f64) -> f64;
    fn inner(s: f64) -> f64;
}

impl Isotropic for Ggx {
    fn with_alpha(alpha: f64) -> Self {
        Ggx(Roughness::isotropic(alpha))
    }

    /// `P22 = 1 / (pi (1 + x^2 + y^2)^2)`; with `x = tan t` and `y = sqrt(1 + x^2) tan s` the
    /// measure becomes the bounded `cos t cos^2 s dt ds / pi`, so the heavy tails of the slope
    /// plane need no truncation.
    fn x_of(t: f64) -> f64 {
        t.tan()
    }
    fn t_of(x: f64) -> f64 {
        x.atan()
    }
    fn outer(t: f64) -> f64 {
        t.cos()
    }
    fn y_of(x: f64, s: f64) -> f64 {
        x.hypot(1.0) * s.tan()
    }
    fn s_of(x: f64, y: f64) -> f64 {
        (y / x.hypot(1.0)).atan()
    }
    fn inner(s: f64) -> f64 {
        s.cos().powi(2)
    }
}

/// Beckmann slopes beyond this are left out: the Gaussian there holds less than 1e-16.
const BECKMANN_TAIL: f64 = 6.0;

impl Isotropic for Beckmann {
    fn with_alpha(alpha: f64) -> Self {
        Beckmann(Roughness::isotropic(alpha))
    }

    /// `P22 = e^{-x^2 - y^2} / pi`: the chart is the slope plane itself, truncated at
    /// `BECKMANN_TAIL`.
    fn x_of(t: f64) -> f64 {
        t
    }
    fn t_of(x: f64) -> f64 {
        x.clamp(-BECKMANN_TAIL, BECKMANN_TAIL)
    }
    fn outer(t: f64) -> f64 {
        (-t * t).exp()
    }
    fn y_of(_: f64, s: f64) -> f64 {
        s
    }
    fn s_of(_: f64, y: f64) -> f64 {
        y.min(BECKMANN_TAIL)
    }
    fn inner(s: f64) -> f64 {
        (-s * s).exp()
    }
}

/// `∫∫ P22(x, y) h(x, y) dy dx` over `x` in `(x0, x1)` and `|y| < y_max(x)`, with `h` even in
/// `y`, by nested adaptive Gauss–Kronrod in the NDF's chart ([`Isotropic`]): the inner integral
/// to `0.05 abs_tol`, the outer to `0.5 abs_tol`.
fn slope_integral<N: Isotropic>(
    (x0, x1): (f64, f64),
    y_max: impl Fn(f64) -> f64,
    h: impl Fn(f64, f64) -> f64,
    abs_tol: f64,
) -> f64 {
    let across = |t: f64| {
        let x = N::x_of(t);
        let at = |s: f64| N::inner(s) * h(x, N::y_of(x, s));
        2.0 * N::outer(t) * integrate(at, 0.0, N::s_of(x, y_max(x)), 0.05 * abs_tol).0
    };
    integrate(across, N::t_of(x0), N::t_of(x1), 0.5 * PI * abs_tol).0 / PI
}

/// Incidence below this cosine is evaluated at it. `E` is continuous there (it tends to 1 at
/// grazing with F = 1), and below it the quadrature of [`directional_albedo`] grows slow (GGX
/// at alpha 0.005: 2 s at `mu = 1e-4`, 12 s at `1e-6`). A model's bin energy weighs `E(mu)` by
/// `mu`: what the clamp changes in any bin is below `2 ∫_0^MU_MIN mu dmu = 1e-8` times the
/// change of `E`, itself below `1 - E(MU_MIN)` (4.2e-3 at GGX alpha 0.005, 4.6e-4 at 0.05).
pub const MU_MIN: f64 = 1e-4;

/// The directional albedo of exact single scattering (§5, §9.4) of an isotropic NDF for light
/// at `mu = cos theta_i` (at least [`MU_MIN`]) with the facet reflectance `f`, to `abs_tol`:
/// `E_F(mu) = (1 / mu) ∫ <wi·m> D(m) F(wi·m) G2(wi, wo) dm`, `wo` the mirror direction, over
/// the normals that reflect above the horizon. In slope space of roughness 1 (normal
/// `(-alpha x, -alpha y, 1)`, `wi` in the xz plane) the integrand is
/// `P22(x, y) (1 - alpha x tan theta) F G2` and the region `wo_z > 0` is exactly
/// `alpha^2 y^2 < (s1 - alpha x)(alpha x - s0)` with `s1 = mu / (1 + sin theta)` and
/// `s0 = -(1 + sin theta) / mu`: the quadrature runs over that region alone, on whose edge the
/// integrand falls to 0 (G2 does), so it never has to find the edge.
pub fn directional_albedo<N: Isotropic>(ndf: &N, mu: f64, f: Fresnel, abs_tol: f64) -> f64 {
    let mu = mu.clamp(MU_MIN, 1.0);
    let sin = (1.0 - mu * mu).max(0.0).sqrt();
    let (wi, tan) = (DVec3::new(sin, 0.0, mu), sin / mu);
    let alpha = ndf.roughness().x;
    let lambda_i = ndf.lambda(wi);
    let (s0, s1) = (-(1.0 + sin) / mu, mu / (1.0 + sin));
    let y_max = |x: f64| ((s1 - alpha * x).max(0.0) * (alpha * x - s0).max(0.0)).sqrt() / alpha;
    let h = |x: f64, y: f64| {
        let m = slope_to_normal(alpha * x, alpha * y);
        let c = wi.dot(m);
        let wo = 2.0 * c * m - wi;
        if c <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        (1.0 - alpha * x * tan) * f.at(c) / (1.0 + lambda_i + ndf.lambda(wo))
    };
    slope_integral::<N>((s0 / alpha, s1 / alpha), y_max, h, abs_tol)
}

/// Gauss–Legendre nodes per panel of an [`Albedo`].
const NODES: usize = 12;

/// Panel edges of an [`Albedo`] in mu: halving towards grazing, where E changes fastest at low
/// roughness, down to [`MU_MIN`], and four equal panels on [1/2, 1].
const EDGES: [f64; 17] = [
    MU_MIN,
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
    1.0,
];

/// The quadrature tolerance of each node of an [`Albedo`].
const NODE_TOLERANCE: f64 = 1e-10;

/// One panel of a piecewise-polynomial E: values at Gauss–Legendre nodes with their
/// quadrature and barycentric weights.
#[derive(Clone, Debug)]
struct Panel {
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

/// A directional albedo `E(mu)` on `[0, 1]` as a function: [`directional_albedo`] at the
/// Gauss–Legendre nodes of graded panels (to 1e-10 each), with polynomial interpolation
/// between them; `average` is `E_avg = 2 ∫ E(mu) mu dmu`, the Gauss–Legendre sum of the same
/// nodes (exact for the interpolant) plus the part below [`MU_MIN`]. The interpolant differs
/// from direct quadrature by at most 1e-6 (GGX and Beckmann, alpha 0.01 to 3; measured in
/// `tests/compensation.rs`: 7.7e-7 at Beckmann alpha 3, `mu = 1`). [`Albedo::from_table`] is the
/// other kind: a row of a user's table.
#[derive(Clone, Debug)]
pub struct Albedo {
    shape: Shape,
    average: f64,
}

/// How an [`Albedo`] is represented between its nodes.
#[derive(Clone, Debug)]
enum Shape {
    /// Exact: polynomial on graded panels.
    Panels(Vec<Panel>),
    /// A user's table ([`AlbedoTable`]): linear between `mu` nodes, clamped outside them.
    Linear { mu: Vec<f64>, e: Vec<f64> },
    /// MaterialX's fit of GGX at this `alpha` ([`materialx_albedo`]).
    MaterialX { alpha: f64 },
}

impl Albedo {
    /// `E_F(mu)` of exact single scattering for an isotropic NDF and one channel's Fresnel.
    pub fn exact<N: Isotropic>(ndf: &N, f: Fresnel) -> Self {
        use rayon::prelude::*;
        let mut panels: Vec<Panel> = EDGES
            .windows(2)
            .map(|w| {
                let nodes = gauss_legendre(NODES, w[0], w[1]);
                // Scaled to the panel so that the products neither overflow nor underflow.
                let barycentric = (0..NODES)
                    .map(|j| {
                        let prod: f64 = (0..NODES)
                            .filter(|&k| k != j)
                            .map(|k| (nodes[j].0 - nodes[k].0) * 4.0 / (w[1] - w[0]))
                            .product();
                        1.0 / prod
                    })
                    .collect();
                Panel { hi: w[1], nodes, values: Vec::new(), barycentric }
            })
            .collect();
        panels.par_iter_mut().for_each(|p| {
            p.values = p.nodes.iter().map(|&(mu, _)| directional_albedo(ndf, mu, f, NODE_TOLERANCE)).collect();
        });
        // Below MU_MIN, E is held at its value there (see `at`).
        let below = panels[0].at(MU_MIN) * MU_MIN * MU_MIN;
        let average = below
            + 2.0
                * panels
                    .iter()
                    .flat_map(|p| p.nodes.iter().zip(&p.values).map(|(&(mu, w), &e)| w * mu * e))
                    .sum::<f64>();
        Albedo { shape: Shape::Panels(panels), average }
    }

    /// `E(mu)` of `table` at roughness `alpha` ([`AlbedoTable::at_alpha`]), given at its
    /// increasing `mu` nodes, linear between them and held at the first and last node's value
    /// outside them, with its `E_avg`.
    pub fn from_table(table: &AlbedoTable, alpha: f64) -> Self {
        let (e, average) = table.at_alpha(alpha);
        Albedo { shape: Shape::Linear { mu: table.mu.clone(), e }, average }
    }

    /// MaterialX's `E(mu)` of GGX at roughness `alpha` ([`materialx_albedo`]), with the
    /// `E_avg` of that fit by adaptive quadrature.
    pub fn materialx(alpha: f64) -> Self {
        let shape = Shape::MaterialX { alpha };
        let average = 2.0 * integrate(|mu| mu * materialx_albedo(mu.max(MATERIALX_MU_MIN), alpha), 0.0, 1.0, 1e-13).0;
        Albedo { shape, average }
    }

    /// `E(mu)` for `mu` in `[0, 1]` (exact: held at `E(MU_MIN)` below [`MU_MIN`], as
    /// [`directional_albedo`] is).
    pub fn at(&self, mu: f64) -> f64 {
        match &self.shape {
            Shape::Panels(panels) => {
                let mu = mu.max(MU_MIN);
                panels.iter().find(|p| mu <= p.hi).unwrap_or(&panels[panels.len() - 1]).at(mu)
            }
            Shape::Linear { mu: nodes, e } => linear(nodes, e, mu),
            Shape::MaterialX { alpha } => materialx_albedo(mu.max(MATERIALX_MU_MIN), *alpha),
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
    /// The model's `F_avg`: exact for Kulla & Conty, Fdez-Agüera's closed form for his and
    /// MaterialX's `F_ss`, `F0` for Turquin.
    f_avg: f64,
}

impl<'a, N: Ndf> Compensated<'a, N> {
    /// `albedo` is `E(mu)` with F = 1; `albedo_fresnel` is `E_F(mu)` with `fresnel` (read by
    /// Fdez-Agüera's model only).
    pub fn new(model: Compensation, ndf: N, fresnel: Fresnel, albedo: &'a Albedo, albedo_fresnel: &'a Albedo) -> Self {
        let f_avg = match model {
            Compensation::KullaConty => fresnel_average(fresnel),
            Compensation::Turquin => fresnel.f0(),
            // MaterialX's `mx_fresnel_average` is `F0 + (F90 - F0) / 21`, with F90 = 1 for
            // every Fresnel but its generalised Schlick: Fdez-Agüera's closed form.
            Compensation::FdezAguera | Compensation::MaterialX => fdez_aguera_fresnel_average(fresnel.f0()),
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
            Compensation::Turquin | Compensation::MaterialX => {
                self.single(wi, wo) * (turquin_scale(self.f_avg, self.albedo.at(wo.z)) - 1.0)
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
    entries: Vec<((AnyNdf, Fresnel), Albedo)>,
    /// A user's table of `E` and `E_avg` with F = 1 (`--albedo-table`), read in place of the
    /// exact functions with F = 1 whatever the NDF; `E_F` with another Fresnel stays exact.
    table: Option<AlbedoTable>,
}

impl AlbedoCache {
    /// A cache that takes `E` and `E_avg` with F = 1 from `table` (see [`AlbedoTable`]).
    pub fn with_table(table: AlbedoTable) -> Self {
        AlbedoCache { entries: Vec::new(), table: Some(table) }
    }

    /// The albedo functions of an isotropic `ndf` with reflectance `f`.
    pub fn get(&mut self, ndf: AnyNdf, f: Fresnel) -> &Albedo {
        let key = (ndf, f);
        let index = match self.entries.iter().position(|(k, _)| *k == key) {
            Some(i) => i,
            None => {
                let albedo = match (&self.table, ndf) {
                    (Some(table), _) if f == Fresnel::One => Albedo::from_table(table, ndf.roughness().x),
                    (_, AnyNdf::Ggx(ndf)) => Albedo::exact(&ndf, f),
                    (_, AnyNdf::Beckmann(ndf)) => Albedo::exact(&ndf, f),
                    (_, AnyNdf::StudentT(_)) => unreachable!("compensation::applies refuses Student-T"),
                };
                self.entries.push((key, albedo));
                self.entries.len() - 1
            }
        };
        &self.entries[index].1
    }
}

/// Whether a case is one the compensation models describe: a conductor on an isotropic GGX or
/// Beckmann surface with the true Smith Lambda and visible normals, lit from outside (their
/// albedo tables and tests do not cover Student-T).
pub fn applies(case: &Case) -> bool {
    unavailable(case).is_none()
}

/// Why the compensation models do not describe `case` (see [`applies`]), or `None`.
fn unavailable(case: &Case) -> Option<&'static str> {
    let Roughness { x, y } = case.roughness();
    if !matches!(case.material, Material::Conductor(_)) {
        Some("not a conductor")
    } else if matches!(case.surface.ndf, AnyNdf::StudentT(_)) {
        Some("a Student-T NDF (the exact albedo quadrature is of GGX and Beckmann)")
    } else if x != y {
        Some("anisotropic")
    } else if case.surface.smith != Smith::Exact || case.surface.normals != Normals::Visible {
        Some("not the exact Smith surface")
    } else if case.side != IncidentSide::Outside {
        Some("light from inside")
    } else {
        None
    }
}

/// Why MaterialX's compensation does not describe `case`, or `None`: besides what every
/// compensation model needs ([`applies`]), its albedo fit is of GGX alone, and of alpha up to 1,
/// where MaterialX clamps its roughness; beyond it the shader would render another surface
/// than the walk's, so there is nothing of MaterialX's to judge.
pub fn materialx_unavailable(case: &Case) -> Option<&'static str> {
    unavailable(case).or_else(|| match case.surface.ndf {
        AnyNdf::Ggx(_) if case.roughness().x > 1.0 => Some("alpha > 1 (MaterialX clamps alpha to 1)"),
        AnyNdf::Ggx(_) => None,
        AnyNdf::Beckmann(_) | AnyNdf::StudentT(_) => Some("not GGX"),
    })
}

/// A compensation model's all-orders lobe of a case integrated over every reflection bin
/// (index `cos * phi_bins + phi`), per channel (`C` = 1 or 3), each bin to `tolerance(bin)`
/// within [`MAX_BIN_EVALUATIONS`], graded towards the specular peak like the `single` model;
/// `None` where the model does not apply (see [`applies`]).
pub fn compensated_bins<const C: usize>(
    model: Compensation,
    case: &Case,
    grid: &Grid,
    tolerance: &(dyn Fn(usize) -> f64 + Sync),
    cache: &mut AlbedoCache,
) -> Option<[LobeIntegrals; C]> {
    let usable = match model {
        Compensation::MaterialX => materialx_unavailable(case).is_none(),
        _ => applies(case),
    };
    if !usable {
        return None;
    }
    let channels = Fresnel::channels::<C>(&case.material)?;
    let (ndf, wi) = (case.surface.ndf, case.wi);
    let albedo = match model {
        Compensation::MaterialX => Albedo::materialx(ndf.roughness().x),
        _ => cache.get(ndf, Fresnel::One).clone(),
    };
    let peak = specular_peak(case, Hemisphere::R);
    let rule = (peak, tolerance, MAX_BIN_EVALUATIONS);
    let mut done: Vec<(Fresnel, LobeIntegrals)> = Vec::new();
    Some(channels.map(|f| {
        // A mono material in an RGB run has three equal channels: integrate them once.
        if let Some((_, lobe)) = done.iter().find(|d| d.0 == f) {
            return lobe.clone();
        }
        let albedo_fresnel = match model {
            Compensation::FdezAguera => cache.get(ndf, f).clone(),
            _ => albedo.clone(),
        };
        let lobe = match ndf {
            AnyNdf::Ggx(ndf) => {
                let lobe = Compensated::new(model, ndf, f, &albedo, &albedo_fresnel);
                integrate_bins(case, grid, Hemisphere::R, rule, |wo| lobe.bsdf(wi, wo) * wo.z)
            }
            AnyNdf::Beckmann(ndf) => {
                let lobe = Compensated::new(model, ndf, f, &albedo, &albedo_fresnel);
                integrate_bins(case, grid, Hemisphere::R, rule, |wo| lobe.bsdf(wi, wo) * wo.z)
            }
            AnyNdf::StudentT(_) => unreachable!("compensation::applies refuses Student-T"),
        };
        done.push((f, lobe.clone()));
        lobe
    }))
}
