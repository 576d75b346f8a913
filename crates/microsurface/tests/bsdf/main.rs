//! The renderer's BSDF (`microsurface::bsdf`, docs/theory.md §13) against oracles that do not
//! share its code path:
//!
//! * **White furnace**: a lossless facet (conductor with `F = 1`, dielectric from either side)
//!   returns weight 1 from every `sample`, exactly (no splitting, no roulette).
//! * **`sample` against `eval`, order by order**: a two-sample chi-square of `sample`'s weighted
//!   histogram against `eval` integrated over the same bins by Monte Carlo (uniform points in
//!   each bin), for orders 1, 2 and 3 and up alone, for every facet and every NDF (GGX,
//!   Beckmann, Student-T), once anisotropic, once with three channels (each channel its own
//!   test); cells with fewer than 30 photons pooled.
//! * **Order 1 of `eval`** equals exact single scattering (`single`, §5) to rounding for
//!   conductor and dielectric facets (both sides), and for Lambertian facets matches the
//!   quadrature of the visible-normal integral (§5, [HD15]) in mean.
//! * **Albedo**: `eval` integrated over the sphere by Monte Carlo equals `sample`'s mean weight.
//! * **Reciprocity** (§9.3): `f(wi -> wo) = f(wo -> wi)` for reflection, and for transmission
//!   `f(wi -> wo) / n_o^2 = f(wo -> wi) / n_i^2`, i.e. `eval` in radiance mode from one end
//!   equals `eval` in importance mode from the other.
//! * **`pdf`**: positive wherever `eval` is, integrates to 1 over the sphere (quadrature), and
//!   MIS with it stays unbiased.
//! * **Robustness**: grazing and below-horizon directions, extreme roughness and `eta` near 1
//!   give finite, non-negative values; out-of-range parameters give errors naming the field.
//!
//! Statistics: every test states its level; the tests of one function share a family level of
//! 0.01 by Sidak's correction. Fixed seeds throughout.

#[path = "../common/mod.rs"]
mod common;

mod order_one;
mod pdf;
mod reciprocity;
mod robustness;
mod sample_eval;

use std::f64::consts::{PI, TAU};

use common::{dir, two_sided_z};
use microsurface::DVec3;
use microsurface::bsdf::{Bsdf, BsdfError, Orders, Transport, stream};
use microsurface::facet::{Conductor, ConductorFresnel, Dielectric, Facet, Hammon, Lambertian};
use microsurface::fresnel;
use microsurface::material::Material;
use microsurface::ndf::{AnyNdf, Beckmann, Ggx, Ndf, Roughness};
use microsurface::normals::Normals;
use microsurface::single;
use microsurface::smith::Smith;
use microsurface::student_t::StudentT;
use microsurface::walk::Microsurface;
use numerics::stats::{WeightedBin, sidak, two_sample};
use rand::{Rng, RngExt};

fn surface<N: Ndf>(ndf: N) -> Microsurface<N> {
    Microsurface { ndf, smith: Smith::Exact, normals: Normals::Visible }
}

fn ggx(alpha: f64) -> AnyNdf {
    AnyNdf::Ggx(Ggx(Roughness::isotropic(alpha)))
}

fn beckmann(alpha: f64) -> AnyNdf {
    AnyNdf::Beckmann(Beckmann(Roughness::isotropic(alpha)))
}

fn student_t(alpha: f64, gamma: f64) -> AnyNdf {
    AnyNdf::StudentT(StudentT::new(Roughness::isotropic(alpha), gamma).expect("gamma > 1.5"))
}

/// The BSDFs under test: run-time NDF and material, as a renderer builds them.
type TestBsdf<const C: usize> = Bsdf<AnyNdf, Material<C>, C>;

fn bsdf<const C: usize>(ndf: AnyNdf, material: Material<C>) -> TestBsdf<C> {
    Bsdf::new(surface(ndf), material).expect("valid parameters")
}

fn mirror() -> Material<1> {
    Material::Conductor(Conductor { fresnel: ConductorFresnel::None })
}

fn glass() -> Material<1> {
    Material::Dielectric(Dielectric { eta: 1.5 })
}

/// A uniform direction on the sphere (density `1 / 4 pi`).
fn uniform_on_sphere<R: Rng>(rng: &mut R) -> DVec3 {
    let z: f64 = 2.0 * rng.random::<f64>() - 1.0;
    let phi = TAU * rng.random::<f64>();
    let r = (1.0 - z * z).max(0.0).sqrt();
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}
