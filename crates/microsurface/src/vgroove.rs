//! Symmetric specular V-grooves (docs/theory.md §14): the microsurface of Lee et al. 2018
//! ("Practical multiple scattering for rough surfaces"), a different one from the Smith height
//! process. Every facet normal `m` of the NDF is one wall of a V-groove (a V-cavity of Heitz 2014)
//! whose other wall is `m` mirrored about the macro normal in the plane of `m` and the normal;
//! light that enters a groove bounces between its walls and leaves after a number of bounces
//! that the groove's cross-section fixes (§14.1). A path of `k` bounces is order `k`.
//!
//! [`bounce_fraction`] is the cross-section (2-D) result, [`order_lobe`] the order-`k` lobe
//! over outgoing directions (§14.2). Everything here is for mirror (conductor) walls and light
//! from above.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use glam::DVec3;

use crate::facet::reflect;
use crate::ndf::Ndf;

/// The fraction, of the light that would fall on the groove's right wall were the left wall
/// not there, that enters the groove, hits the right wall first and leaves after exactly `k`
/// bounces (§14.1). The cross-section: walls tilted by `theta_s` in `(0, pi/2)` (the right
/// wall's normal is `(-sin theta_s, cos theta_s)`, the left wall's its mirror); light comes from
/// the in-plane direction at `theta_i` from the normal towards `+x` (towards the right wall's
/// side), `|theta_i| < pi/2`. Zero where the right wall faces away from the light.
///
/// With `beta = pi/2 - theta_s` (half the groove's opening) and a ray entering at signed
/// distance `p` from the groove's apex across the ray (`p > 0`: right of it), the unfolded
/// (kaleidoscope) ray crosses the virtual walls at `psi_j = (2j + 1) beta - theta_i` that lie in
/// `[0, pi]` and reach it, `sin psi_j >= p`: `n(p) = #{j >= 0 : psi_j in [0, pi],
/// sin psi_j >= p}` bounces. Entering rays are uniform in `p` over
/// `[sin(-beta - theta_i), sin(beta - theta_i)]`; those with `p > 0` hit the right wall first,
/// whose unshadowed width is `sin(beta - theta_i) = cos(theta_s + theta_i)`.
pub fn bounce_fraction(theta_i: f64, theta_s: f64, k: usize) -> f64 {
    let beta = FRAC_PI_2 - theta_s;
    let width = (beta - theta_i).sin();
    if k == 0 || width <= 0.0 || beta <= 0.0 {
        return 0.0;
    }
    let lo = (-beta - theta_i).sin().max(0.0);
    // The virtual walls in [0, pi]: j from first to last. Their thresholds sin(psi_j) rise then
    // fall, so the smallest remaining one is always at an end: popping the ends, the
    // (count - k)-th smallest is t_{k+1} and the next one t_k (p in (t_{k+1}, t_k] makes k
    // bounces), in O(count - k) steps and no allocation.
    let first = ((theta_i / beta - 1.0) / 2.0).ceil().max(0.0) as i64;
    let last = (((PI + theta_i) / beta - 1.0) / 2.0).floor() as i64;
    let psi = |j: i64| (2 * j + 1) as f64 * beta - theta_i;
    let (mut a, mut b) = (first, last);
    // Guard the ends against rounding: every psi kept lies in [0, pi].
    while a <= b && psi(a) < 0.0 {
        a += 1;
    }
    while a <= b && psi(b) > PI {
        b -= 1;
    }
    let count = (b - a + 1).max(0) as usize;
    if count < k {
        return 0.0;
    }
    let mut pop = || {
        let (sa, sb) = (psi(a).sin(), psi(b).sin());
        if sa <= sb {
            a += 1;
            sa
        } else {
            b -= 1;
            sb
        }
    };
    let mut next_below = f64::NEG_INFINITY;
    for _ in 0..count - k {
        next_below = pop();
    }
    let upper = pop().min(width);
    let lower = next_below.max(lo);
    ((upper - lower) / width).clamp(0.0, 1.0)
}

/// The Fresnel product of the `k` bounces of a ray arriving from `wi` in the groove whose first
/// wall is `m` and second `m2` (walls alternate), and the direction it leaves along.
fn bounces(wi: DVec3, m: DVec3, m2: DVec3, k: usize, fresnel: &impl Fn(f64) -> f64) -> (f64, DVec3) {
    // d is the direction of travel: each wall mirrors it, d - 2 (d·n) n.
    let (mut d, mut f) = (-wi, 1.0);
    for j in 0..k {
        let n = if j % 2 == 0 { m } else { m2 };
        f *= fresnel(d.dot(n).abs());
        d = -reflect(d, n);
    }
    (f, d)
}

/// The order-`k` lobe of the V-groove microsurface of `ndf` (§14.2): the energy per steradian
/// of `wo` per unit incident energy from `wi` (`f_k(wi, wo) cos theta_o`), both above the
/// horizon, with the walls' reflectance `fresnel(cos)`:
///
/// `sum over grooves D(m) <wi·m> g_k F_k sin theta_m / (cos theta_i 2k |(wi + wo)·e|)`,
///
/// the sum over the grooves (a wall `m` hit first) that send `wi` to `wo` in `k` bounces: their
/// axis is horizontal and orthogonal to `wi + wo`, `e` the horizontal unit vector towards which
/// `m` tilts, `g_k` the [`bounce_fraction`] of `m`'s cross-section, `F_k` the product of the
/// walls' Fresnel along the path, and `sin theta_m / (2k |(wi + wo)·e|)` the Jacobian
/// `d omega_m / d omega_o` (§14.2). Zero for a `wo` along the groove's degenerate axis
/// (`wi + wo` vertical), a set of no measure.
pub fn order_lobe<N: Ndf>(ndf: &N, wi: DVec3, wo: DVec3, k: usize, fresnel: impl Fn(f64) -> f64) -> f64 {
    if wi.z <= 0.0 || wo.z <= 0.0 || k == 0 {
        return 0.0;
    }
    let sum = wi + wo;
    let horizontal = DVec3::new(sum.x, sum.y, 0.0);
    let length = horizontal.length();
    if length <= 1e-12 * sum.length() {
        return 0.0;
    }
    let mut total = 0.0;
    // The two orientations of the groove whose cross-section holds wi + wo: the wall hit
    // first tilts towards e = -x' or towards e = +x'.
    for e in [horizontal / length, -horizontal / length] {
        let x = -e;
        let theta_i = wi.dot(x).atan2(wi.z);
        let theta_o = wo.dot(x).atan2(wo.z);
        // A wall tilted by theta_m towards -x' turns the in-plane angle by k bounces to
        // theta_o = -2k theta_m - theta_i (k odd) or theta_i + 2k theta_m - pi (k even).
        let c = if k % 2 == 1 { -(theta_o + theta_i) } else { theta_o - theta_i + PI };
        let c = c.rem_euclid(TAU);
        let jacobian_denominator = 2.0 * k as f64 * sum.dot(e).abs();
        // k bounces need walls steep enough for k virtual walls in [0, pi]: at most
        // pi / (2 beta) + 1 fit, so beta <= pi / (2 (k - 1)); only the candidates
        // 2k theta_m = c + 2 pi j between that bound and k pi are worth a look.
        let steepest = if k > 1 { FRAC_PI_2 - PI / (2 * (k - 1)) as f64 } else { 0.0 };
        let j_min = ((2 * k) as f64 * steepest.max(0.0) - c) / TAU;
        let j_max = ((k as f64) * PI - c) / TAU;
        for j in (j_min.ceil().max(0.0) as usize)..=(j_max.floor().max(0.0) as usize) {
            let theta_m = (c + TAU * j as f64) / (2 * k) as f64;
            if theta_m <= 0.0 || theta_m >= FRAC_PI_2 {
                continue;
            }
            let g = bounce_fraction(theta_i, theta_m, k);
            if g <= 0.0 {
                continue;
            }
            let (sin_m, cos_m) = theta_m.sin_cos();
            let m = sin_m * e + cos_m * DVec3::Z;
            let m2 = -sin_m * e + cos_m * DVec3::Z;
            let (f, _) = bounces(wi, m, m2, k, &fresnel);
            total += ndf.d(m) * wi.dot(m) * g * f * sin_m / (wi.z * jacobian_denominator);
        }
    }
    total
}

/// The orders `orders` of the V-groove lobe together: the sum of [`order_lobe`] over them.
pub fn orders_lobe<N: Ndf>(
    ndf: &N,
    wi: DVec3,
    wo: DVec3,
    orders: std::ops::RangeInclusive<usize>,
    fresnel: impl Fn(f64) -> f64,
) -> f64 {
    orders.map(|k| order_lobe(ndf, wi, wo, k, &fresnel)).sum()
}

/// Where a ray from `wi` leaves the groove whose first wall is `m` after `k` bounces, with the
/// walls' Fresnel product: the forward map that [`order_lobe`] inverts (for tests and samplers).
pub fn leave(wi: DVec3, m: DVec3, k: usize, fresnel: impl Fn(f64) -> f64) -> (f64, DVec3) {
    let m2 = DVec3::new(-m.x, -m.y, m.z);
    bounces(wi, m, m2, k, &fresnel)
}
