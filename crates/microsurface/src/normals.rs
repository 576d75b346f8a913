//! How the facet hit by a ray is drawn (docs/theory.md §3.1, §3.3).

use std::f64::consts::PI;

use glam::DVec3;
use rand::Rng;

use crate::ndf::Ndf;
use crate::random::open01;

/// The law of the normal of the facet a ray hits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Normals {
    /// The visible-normal distribution `D_w(m) ∝ <w·m> D(m)` with `w = -d` (§3.1): what the
    /// Smith microsurface implies.
    Visible,
    /// Hammon 2017's rejection sampler ("Intersection normal" slides): `m ~ D(m) m_z`,
    /// restricted to `d·m < 0`. It samples `D(m) m_z 1[w·m > 0] / N(w)`, not the visible
    /// normals (§3.3); kept to measure its effect.
    HammonRejection,
}

impl Normals {
    /// The law's name as configurations spell it.
    pub fn name(self) -> &'static str {
        match self {
            Normals::Visible => "vndf",
            Normals::HammonRejection => "hammon-rejection",
        }
    }

    /// Draws the normal of the facet hit by a ray travelling along `d`.
    #[inline]
    pub fn sample<N: Ndf, R: Rng + ?Sized>(self, ndf: &N, d: DVec3, rng: &mut R) -> DVec3 {
        match self {
            Normals::Visible => ndf.sample_visible(-d, rng),
            Normals::HammonRejection => hammon_rejection(ndf, d, rng),
        }
    }

    /// Draws the normals of the facets hit by `L` rays at once (travelling along `d`), each
    /// with the law of [`Normals::sample`]; the order of the draws is the sampler's own.
    #[inline]
    pub fn sample_lanes<N: Ndf, R: Rng + ?Sized, const L: usize>(
        self,
        ndf: &N,
        d: [DVec3; L],
        rng: &mut R,
    ) -> [DVec3; L] {
        match self {
            Normals::Visible => ndf.sample_visible_lanes(d.map(|d| -d), rng),
            Normals::HammonRejection => d.map(|d| hammon_rejection(ndf, d, rng)),
        }
    }
}

/// Hammon's sampler, step by step as the seed gives it, run in the stretched roughness-1
/// configuration (§1.1; stretching keeps the sign of `T·m` and maps `D(m) m_z` to its
/// roughness-1 form) and in the azimuthal frame of the travel direction `T`:
///
/// 1. `phi_m = 2 pi X0`; for `T_z > 0`, `X1` is shrunk to the slopes steep enough to face `T`
///    (`tan theta_m > T_z / sqrt(1 - T_z^2)`, the seed's bound, exact by §3.3 item 3);
/// 2. `theta_m` from `X1` by the NDF's slope-radius inversion (the seed's
///    `cos^2 theta = (1 - X1) / (1 - (1 - alpha^2) X1)` for GGX);
/// 3. return `m` if `T·m < 0`, else start over.
///
/// The seed's "negate `phi_m` and retry" step is omitted: in `T`'s azimuthal frame it maps a
/// rejected normal to one with the same `T·m`, so it can never succeed; in a fixed frame it
/// would bias the result (§3.3 item 3).
fn hammon_rejection<N: Ndf, R: Rng + ?Sized>(ndf: &N, d: DVec3, rng: &mut R) -> DVec3 {
    let roughness = ndf.roughness();
    let t = roughness.stretch(d);
    let t_h = t.x.hypot(t.y);
    let (cos_b, sin_b) = if t_h > 0.0 { (t.x / t_h, t.y / t_h) } else { (1.0, 0.0) };
    let x1_min = if t.z > 0.0 { if t_h > 0.0 { ndf.std_slope_cdf(t.z / t_h) } else { 1.0 } } else { 0.0 };
    if x1_min >= 1.0 {
        // Travelling straight up: no facet faces the ray (A(-z) = 0, §10).
        return DVec3::Z;
    }
    loop {
        let phi = 2.0 * PI * open01(rng);
        let x1 = x1_min + (1.0 - x1_min) * open01(rng);
        let r = ndf.std_slope_radius(x1);
        let (s, c) = phi.sin_cos();
        let m_local = DVec3::new(c * r, s * r, 1.0);
        if t_h * m_local.x + t.z * m_local.z < 0.0 {
            let m = DVec3::new(cos_b * m_local.x - sin_b * m_local.y, sin_b * m_local.x + cos_b * m_local.y, 1.0);
            return roughness.unstretch_normal(m.normalize());
        }
    }
}
