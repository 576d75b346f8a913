//! A facet material chosen at run time: one of the micro-BSDFs of [`crate::facet`] with its
//! Fresnel data (docs/theory.md §4.2–§4.5).
//!
//! Configurations and renderers pick a material by name; the walk is generic over
//! [`Facet`]. [`Material`] is that choice as a value, and implements [`Facet`] by dispatching
//! to its variant, so that code which does not need each material compiled on its own (a
//! renderer's BSDF, a model's bin integral) takes a `Material` directly. Adding a material is
//! one variant here and one `Facet` implementation; the compiler lists every `match` to extend.

use glam::DVec3;
use rand::Rng;

use crate::facet::{
    Conductor, ConductorFresnel, Dielectric, Facet, Hammon, Interaction, Lambertian, ParameterError, Side,
};
use crate::ndf::Ndf;

/// The micro-BSDF of every facet, with `C` colour channels (1 or 3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Material<const C: usize> {
    /// Mirror facets with a conductor's Fresnel reflectance (§4.2).
    Conductor(Conductor<C>),
    /// Smooth dielectric facets of relative index `eta = n_inside / n_outside` (§4.3).
    Dielectric(Dielectric),
    /// Lambertian facets (§4.4).
    Lambertian(Lambertian<C>),
    /// Hammon 2017's specular-plus-diffuse facets (§4.5).
    Hammon(Hammon<C>),
}

impl<const C: usize> Material<C> {
    /// Whether light can pass to the other side of the surface (only dielectrics transmit).
    pub fn transmits(&self) -> bool {
        matches!(self, Material::Dielectric(_))
    }

    /// The material's kind as configurations spell it.
    pub fn kind(&self) -> &'static str {
        match self {
            Material::Conductor(_) => "conductor",
            Material::Dielectric(_) => "dielectric",
            Material::Lambertian(_) => "diffuse",
            Material::Hammon(_) => "hammon",
        }
    }
}

impl Material<3> {
    /// The material in its first `C` channels (`C` is 1 or 3): a walk of one channel takes the
    /// first of a material whose parameters are the same in every channel.
    pub fn channels<const C: usize>(&self) -> Material<C> {
        let first = |v: [f64; 3]| -> [f64; C] { std::array::from_fn(|i| v[i]) };
        match *self {
            Material::Conductor(Conductor { fresnel }) => Material::Conductor(Conductor {
                fresnel: match fresnel {
                    ConductorFresnel::None => ConductorFresnel::None,
                    ConductorFresnel::Schlick { f0 } => ConductorFresnel::Schlick { f0: first(f0) },
                    ConductorFresnel::Exact { eta, k } => ConductorFresnel::Exact { eta: first(eta), k: first(k) },
                },
            }),
            Material::Dielectric(d) => Material::Dielectric(d),
            Material::Lambertian(Lambertian { albedo }) => Material::Lambertian(Lambertian { albedo: first(albedo) }),
            Material::Hammon(Hammon { f0, albedo }) => {
                Material::Hammon(Hammon { f0: first(f0), albedo: first(albedo) })
            }
        }
    }
}

/// Calls `$body` with `$f` bound to the facet inside a [`Material`].
macro_rules! dispatch {
    ($material:expr, $f:ident => $body:expr) => {
        match $material {
            Material::Conductor($f) => $body,
            Material::Dielectric($f) => $body,
            Material::Lambertian($f) => $body,
            Material::Hammon($f) => $body,
        }
    };
}

impl<const C: usize> Facet<C> for Material<C> {
    fn interact<R: Rng + ?Sized>(&self, w: DVec3, m: DVec3, side: Side, rng: &mut R) -> Interaction<C> {
        dispatch!(self, f => f.interact(w, m, side, rng))
    }

    fn may_split(&self) -> bool {
        dispatch!(self, f => Facet::<C>::may_split(f))
    }

    fn phase<N: Ndf, R: Rng + ?Sized>(
        &self,
        ndf: &N,
        w: DVec3,
        d: DVec3,
        side: Side,
        crosses: bool,
        rng: &mut R,
    ) -> [f64; C] {
        dispatch!(self, f => f.phase(ndf, w, d, side, crosses, rng))
    }

    fn refraction_eta(&self) -> Option<f64> {
        dispatch!(self, f => Facet::<C>::refraction_eta(f))
    }

    fn mirror_share(&self) -> f64 {
        dispatch!(self, f => Facet::<C>::mirror_share(f))
    }

    fn check(&self) -> Result<(), ParameterError> {
        dispatch!(self, f => Facet::<C>::check(f))
    }
}
