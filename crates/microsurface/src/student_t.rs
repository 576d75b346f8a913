//! The Student-T NDF (docs/theory.md §1.6): a one-parameter family of tails between GGX
//! (`gamma = 2`) and Beckmann (`gamma -> inf`), with its exact Smith Lambda and an exact
//! full-sphere visible-normal sampler (§3.4).
//!
//! Everything is computed in the stretched configuration of roughness 1 (§1.1), where the
//! slope density is `P22(r) = ((gamma-1) / (gamma-1 + r^2))^gamma / pi`.

use glam::DVec3;
use rand::Rng;
use rand_distr::{Distribution, Gamma};

use crate::beta::{ln_beta, regularized_incomplete_beta};
use crate::ndf::{Ndf, Roughness, SQRT_PI, lambda_from_above, std_beckmann_slope};
use crate::random::{exp1, open01};

/// Anisotropic Student-T with roughness (alpha_x, alpha_y) and shape `gamma > 3/2` (§1.6).
///
/// Built by [`StudentT::new`], which keeps the constants of the shape that every Lambda and
/// every sample needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StudentT {
    roughness: Roughness,
    gamma: f64,
    /// Degrees of freedom of the 1-D slope marginal, `nu = 2 gamma - 2` (§1.6).
    nu: f64,
    /// `ln(1 / (sqrt(nu) B(nu/2, 1/2)))`, the logarithm of the Student-t density's constant.
    ln_t_constant: f64,
    /// `E[s_G]` of the scale mixture (§3.4), `sqrt(gamma-1) Γ(gamma-3/2) / Γ(gamma-1)`.
    mean_scale: f64,
    /// The mixing law of the scale mixture, `G ~ Gamma(gamma - 1, 1)` (§3.4).
    mixing: Gamma<f64>,
    /// The mixing law weighted by the scale `s_G = sqrt((gamma-1) / G)`, `Gamma(gamma - 3/2, 1)`.
    scaled_mixing: Gamma<f64>,
    /// The mixing law weighted by `s_G^3`, `Gamma(gamma - 5/2, 1)`, for the proposal below the
    /// horizon near the nadir (§3.4); it exists for `gamma > 5/2`, and is used only above 3.
    nadir_mixing: Option<Gamma<f64>>,
}

impl StudentT {
    /// The Student-T NDF of `roughness` and shape `gamma`, which must be finite and above 3/2
    /// (below, the slopes have no finite mean and Lambda does not exist); `None` otherwise.
    pub fn new(roughness: Roughness, gamma: f64) -> Option<Self> {
        if !(gamma.is_finite() && gamma > 1.5) {
            return None;
        }
        let nu = 2.0 * gamma - 2.0;
        // Γ(gamma-3/2) / Γ(gamma-1) = B(gamma-3/2, 1/2) / sqrt(pi), without the cancellation of
        // two large ln Γ at large gamma (beta.rs).
        let mean_scale = (gamma - 1.0).sqrt() * ln_beta(gamma - 1.5, 0.5).exp() / SQRT_PI;
        Some(Self {
            roughness,
            gamma,
            nu,
            ln_t_constant: -0.5 * nu.ln() - ln_beta(0.5 * nu, 0.5),
            mean_scale,
            mixing: Gamma::new(gamma - 1.0, 1.0).ok()?,
            scaled_mixing: Gamma::new(gamma - 1.5, 1.0).ok()?,
            nadir_mixing: Gamma::new(gamma - 2.5, 1.0).ok(),
        })
    }

    /// The shape parameter `gamma`.
    pub fn gamma(&self) -> f64 {
        self.gamma
    }

    /// `E[(X - a)_+]` for `a >= 0` and the roughness-1 slope marginal `X = T / sqrt(2)`,
    /// `T ~ t_nu` (§1.6). Lambda above the horizon is this over `a`, and the projected area
    /// `max(w_z, 0) + |tangential| E[(X - |a|)_+]` on the whole sphere.
    ///
    /// With `b = a sqrt(2)` and `x = nu / (nu + b^2)`:
    /// `E[(T - b)_+] = x^{(nu-1)/2} / (sqrt(nu) B(nu/2, 1/2)) * K(x)`, where
    /// `K(x) = nu/(nu-1) - (1-x) 2F1((nu+1)/2, 1; nu/2+1; x)` is, by the series of 2F1,
    /// `1/(nu-1) + sum_{n>=1} c_{n-1} x^n / (nu + 2n)` with `c_0 = 1`,
    /// `c_n = c_{n-1} (nu + 2n - 1) / (nu + 2n)`: positive terms, no cancellation. Its terms
    /// fall at least as `x^n`, so it is summed for `x <= 1/2` (at most about 55 terms).
    /// Above, `K(x) = nu/(nu-1) - sqrt(nu) B(nu/2,1/2) x^{-(nu-1)/2} b S(b)` with the tail
    /// `S(b) = I_x(nu/2, 1/2) / 2` ([`regularized_incomplete_beta`]); the difference loses
    /// at most a factor `nu/(nu-1) / K(x) < nu` of relative precision, and there `b^2 < nu`,
    /// where it is much less (§1.6). A mean below the normal doubles is returned as 0.
    fn tail_mean(&self, a: f64) -> f64 {
        if a.is_infinite() {
            return 0.0;
        }
        let nu = self.nu;
        let b2 = 2.0 * a * a;
        let ln_x = -(b2 / nu).ln_1p();
        let x = ln_x.exp();
        let scale = ((0.5 * (nu - 1.0)) * ln_x + self.ln_t_constant).exp();
        if scale < f64::MIN_POSITIVE {
            // The mean is below the normal doubles (b^2 of several hundred at large nu); the
            // fraction's `tail / scale` would be 0/0.
            return 0.0;
        }
        let k = if x <= 0.5 {
            let (mut c, mut xn, mut sum, mut n) = (1.0, 1.0, 1.0 / (nu - 1.0), 1.0);
            loop {
                xn *= x;
                let term = c * xn / (nu + 2.0 * n);
                sum += term;
                // The remainder is below term * x / (1 - x) <= term.
                if term < 1e-17 * sum {
                    break sum;
                }
                c *= (nu + 2.0 * n - 1.0) / (nu + 2.0 * n);
                n += 1.0;
            }
        } else {
            let b = b2.sqrt();
            let tail = 0.5 * regularized_incomplete_beta(x, 0.5 * nu, 0.5);
            nu / (nu - 1.0) - b * tail / scale
        };
        std::f64::consts::FRAC_1_SQRT_2 * scale * k
    }

    /// `a = w_z / sqrt(alpha_x^2 w_x^2 + alpha_y^2 w_y^2)`, `±inf` at the poles (§1.4).
    fn a(&self, w: DVec3) -> f64 {
        w.z / self.roughness.tangential2(w).sqrt()
    }

    /// The roughness-1 slopes of a visible normal as `(x, s, z)`, all divided by one factor
    /// `f >= 1` so that none overflows: `x / z` is the slope along the view azimuth of a
    /// direction with `mu = cot theta'` (stretched, §3.1) and `s / z` the scale `s_G` of the
    /// Beckmann component it was drawn in. The pair is distributed as the visible slopes of the
    /// scale mixture (§3.4), so that the orthogonal slope is that component's normal of
    /// variance `s_G^2 / 2`.
    ///
    /// Each branch is a rejection loop whose acceptance is at least 1/4 for every `gamma > 3/2`
    /// and every `mu` (§3.4, by quadrature; 1/4 is reached at the nadir at `gamma = 3`), so
    /// at most 4 passes on average and a sample costs O(1) up to the nadir at any shape.
    /// Measured (`cargo test --release -p smithwalk-microsurface --test distributions
    /// near_the_nadir -- --nocapture`, 10^4 normals 1e-3 to 1e-300 rad from the nadir): 6.1
    /// random words a normal at `gamma` 1e6 and 1e3, 20.7 at 3.2, 7.2 at 1.6.
    fn visible_slope<R: Rng + ?Sized>(&self, mu: f64, rng: &mut R) -> (f64, f64, f64) {
        let scale = |g: f64| ((self.gamma - 1.0) / g).sqrt();
        if mu >= 0.0 {
            // (mu - x)_+ <= mu + (-x)_+: the component of mass mu draws G from the mixing law
            // and x from its Beckmann slope; the other, of mass E[s_G] / (2 sqrt(pi)), G from the
            // scale-weighted law and -x = s_G sqrt(E). Kept with (mu - x)_+ / (mu + (-x)_+).
            // P(first) is written to stay 1 at mu = inf.
            let p_first = 1.0 / (1.0 + self.mean_scale / (2.0 * SQRT_PI * mu));
            loop {
                if open01(rng) >= p_first {
                    let s = scale(self.scaled_mixing.sample(rng));
                    return (-s * exp1(rng).sqrt(), s, 1.0);
                }
                let s = scale(self.mixing.sample(rng));
                let x = s * std_beckmann_slope(rng);
                if x <= 0.0 || open01(rng) < 1.0 - x / mu {
                    return (x, s, 1.0);
                }
            }
        }
        // Below the horizon, t = -x > a = -mu. Both proposals are written in a_G = a / s_G,
        // a_G^2 = g k with k = a^2 / (gamma - 1 + a^2) and g a Gamma draw, so that nothing
        // squares `a` (near the nadir it reaches 1e154 and more, where a^2 overflows), and
        // return t / a (`stretch`) and s_G / a = 1 / a_G.
        let a = -mu;
        let inv = 1.0 / a;
        let k = 1.0 / (1.0 + (self.gamma - 1.0) * inv * inv);
        let (stretch, inv_a_g) = match self.nadir_mixing {
            // Near the nadir (§3.4): in s = t/s_G - a_G the target is Gamma(gamma - 5/2, 1) in
            // g times Gamma(2, 2 a_G) in s times e^{-s^2}, Beckmann's large-a proposal (§3.2)
            // with G drawn jointly: s = (E1 + E2) / (2 a_G), kept when E3 > s^2.
            Some(nadir) if (self.gamma - 2.5) * k > 0.5 => loop {
                let a_g = (nadir.sample(rng) * k).sqrt();
                let s = (exp1(rng) + exp1(rng)) / (2.0 * a_g);
                if exp1(rng) > s * s {
                    break (1.0 + s / a_g, 1.0 / a_g);
                }
            },
            // Elsewhere the proposal t e^{-t^2/s^2} on t > a, of mass s e^{-a^2/s^2} / (2 sqrt(pi))
            // given G, so G from the mixing law weighted by it, g ~ Gamma(gamma - 3/2, 1); then
            // t = sqrt(a^2 + s^2 E), kept with (t - a) / t = 1 - 1 / stretch.
            _ => loop {
                let a_g = (self.scaled_mixing.sample(rng) * k).sqrt();
                let stretch = (1.0 + exp1(rng) / (a_g * a_g)).sqrt();
                if open01(rng) * stretch < stretch - 1.0 {
                    break (stretch, 1.0 / a_g);
                }
            },
        };
        // Slopes a stretch and a / a_G, which overflow near the nadir at small G, divided by
        // max(a, 1).
        let (a_f, z) = if a > 1.0 { (1.0, inv) } else { (a, 1.0) };
        (-a_f * stretch, a_f * inv_a_g, z)
    }
}

impl Ndf for StudentT {
    fn roughness(&self) -> Roughness {
        self.roughness
    }

    fn d(&self, m: DVec3) -> f64 {
        if m.z <= 0.0 {
            return 0.0;
        }
        let Roughness { x: ax, y: ay } = self.roughness;
        let (sx, sy) = (m.x / (ax * m.z), m.y / (ay * m.z));
        let mz2 = m.z * m.z;
        // ((g-1) / (g-1 + r^2))^g = exp(-g ln(1 + r^2/(g-1))), exact as gamma grows.
        let p22 = (-self.gamma * ((sx * sx + sy * sy) / (self.gamma - 1.0)).ln_1p()).exp();
        p22 / (std::f64::consts::PI * ax * ay * mz2 * mz2)
    }

    /// `Lambda = E[(X - a)_+] / a` (§1.4, §1.6) above the horizon, `-1 - Lambda(-w)` below.
    fn lambda(&self, w: DVec3) -> f64 {
        lambda_from_above(w, self.a(w), |a| self.tail_mean(a) / a)
    }

    /// `A = max(w_z, 0) + |A_t w| E[(X - |a|)_+]` on the whole sphere (§1.5, §1.6): the
    /// `(1 + Lambda) w_z` above the horizon and `Lambda(-w) |w_z|` below, without the division
    /// by `a` that is 0/0 at the horizon.
    fn projected_area(&self, w: DVec3) -> f64 {
        let t = self.roughness.tangential2(w);
        if t == 0.0 {
            return w.z.max(0.0);
        }
        let t = t.sqrt();
        w.z.max(0.0) + t * self.tail_mean((w.z / t).abs())
    }

    /// The scale mixture of Beckmann visible slopes (§3.4), exact on the full sphere; the frame
    /// and the poles as in Beckmann's sampler.
    fn sample_visible<R: Rng + ?Sized>(&self, w: DVec3, rng: &mut R) -> DVec3 {
        let ws = self.roughness.stretch(w);
        let sin_theta = ws.x.hypot(ws.y);
        let mu = ws.z / sin_theta;
        let (cos_phi, sin_phi) = if mu.is_finite() {
            (ws.x / sin_theta, ws.y / sin_theta)
        } else if ws.z > 0.0 {
            (1.0, 0.0)
        } else {
            return DVec3::Z;
        };
        let (x, s, z) = self.visible_slope(mu, rng);
        let y = s * std_beckmann_slope(rng);
        // Slopes near the nadir reach 1e154 and more (times z): scaled before squaring (normalize).
        let c = x.abs().max(y.abs()).max(z);
        let (x, y) = (x / c, y / c);
        let sx = cos_phi * x - sin_phi * y;
        let sy = sin_phi * x + cos_phi * y;
        DVec3::new(-self.roughness.x * sx, -self.roughness.y * sy, z / c).normalize()
    }

    /// The slope radius of `D(m) m_z` has `P(r' > r) = (1 + r^2/(gamma-1))^{-(gamma-1)}`, so
    /// `r^2 = (gamma-1) ((1-u)^{-1/(gamma-1)} - 1)`.
    fn std_slope_radius(&self, u: f64) -> f64 {
        let g1 = self.gamma - 1.0;
        (g1 * (-(-u).ln_1p() / g1).exp_m1()).sqrt()
    }

    fn std_slope_cdf(&self, r: f64) -> f64 {
        let g1 = self.gamma - 1.0;
        -(-g1 * (r * r / g1).ln_1p()).exp_m1()
    }
}

/// The 1-D marginal of the Student-T slope in the vertical plane of a direction with projected
/// roughness `alpha_i` (§1.6): `x = (alpha_i / sqrt 2) T`, `T ~ t_nu`, `nu = 2 gamma - 2`.
pub fn student_t_slope_marginal(q: f64, alpha_i: f64, gamma: f64) -> f64 {
    let nu = 2.0 * gamma - 2.0;
    let t = std::f64::consts::SQRT_2 * q / alpha_i;
    let ln_density = -0.5 * (nu + 1.0) * (t * t / nu).ln_1p() - 0.5 * nu.ln() - ln_beta(0.5 * nu, 0.5);
    std::f64::consts::SQRT_2 * ln_density.exp() / alpha_i
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ndf::{Beckmann, Ggx};

    /// Directions over the whole sphere, from the poles to within 1e-9 rad of the horizon on
    /// both sides, at azimuths that mix the two roughnesses.
    fn sphere() -> Vec<DVec3> {
        let mut thetas: Vec<f64> = (0..=36).map(|i| f64::from(i) * 5f64.to_radians()).collect();
        for e in [1e-3, 1e-6, 1e-9] {
            thetas.extend([std::f64::consts::FRAC_PI_2 - e, std::f64::consts::FRAC_PI_2 + e]);
        }
        thetas.extend([1e-6, 1e-3, std::f64::consts::PI - 1e-3]);
        let mut out = Vec::new();
        for theta in thetas {
            for phi in [0.0f64, 0.7, 1.9, 4.0] {
                let (st, ct) = theta.sin_cos();
                out.push(DVec3::new(st * phi.cos(), st * phi.sin(), ct));
            }
        }
        out
    }

    const ROUGHNESSES: [Roughness; 4] = [
        Roughness { x: 0.5, y: 0.5 },
        Roughness { x: 0.05, y: 0.05 },
        Roughness { x: 0.6, y: 0.25 },
        Roughness { x: 2.0, y: 1.5 },
    ];

    /// §1.6: at `gamma = 2` the family is GGX. Lambda and the projected area agree to a
    /// relative 1e-12 over the whole sphere, grazing directions included.
    #[test]
    fn is_ggx_at_gamma_2() {
        let mut worst: f64 = 0.0;
        for r in ROUGHNESSES {
            let (st, ggx) = (StudentT::new(r, 2.0).unwrap(), Ggx(r));
            for w in sphere() {
                for (x, y) in [(st.lambda(w), ggx.lambda(w)), (st.projected_area(w), ggx.projected_area(w))] {
                    let rel = if x == y { 0.0 } else { ((x - y) / y).abs() };
                    assert!(rel < 1e-12, "{r:?} w={w}: {x} vs GGX {y}");
                    worst = worst.max(rel);
                }
                let m = DVec3::new(0.3, -0.2, 0.9).normalize();
                assert!(((st.d(m) - ggx.d(m)) / ggx.d(m)).abs() < 1e-13);
            }
        }
        println!("largest relative difference from GGX: {worst:e}");
    }

    /// §1.6: as `gamma -> inf` the family tends to Beckmann as `1/gamma`. At `gamma = 1e6`
    /// Lambda is within a relative 1e-4 wherever Beckmann's exceeds 1e-6.
    #[test]
    fn tends_to_beckmann() {
        let mut worst: f64 = 0.0;
        for r in ROUGHNESSES {
            let (st, beckmann) = (StudentT::new(r, 1e6).unwrap(), Beckmann(r));
            for w in sphere() {
                let (x, y) = (st.lambda(w), beckmann.lambda(w));
                if y.abs() > 1e-6 && y.is_finite() {
                    let rel = ((x - y) / y).abs();
                    assert!(rel < 1e-4, "{r:?} w={w}: {x} vs Beckmann {y}");
                    worst = worst.max(rel);
                }
            }
        }
        println!("largest relative difference from Beckmann at gamma = 1e6: {worst:e}");
    }

    /// The slope-radius law of `D(m) m_z` and its inverse (Hammon's sampler, §3.3).
    #[test]
    fn slope_radius_inverts_its_cdf() {
        for gamma in [1.6, 2.0, 3.0, 10.0, 1e6] {
            let st = StudentT::new(Roughness::isotropic(1.0), gamma).unwrap();
            for u in [1e-12, 0.1, 0.5, 0.9, 1.0 - 1e-12] {
                let back = st.std_slope_cdf(st.std_slope_radius(u));
                assert!(((back - u) / u).abs() < 1e-9, "gamma {gamma}, u {u}: {back}");
            }
        }
    }

    /// Shapes at or below 3/2, and non-finite ones, are refused.
    #[test]
    fn refuses_shapes_without_a_finite_mean_slope() {
        for gamma in [1.5, 1.0, -2.0, f64::NAN, f64::INFINITY] {
            assert!(StudentT::new(Roughness::isotropic(0.5), gamma).is_none(), "gamma {gamma}");
        }
    }
}
