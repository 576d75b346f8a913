//! The microsurface as a renderer's BSDF: `sample`, `eval` and `pdf` of the multiple-scattering
//! lobe of the walk, order by order (docs/theory.md §13; conventions in docs/rendering.md).
//!
//! * [`Bsdf::sample`] walks one photon (§4.1, no splitting: two-branch facets choose a branch at
//!   random, §4.6) and returns its escape direction and weight:
//!   `E[weight g(wo)] = ∫ f(wi, wo) |cos theta_o| g(wo) dwo` for every `g`, per channel.
//! * [`Bsdf::eval`] is an unbiased estimate of `f(wi, wo) |cos theta_o|`: the order-1 term with
//!   the depth of the first hit integrated out (exact for conductor and dielectric facets,
//!   one visible normal for diffuse exits, §13.2), plus Heitz 2016's next-event estimate
//!   (§4.7) for every later hit of one walk from `wi`, with the event of that hit integrated
//!   out (§13.3: bounded where Heitz's has infinite variance).
//! * [`Bsdf::pdf`] is a deterministic density for multiple-importance weights: a mixture of the
//!   visible-normal density of the order-1 specular lobe and a cosine lobe (§13.4). It is not
//!   the density of `sample`'s directions (which has no closed form); MIS weights built on it
//!   keep an estimator unbiased because they still sum to one (tests/bsdf/pdf.rs checks this).
//!
//! Directions point away from the surface (§0), in the local frame (`z` the macro normal),
//! unit length; `wi` is the direction the walk enters from. Random numbers come from a caller's
//! [`Stream`] (see [`stream`]), so that a renderer's seed fixes every result.

use glam::DVec3;
use rand::{Rng, SeedableRng};

use crate::facet::{
    Conductor, ConductorFresnel, Dielectric, Facet, Hammon, Lambertian, ParameterError, Side, mirror_density,
    refraction_density,
};
use crate::fresnel;
use crate::height::other_side_depth;
use crate::material::Material;
use crate::ndf::{AnyNdf, Beckmann, Ggx, Ndf, Roughness};
use crate::nee::contribution;
use crate::normals::Normals;
use crate::random::{exp1, open01};
use crate::single::{g2_reflection, g2_transmission};
use crate::smith::Smith;
use crate::student_t::StudentT;
use crate::walk::{EnergyPolicy, Loss, Microsurface, Observer};

/// A set of scattering orders (facet interactions before the escape): the orders `k <= 64`
/// whose bit `k - 1` is set in `mask`, and every order `k >= from`. A plain pair of integers,
/// for foreign interfaces; `from = u32::MAX` adds no tail.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Orders {
    /// Bit `k - 1` set: order `k` (1 to 64) is in the set.
    pub mask: u64,
    /// Every order from this one on is in the set (`u32::MAX`: none).
    pub from: u32,
}

impl Orders {
    /// Every order: the full BSDF.
    pub const ALL: Orders = Orders { mask: 0, from: 1 };

    /// Order `k` alone (`1 <= k <= 64`); `None` otherwise.
    pub fn only(k: u32) -> Option<Orders> {
        (1..=64).contains(&k).then(|| Orders { mask: 1 << (k - 1), from: u32::MAX })
    }

    /// Every order from `k` on ("`k` and above"; `k = 1` is [`Orders::ALL`]).
    pub fn at_least(k: u32) -> Orders {
        Orders { mask: 0, from: k.max(1) }
    }

    /// The orders in either set.
    pub fn union(self, other: Orders) -> Orders {
        Orders { mask: self.mask | other.mask, from: self.from.min(other.from) }
    }

    /// Whether order `k` is in the set (order 0, no interaction, never is).
    pub fn contains(self, k: u32) -> bool {
        k >= 1 && (k >= self.from || (k <= 64 && (self.mask >> (k - 1)) & 1 == 1))
    }

    /// Whether the set holds an order above 1 (only those need a walk in [`Bsdf::eval`]).
    fn beyond_first(self) -> bool {
        self.mask >> 1 != 0 || self.from != u32::MAX
    }
}

/// Which quantity a renderer transports, as Mitsuba's `TransportMode` (§13.1,
/// docs/rendering.md).
///
/// The walk from `wi` carries light (power) that arrives from `wi`: its lobe is the BSDF
/// `f(wi -> wo)` of light from `wi`, whose transmission part obeys
/// `f(wi -> wo) / n_o^2 = f(wo -> wi) / n_i^2` (§9.3). A path tracer that starts at the camera
/// calls the BSDF with `wi` towards the camera and needs `f(wo -> wi)` instead: `Radiance`
/// multiplies transmission by `(n_i / n_o)^2`. Reflection is the same in both modes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Transport {
    /// `wi` is towards the light (light tracing, importance in Mitsuba's words): `f(wi -> wo)`.
    Importance,
    /// `wi` is towards the camera (path tracing): `f(wo -> wi)`, transmission times
    /// `(n_i / n_o)^2`.
    Radiance,
}

/// Why a BSDF cannot be built.
#[derive(Clone, Debug, PartialEq)]
pub enum BsdfError {
    /// A parameter out of range.
    Parameter(ParameterError),
    /// The surface uses a model whose BSDF is not the one `eval` computes: its order-1 term and
    /// next-event estimates assume the true Smith Lambda and visible normals (§2.6, §3.1).
    Model {
        /// The surface's field: `smith` or `normals`.
        field: &'static str,
        /// What the BSDF needs there.
        allowed: &'static str,
    },
    /// A name or a choice that is not one of the allowed ones (a [`Description`]'s `ndf`,
    /// `material`, `fresnel`, or an empty set of orders).
    Choice {
        /// The field, as renderers spell it.
        field: &'static str,
        /// The value given, as text.
        value: String,
        /// What is allowed, in words.
        allowed: &'static str,
    },
}

impl std::fmt::Display for BsdfError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BsdfError::Parameter(e) => e.fmt(f),
            BsdfError::Model { field, allowed } => write!(f, "{field}: the BSDF needs {allowed}"),
            BsdfError::Choice { field, value, allowed } => {
                write!(f, "{field} = {value} is not allowed: allowed is {allowed}")
            }
        }
    }
}

impl std::error::Error for BsdfError {}

impl From<ParameterError> for BsdfError {
    fn from(e: ParameterError) -> Self {
        BsdfError::Parameter(e)
    }
}

/// One sampled direction (see [`Bsdf::sample`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample<const C: usize> {
    /// The escape direction, pointing away from the surface (below the horizon for a
    /// transmission). For a photon absorbed or lost before it escaped: the macro normal on
    /// `wi`'s side, with weight 0.
    pub wo: DVec3,
    /// The photon's weight per channel: `f |cos theta_o| / density`, 0 when the photon is
    /// absorbed, lost, or escapes at an order outside the BSDF's set.
    pub weight: [f64; C],
    /// The photon's scattering order (0 if it never escaped).
    pub order: u32,
}

/// A reference BSDF as a renderer names it: the NDF and the facet material by name, every
/// parameter any material takes in RGB (those its material does not use are ignored), and the
/// orders. The bindings for other languages (Python, C) build their BSDFs here, so that they
/// accept the same names and ranges and report the same errors.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Description<'a> {
    /// The NDF: `"ggx"`, `"beckmann"` or `"student-t"` (§1.6).
    pub ndf: &'a str,
    /// The roughness along the tangent `x` (`alpha_u`) and `y` (`alpha_v`) axes; both finite
    /// and > 0.
    pub alpha: Roughness,
    /// The Student-T shape `gamma` (§1.6), finite and > 3/2; ignored by the other NDFs.
    pub gamma: f64,
    /// The facets (§4.2-4.5): `"conductor"`, `"dielectric"`, `"lambertian"` or `"hammon"`.
    pub material: &'a str,
    /// A conductor's Fresnel reflectance: `"none"` (F = 1, a lossless mirror), `"schlick"`
    /// (from `f0`) or `"exact"` (from `eta` and `k`); ignored by the other materials.
    pub fresnel: &'a str,
    /// A conductor's real index per channel (`fresnel = "exact"`); a dielectric's relative
    /// index `n_inside / n_outside` in the first channel.
    pub eta: [f64; 3],
    /// A conductor's extinction coefficient per channel (`fresnel = "exact"`).
    pub k: [f64; 3],
    /// The reflectance at normal incidence: a Schlick conductor's, or Hammon's coat.
    pub f0: [f64; 3],
    /// The diffuse albedo of Lambertian facets or of Hammon's base.
    pub albedo: [f64; 3],
    /// The orders kept; not empty.
    pub orders: Orders,
}

impl Description<'_> {
    /// The BSDF described, on the true Smith microsurface with visible normals (the surface
    /// whose BSDF `eval` computes). Errors name the first field out of range or unknown.
    pub fn bsdf(&self) -> Result<Bsdf<AnyNdf, Material<3>, 3>, BsdfError> {
        let choice = |field, value: &str, allowed| BsdfError::Choice { field, value: format!("{value:?}"), allowed };
        for (field, value) in [("alpha_u", self.alpha.x), ("alpha_v", self.alpha.y)] {
            if !(value > 0.0 && value.is_finite()) {
                return Err(ParameterError { field, value, allowed: "a finite number > 0" }.into());
            }
        }
        let ndf = match self.ndf {
            "ggx" => AnyNdf::Ggx(Ggx(self.alpha)),
            "beckmann" => AnyNdf::Beckmann(Beckmann(self.alpha)),
            "student-t" => AnyNdf::StudentT(StudentT::new(self.alpha, self.gamma).ok_or(ParameterError {
                field: "gamma",
                value: self.gamma,
                allowed: "a Student-T shape, finite and > 1.5",
            })?),
            other => return Err(choice("ndf", other, "\"ggx\", \"beckmann\" or \"student-t\"")),
        };
        let material = match self.material {
            "conductor" => Material::Conductor(Conductor {
                fresnel: match self.fresnel {
                    "none" => ConductorFresnel::None,
                    "schlick" => ConductorFresnel::Schlick { f0: self.f0 },
                    "exact" => ConductorFresnel::Exact { eta: self.eta, k: self.k },
                    other => return Err(choice("fresnel", other, "\"none\", \"schlick\" or \"exact\"")),
                },
            }),
            "dielectric" => Material::Dielectric(Dielectric { eta: self.eta[0] }),
            "lambertian" => Material::Lambertian(Lambertian { albedo: self.albedo }),
            "hammon" => Material::Hammon(Hammon { f0: self.f0, albedo: self.albedo }),
            other => {
                return Err(choice("material", other, "\"conductor\", \"dielectric\", \"lambertian\" or \"hammon\""));
            }
        };
        let Orders { mask, from } = self.orders;
        if from == 0 || (mask == 0 && from == u32::MAX) {
            return Err(BsdfError::Choice {
                field: "orders",
                value: format!("(mask {mask:#x}, from {from})"),
                allowed: "a set of at least one order: bit k - 1 of the mask for order k, \
                          from >= 1 for every order from there on (4294967295: none)",
            });
        }
        let surface = Microsurface { ndf, smith: Smith::Exact, normals: Normals::Visible };
        Ok(Bsdf::new(surface, material)?.with_orders(self.orders))
    }
}

/// The random stream of one BSDF call: PCG 64 (multiplicative congruential, 128-bit state).
pub type Stream = rand_pcg::Pcg64Mcg;

/// The stream of one call (§13.5), from a renderer's 64-bit `key` (e.g. a hash of pixel, sample index
/// and bounce) and any `numbers` it has at hand (Mitsuba's `sample` passes three uniforms;
/// `eval` none, but the directions' components serve): every number's bit pattern is mixed
/// into the key by SplitMix64's finalizer, so that different keys or numbers give
/// independent-looking streams and equal ones give the same results.
pub fn stream(key: u64, numbers: &[f64]) -> Stream {
    let seed = numbers.iter().fold(mix(key), |h, x| mix(h ^ x.to_bits()));
    Stream::seed_from_u64(seed)
}

/// SplitMix64's finalizer (Steele, Lea & Flood 2014): a bijection of 64-bit words that
/// spreads every input bit over the output.
fn mix(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The multiple-scattering BSDF of a microsurface with facets `F`, restricted to a set of
/// orders. Built by [`Bsdf::new`], which checks the parameters.
#[derive(Clone, Copy, Debug)]
pub struct Bsdf<N, F, const C: usize> {
    surface: Microsurface<N>,
    facet: F,
    orders: Orders,
}

/// The walk of `sample` and `eval`: one ray, branches chosen at random, no roulette (a weight
/// is never raised, so a lossless facet gives weight 1 exactly).
const ONE_RAY: EnergyPolicy = EnergyPolicy { split: false, threshold: 0.0 };

impl<N: Ndf, F: Facet<C>, const C: usize> Bsdf<N, F, C> {
    /// The BSDF of all orders. Errors: a roughness that is not finite and > 0, a facet
    /// parameter out of range ([`Facet::check`]), or a surface not driven by the true Smith
    /// Lambda with visible normals.
    pub fn new(surface: Microsurface<N>, facet: F) -> Result<Self, BsdfError> {
        let roughness = surface.ndf.roughness();
        for (field, value) in [("alpha_x", roughness.x), ("alpha_y", roughness.y)] {
            if !(value > 0.0 && value.is_finite()) {
                return Err(ParameterError { field, value, allowed: "a finite number > 0" }.into());
            }
        }
        if surface.smith != Smith::Exact {
            return Err(BsdfError::Model { field: "smith", allowed: "the true Smith Lambda (Smith::Exact)" });
        }
        if surface.normals != Normals::Visible {
            return Err(BsdfError::Model { field: "normals", allowed: "visible normals (Normals::Visible)" });
        }
        facet.check()?;
        Ok(Bsdf { surface, facet, orders: Orders::ALL })
    }

    /// The same BSDF restricted to `orders`.
    pub fn with_orders(self, orders: Orders) -> Self {
        Bsdf { orders, ..self }
    }

    /// The orders this BSDF is restricted to.
    pub fn orders(&self) -> Orders {
        self.orders
    }

    /// The microsurface: NDF, Smith variant and law of the hit normals.
    pub fn surface(&self) -> &Microsurface<N> {
        &self.surface
    }

    /// The facet material.
    pub fn facet(&self) -> &F {
        &self.facet
    }

    /// The side `wi` enters from, if it can: above the horizon, or below it for a facet that
    /// refracts; `None` for a direction along the horizon or not finite.
    fn entry_side(&self, wi: DVec3) -> Option<Side> {
        if !wi.is_finite() {
            return None;
        }
        if wi.z > 0.0 {
            Some(Side::Outside)
        } else if wi.z < 0.0 && self.facet.refraction_eta().is_some() {
            Some(Side::Inside)
        } else {
            None
        }
    }

    /// The factor of a transmitted lobe under `transport`: `(n_i / n_o)^2` for radiance with
    /// `n_i` the index on `wi`'s side, 1 otherwise.
    fn transmission_factor(&self, side: Side, transport: Transport) -> f64 {
        match (transport, self.facet.refraction_eta()) {
            (Transport::Radiance, Some(eta)) => match side {
                Side::Outside => 1.0 / (eta * eta),
                Side::Inside => eta * eta,
            },
            _ => 1.0,
        }
    }

    /// One photon from `wi` (§4.1): where it escapes and with which weight, such that
    /// `E[weight g(wo)] = ∫ f(wi, wo) |cos theta_o| g(wo) dwo` per channel over the orders of
    /// the set (orders outside it escape with weight 0). Reflection from a lossless facet has
    /// weight 1 exactly. `transport` scales a transmission ([`Transport`]). A `wi` that cannot
    /// enter (along the horizon, below it without refraction, not finite) gives weight 0.
    ///
    /// Random numbers: the walk draws from `rng` as many as it needs (a free flight, a normal
    /// and a facet interaction per bounce); seed it with [`stream`].
    pub fn sample<R: Rng + ?Sized>(&self, wi: DVec3, transport: Transport, rng: &mut R) -> Sample<C> {
        let none = |side: Side| Sample { wo: side.frame(DVec3::Z), weight: [0.0; C], order: 0 };
        let Some(side) = self.entry_side(wi) else {
            return none(if wi.z < 0.0 { Side::Inside } else { Side::Outside });
        };
        let mut first = FirstEscape { escape: None };
        self.surface.trace_unsplit(&self.facet, &ONE_RAY, wi, rng, &mut first);
        let Some((order, exit, wo, weight)) = first.escape else { return none(side) };
        let factor = if exit == side { 1.0 } else { self.transmission_factor(side, transport) };
        let kept = if self.orders.contains(order) { factor } else { 0.0 };
        Sample { wo, weight: weight.map(|w| finite_or_zero(w * kept)), order }
    }

    /// An unbiased estimate of `f(wi, wo) |cos theta_o|` over the orders of the set, per
    /// channel: [`Bsdf::single_scattering`] for order 1, plus one walk from `wi` with a
    /// next-event estimate towards `wo` for each of its hits of order 2 and above, the hit's
    /// depth integrated out (§13.3); no walk when the set has no order above 1. 0 when `wi` cannot enter (see
    /// [`Bsdf::sample`]), when `wo` lies along the horizon, is not finite, or is on the other
    /// side of a surface that does not transmit. Never NaN, negative or infinite.
    ///
    /// Random numbers: from `rng`, as many as the walk needs plus a stream of its own for the
    /// facets' stochastic phase functions (seeded from one draw); a renderer without random
    /// numbers at hand (Mitsuba's `eval`) seeds it with [`stream`] from a key and `wi`, `wo`.
    pub fn eval<R: Rng + ?Sized>(&self, wi: DVec3, wo: DVec3, transport: Transport, rng: &mut R) -> [f64; C] {
        let Some(side) = self.entry_side(wi) else { return [0.0; C] };
        if !wo.is_finite() || wo.z == 0.0 {
            return [0.0; C];
        }
        let crosses = (wo.z < 0.0) != (side == Side::Inside);
        if crosses && self.facet.refraction_eta().is_none() {
            return [0.0; C];
        }
        let mut sum = if self.orders.contains(1) { self.single_scattering(wi, wo, rng) } else { [0.0; C] };
        if self.orders.beyond_first() {
            let mut phase_rng = Stream::seed_from_u64(rng.next_u64());
            let mut next_event = NextEventSum {
                surface: &self.surface,
                facet: &self.facet,
                orders: self.orders,
                wo,
                rng: &mut phase_rng,
                departure: None,
                sum: [0.0; C],
            };
            self.surface.trace_unsplit(&self.facet, &ONE_RAY, wi, rng, &mut next_event);
            for (s, n) in sum.iter_mut().zip(next_event.sum) {
                *s += n;
            }
        }
        let factor = if crosses { self.transmission_factor(side, transport) } else { 1.0 };
        sum.map(|s| finite_or_zero(s * factor))
    }

    /// [`Bsdf::eval`] from both ends (§13.3): the mean of the estimate from `wi` and of the
    /// estimate from `wo` turned around by reciprocity (`eval(wo, wi)` in the other transport
    /// mode, times `|cos theta_o| / |cos theta_i|`). Same expectation, twice the cost; it
    /// pays where one end's estimate is heavy-tailed (grazing refraction into a dielectric:
    /// about 2x less variance per unit of time) and loses where the other end's is (up to 2x
    /// more).
    pub fn eval_bidirectional<R: Rng + ?Sized>(
        &self,
        wi: DVec3,
        wo: DVec3,
        transport: Transport,
        rng: &mut R,
    ) -> [f64; C] {
        let reverse = match transport {
            Transport::Importance => Transport::Radiance,
            Transport::Radiance => Transport::Importance,
        };
        let forward = self.eval(wi, wo, transport, rng);
        let backward = self.eval(wo, wi, reverse, rng);
        let turn = wo.z.abs() / wi.z.abs();
        std::array::from_fn(|c| finite_or_zero(0.5 * (forward[c] + backward[c] * turn)))
    }

    /// The order-1 lobe `f_1(wi, wo) |cos theta_o|` of light from `wi` (§13.2): the facet's
    /// phase function towards `wo` times the probability, integrated over the depth of the
    /// first hit, that `wo` escapes from it: `(1 + Lambda(wi)) G2(wi, wo)` for a reflection,
    /// `(1 + Lambda(wi)) G2^T(wi, wo)` for a transmission. Exact for conductor and dielectric
    /// facets (the closed forms of §5); facets whose phase function is stochastic (diffuse
    /// exits) draw one visible normal from `rng`. Not scaled for [`Transport::Radiance`]; 0 for
    /// directions that [`Bsdf::eval`] gives 0.
    pub fn single_scattering<R: Rng + ?Sized>(&self, wi: DVec3, wo: DVec3, rng: &mut R) -> [f64; C] {
        let Some(side) = self.entry_side(wi) else { return [0.0; C] };
        // In the frame of wi's side (§4.3): w above the horizon.
        let (w, o) = (side.frame(wi), side.frame(wo));
        let ndf = &self.surface.ndf;
        let crosses = o.z < 0.0;
        if !wo.is_finite() || o.z == 0.0 || (crosses && self.facet.refraction_eta().is_none()) {
            return [0.0; C];
        }
        let g2 = if crosses { g2_transmission(ndf, w, o) } else { g2_reflection(ndf, w, o) };
        let escape = (1.0 + ndf.lambda(w)) * g2;
        let phase = self.facet.phase(ndf, w, o, side, crosses, rng);
        phase.map(|p| finite_or_zero(p * escape))
    }

    /// The density (per unit solid angle of `wo`, over the whole sphere) used for
    /// multiple-importance weights (§13.4): deterministic, positive wherever `f` is,
    /// integrating to 1. It mixes
    ///
    /// * the order-1 specular lobe of a lossless facet: mirror reflection of the visible
    ///   normals of `wi`, plus their refraction for a dielectric, each weighted by Fresnel; the
    ///   part of each that points to the wrong side of the horizon is folded back by mirroring
    ///   `wo` in the horizon, so that the lobe integrates to 1 over the directions `f` covers;
    /// * a cosine lobe on `wi`'s side (and for a dielectric one on the other side, the two
    ///   weighted by the Fresnel transmittance at macro incidence, clamped to [0.1, 0.9]),
    ///
    /// with the cosine lobe's weight `1 - s (1 - r)`: `s` the facet's
    /// [`Facet::mirror_share`], `r = alpha_x alpha_y / (1 + alpha_x alpha_y)` clamped to
    /// [0.05, 0.5] (multiple scattering grows with roughness). It approximates `sample`'s
    /// density. 0 where [`Bsdf::eval`] is 0 by rule: `wi` cannot enter, `wo` lies along the
    /// horizon, is not finite, or is across a surface that does not transmit.
    pub fn pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        let Some(side) = self.entry_side(wi) else { return 0.0 };
        if !wo.is_finite() || wo.z == 0.0 {
            return 0.0;
        }
        let (w, o) = (side.frame(wi), side.frame(wo));
        let eta = self.facet.refraction_eta().map(|eta| if side == Side::Outside { eta } else { 1.0 / eta });
        if o.z < 0.0 && eta.is_none() {
            return 0.0;
        }
        let ndf = &self.surface.ndf;
        let flipped = DVec3::new(o.x, o.y, -o.z);
        let reflected = |d: DVec3| {
            mirror_density(ndf, w, d).map_or(0.0, |(p, c)| eta.map_or(p, |eta| p * fresnel::dielectric(eta, c)))
        };
        let refracted = |eta: f64, d: DVec3| {
            refraction_density(ndf, w, d, eta).map_or(0.0, |(p, c)| p * (1.0 - fresnel::dielectric(eta, c)))
        };
        let (specular, cosine) = match eta {
            None => (reflected(o) + reflected(flipped), o.z / std::f64::consts::PI),
            Some(eta) => {
                let transmitted = (1.0 - fresnel::dielectric(eta, w.z)).clamp(0.1, 0.9);
                let (specular, share) = if o.z > 0.0 {
                    (reflected(o) + reflected(flipped), 1.0 - transmitted)
                } else {
                    (refracted(eta, o) + refracted(eta, flipped), transmitted)
                };
                (specular, share * o.z.abs() / std::f64::consts::PI)
            }
        };
        let roughness = ndf.roughness();
        let area = roughness.x * roughness.y;
        let multiple = (area / (1.0 + area)).clamp(0.05, 0.5);
        let diffuse_weight = 1.0 - self.facet.mirror_share().clamp(0.0, 1.0) * (1.0 - multiple);
        finite_or_zero((1.0 - diffuse_weight) * specular + diffuse_weight * cosine)
    }
}

/// `x` if finite, else 0: the last guard that keeps NaN and infinities out of a renderer.
fn finite_or_zero(x: f64) -> f64 {
    if x.is_finite() { x } else { 0.0 }
}

/// Records the escape of a walk's only ray: its order, side, direction and weight.
struct FirstEscape<const C: usize> {
    escape: Option<(u32, Side, DVec3, [f64; C])>,
}

impl<const C: usize> Observer<C> for FirstEscape<C> {
    fn escape(&mut self, order: u32, side: Side, dir: DVec3, weight: &[f64; C]) {
        self.escape.get_or_insert((order, side, dir, *weight));
    }

    fn lose(&mut self, _loss: Loss, _weight: &[f64; C]) {}
}

/// Sums the next-event estimate towards `wo` of every order from 2 on that is in `orders`
/// (§13.3), with the depth of each hit integrated out of its probability: for the ray that
/// leaves hit `k` (depth `tau_k`, travel direction `d`, weight `beta`), order `k + 1` gets
/// `beta P(hit) p(-d -> wo) G1(wo, tau')`, `P(hit)` the probability that the flight meets a facet
/// before it escapes and `tau'` that facet's depth drawn from the flight's law given a hit.
/// (Heitz's estimator, the same at the hit the walk makes, divides by the hit's probability
/// through the phase function's `1 / A(-d)`: its variance is infinite for rays leaving
/// upwards near the normal, where `Lambda` vanishes.) Order 1 is [`Bsdf::single_scattering`].
///
/// A ray leaves hit `k` when it either hits again (reported at hit `k + 1` with its travel
/// direction and weight) or escapes (reported with the same): both close the departure.
struct NextEventSum<'a, N, F, R, const C: usize> {
    surface: &'a Microsurface<N>,
    facet: &'a F,
    orders: Orders,
    wo: DVec3,
    rng: &'a mut R,
    /// The depth and side of the last hit, the departure of the ray in flight.
    departure: Option<(f64, Side)>,
    sum: [f64; C],
}

impl<N: Ndf, F: Facet<C>, R: Rng, const C: usize> NextEventSum<'_, N, F, R, C> {
    /// Adds the order-`order` term of the ray that left the last hit along `d` into `side`
    /// with weight `beta`.
    fn depart(&mut self, order: u32, side: Side, d: DVec3, beta: &[f64; C]) {
        let Some((tau, from)) = self.departure else { return };
        if order < 2 || !self.orders.contains(order) {
            return;
        }
        let tau = if from == side { tau } else { other_side_depth(tau) };
        let own = side.frame(d);
        let rate = self.surface.smith.rate(&self.surface.ndf, own);
        // The next hit's depth given a hit (§2.4): upwards a truncated exponential in [0, tau],
        // downwards an exponential (every downward flight hits).
        let (hit, next) = if own.z > 0.0 {
            let hit = -(-rate * tau).exp_m1();
            let travelled = -(-open01(self.rng) * hit).ln_1p() / rate;
            (hit, (tau - travelled).max(0.0))
        } else {
            (1.0, tau + exp1(self.rng) / rate)
        };
        if hit.is_nan() || hit <= 0.0 {
            return;
        }
        let (value, _) = contribution(&self.surface.ndf, self.facet, next, side, d, self.wo, self.rng);
        for ((s, w), v) in self.sum.iter_mut().zip(beta).zip(value) {
            let term = w * hit * v;
            // A phase function of an incidence with no visible facet (A = 0 in floating point)
            // is infinite where the hit probability is 0: such a term carries nothing.
            if term.is_finite() {
                *s += term;
            }
        }
    }
}

impl<N: Ndf, F: Facet<C>, R: Rng, const C: usize> Observer<C> for NextEventSum<'_, N, F, R, C> {
    fn escape(&mut self, order: u32, side: Side, dir: DVec3, weight: &[f64; C]) {
        self.depart(order + 1, side, dir, weight);
    }

    fn lose(&mut self, _loss: Loss, _weight: &[f64; C]) {}

    fn hit(&mut self, order: u32, tau: f64, side: Side, d: DVec3, weight: &[f64; C]) {
        self.depart(order, side, d, weight);
        self.departure = Some((tau, side));
    }
}
