#![warn(missing_docs)]
//! The statistical Smith microsurface as a random medium.
//!
//! A microsurface is composed of independent pieces, each behind a trait where real
//! alternatives exist (docs/theory.md §0–§4):
//!
//! * [`ndf`]: the distribution of normals (GGX, Beckmann), its Smith `Lambda`, projected area
//!   and exact full-sphere visible-normal sampling;
//! * [`student_t`]: the Student-T NDF, between GGX and Beckmann, with its exact `Lambda` and
//!   visible-normal sampler;
//! * [`tabulated`]: an isotropic NDF read from a table of D(theta_m), with Lambda and
//!   visible-normal sampling tabulated to stated errors;
//! * [`smith`]: which `Lambda` drives the height process (true full-sphere Smith or Hammon's
//!   symmetric variant);
//! * [`height`]: the height process as free flights in optical depth;
//! * [`normals`]: how the facet hit by a ray is drawn (visible normals or Hammon's rejection);
//! * [`fresnel`]: Fresnel reflectances;
//! * [`facet`]: the micro-BSDF of a single facet (conductor, dielectric, Lambertian, Hammon);
//! * [`material`]: a facet material chosen at run time, dispatching to its micro-BSDF;
//! * [`walk`]: the random walk of Heitz et al. 2016 that composes them;
//! * [`bsdf`]: the walk as a renderer's BSDF (`sample`, `eval`, `pdf`, per order);
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
//!
//! # Public API
//!
//! This crate is what the `smithwalk` command line, its Python package and outside Rust code
//! link against. Its public API is every public item documented here; the items outside Rust
//! users are meant to build on are:
//!
//! * the surface: [`ndf::Ndf`] (the trait every NDF implements), [`ndf::Ggx`],
//!   [`ndf::Beckmann`], [`student_t::StudentT`], [`tabulated::Tabulated`], [`ndf::Roughness`], and
//!   [`ndf::AnyNdf`] (an NDF chosen at run time);
//!   [`smith::Smith`], [`normals::Normals`], and [`walk::Microsurface`], which composes them;
//! * the facets: [`facet::Facet`] (the trait every micro-BSDF implements), [`facet::Conductor`]
//!   with its [`facet::ConductorFresnel`], [`facet::Dielectric`], [`facet::Lambertian`],
//!   [`facet::Hammon`], and [`material::Material`] (a material chosen at run time);
//! * the walk: [`walk::Microsurface::trace`] with an [`walk::Observer`] and an
//!   [`walk::EnergyPolicy`];
//! * the oracles: [`single`] (exact single scattering), [`nee`] (next-event estimation),
//!   [`position_free`], [`wang`], [`cui`]; the V-groove microsurface of Lee et al. 2018:
//!   [`vgroove`].
//!
//! Directions are [`DVec3`] (glam's, re-exported), pointing away from the surface (§0); a
//! `const C: usize` parameter is the number of colour channels (1 or 3). The version policy
//! (semantic versioning; while at 0.x, a minor version may break the API, a patch never does)
//! is in the repository's CHANGELOG.md.

pub mod beta;
pub mod bsdf;
pub mod chain;
pub mod cui;
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
pub mod student_t;
pub mod tabulated;
pub mod vgroove;
pub mod walk;
pub mod wang;

pub use glam::DVec3;
