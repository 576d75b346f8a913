//! Fresnel reflectances (docs/theory.md §4.2, §4.3, §4.5). `c` is the cosine between the
//! direction towards the light and the facet normal, in [0, 1].

/// Schlick's approximation `F0 + (1 - F0) (1 - c)^5`.
#[inline]
pub fn schlick(f0: f64, c: f64) -> f64 {
    let t = 1.0 - c.clamp(0.0, 1.0);
    let t2 = t * t;
    f0 + (1.0 - f0) * t2 * t2 * t
}

/// Exact unpolarized reflectance of a conductor of complex relative index `eta + i k` (§4.2),
/// in the real form of pbrt/Mitsuba's `fresnelConductorExact`.
pub fn conductor(eta: f64, k: f64, c: f64) -> f64 {
    let c = c.clamp(0.0, 1.0);
    let c2 = c * c;
    let s2 = 1.0 - c2;
    let t0 = eta * eta - k * k - s2;
    let a2b2 = (t0 * t0 + 4.0 * eta * eta * k * k).sqrt();
    let a = (0.5 * (a2b2 + t0)).max(0.0).sqrt();
    let rs = (a2b2 - 2.0 * a * c + c2) / (a2b2 + 2.0 * a * c + c2);
    let t1 = c2 * a2b2 + s2 * s2;
    let t2 = 2.0 * a * c * s2;
    let rp = rs * (t1 - t2) / (t1 + t2);
    0.5 * (rs + rp)
}

/// Exact unpolarized reflectance of a dielectric interface with relative index
/// `eta = eta_t / eta_i` (\[W07\] Eq. 22, §4.3); 1 under total internal reflection.
pub fn dielectric(eta: f64, c: f64) -> f64 {
    let c = c.clamp(0.0, 1.0);
    let g2 = eta * eta - 1.0 + c * c;
    if g2 <= 0.0 {
        return 1.0;
    }
    let g = g2.sqrt();
    let a = (g - c) / (g + c);
    let b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);
    0.5 * a * a * (1.0 + b * b)
}
