//! Micro-BSDFs: what happens when a ray meets a single facet (docs/theory.md §4.2–§4.5).
//!
//! A facet interaction returns one or two weighted branches. The walk decides how to follow
//! two branches (split both, or choose one; §4.6); weights below one are absorption. A path
//! carries `C` channel weights (1 or 3): geometry is shared, Fresnel and albedo act per channel.

use std::f64::consts::PI;

use glam::DVec3;
use rand::Rng;

use crate::fresnel;
use crate::ndf::Ndf;
use crate::random::{azimuth, open01};
use crate::roots::newton_bisect;

/// Which side of the heightfield a ray is on (§4.3): outside (above) or inside (below, only
/// for dielectrics).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Side {
    /// Above the heightfield, where light arrives from (the `+z` side).
    Outside,
    /// Below the heightfield, inside a dielectric.
    Inside,
}

impl Side {
    /// The side across the interface.
    pub fn other(self) -> Self {
        match self {
            Side::Outside => Side::Inside,
            Side::Inside => Side::Outside,
        }
    }

    /// A direction in the frame of this side (§4.3): unchanged outside, negated (flipped)
    /// inside.
    #[inline]
    pub fn frame(self, d: DVec3) -> DVec3 {
        // The sign bit flipped on the inside: exactly `-d`, without a branch on the side.
        let flip = u64::from(self == Side::Inside) << 63;
        let f = |x: f64| f64::from_bits(x.to_bits() ^ flip);
        DVec3::new(f(d.x), f(d.y), f(d.z))
    }
}

/// One outcome of a facet interaction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Branch<const C: usize> {
    /// New travel direction (unit).
    pub dir: DVec3,
    /// Per-channel factor on the path weight.
    pub weight: [f64; C],
    /// Whether the ray passes to the other side of the interface (refraction).
    pub crosses: bool,
}

/// The outcomes of a facet interaction (§4.6).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Interaction<const C: usize> {
    /// A single outcome; its weight is the facet's albedo for this incidence.
    One(Branch<C>),
    /// Two exclusive outcomes (reflect or refract; specular or diffuse exit).
    Two(Branch<C>, Branch<C>),
}

/// A facet material: the micro-BSDF of one facet.
pub trait Facet<const C: usize>: Send + Sync {
    /// The interaction of light arriving from `w` (pointing away from the facet) with a facet
    /// of normal `m`, `w·m > 0`, on `side` of the surface.
    fn interact<R: Rng + ?Sized>(&self, w: DVec3, m: DVec3, side: Side, rng: &mut R) -> Interaction<C>;

    /// Whether [`Facet::interact`] may return two branches.
    fn may_split(&self) -> bool;

    /// The phase function of the microsurface's hit facets (§4.2–§4.5): the density, per unit
    /// solid angle of the new travel direction `d`, of leaving a hit with incident direction
    /// `w` through the reflecting (`crosses = false`) or refracting branch, times its
    /// per-channel weight. Directions are in the frame of the ray's side (flipped inside,
    /// §4.3), where `eta` is the relative index seen by the ray. Facets without a closed form
    /// evaluate it stochastically with one visible normal from `rng` (unbiased, §4.4).
    fn phase<N: Ndf, R: Rng + ?Sized>(
        &self,
        ndf: &N,
        w: DVec3,
        d: DVec3,
        side: Side,
        crosses: bool,
        rng: &mut R,
    ) -> [f64; C];

    /// The material's relative index `eta = n_inside / n_outside` if light can cross to the
    /// other side of the surface (only smooth dielectric facets refract); `None` otherwise.
    fn refraction_eta(&self) -> Option<f64> {
        None
    }

    /// The share of the facet's scattering that leaves in the mirror direction, in [0, 1]: the
    /// weight of the specular lobe in an importance density (a renderer's MIS density,
    /// [`crate::bsdf`]). A heuristic for efficiency only; 0, the default, means diffuse.
    fn mirror_share(&self) -> f64 {
        0.0
    }

    /// Checks the facet's parameters: an error names the first one out of range.
    fn check(&self) -> Result<(), ParameterError> {
        Ok(())
    }
}

/// A parameter out of its allowed range: which one, its value and what is allowed.
#[derive(Clone, Debug, PartialEq)]
pub struct ParameterError {
    /// The parameter's name as configurations and renderers spell it (`eta`, `alpha_x`, ...).
    pub field: &'static str,
    /// The value given (the first channel out of range for a per-channel parameter).
    pub value: f64,
    /// What is allowed, in words.
    pub allowed: &'static str,
}

impl std::fmt::Display for ParameterError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} = {} is out of range: allowed is {}", self.field, self.value, self.allowed)
    }
}

impl std::error::Error for ParameterError {}

/// Checks that every channel of `values` lies in `range` (NaN never does).
pub(crate) fn check_range<const C: usize>(
    field: &'static str,
    values: &[f64; C],
    range: impl std::ops::RangeBounds<f64>,
    allowed: &'static str,
) -> Result<(), ParameterError> {
    match values.iter().find(|v| !range.contains(v)) {
        Some(&value) => Err(ParameterError { field, value, allowed }),
        None => Ok(()),
    }
}

/// Finite and positive (`(0, inf)`).
const POSITIVE: (std::ops::Bound<f64>, std::ops::Bound<f64>) =
    (std::ops::Bound::Excluded(0.0), std::ops::Bound::Included(f64::MAX));

/// `D(h) / (4 A(w))`: the density of mirror-reflected directions `w -> d` (§3.1), 0 when the
/// half vector faces away; returns it with the cosine `w·h` for the Fresnel factor.
pub(crate) fn mirror_density<N: Ndf>(ndf: &N, w: DVec3, d: DVec3) -> Option<(f64, f64)> {
    let h = (w + d).normalize();
    let c = w.dot(h);
    if !(h.z > 0.0 && c > 0.0) {
        return None;
    }
    Some((ndf.d(h) / (4.0 * ndf.projected_area(w)), c))
}

/// `D_w(h) eta^2 |d·h| / (w·h + eta d·h)^2`: the density of directions `w -> d` refracted
/// by visible normals with relative index `eta` (§4.3), 0 when no facet refracts `w` into
/// `d`; returns it with the cosine `w·h` for the Fresnel factor.
pub(crate) fn refraction_density<N: Ndf>(ndf: &N, w: DVec3, d: DVec3, eta: f64) -> Option<(f64, f64)> {
    // h ∝ -(w + eta d), oriented up; needs w·h > 0 > d·h.
    let mut h = -(w + eta * d).normalize();
    if h.z < 0.0 {
        h = -h;
    }
    let (ci, co) = (w.dot(h), d.dot(h));
    if !(h.z > 0.0 && ci > 0.0 && co < 0.0) {
        return None;
    }
    let visible = ci * ndf.d(h) / ndf.projected_area(w);
    let denom = ci + eta * co;
    Some((visible * eta * eta * -co / (denom * denom), ci))
}

/// Mirror reflection of `w` about `m`: `2 (w·m) m - w`.
#[inline]
pub fn reflect(w: DVec3, m: DVec3) -> DVec3 {
    2.0 * w.dot(m) * m - w
}

/// Refraction of `w` through a facet `m` with relative index `eta = eta_t / eta_i` (§4.3):
/// `(c/eta - sqrt(1 - (1 - c^2)/eta^2)) m - w/eta`; `None` under total internal reflection.
#[inline]
pub fn refract(w: DVec3, m: DVec3, eta: f64) -> Option<DVec3> {
    let c = w.dot(m);
    let k = 1.0 - (1.0 - c * c) / (eta * eta);
    if k <= 0.0 {
        return None;
    }
    Some(((c / eta - k.sqrt()) * m - w / eta).normalize())
}

/// Fresnel law of a conductor facet (§4.2), per channel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ConductorFresnel<const C: usize> {
    /// `F = 1`: the white furnace.
    None,
    /// Schlick's approximation from normal-incidence reflectance F0.
    Schlick {
        /// Reflectance at normal incidence, per channel.
        f0: [f64; C],
    },
    /// Exact Fresnel of the complex relative index `eta + i k`.
    Exact {
        /// Real part of the relative index, per channel.
        eta: [f64; C],
        /// Extinction coefficient, per channel.
        k: [f64; C],
    },
}

impl<const C: usize> ConductorFresnel<C> {
    /// The reflectance of every channel for the cosine `c` between the incident direction and
    /// the facet normal (§4.2).
    #[inline]
    pub fn reflectances(&self, c: f64) -> [f64; C] {
        match *self {
            ConductorFresnel::None => [1.0; C],
            ConductorFresnel::Schlick { f0 } => f0.map(|f0| fresnel::schlick(f0, c)),
            ConductorFresnel::Exact { eta, k } => std::array::from_fn(|i| fresnel::conductor(eta[i], k[i], c)),
        }
    }

    /// The reflectance of channel `channel` alone (see [`ConductorFresnel::reflectances`]).
    pub fn reflectance(&self, channel: usize, c: f64) -> f64 {
        match *self {
            ConductorFresnel::None => 1.0,
            ConductorFresnel::Schlick { f0 } => fresnel::schlick(f0[channel], c),
            ConductorFresnel::Exact { eta, k } => fresnel::conductor(eta[channel], k[channel], c),
        }
    }
}

/// Mirror facets that reflect `F` and absorb the rest (§4.2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Conductor<const C: usize> {
    /// The facets' Fresnel law.
    pub fresnel: ConductorFresnel<C>,
}

impl<const C: usize> Facet<C> for Conductor<C> {
    fn interact<R: Rng + ?Sized>(&self, w: DVec3, m: DVec3, _side: Side, _rng: &mut R) -> Interaction<C> {
        let weight = self.fresnel.reflectances(w.dot(m));
        Interaction::One(Branch { dir: reflect(w, m), weight, crosses: false })
    }

    fn may_split(&self) -> bool {
        false
    }

    fn phase<N: Ndf, R: Rng + ?Sized>(
        &self,
        ndf: &N,
        w: DVec3,
        d: DVec3,
        _side: Side,
        crosses: bool,
        _rng: &mut R,
    ) -> [f64; C] {
        match mirror_density(ndf, w, d) {
            Some((density, c)) if !crosses => self.fresnel.reflectances(c).map(|f| f * density),
            _ => [0.0; C],
        }
    }

    fn mirror_share(&self) -> f64 {
        1.0
    }

    fn check(&self) -> Result<(), ParameterError> {
        match self.fresnel {
            ConductorFresnel::None => Ok(()),
            ConductorFresnel::Schlick { f0 } => check_range("f0", &f0, 0.0..=1.0, "a number in [0, 1]"),
            ConductorFresnel::Exact { eta, k } => {
                check_range("eta", &eta, POSITIVE, "a finite number > 0")?;
                check_range("k", &k, 0.0..=f64::MAX, "a finite number >= 0")
            }
        }
    }
}

/// Smooth dielectric facets of relative index `eta = n_inside / n_outside` (§4.3): reflect
/// with the exact Fresnel probability, refract otherwise; no absorption.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dielectric {
    /// The relative index `n_inside / n_outside`, every channel.
    pub eta: f64,
}

impl<const C: usize> Facet<C> for Dielectric {
    fn interact<R: Rng + ?Sized>(&self, w: DVec3, m: DVec3, side: Side, _rng: &mut R) -> Interaction<C> {
        let eta = match side {
            Side::Outside => self.eta,
            Side::Inside => 1.0 / self.eta,
        };
        let reflected = Branch { dir: reflect(w, m), weight: [1.0; C], crosses: false };
        let f = fresnel::dielectric(eta, w.dot(m));
        match refract(w, m, eta) {
            Some(dir) if f < 1.0 => Interaction::Two(
                Branch { weight: [f; C], ..reflected },
                Branch { dir, weight: [1.0 - f; C], crosses: true },
            ),
            _ => Interaction::One(reflected),
        }
    }

    fn may_split(&self) -> bool {
        true
    }

    fn phase<N: Ndf, R: Rng + ?Sized>(
        &self,
        ndf: &N,
        w: DVec3,
        d: DVec3,
        side: Side,
        crosses: bool,
        _rng: &mut R,
    ) -> [f64; C] {
        let eta = match side {
            Side::Outside => self.eta,
            Side::Inside => 1.0 / self.eta,
        };
        if !crosses {
            return match mirror_density(ndf, w, d) {
                Some((density, c)) => [fresnel::dielectric(eta, c) * density; C],
                None => [0.0; C],
            };
        }
        match refraction_density(ndf, w, d, eta) {
            Some((density, c)) => [(1.0 - fresnel::dielectric(eta, c)) * density; C],
            None => [0.0; C],
        }
    }

    fn refraction_eta(&self) -> Option<f64> {
        Some(self.eta)
    }

    fn mirror_share(&self) -> f64 {
        1.0
    }

    fn check(&self) -> Result<(), ParameterError> {
        check_range("eta", &[self.eta], POSITIVE, "a finite number > 0")
    }
}

/// Lambertian facets of albedo `rho` (§4.4): cosine-distributed exit about `m`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lambertian<const C: usize> {
    /// The facets' albedo, per channel.
    pub albedo: [f64; C],
}

impl<const C: usize> Facet<C> for Lambertian<C> {
    fn interact<R: Rng + ?Sized>(&self, _w: DVec3, m: DVec3, _side: Side, rng: &mut R) -> Interaction<C> {
        let u = open01(rng);
        let cos_theta = (1.0 - u).sqrt();
        let dir = about_normal(m, cos_theta, azimuth(rng));
        Interaction::One(Branch { dir, weight: self.albedo, crosses: false })
    }

    fn may_split(&self) -> bool {
        false
    }

    fn phase<N: Ndf, R: Rng + ?Sized>(
        &self,
        ndf: &N,
        w: DVec3,
        d: DVec3,
        _side: Side,
        crosses: bool,
        rng: &mut R,
    ) -> [f64; C] {
        if crosses {
            return [0.0; C];
        }
        let cosine = ndf.sample_visible(w, rng).dot(d).max(0.0) / PI;
        self.albedo.map(|a| a * cosine)
    }

    fn check(&self) -> Result<(), ParameterError> {
        check_range("albedo", &self.albedo, 0.0..=1.0, "a number in [0, 1]")
    }
}

/// Hammon 2017's facet (§4.5): Schlick-Fresnel mirror reflection, plus a normalized
/// Fresnel-weighted diffuse exit with density `k (1 - (1 - c)^5) c`, `k = 21 / (20 pi)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hammon<const C: usize> {
    /// Reflectance of the specular coat at normal incidence (Schlick), per channel.
    pub f0: [f64; C],
    /// Albedo of the diffuse base, per channel.
    pub albedo: [f64; C],
}

impl<const C: usize> Facet<C> for Hammon<C> {
    fn interact<R: Rng + ?Sized>(&self, w: DVec3, m: DVec3, _side: Side, rng: &mut R) -> Interaction<C> {
        let f = self.f0.map(|f0| fresnel::schlick(f0, w.dot(m)));
        let specular = Branch { dir: reflect(w, m), weight: f, crosses: false };
        let cos_theta = hammon_exit_cosine(open01(rng));
        let dir = about_normal(m, cos_theta, azimuth(rng));
        let weight = std::array::from_fn(|i| (1.0 - f[i]) * self.albedo[i]);
        Interaction::Two(specular, Branch { dir, weight, crosses: false })
    }

    fn may_split(&self) -> bool {
        true
    }

    fn phase<N: Ndf, R: Rng + ?Sized>(
        &self,
        ndf: &N,
        w: DVec3,
        d: DVec3,
        _side: Side,
        crosses: bool,
        rng: &mut R,
    ) -> [f64; C] {
        if crosses {
            return [0.0; C];
        }
        let specular = mirror_density(ndf, w, d);
        let m = ndf.sample_visible(w, rng);
        let (ci, co) = (w.dot(m), d.dot(m).max(0.0));
        let exit = HAMMON_K * (1.0 - (1.0 - co).powi(5)) * co;
        std::array::from_fn(|i| {
            let spec = specular.map_or(0.0, |(density, c)| fresnel::schlick(self.f0[i], c) * density);
            spec + (1.0 - fresnel::schlick(self.f0[i], ci)) * self.albedo[i] * exit
        })
    }

    /// Hammon's mirror part carries `F` (small at normal incidence, 1 at grazing); a fixed
    /// half keeps both lobes in the importance density.
    fn mirror_share(&self) -> f64 {
        0.5
    }

    fn check(&self) -> Result<(), ParameterError> {
        check_range("f0", &self.f0, 0.0..=1.0, "a number in [0, 1]")?;
        check_range("albedo", &self.albedo, 0.0..=1.0, "a number in [0, 1]")
    }
}

/// Hammon's normalization of the Fresnel-weighted exit lobe, `k = 21 / (20 pi)` (§4.5).
const HAMMON_K: f64 = 21.0 / (20.0 * PI);

/// The direction at polar angle `acos(cos_theta)` and azimuth `(cos phi, sin phi)` about the
/// unit vector `m`.
#[inline]
fn about_normal(m: DVec3, cos_theta: f64, (c, s): (f64, f64)) -> DVec3 {
    let (t, b) = m.any_orthonormal_pair();
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    (sin_theta * c * t + sin_theta * s * b + cos_theta * m).normalize()
}

/// CDF of the cosine of Hammon's exit direction about the facet normal (§4.5):
/// `Y(c) = 7/2 c^3 - 21/4 c^4 + 21/5 c^5 - 7/4 c^6 + 3/10 c^7`.
pub fn hammon_exit_cdf(c: f64) -> f64 {
    c * c * c * (3.5 + c * (-5.25 + c * (4.2 + c * (-1.75 + c * 0.3))))
}

/// Solves `Y(c) = u` for the exit cosine (§4.5): Hammon's rational initial guess, then Newton
/// steps safeguarded by bisection (Newton is slow near `c = 0` where `Y' -> 0`), to full
/// double precision.
pub fn hammon_exit_cosine(u: f64) -> f64 {
    let (u2, u3) = (u * u, u * u * u);
    let guess =
        (0.0114813 + 154.4 * u + 13002.4 * u2 + 38295.9 * u3) / (1.0 + 1483.57 * u + 33596.4 * u2 + 16520.2 * u3);
    let density = |c: f64| 2.1 * c * (1.0 - (1.0 - c).powi(5));
    newton_bisect(|c| hammon_exit_cdf(c) - u, density, 0.0, 1.0, guess)
}
