//! A tabulated isotropic NDF (docs/theory.md §1.7, §3.5): D(theta_m) given at nodes in the
//! normal's polar angle, linear in theta_m between them, normalized to a projected area of 1;
//! its Smith Lambda by quadrature of its definition, tabulated over the direction's angle;
//! visible normals by inversion of two tabulated radial laws and an exact rejection step.
//!
//! Anisotropic slope tables are not supported: the table is a function of theta_m alone, so
//! its slopes are centrally symmetric (the inside/outside flip of the walk, §4.3, needs that)
//! by construction.
//!
//! The table is in the normal's angle, not in a roughness: [`Ndf::roughness`] returns 1, the
//! identity stretch (§1.1), so that everything computed "in the roughness-1 configuration"
//! (Hammon's normals, §3.3) is computed on the table itself.

mod input;

use std::f64::consts::{PI, TAU};

use glam::DVec3;
use rand::Rng;

use crate::ndf::{Ndf, Roughness};
use crate::random::{azimuth, open01};

pub use input::{HEADER, MAX_STEP_DEG, MIN_ROWS, TableError};

/// The step in theta_m (degrees) the docs recommend (docs/theory.md §1.7): 361 rows from 0 to 90
/// degrees. Tables of GGX (roughness 0.1 to 2) and Student-T (gamma 3) at this step reproduce
/// their Lambda within 2.2e-5 (1 + |Lambda|) over the whole sphere.
pub const RECOMMENDED_STEP_DEG: f64 = 0.25;

/// Intervals of the table of `T(mu) = E[(X - mu)_+]` over `u = sin theta / (sin theta + |cos theta|)`
/// of the direction (§1.7).
const TAIL_INTERVALS: usize = 512;
/// Cells of the quantile tables of the two radial laws (§3.5), and of the refinements of their
/// first and last cells: the sampled law is within `1 / QUANTILE_CELLS` of the exact one in
/// Kolmogorov distance whatever the table, and the cells near the pole and the horizon, where
/// the laws are least uniform in theta, carry `1 / QUANTILE_CELLS^2` each.
const QUANTILE_CELLS: usize = 4096;

/// Gauss–Legendre nodes and weights of order 8 on [-1, 1], the positive half (Abramowitz &
/// Stegun Table 25.4).
const GAUSS_LEGENDRE_8: [(f64, f64); 4] = [
    (0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (0.796_666_477_413_626_7, 0.222_381_034_453_374_5),
    (0.960_289_856_497_536_3, 0.101_228_536_290_376_3),
];

/// `∫_a^b f` by 8-point Gauss–Legendre: exact to rounding for the analytic integrands of a
/// table's interval (§1.7).
fn gauss_legendre_8(a: f64, b: f64, f: impl Fn(f64) -> f64) -> f64 {
    let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
    GAUSS_LEGENDRE_8.iter().map(|&(x, w)| w * (f(mid - half * x) + f(mid + half * x))).sum::<f64>() * half
}

/// The isotropic NDF of a table of D(theta_m) (§1.7). Built by [`Tabulated::new`] or
/// [`Tabulated::from_csv`]; cheap to copy.
///
/// The [`Ndf`] trait asks for `Copy` (walks copy their surface into every lane), so the tables
/// are allocated once per build and kept for the rest of the process: a run builds one per
/// table file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tabulated {
    table: &'static Table,
}

/// What a [`Tabulated`] computes from: the normalized nodes and the tables derived from them.
#[derive(Debug, PartialEq)]
struct Table {
    /// Node angles theta_i (radians), from 0, strictly increasing.
    theta: Vec<f64>,
    /// D at the nodes, normalized [sr^-1].
    d: Vec<f64>,
    /// The factor the input's D was multiplied by.
    scale: f64,
    /// `(T, h dT/du)` at `u_k = k h`, `h = 1 / TAIL_INTERVALS` (§1.7).
    tail: Vec<(f64, f64)>,
    /// `T(0) = E[X_+] = E[r] / pi`, the mass of the second proposal of §3.5.
    tail_at_horizon: f64,
    /// The quantiles of the slope radius of `D(m) m_z`, `∝ D sin theta cos theta dtheta`.
    area_quantiles: Quantiles,
    /// The quantiles of the slope radius weighted by itself, `∝ D sin^2 theta dtheta`.
    mean_quantiles: Quantiles,
    /// Largest relative error of the interpolated T at the midpoints of its intervals.
    tail_error: f64,
    /// Largest error of the quantile tables' CDF at their cells' midpoints.
    quantile_error: f64,
}

impl Tabulated {
    /// The NDF of the rows of `csv` (header [`HEADER`], then `theta_m_deg,D` per line; lines
    /// starting with `#` are comments), checked and normalized as [`Tabulated::new`] does.
    pub fn from_csv(csv: &str) -> Result<Self, TableError> {
        Self::from_rows(&input::parse_csv(csv)?)
    }

    /// The NDF of D at the angles `theta_deg` (degrees), in any unit proportional to sr^-1:
    /// checked (§1.7: finite, `D >= 0`, at least [`MIN_ROWS`] angles from 0 rising by at most
    /// [`MAX_STEP_DEG`] up to 90 degrees, or up to a cut-off where D is 0) and multiplied by
    /// the factor that makes its projected area 1 ([`Tabulated::scale`]). The error names the
    /// first fault; rows are numbered as in a CSV file, the first at line 2.
    pub fn new(theta_deg: &[f64], d: &[f64]) -> Result<Self, TableError> {
        let rows: Vec<_> = theta_deg.iter().zip(d).enumerate().map(|(i, (&t, &d))| (i + 2, t, d)).collect();
        Self::from_rows(&rows)
    }

    fn from_rows(rows: &[(usize, f64, f64)]) -> Result<Self, TableError> {
        input::check(rows)?;
        let theta = rows.iter().map(|r| r.1.to_radians()).collect();
        let d = rows.iter().map(|r| r.2).collect();
        Ok(Self { table: Box::leak(Box::new(Table::build(theta, d))) })
    }

    /// The factor the table's D was multiplied by to make its projected area 1 (§1.7).
    pub fn scale(&self) -> f64 {
        self.table.scale
    }

    /// Largest relative error of Lambda's interpolation measured at the midpoints of its
    /// table's intervals, where a cubic Hermite interpolant errs most (§1.7); where
    /// `T < 10^-6 T(0)` the error is measured relative to `10^-6 T(0)`.
    pub fn lambda_error(&self) -> f64 {
        self.table.tail_error
    }

    /// Largest difference between the radial laws the visible-normal sampler draws from and the
    /// table's, in CDF, at the midpoints of their quantile cells (§3.5); at most
    /// `1 / 4096` whatever the table, and `1 / 4096^2` in the first and last cells.
    pub fn sampler_error(&self) -> f64 {
        self.table.quantile_error
    }
}

impl Table {
    /// `T(|mu|) = E[(X - |mu|)_+]` of the direction with sine `s` and absolute cosine `c`
    /// (§1.7), by cubic Hermite interpolation in `u = s / (s + c)`.
    #[inline]
    fn tail(&self, s: f64, c: f64) -> f64 {
        let x = s / (s + c) * TAIL_INTERVALS as f64;
        let i = (x as usize).min(TAIL_INTERVALS - 1);
        let f = x - i as f64;
        let ((t0, d0), (t1, d1)) = (self.tail[i], self.tail[i + 1]);
        let f2 = f * f;
        let (h01, h11) = (f2 * (3.0 - 2.0 * f), f2 * (f - 1.0));
        let h10 = f * (1.0 - f) * (1.0 - f);
        ((1.0 - h01) * t0 + h10 * d0 + h01 * t1 + h11 * d1).max(0.0)
    }

    fn build(theta: Vec<f64>, d: Vec<f64>) -> Self {
        let mut table = Table {
            theta,
            d,
            scale: 1.0,
            tail: Vec::new(),
            tail_at_horizon: 0.0,
            area_quantiles: Quantiles::default(),
            mean_quantiles: Quantiles::default(),
            tail_error: 0.0,
            quantile_error: 0.0,
        };
        // §1.7: ∫ D m_z dm = 2 pi ∫ D sin cos dtheta = 1.
        table.scale = 1.0 / (TAU * table.cumulative(|t| t.sin() * t.cos()).last().unwrap());
        table.d.iter_mut().for_each(|d| *d *= table.scale);
        table.tail_at_horizon = table.tail_and_exceedance(0.0).0;
        // At u = 0 (the zenith) T = 0 and dT/du = pi D(90 deg) / 4 (the r^-4 tail of the slope
        // density; 0 for a cut-off, whose last D is 0).
        let h = 1.0 / TAIL_INTERVALS as f64;
        let d_end = *table.d.last().unwrap();
        let node = |table: &Table, u: f64| {
            if u == 0.0 {
                return (0.0, h * PI * d_end / 4.0);
            }
            let (t, above) = table.tail_and_exceedance((1.0 - u).atan2(u));
            // dT/dmu = -P(X > mu) and mu = (1 - u) / u.
            (t, h * above / (u * u))
        };
        table.tail = (0..=TAIL_INTERVALS).map(|k| node(&table, k as f64 * h)).collect();
        let floor = 1e-6 * table.tail_at_horizon;
        table.tail_error = (0..TAIL_INTERVALS)
            .map(|k| {
                let u = (k as f64 + 0.5) * h;
                let exact = table.tail_and_exceedance((1.0 - u).atan2(u)).0;
                (table.tail(u, 1.0 - u) - exact).abs() / exact.max(floor)
            })
            .fold(0.0, f64::max);
        let area = |t: f64| t.sin() * t.cos();
        let mean = |t: f64| t.sin() * t.sin();
        table.area_quantiles = table.quantiles(area);
        table.mean_quantiles = table.quantiles(mean);
        table.quantile_error = table
            .quantile_error_of(&table.area_quantiles, area)
            .max(table.quantile_error_of(&table.mean_quantiles, mean));
        table
    }

    /// D at `theta` (radians), linear between the nodes, 0 beyond the last.
    #[inline]
    fn d_at(&self, theta: f64) -> f64 {
        let i = self.theta.partition_point(|&t| t <= theta);
        if i == 0 || i == self.theta.len() {
            return if theta == *self.theta.last().unwrap() { *self.d.last().unwrap() } else { 0.0 };
        }
        let (a, b) = (self.theta[i - 1], self.theta[i]);
        self.d[i - 1] + (self.d[i] - self.d[i - 1]) * (theta - a) / (b - a)
    }

    /// D on the table's interval `i`, `[theta_i, theta_{i+1}]`, where it is linear.
    #[inline]
    fn on_interval(&self, i: usize) -> impl Fn(f64) -> f64 + '_ {
        let (a, b, da, db) = (self.theta[i], self.theta[i + 1], self.d[i], self.d[i + 1]);
        move |theta| da + (db - da) * (theta - a) / (b - a)
    }

    /// `∫_{theta_i}^{theta} D weight` within the interval `i` (where D is linear, so that the
    /// integrand is analytic and Gauss–Legendre exact to rounding).
    fn partial(&self, i: usize, theta: f64, weight: impl Fn(f64) -> f64) -> f64 {
        let d = self.on_interval(i);
        gauss_legendre_8(self.theta[i], theta, |t| d(t) * weight(t))
    }

    /// `∫_0^{theta_i} D weight` at every node `theta_i`.
    fn cumulative(&self, weight: impl Fn(f64) -> f64 + Copy) -> Vec<f64> {
        let mut out = vec![0.0];
        for i in 0..self.theta.len() - 1 {
            out.push(out[i] + self.partial(i, self.theta[i + 1], weight));
        }
        out
    }

    /// `∫_0^theta D weight`, from the nodes' `cumulative`.
    fn cdf(&self, cumulative: &[f64], theta: f64, weight: impl Fn(f64) -> f64) -> f64 {
        let i = self.theta.partition_point(|&t| t <= theta);
        if i == self.theta.len() {
            return *cumulative.last().unwrap();
        }
        cumulative[i - 1] + self.partial(i - 1, theta, weight)
    }

    /// `(T(mu), P(X > mu))` for `mu = tan beta >= 0` (§1.7): with the slope radius `r = tan theta`,
    /// `T = (2 / cos beta) ∫_beta D sin theta (S - sin beta cos theta phi0) dtheta` and
    /// `P = 2 ∫_beta D sin theta cos theta phi0 dtheta`, `S = sqrt(sin(theta - beta) sin(theta + beta))`,
    /// `phi0 = atan2(S, sin beta cos theta)`. Both are analytic in `t = sqrt(theta - beta)`,
    /// not in theta (a square root at `theta = beta`), so each interval is integrated in t.
    fn tail_and_exceedance(&self, beta: f64) -> (f64, f64) {
        let (sb, cb) = beta.sin_cos();
        let (mut tail, mut above) = (0.0, 0.0);
        for i in 0..self.theta.len() - 1 {
            let (a, b) = (self.theta[i], self.theta[i + 1]);
            if b <= beta {
                continue;
            }
            let d = self.on_interval(i);
            let (t0, t1) = ((a.max(beta) - beta).sqrt(), (b - beta).sqrt());
            let (mid, half) = (0.5 * (t0 + t1), 0.5 * (t1 - t0));
            for &(x, w) in &GAUSS_LEGENDRE_8 {
                for t in [mid - half * x, mid + half * x] {
                    let theta = beta + t * t;
                    let (st, ct) = theta.sin_cos();
                    let s = ((t * t).sin() * (theta + beta).sin()).max(0.0).sqrt();
                    let phi0 = s.atan2(sb * ct);
                    // dtheta = 2 t dt.
                    let weight = w * half * 2.0 * t * d(theta) * 2.0 * st;
                    tail += weight * (s - sb * ct * phi0) / cb;
                    above += weight * ct * phi0;
                }
            }
        }
        (tail, above)
    }

    /// The quantiles of the law `∝ D(theta) weight(theta) dtheta` on `[0, theta_max]`.
    fn quantiles(&self, weight: impl Fn(f64) -> f64 + Copy) -> Quantiles {
        let cumulative = self.cumulative(weight);
        let k = QUANTILE_CELLS as f64;
        let nodes = |offset: f64, width: f64| -> Vec<f64> {
            (0..=QUANTILE_CELLS).map(|j| self.quantile_of(&cumulative, weight, offset + width * j as f64 / k)).collect()
        };
        Quantiles {
            main: Cells::new(nodes(0.0, 1.0)),
            first: Cells::new(nodes(0.0, 1.0 / k)),
            last: Cells::new(nodes(1.0 - 1.0 / k, 1.0 / k)),
        }
    }

    /// theta where the law `∝ D weight` (with the nodes' `cumulative`) reaches the probability
    /// `p`: Newton's method safeguarded by bisection in the table's interval that holds it.
    fn quantile_of(&self, cumulative: &[f64], weight: impl Fn(f64) -> f64, p: f64) -> f64 {
        let total = *cumulative.last().unwrap();
        // The end of the support: the last node before which there is mass.
        let end = cumulative.iter().position(|&c| c >= total).unwrap();
        if p <= 0.0 {
            return 0.0;
        }
        if p >= 1.0 {
            return self.theta[end];
        }
        let target = total * p;
        let i = cumulative.partition_point(|&c| c < target).clamp(1, end) - 1;
        let (mut lo, mut hi) = (self.theta[i], self.theta[i + 1]);
        let mut x = 0.5 * (lo + hi);
        for _ in 0..100 {
            let f = cumulative[i] + self.partial(i, x, &weight) - target;
            if f.abs() <= 1e-16 * total || hi - lo < 1e-15 {
                break;
            }
            if f > 0.0 {
                hi = x
            } else {
                lo = x
            }
            let newton = x - f / (self.on_interval(i)(x) * weight(x));
            x = if newton > lo && newton < hi { newton } else { 0.5 * (lo + hi) };
        }
        x
    }

    /// The largest `|F(theta_Q(u)) - u|` at the midpoints `u` of the cells of `quantiles` (the
    /// refined ones at the ends), with F the exact CDF of the law `∝ D weight`.
    fn quantile_error_of(&self, quantiles: &Quantiles, weight: impl Fn(f64) -> f64 + Copy) -> f64 {
        let cumulative = self.cumulative(weight);
        let total = *cumulative.last().unwrap();
        let k = QUANTILE_CELLS as f64;
        let main = (1..QUANTILE_CELLS - 1).map(|j| (j as f64 + 0.5) / k);
        let ends = (0..QUANTILE_CELLS).flat_map(|j| [(j as f64 + 0.5) / (k * k), 1.0 - (j as f64 + 0.5) / (k * k)]);
        let theta = |u: f64| {
            let (s, c) = quantiles.at(u);
            s.atan2(c)
        };
        main.chain(ends).map(|u| (self.cdf(&cumulative, theta(u), weight) / total - u).abs()).fold(0.0, f64::max)
    }
}

/// The quantiles of a radial law (§3.5): at `u = k / QUANTILE_CELLS`, and within the first
/// and the last of those cells at `QUANTILE_CELLS` quantiles of their own.
#[derive(Debug, Default, PartialEq)]
struct Quantiles {
    main: Cells,
    first: Cells,
    last: Cells,
}

impl Quantiles {
    /// `(sin theta, cos theta)` at the probability `u`.
    #[inline]
    fn at(&self, u: f64) -> (f64, f64) {
        let k = QUANTILE_CELLS as f64;
        let x = u * k;
        let i = (x as usize).min(QUANTILE_CELLS - 1);
        match i {
            0 => self.first.point(x * k),
            _ if i == QUANTILE_CELLS - 1 => self.last.point((x - i as f64) * k),
            _ => self.main.point(x),
        }
    }

    /// The probability below the angle with `(sin, cos)` `sc`, the inverse of [`Quantiles::at`].
    #[inline]
    fn cdf(&self, sc: (f64, f64)) -> f64 {
        let k = QUANTILE_CELLS as f64;
        let x = self.main.position(sc);
        let x = match x as usize {
            0 => self.first.position(sc) / k,
            i if i == QUANTILE_CELLS - 1 => i as f64 + self.last.position(sc) / k,
            _ => x,
        };
        (x / k).min(1.0)
    }
}

/// `QUANTILE_CELLS` cells between `QUANTILE_CELLS + 1` quantile nodes, each node's angle
/// stored as its `(sin, cos)`. Within a cell the normal runs along the chord between the nodes' normals,
/// normalized (for cells of at most a few hundredths of a degree, as good as linear in theta),
/// so that a draw needs no trigonometry.
#[derive(Debug, Default, PartialEq)]
struct Cells {
    sin_cos: Vec<(f64, f64)>,
}

impl Cells {
    fn new(theta: Vec<f64>) -> Self {
        Cells { sin_cos: theta.iter().map(|t| t.sin_cos()).collect() }
    }

    /// `(sin theta, cos theta)` at the position `x` in `[0, QUANTILE_CELLS)`: in cell
    /// `floor(x)`, at the fraction `x - floor(x)` of its chord.
    #[inline]
    fn point(&self, x: f64) -> (f64, f64) {
        let i = (x as usize).min(QUANTILE_CELLS - 1);
        let f = x - i as f64;
        let ((s0, c0), (s1, c1)) = (self.sin_cos[i], self.sin_cos[i + 1]);
        let (s, c) = (s0 + f * (s1 - s0), c0 + f * (c1 - c0));
        let norm = (s * s + c * c).sqrt();
        (s / norm, c / norm)
    }

    /// The position of the angle with `(sin, cos)` `(s, c)`, the inverse of [`Cells::point`]:
    /// on the chord between the normals of angles `theta_0` and `theta_1`, the point at the
    /// fraction `f` has the angle `theta` with
    /// `f = sin(theta - theta_0) / (sin(theta - theta_0) + sin(theta_1 - theta))`, each sine a
    /// cross product of the two `(sin, cos)`: no trigonometry. `QUANTILE_CELLS` beyond the last
    /// node.
    #[inline]
    fn position(&self, (s, c): (f64, f64)) -> f64 {
        // sin(theta - theta_node) >= 0: the node is at or below the angle.
        let i = self.sin_cos.partition_point(|&(sn, cn)| s * cn - c * sn >= 0.0);
        if i > QUANTILE_CELLS {
            return QUANTILE_CELLS as f64;
        }
        let ((s0, c0), (s1, c1)) = (self.sin_cos[i - 1], self.sin_cos[i]);
        let (after, before) = (s * c0 - c * s0, s1 * c - c1 * s);
        (i - 1) as f64 + after / (after + before)
    }
}

impl Ndf for Tabulated {
    /// 1: the table is in the normal's angle, and the stretch of §1.1 is the identity.
    fn roughness(&self) -> Roughness {
        Roughness::isotropic(1.0)
    }

    fn d(&self, m: DVec3) -> f64 {
        if m.z <= 0.0 {
            return 0.0;
        }
        self.table.d_at(m.x.hypot(m.y).atan2(m.z))
    }

    /// `Lambda = T(mu) / mu` above the horizon (§1.4, §1.7), `-1 - Lambda(-w)` below.
    fn lambda(&self, w: DVec3) -> f64 {
        if w.z == 0.0 {
            return if w.z.is_sign_positive() { f64::INFINITY } else { f64::NEG_INFINITY };
        }
        let (s, c) = ((w.x * w.x + w.y * w.y).sqrt(), w.z.abs());
        let above = self.table.tail(s, c) * s / c;
        if w.z > 0.0 { above } else { -1.0 - above }
    }

    /// `A = max(w_z, 0) + sin theta T(|mu|)` on the whole sphere (§1.5, §1.7).
    fn projected_area(&self, w: DVec3) -> f64 {
        let s = (w.x * w.x + w.y * w.y).sqrt();
        w.z.max(0.0) + s * self.table.tail(s, w.z.abs())
    }

    /// Rejection from the two radial laws of the table (§3.5), in the frame of w's azimuth.
    /// Exact for the laws the quantile tables sample ([`Tabulated::sampler_error`]).
    fn sample_visible<R: Rng + ?Sized>(&self, w: DVec3, rng: &mut R) -> DVec3 {
        let table = self.table;
        let s = (w.x * w.x + w.y * w.y).sqrt();
        let (cos_o, sin_o) = if s > 0.0 { (w.x / s, w.y / s) } else { (1.0, 0.0) };
        let c = w.z;
        // A normal of polar angle theta at azimuth psi from w's with density ∝ cos psi on
        // |psi| < pi/2 (sin psi uniform): the facets that lean towards w.
        let leaning = |(st, ct): (f64, f64), rng: &mut R| {
            let v = 2.0 * open01(rng) - 1.0;
            DVec3::new(st * (1.0 - v * v).sqrt(), st * v, ct)
        };
        let m = if c >= 0.0 {
            // (mu - x)_+ <= mu + (-x)_+ in the slope x along w: the first proposal (mass mu) is
            // D m_z itself, the second (mass T(0)) the leaning facets; p_first = mu / (mu + T(0)).
            let p_first = c / (c + table.tail_at_horizon * s);
            loop {
                if open01(rng) >= p_first {
                    break leaning(table.mean_quantiles.at(open01(rng)), rng);
                }
                let (st, ct) = table.area_quantiles.at(open01(rng));
                let (cp, sp) = azimuth(rng);
                let m = DVec3::new(st * cp, st * sp, ct);
                // Kept with (w·m)_+ / (c m_z): always where the facet leans towards w.
                if m.x >= 0.0 || open01(rng) * c * ct < c * ct + s * m.x {
                    break m;
                }
            }
        } else {
            // Below the horizon only slopes r > a = |c| / s face w: the leaning facets of those
            // radii, kept with (w·m)_+ / (s m_x) = (t - a) / t in the slope t = r cos psi.
            // tan theta_a = a = |c| / s, and (s, c) is a unit vector.
            let u0 = table.mean_quantiles.cdf((-c, s));
            if u0 >= 1.0 {
                return DVec3::Z;
            }
            loop {
                let m = leaning(table.mean_quantiles.at(u0 + (1.0 - u0) * open01(rng)), rng);
                let toward = s * m.x;
                if open01(rng) * toward < toward + c * m.z {
                    break m;
                }
            }
        };
        DVec3::new(m.x * cos_o - m.y * sin_o, m.x * sin_o + m.y * cos_o, m.z)
    }

    /// The slope radius at the quantile `u` of `D(m) m_z` (Hammon's sampler, §3.3).
    fn std_slope_radius(&self, u: f64) -> f64 {
        let (s, c) = self.table.area_quantiles.at(u);
        s / c
    }

    fn std_slope_cdf(&self, r: f64) -> f64 {
        let norm = r.hypot(1.0);
        let sc = if norm.is_finite() { (r / norm, 1.0 / norm) } else { (1.0, 0.0) };
        self.table.area_quantiles.cdf(sc)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A valid table: a cosine lobe every degree.
    fn rows() -> (Vec<f64>, Vec<f64>) {
        let theta: Vec<f64> = (0..=90).map(f64::from).collect();
        let d = theta.iter().map(|t: &f64| t.to_radians().cos()).collect();
        (theta, d)
    }

    /// Each fault of §1.7 is refused with its own error, naming the line (the CSV file's: the
    /// first row is line 2) and the value.
    #[test]
    fn refuses_each_fault_with_its_own_error() {
        let refuse = |edit: &dyn Fn(&mut Vec<f64>, &mut Vec<f64>)| {
            let (mut theta, mut d) = rows();
            edit(&mut theta, &mut d);
            Tabulated::new(&theta, &d).unwrap_err()
        };
        assert_eq!(
            refuse(&|t, d| {
                t.truncate(15);
                d.truncate(15);
            }),
            TableError::TooFewRows { rows: 15 }
        );
        assert_eq!(refuse(&|_, d| d[10] = -1.0), TableError::Negative { line: 12, value: -1.0 });
        let nan = refuse(&|_, d| d[3] = f64::NAN);
        assert!(matches!(nan, TableError::NotFinite { line: 5, column: "D", .. }), "{nan:?}");
        assert_eq!(
            refuse(&|t, _| t[7] = f64::INFINITY),
            TableError::NotFinite { line: 9, column: "theta_m_deg", value: f64::INFINITY }
        );
        assert_eq!(refuse(&|t, _| t[0] = 0.5), TableError::FirstAngle { theta: 0.5 });
        assert_eq!(refuse(&|t, _| t[20] = 19.0), TableError::NotIncreasing { line: 22, theta: 19.0, previous: 19.0 });
        assert_eq!(
            refuse(&|t, d| {
                t.remove(30);
                d.remove(30);
            }),
            TableError::StepTooWide { line: 32, step: 2.0 }
        );
        assert_eq!(refuse(&|t, _| t[90] = 90.5), TableError::AboveNinety { line: 92, theta: 90.5 });
        assert_eq!(
            refuse(&|t, d| {
                t.truncate(61);
                d.truncate(61);
            }),
            TableError::EndsEarly { theta: 60.0, value: 60f64.to_radians().cos() }
        );
        assert_eq!(refuse(&|_, d| d.iter_mut().for_each(|x| *x = 0.0)), TableError::AllZero);
        // Every message names what is allowed.
        for e in [TableError::TooFewRows { rows: 3 }, TableError::StepTooWide { line: 4, step: 2.0 }] {
            assert!(e.to_string().contains("at least 16") || e.to_string().contains("at most 1 deg"), "{e}");
        }
    }

    /// The CSV form: comments and blank lines skipped, the header required, each line two
    /// numbers; errors name the file's line.
    #[test]
    fn reads_csv_and_names_the_bad_line() {
        let (theta, d) = rows();
        let body: String = theta.iter().zip(&d).map(|(t, d)| format!("{t},{d}\n")).collect();
        let csv = format!("# a cosine lobe\n\ntheta_m_deg, D\n{body}");
        let table = Tabulated::from_csv(&csv).unwrap();
        // ∫ cos * cos sin 2 pi dtheta = 2 pi / 3: the factor is 3 / (2 pi), to the relative
        // 1e-4 by which the linear interpolant of the cosine every degree differs.
        assert!((table.scale() / (3.0 / TAU) - 1.0).abs() < 1e-4, "scale {}", table.scale());
        assert_eq!(Tabulated::from_csv("theta,D\n0,1\n"), Err(TableError::Header { found: "theta,D".into() }));
        let bad = csv.replace("\n45,", "\n45;");
        assert_eq!(
            Tabulated::from_csv(&bad),
            Err(TableError::Row { line: 49, text: format!("45;{}", 45f64.to_radians().cos()) })
        );
        let negative = csv.replace("\n45,", "\n45,-");
        assert!(matches!(Tabulated::from_csv(&negative), Err(TableError::Negative { line: 49, .. })));
    }

    /// Hammon's sampler's slope-radius law (§3.3): the quantile table and its CDF invert each
    /// other, and match the exact CDF of a cosine lobe, `1 - cos^3 theta`, within the stated
    /// sampler error.
    #[test]
    fn slope_radius_quantiles_invert_their_cdf() {
        let (theta, d) = rows();
        let table = Tabulated::new(&theta, &d).unwrap();
        for u in [1e-9, 1e-5, 0.1, 0.5, 0.9, 1.0 - 1e-5, 1.0 - 1e-9] {
            let r = table.std_slope_radius(u);
            assert!((table.std_slope_cdf(r) - u).abs() < 1e-12, "u {u}: {}", table.std_slope_cdf(r));
            // The table's own D is linear between the nodes, not the cosine: a relative 1e-4 in
            // its CDF on top of the quantile table's error.
            let exact = 1.0 - r.atan().cos().powi(3);
            assert!((exact - u).abs() < table.sampler_error() + 1e-4 * u, "u {u}: exact CDF {exact}");
        }
    }
}
