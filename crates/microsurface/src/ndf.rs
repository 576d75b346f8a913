//! Normal distribution functions: D, Smith Lambda, projected area and visible-normal sampling
//! (docs/theory.md §1 and §3).
//!
//! Both NDFs are anisotropic with roughness (alpha_x, alpha_y) and stretch-invariant (§1.1):
//! every quantity is computed in the stretched configuration of roughness 1 where that is
//! simpler or more accurate.

use std::f64::consts::{FRAC_1_SQRT_2, PI};

use glam::DVec3;
use rand::Rng;
use statrs::function::erf::erfc;

use crate::random::{azimuth, exp1, normal1, open01};
use crate::student_t::StudentT;

pub(crate) const SQRT_PI: f64 = 1.772_453_850_905_516;

/// Anisotropic roughness: the slope scales along the tangent axes x and y (§0, §1.2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Roughness {
    /// Roughness along the tangent axis x.
    pub x: f64,
    /// Roughness along the tangent axis y.
    pub y: f64,
}

impl Roughness {
    /// The same roughness `alpha` along both axes.
    pub fn isotropic(alpha: f64) -> Self {
        Self { x: alpha, y: alpha }
    }

    /// `alpha_x^2 w_x^2 + alpha_y^2 w_y^2`: the squared projected roughness times `1 - w_z^2` (§1.3).
    #[inline]
    pub(crate) fn tangential2(self, w: DVec3) -> f64 {
        let (ax, ay) = (self.x * w.x, self.y * w.y);
        ax * ax + ay * ay
    }

    /// The direction in the stretched roughness-1 configuration, `normalize(ax wx, ay wy, wz)` (§1.1).
    #[inline]
    pub fn stretch(self, w: DVec3) -> DVec3 {
        DVec3::new(self.x * w.x, self.y * w.y, w.z).normalize()
    }

    /// The normal of unit roughness `m'` mapped back to this roughness, `normalize(ax m'x, ay m'y, m'z)` (§1.1).
    #[inline]
    pub fn unstretch_normal(self, m: DVec3) -> DVec3 {
        let n = DVec3::new(self.x * m.x, self.y * m.y, m.z);
        let len = n.length();
        if len > 0.0 { n / len } else { DVec3::Z }
    }
}

/// A microfacet normal distribution (§1.2): the alternatives are GGX, Beckmann and Student-T
/// (§1.6, [`crate::student_t`]).
pub trait Ndf: Copy + Send + Sync {
    /// The roughness (alpha_x, alpha_y) that stretches the roughness-1 configuration (§1.1).
    fn roughness(&self) -> Roughness;

    /// The distribution of normals D(m) [sr^-1] for `m_z > 0` (§1.2), zero below.
    fn d(&self, m: DVec3) -> f64;

    /// The true full-sphere Smith Lambda(w) (§1.4): `Lambda(-w) = -1 - Lambda(w)`,
    /// `>= 0` above the horizon, `<= -1` below, `+inf` for `w_z = +0` and `-inf` for `w_z = -0`.
    fn lambda(&self, w: DVec3) -> f64;

    /// The projected area A(w) = ∫ D(m) <w·m> dm of the facets facing w, any w (§1.5).
    fn projected_area(&self, w: DVec3) -> f64;

    /// Draws m from the visible-normal distribution `D_w(m) = <w·m> D(m) / A(w)` (§3.1),
    /// exactly, for any `w` on the sphere except `-z` (where `A = 0`; then it returns `+z`).
    fn sample_visible<R: Rng + ?Sized>(&self, w: DVec3, rng: &mut R) -> DVec3;

    /// [`Ndf::sample_visible`] for `L` directions at once, for walks of photons side by side.
    /// An NDF whose sampler is a fixed computation on its random numbers draws them all first,
    /// so that the `L` computations are independent and overlap.
    #[inline]
    fn sample_visible_lanes<R: Rng + ?Sized, const L: usize>(&self, w: [DVec3; L], rng: &mut R) -> [DVec3; L] {
        w.map(|w| self.sample_visible(w, rng))
    }

    /// Slope radius `r = tan(theta_m)` of a normal drawn from `D(m) m_z` in the roughness-1
    /// configuration, as a function of a uniform `u` (the inverse of [`Ndf::std_slope_cdf`]).
    fn std_slope_radius(&self, u: f64) -> f64;

    /// Probability that a normal drawn from `D(m) m_z` (roughness 1) has slope radius below `r`.
    fn std_slope_cdf(&self, r: f64) -> f64;
}

/// Anisotropic GGX (Trowbridge–Reitz), §1.2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ggx(pub Roughness);

impl Ndf for Ggx {
    fn roughness(&self) -> Roughness {
        self.0
    }

    fn d(&self, m: DVec3) -> f64 {
        if m.z <= 0.0 {
            return 0.0;
        }
        let Roughness { x: ax, y: ay } = self.0;
        let (sx, sy) = (m.x / ax, m.y / ay);
        let k = sx * sx + sy * sy + m.z * m.z;
        1.0 / (PI * ax * ay * k * k)
    }

    /// `Lambda = (|A w| - w_z) / (2 w_z)` (§1.4, vector form), rearranged above the horizon
    /// as `t / (2 w_z (|A w| + w_z))` so that it does not cancel near the zenith.
    fn lambda(&self, w: DVec3) -> f64 {
        let t = self.0.tangential2(w);
        let norm = (t + w.z * w.z).sqrt();
        if w.z > 0.0 { t / (2.0 * w.z * (norm + w.z)) } else { (norm - w.z) / (2.0 * w.z) }
    }

    /// `A = (w_z + |A w|) / 2` (§1.5), rearranged below the horizon to avoid cancellation.
    fn projected_area(&self, w: DVec3) -> f64 {
        let t = self.0.tangential2(w);
        let norm = (t + w.z * w.z).sqrt();
        if w.z >= 0.0 {
            0.5 * (w.z + norm)
        } else if t > 0.0 {
            0.5 * t / (norm - w.z)
        } else {
            0.0
        }
    }

    /// Dupuy & Benyoub 2023 spherical caps (§3.2), exact on the full sphere.
    fn sample_visible<R: Rng + ?Sized>(&self, w: DVec3, rng: &mut R) -> DVec3 {
        let azimuth = azimuth(rng);
        self.cap_sample(w, azimuth, open01(rng))
    }

    #[inline]
    fn sample_visible_lanes<R: Rng + ?Sized, const L: usize>(&self, w: [DVec3; L], rng: &mut R) -> [DVec3; L] {
        let azimuths: [(f64, f64); L] = std::array::from_fn(|_| azimuth(rng));
        let heights: [f64; L] = std::array::from_fn(|_| open01(rng));
        std::array::from_fn(|i| self.cap_sample(w[i], azimuths[i], heights[i]))
    }

    /// `cos^2 theta = 1 - u` for roughness 1 (\[Ham17\], "Intersection normal"), so `tan^2 = u / (1 - u)`.
    fn std_slope_radius(&self, u: f64) -> f64 {
        (u / (1.0 - u)).sqrt()
    }

    fn std_slope_cdf(&self, r: f64) -> f64 {
        let r2 = r * r;
        if r2.is_infinite() { 1.0 } else { r2 / (1.0 + r2) }
    }
}

impl Ggx {
    /// The visible normal of `w` for the random azimuth `(cos phi, sin phi)` and uniform `u`
    /// (§3.2): in the stretched configuration, the point of the spherical cap
    /// `z in (-w'_z, 1]` at height `z = (1 - u)(1 + w'_z) - w'_z` and azimuth phi, plus `w'`,
    /// is the half vector; unstretched, the normal.
    #[inline]
    fn cap_sample(&self, w: DVec3, (c, s): (f64, f64), u: f64) -> DVec3 {
        let ws = self.0.stretch(w);
        let z = (1.0 - u) * (1.0 + ws.z) - ws.z;
        let sin_theta = (1.0 - z * z).max(0.0).sqrt();
        let h = DVec3::new(sin_theta * c, sin_theta * s, z) + ws;
        self.0.unstretch_normal(DVec3::new(h.x, h.y, h.z.max(0.0)))
    }
}

/// Anisotropic Beckmann, §1.2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Beckmann(pub Roughness);

/// Beckmann Lambda for `a = w_z / (alpha_i sqrt(1 - w_z^2)) > 0` (§1.4), written with erfc so that
/// `erf(a) - 1` does not cancel (§10): `Lambda = (e^{-a^2} / (a sqrt(pi)) - erfc(a)) / 2`.
/// Near `a = 27` both terms are subnormal and their rounded difference can come out negative;
/// Lambda is clamped at 0 there (a negative extinction rate would send rays to infinite depth).
fn beckmann_lambda_above(a: f64) -> f64 {
    if a.is_infinite() {
        return 0.0;
    }
    (0.5 * ((-a * a).exp() / (a * SQRT_PI) - erfc(a))).max(0.0)
}

/// Lambda on the whole sphere (§1.4) of an NDF whose Lambda above the horizon is a function
/// `above(a)` of `a = w_z / |A_t w|` alone (Beckmann, Student-T): NaN where `a` is (a zero or
/// NaN direction), `±inf` on the horizon from either side, and `-1 - Lambda(-w)` below it.
pub(crate) fn lambda_from_above(w: DVec3, a: f64, above: impl FnOnce(f64) -> f64) -> f64 {
    if a.is_nan() {
        return f64::NAN;
    }
    if w.z == 0.0 {
        return if w.z.is_sign_positive() { f64::INFINITY } else { f64::NEG_INFINITY };
    }
    if a > 0.0 { above(a) } else { -1.0 - above(-a) }
}

impl Beckmann {
    /// `a = w_z / sqrt(alpha_x^2 w_x^2 + alpha_y^2 w_y^2)` (§1.4), `±inf` at the poles.
    fn a(&self, w: DVec3) -> f64 {
        w.z / self.0.tangential2(w).sqrt()
    }
}

impl Ndf for Beckmann {
    fn roughness(&self) -> Roughness {
        self.0
    }

    fn d(&self, m: DVec3) -> f64 {
        if m.z <= 0.0 {
            return 0.0;
        }
        let Roughness { x: ax, y: ay } = self.0;
        let (sx, sy) = (m.x / (ax * m.z), m.y / (ay * m.z));
        let mz2 = m.z * m.z;
        (-(sx * sx + sy * sy)).exp() / (PI * ax * ay * mz2 * mz2)
    }

    fn lambda(&self, w: DVec3) -> f64 {
        lambda_from_above(w, self.a(w), beckmann_lambda_above)
    }

    /// `A = (1 + Lambda(w)) w_z` above the horizon and `Lambda(-w) |w_z|` below (§1.5, §10).
    fn projected_area(&self, w: DVec3) -> f64 {
        let a = self.a(w);
        if w.z > 0.0 {
            (1.0 + beckmann_lambda_above(a)) * w.z
        } else if w.z < 0.0 {
            beckmann_lambda_above(-a) * -w.z
        } else {
            self.0.tangential2(w).sqrt() / (2.0 * SQRT_PI)
        }
    }

    /// Exact full-sphere sampler in the stretched frame aligned with w (§3.1): the slope along w
    /// has density `∝ (mu - x) e^{-x^2}` on `x < mu = cot theta'` ([`visible_slope_beckmann`])
    /// and the orthogonal slope is an independent normal of variance 1/2. Where `mu` overflows
    /// (a tangential part below 1e-308) `w` is taken as the pole: upward, the slope along any
    /// azimuth is that normal too; downward, `A(w)` is 0 to double precision and `+z` is returned.
    fn sample_visible<R: Rng + ?Sized>(&self, w: DVec3, rng: &mut R) -> DVec3 {
        let ws = self.0.stretch(w);
        let sin_theta = ws.x.hypot(ws.y);
        let mu = ws.z / sin_theta;
        let (x, cos_phi, sin_phi) = if mu.is_finite() {
            (visible_slope_beckmann(mu, rng), ws.x / sin_theta, ws.y / sin_theta)
        } else if ws.z > 0.0 {
            (std_beckmann_slope(rng), 1.0, 0.0)
        } else {
            return DVec3::Z;
        };
        let y = std_beckmann_slope(rng);
        let sx = cos_phi * x - sin_phi * y;
        let sy = sin_phi * x + cos_phi * y;
        slope_to_normal(self.0.x * sx, self.0.y * sy)
    }

    /// `tan^2 theta = -ln(1 - u)` for roughness 1.
    fn std_slope_radius(&self, u: f64) -> f64 {
        (-(-u).ln_1p()).sqrt()
    }

    fn std_slope_cdf(&self, r: f64) -> f64 {
        -(-r * r).exp_m1()
    }
}

/// One of the NDFs, chosen at run time (a configuration's or a renderer's `distribution`).
///
/// Every quantity dispatches to the variant. Hot loops that want each NDF compiled on its own
/// match once outside the loop and call the variant's type directly; adding an NDF is one
/// variant here, and the compiler lists every `match` to extend.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AnyNdf {
    /// GGX (Trowbridge–Reitz).
    Ggx(Ggx),
    /// Beckmann.
    Beckmann(Beckmann),
    /// Student-T (§1.6), between the two.
    StudentT(StudentT),
}

impl AnyNdf {
    /// The NDF's name as configurations spell it.
    pub fn name(&self) -> &'static str {
        match self {
            AnyNdf::Ggx(_) => "ggx",
            AnyNdf::Beckmann(_) => "beckmann",
            AnyNdf::StudentT(_) => "student-t",
        }
    }
}

/// Calls `$body` with `$n` bound to the concrete NDF inside an [`AnyNdf`].
macro_rules! dispatch {
    ($any:expr, $n:ident => $body:expr) => {
        match $any {
            AnyNdf::Ggx($n) => $body,
            AnyNdf::Beckmann($n) => $body,
            AnyNdf::StudentT($n) => $body,
        }
    };
}

impl Ndf for AnyNdf {
    fn roughness(&self) -> Roughness {
        dispatch!(self, n => n.roughness())
    }

    fn d(&self, m: DVec3) -> f64 {
        dispatch!(self, n => n.d(m))
    }

    fn lambda(&self, w: DVec3) -> f64 {
        dispatch!(self, n => n.lambda(w))
    }

    fn projected_area(&self, w: DVec3) -> f64 {
        dispatch!(self, n => n.projected_area(w))
    }

    fn sample_visible<R: Rng + ?Sized>(&self, w: DVec3, rng: &mut R) -> DVec3 {
        dispatch!(self, n => n.sample_visible(w, rng))
    }

    fn sample_visible_lanes<R: Rng + ?Sized, const L: usize>(&self, w: [DVec3; L], rng: &mut R) -> [DVec3; L] {
        dispatch!(self, n => n.sample_visible_lanes(w, rng))
    }

    fn std_slope_radius(&self, u: f64) -> f64 {
        dispatch!(self, n => n.std_slope_radius(u))
    }

    fn std_slope_cdf(&self, r: f64) -> f64 {
        dispatch!(self, n => n.std_slope_cdf(r))
    }
}

/// The normal of slope (x, y): `normalize(-x, -y, 1)` (§1.1).
#[inline]
pub fn slope_to_normal(x: f64, y: f64) -> DVec3 {
    DVec3::new(-x, -y, 1.0).normalize()
}

/// One slope coordinate of the roughness-1 Beckmann distribution, density `e^{-x^2} / sqrt(pi)`:
/// a normal of variance 1/2.
#[inline]
pub(crate) fn std_beckmann_slope<R: Rng + ?Sized>(rng: &mut R) -> f64 {
    normal1(rng) * FRAC_1_SQRT_2
}

/// Draws the slope along the view direction from `p(x) ∝ (mu - x) e^{-x^2}`, `x < mu`, for any
/// finite `mu` (§3.1, roughness 1), exactly, by rejection from proposals that need no special
/// function. In `t = -x` the target is `q(t) = (mu + t) e^{-t^2}` on `t > -mu`. With `E`
/// standard exponentials:
///
/// * `mu >= 0`: `q <= g = mu e^{-t^2} + max(t, 0) e^{-t^2}`, a mixture of the normal of variance
///   1/2 (mass `mu sqrt(pi)`) and `t e^{-t^2}` on `t > 0` (mass 1/2, `t = sqrt(E)`). A draw from
///   `g` is kept with `q / g`: 1 for `t >= 0`, `1 + t / mu` on `(-mu, 0)`, 0 below. The
///   acceptance `∫q / ∫g` is at least 0.766 (at `mu = 0.52`).
/// * `mu < 0`, `a = -mu`: `q = (t - a) e^{-t^2}` on `t > a`.
///   - For `a < 1/sqrt(2)`: the tail `t e^{-t^2}` on `t > a` (`t = sqrt(a^2 + E)`), kept with
///     `1 - a / t`. Acceptance `R(a) = 1 - a sqrt(pi) e^{a^2} erfc(a)`.
///   - Beyond: `s = t - a` has density `∝ s e^{-2 a s} e^{-s^2}`, so a Gamma(2, 2a) draw
///     `(E1 + E2) / (2a)` is kept with `e^{-s^2}` (when `E3 > s^2`). Acceptance `2 a^2 R(a)`,
///     which is why the switch is at `a = 1/sqrt(2)` (both 0.34 there); it tends to 1 as `a`
///     grows, where the tail proposal's tends to 0.
pub fn visible_slope_beckmann<R: Rng + ?Sized>(mu: f64, rng: &mut R) -> f64 {
    if mu >= 0.0 {
        // P(normal component) = mu sqrt(pi) / (mu sqrt(pi) + 1/2), written to stay 1 at mu = inf.
        let p_normal = 1.0 / (1.0 + 0.5 / (mu * SQRT_PI));
        loop {
            if open01(rng) >= p_normal {
                return -exp1(rng).sqrt();
            }
            let t = std_beckmann_slope(rng);
            if t >= 0.0 || open01(rng) < 1.0 + t / mu {
                return -t;
            }
        }
    }
    let a = -mu;
    if a < FRAC_1_SQRT_2 {
        loop {
            let t = (a * a + exp1(rng)).sqrt();
            if open01(rng) * t < t - a {
                return -t;
            }
        }
    }
    let rate = 2.0 * a;
    loop {
        let s = (exp1(rng) + exp1(rng)) / rate;
        if exp1(rng) > s * s {
            return mu - s;
        }
    }
}

/// The 1-D marginal of the slope in the vertical plane of a direction with projected roughness
/// `alpha_i` (§1.3): the integrand of the Smith definition of Lambda (§1.4).
pub fn ggx_slope_marginal(q: f64, alpha_i: f64) -> f64 {
    let a2 = alpha_i * alpha_i;
    a2 / (2.0 * (a2 + q * q).powf(1.5))
}

/// Beckmann counterpart of [`ggx_slope_marginal`] (§1.3).
pub fn beckmann_slope_marginal(q: f64, alpha_i: f64) -> f64 {
    let t = q / alpha_i;
    (-t * t).exp() / (alpha_i * SQRT_PI)
}
