//! Which Smith `Lambda` drives the height process (docs/theory.md §1.4, §2.4, §2.7).

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
    /// The variant's name as configurations spell it.
    pub fn name(self) -> &'static str {
        match self {
            Smith::Exact => "exact",
            Smith::Symmetric => "symmetric",
        }
    }

    /// Extinction rate in optical depth of a ray travelling along `d` (§2.4):
    /// `lambda(d) = Lambda(d)` upward and `1 + Lambda(-d)` downward (true Smith), or
    /// `Lambda(-d)` downward with Hammon's variant (§2.7). `+inf` for horizontal travel.
    #[inline]
    pub fn rate<N: Ndf>(self, ndf: &N, d: DVec3) -> f64 {
        // `Lambda(-d)` of a downward ray is `Lambda` of its mirror image in the horizon (Lambda
        // depends on the azimuth only through squares), so both cases evaluate Lambda above
        // the horizon and the exact variant adds 1 downward: no branch on the direction,
        // whose sign the walk cannot predict.
        let above = ndf.lambda(DVec3::new(d.x, d.y, d.z.abs()));
        match self {
            Smith::Exact => above + f64::from(u8::from(d.z < 0.0)),
            Smith::Symmetric => above,
        }
    }
}
