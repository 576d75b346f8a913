//! The statistical Smith microsurface as a random medium.
//!
//! A microsurface is composed of independent pieces, each behind a trait where real
//! alternatives exist (docs/theory.md §0–§4):
//!
//! * [`ndf`]: the distribution of normals (GGX, Beckmann), its Smith `Lambda`, projected area
//!   and exact full-sphere visible-normal sampling;
//! * [`smith`]: which `Lambda` drives the height process (true full-sphere Smith or Hammon's
//!   symmetric variant);
//! * [`height`]: the height process as free flights in optical depth;
//! * [`normals`]: how the facet hit by a ray is drawn (visible normals or Hammon's rejection);
//! * [`fresnel`]: Fresnel reflectances;
//! * [`facet`]: the micro-BSDF of a single facet (conductor, dielectric, Lambertian, Hammon);
//! * [`material`]: a facet material chosen at run time, dispatching to its micro-BSDF;
//! * [`walk`]: the random walk of Heitz et al. 2016 that composes them;
//! * [`single`]: exact single scattering, the walk's order-1 oracle;
//! * [`beta`]: the Beta function of transmitted masking, exact towards the horizon;
//! * [`slope`]: closed-form GGX masses and visible-normal probabilities of slope-space
//!   polygons (exact histogram oracles);
//! * [`nee`]: next-event estimation, a second estimator of the walk's lobes;
//! * [`chain`]: height-free chains of visible-normal scatterings, with a visibility model;
//! * [`wang`]: the position-free models of Wang et al. 2022 as chain visibilities;
//! * [`position_free`]: the exact position-free form (depths integrated out), the walk's
//!   height-free twin for one-sided facets;
//! * [`random`], [`roots`]: variates and the root finder behind the inverse-CDF samplers.
//!
//! Everything here is pure physics: no I/O, no threads, no binning.

pub mod beta;
pub mod chain;
pub mod facet;
pub mod fresnel;
pub mod height;
pub mod material;
pub mod ndf;
pub mod nee;
pub mod normals;
pub mod position_free;
pub mod random;
pub mod roots;
pub mod single;
pub mod slope;
pub mod smith;
pub mod walk;
pub mod wang;

pub use glam::DVec3;
