//! Which Smith `Lambda` drives the height process (THEORY.md §1.4, §2.4, §2.7).

use glam::DVec3;

use crate::ndf::Ndf;

/// The Smith masking variant used for the free flights of the walk.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Smith {
    /// The true full-sphere Lambda, `Lambda(-w) = -1 - Lambda(w)` (§1.4): the only variant
    /// consistent with the Smith microsurface; the walk built on it is reciprocal (§2.6).
    Exact,
    /// Hammon 2017's redefinition `Lambda_H(-w) = -Lambda_H(w)` (§1.4): downward rays penetrate
    /// deeper, single scattering vanishes at normal incidence and rays can be trapped at the
    /// bottom of the height support (§2.7). Kept to replicate and measure that paper.
    Symmetric,
}

impl Smith {
    /// Extinction rate in optical depth of a ray travelling along `d` (§2.4):
    /// `lambda(d) = Lambda(d)` upward and `1 + Lambda(-d)` downward (true Smith), or
    /// `Lambda(-d)` downward with Hammon's variant (§2.7). `+inf` for horizontal travel.
    #[inline]
    pub fn rate<N: Ndf>(self, ndf: &N, d: DVec3) -> f64 {
        if d.z > 0.0 {
            ndf.lambda(d)
        } else if d.z < 0.0 {
            match self {
                Smith::Exact => 1.0 + ndf.lambda(-d),
                Smith::Symmetric => ndf.lambda(-d),
            }
        } else {
            f64::INFINITY
        }
    }
}
